// The HTML report's time slider (docs/viewer.md, "A path checked continuously"), in headless
// Chromium: `cadclash check box_a.obj box_near.obj --path P.csv --continuous --html`, then the
// slider is set to times inside and outside the timeline's spans and the page's drawn state is
// checked against the JSON report of the same run and against poses computed here from the CSV.
//
// Cases:
// - contact: data/collide/path_ok.csv (--tolerance 0.01): the near box comes within the tolerance
//   of box_a at t ~ 0.98 and stays in contact to step 2. At a time inside a span proved in contact
//   at both ends, and at the middle of the narrow span where the contact begins, the surfaces
//   coloured (and their states and colours) are exactly those whose timeline spans hold the time;
//   at a time no span holds nothing is coloured (nor drawn: pixels read back). The moving box is
//   drawn where the CSV's poses, interpolated here, put it.
// - turn: a path written here that turns the near box about z by 170 degrees, then by 80 more
//   (its last quaternion given with the opposite sign: the shorter arc must be taken), with step
//   numbers 0, 1, 3, and moves it as it turns: the box is drawn at the screw computed here (the
//   textbook formulas: slerp, and FCL's axis point of the displacement; not the page's), at several
//   times; it never comes near box_a, so nothing is coloured.
// - plain: path_ok.csv without --continuous: no slider, the page as before (last step, class
//   colours); and the JSON report is the same bytes with and without --html.
//
// Usage: node path_test.mjs --cadclash EXE --viewer-dir DIR --out DIR --data DIR
// Exit codes: 0 pass, 1 fail, 77 skipped (the data is missing).
import { existsSync, mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { CHROMIUM, CHROMIUM_ARGS, Failure, cadclash, check, keyArgs, openReport, runTest } from './browser_common.mjs';

// The page's colours of the two time states (viewer/src/classes.js, TIME_COLOURS).
const STATE_COLOUR = { contact: 0xff8c1a, may: 0xf032e6 };
// The instance matrices are drawn from Float32 buffers.
const POSE_TOLERANCE = 1e-5;

function args() {
  return keyArgs(['cadclash', 'viewer-dir', 'out', 'data']);
}

// The CSV's poses per step, read here: {steps: [numbers], poses: Map path -> per step [t, q]}
// (an instance keeps its place until a row moves it; the boxes start at the identity).
function readPath(csv) {
  const rows = [];
  for (const line of readFileSync(csv, 'utf8').split('\n')) {
    const l = line.trim();
    if (!l || l.startsWith('#') || l.startsWith('step')) continue;
    const f = l.split(',');
    const q = f.slice(5, 9).map(Number);
    const n = Math.hypot(...q);
    rows.push({ step: Number(f[0]), path: f[1], t: f.slice(2, 5).map(Number), q: q.map((c) => c / n) });
  }
  const steps = [...new Set(rows.map((r) => r.step))];
  const paths = [...new Set(rows.map((r) => r.path))];
  const poses = new Map();
  for (const p of paths) {
    let now = { t: [0, 0, 0], q: [1, 0, 0, 0] };
    poses.set(p, steps.map((s) => {
      for (const r of rows) if (r.step === s && r.path === p) now = { t: r.t, q: r.q };
      return now;
    }));
  }
  return { steps, poses };
}

// The textbook slerp on the shorter arc.
function slerp(a, b, s) {
  let dot = a.reduce((sum, c, k) => sum + c * b[k], 0);
  if (dot < 0) { b = b.map((c) => -c); dot = -dot; }
  if (dot > 1 - 1e-12) return a.map((c, k) => c + s * (b[k] - c));
  const theta = Math.acos(dot);
  const wa = Math.sin((1 - s) * theta) / Math.sin(theta), wb = Math.sin(s * theta) / Math.sin(theta);
  return a.map((c, k) => wa * c + wb * b[k]);
}

// Where the CSV puts instance `path` at time t: the screw of the displacement between the two steps
// (a turn about an axis and a shift along it): its rotation slerped, its axis through the point FCL's
// ScrewMotion takes, (t_a + t_b + axis x (t_b - t_a) cot(angle / 2)) / 2, a's origin turned about
// it and shifted along it.
function expectedPose(path, { steps, poses }, t) {
  const at = poses.get(path);
  if (t <= steps[0]) return at[0];
  if (t >= steps.at(-1)) return at.at(-1);
  let k = 0;
  while (steps[k + 1] <= t) ++k;
  const s = (t - steps[k]) / (steps[k + 1] - steps[k]);
  const a = at[k], b = at[k + 1];
  const q = slerp(a.q, b.q, s);
  // The world turn b.q a.q^-1 on the shorter arc.
  const [aw, ax, ay, az] = a.q, [bw, bx, by, bz] = b.q;
  let r = [bw * aw + bx * ax + by * ay + bz * az, -bw * ax + bx * aw - by * az + bz * ay,
    -bw * ay + bx * az + by * aw - bz * ax, -bw * az - bx * ay + by * ax + bz * aw];
  if (r[0] < 0) r = r.map((c) => -c);
  const v = Math.hypot(r[1], r[2], r[3]);
  const o = b.t.map((c, i) => c - a.t[i]);
  if (v < 1e-12) return { t: a.t.map((c, i) => c + s * o[i]), q };
  const angle = 2 * Math.atan2(v, r[0]), axis = [r[1] / v, r[2] / v, r[3] / v];
  const x = [axis[1] * o[2] - axis[2] * o[1], axis[2] * o[0] - axis[0] * o[2], axis[0] * o[1] - axis[1] * o[0]];
  const cot = 1 / Math.tan(angle / 2);
  const p = [0, 1, 2].map((i) => (a.t[i] + b.t[i] + x[i] * cot) / 2);
  const along = axis.reduce((sum, c, i) => sum + c * o[i], 0);
  const turn = { t: [0, 0, 0], q: [Math.cos(s * angle / 2), ...axis.map((c) => c * Math.sin(s * angle / 2))] };
  const moved = place(turn, a.t.map((c, i) => c - p[i]));
  return { t: moved.map((c, i) => p[i] + c + s * along * axis[i]), q };
}

// p rotated by unit quaternion q = [w, x, y, z], then moved by t.
function place({ t, q }, p) {
  const [w, x, y, z] = q;
  const u = [x, y, z];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const c1 = cross(u, p), c2 = cross(u, c1);
  return p.map((v, k) => v + 2 * w * c1[k] + 2 * c2[k] + t[k]);
}

// p by a column-major 4x4 matrix.
const transform = (m, p) => [0, 1, 2].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);

// Corners of the near box (data/collide/box_near.obj) and of box_a: where the drawn matrix and the
// expected pose put them must agree.
const CORNERS = [[1.5, 0, 0], [2.5, 1, 1], [1.5, 1, 0], [0, 0, 0], [1, 1, 1]];

function checkPoses(state, path, t, what) {
  for (const inst of state.instances) {
    const want = expectedPose(inst.path, path, t);
    const drawn = [inst.matrix, ...state.coloured.filter((c) => c.instance === inst.instance).map((c) => c.matrix)];
    for (const m of drawn)
      for (const p of CORNERS) {
        const got = transform(m, p), exp = place(want, p);
        const err = Math.max(...got.map((v, k) => Math.abs(v - exp[k])));
        check(err <= POSE_TOLERANCE, `${what}: ${inst.path} drawn with ${p} at ${got}, expected ${exp} (t = ${t})`);
      }
  }
}

// The surfaces the JSON timeline has in contact (or maybe) at time t: "path\nsurface" -> state,
// contact winning over may for a surface in several pairs.
function expectedColoured(report, t) {
  const out = new Map();
  for (const pair of report.timeline.pairs)
    for (const sp of pair.surfaces) {
      let state = null;
      for (const s of sp.spans) if (s.t0 <= t && t <= s.t1) state = s.contact_at_ends ? 'contact' : (state ?? 'may');
      if (!state) continue;
      for (const side of [sp.a, sp.b]) {
        check(side.surface !== undefined, 'a whole-part timeline side: this test expects surface pairs');
        const key = `${side.instance}\n${side.surface}`;
        if (out.get(key) !== 'contact') out.set(key, state);
      }
    }
  return out;
}

const openPage = (browser, html) => openReport(browser, html);

// Moves the slider to t as a user does (its input event), and returns what the page draws then.
async function slideTo(page, t) {
  await page.$eval('#path-slider', (el, v) => {
    el.value = String(v);
    el.dispatchEvent(new Event('input', { bubbles: true }));
  }, t);
  await page.waitForFunction((v) => document.documentElement.dataset.cadclashTime === String(v), t, { timeout: 10000 });
  return page.evaluate(() => window.cadclashViewer.path.state());
}

// Pixels the coloured surfaces cover alone (no grey context, no selection).
const colouredPixels = (page) =>
  page.evaluate(() => window.cadclashViewer.coveredPixels({ context: false, sides: [false, false] }).covered);

async function checkColoured(page, report, state, t, what) {
  check(Math.abs(state.time - t) < 1e-12, `${what}: the page shows t = ${state.time}, expected ${t}`);
  check(!state.classColoursShown, `${what}: the class colours of the last step are drawn over the time slider's`);
  const want = expectedColoured(report, t);
  const got = new Map(state.coloured.map((c) => [`${c.path}\n${c.name}`, c]));
  for (const [key, st] of want) {
    const c = got.get(key);
    check(c, `${what}: ${key.replace('\n', ' ')} is not coloured, expected ${st} (t = ${t})`);
    check(c.state === st, `${what}: ${key.replace('\n', ' ')} is coloured ${c.state}, expected ${st}`);
    check(c.colour === STATE_COLOUR[st], `${what}: ${key.replace('\n', ' ')} has colour ${c.colour.toString(16)}, expected ${STATE_COLOUR[st].toString(16)}`);
  }
  for (const key of got.keys()) check(want.has(key), `${what}: ${key.replace('\n', ' ')} is coloured, but no span holds t = ${t}`);
  // The timeline list marks the same surface pairs.
  const rows = await page.$$eval('#timeline-pairs tr[data-pair]', (trs) => trs.map((tr) => tr.dataset.state));
  const pairStates = report.timeline.pairs.flatMap((p) => p.surfaces.map((sp) => {
    let st = '';
    for (const s of sp.spans) if (s.t0 <= t && t <= s.t1) st = s.contact_at_ends ? 'contact' : (st || 'may');
    return st;
  }));
  check(JSON.stringify(rows) === JSON.stringify(pairStates), `${what}: the timeline list marks ${rows}, expected ${pairStates}`);
  const pixels = await colouredPixels(page);
  if (want.size) check(pixels > 0, `${what}: ${want.size} surfaces should be coloured, none is drawn`);
  else check(pixels === 0, `${what}: nothing is in contact, yet coloured surfaces cover ${pixels} pixels`);
  const states = [...want.values()];
  console.log(`${what}: t = ${t}: ${states.filter((s) => s === 'contact').length} surfaces in contact, ` +
              `${states.filter((s) => s === 'may').length} may begin or end, ${pixels} pixels coloured`);
}

async function contactCase(browser, a, out, csv) {
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  cadclash(a.cadclash, ['check', join(a.data, 'box_a.obj'), join(a.data, 'box_near.obj'), '--path', csv, '--continuous',
                        '--tolerance', '0.01', '--no-timings', '--json', json, '--html', html]);
  const report = JSON.parse(readFileSync(json, 'utf8'));
  const path = readPath(csv);
  const pairs = report.timeline.pairs;
  check(pairs.length === 1, `the timeline has ${pairs.length} instance pairs, expected 1`);
  const contact = pairs[0].spans.find((s) => s.contact_at_ends && s.t1 - s.t0 > 0.5);
  const narrow = pairs[0].spans.find((s) => !s.contact_at_ends);
  check(contact && narrow, `expected a long contact span and a narrow one: ${JSON.stringify(pairs[0].spans)}`);
  const page = await openPage(browser, html);
  try {
    const p = await page.evaluate(() => window.cadclashViewer.path && { first: window.cadclashViewer.path.first, last: window.cadclashViewer.path.last });
    check(p && p.first === path.steps[0] && p.last === path.steps.at(-1), `the slider runs over ${JSON.stringify(p)}, expected ${path.steps[0]}..${path.steps.at(-1)}`);
    check(await page.isVisible('#path-slider') && await page.isVisible('#path-play'), 'no slider or play button');
    // It opens at the last step, as a page without a slider does.
    const first = await page.evaluate(() => window.cadclashViewer.path.state());
    check(first.time === path.steps.at(-1), `the page opens at t = ${first.time}, expected the last step`);
    // Inside the contact span, between two steps (the box moves in x, y and z there).
    // Times with a few digits: a range input gives back its value in fewer digits than a double's.
    const round6 = (t) => Math.round(t * 1e6) / 1e6;
    const tContact = round6(Math.max(contact.t0 + 0.4 * (contact.t1 - contact.t0), 1.2));
    check(tContact < contact.t1 && !Number.isInteger(tContact), `no time inside ${JSON.stringify(contact)} between steps`);
    let state = await slideTo(page, tContact);
    await checkColoured(page, report, state, tContact, 'inside the contact span');
    check(state.coloured.some((c) => c.state === 'contact'), 'inside the contact span nothing is coloured in contact');
    checkPoses(state, path, tContact, 'inside the contact span');
    await page.screenshot({ path: join(out, 'viewer.png') });
    // The middle of the narrow span where the contact begins: "may begin or end here".
    const tNarrow = round6((narrow.t0 + narrow.t1) / 2);
    check(narrow.t0 < tNarrow && tNarrow < narrow.t1, `no six-digit time inside ${JSON.stringify(narrow)}`);
    state = await slideTo(page, tNarrow);
    await checkColoured(page, report, state, tNarrow, 'inside the narrow span');
    check(state.coloured.some((c) => c.state === 'may'), 'inside the narrow span nothing is coloured "may begin or end"');
    checkPoses(state, path, tNarrow, 'inside the narrow span');
    // Before it, halfway between steps 0 and 1: the boxes are apart.
    const tFree = 0.5;
    check(pairs[0].spans.every((s) => tFree < s.t0 || tFree > s.t1), `t = ${tFree} is inside a span`);
    state = await slideTo(page, tFree);
    await checkColoured(page, report, state, tFree, 'apart');
    check(state.coloured.length === 0, `at t = ${tFree} ${state.coloured.length} surfaces are coloured`);
    checkPoses(state, path, tFree, 'apart');
    // Clicking a span link goes to its middle.
    await page.locator('#timeline a[data-t]').first().click();
    const linked = (pairs[0].spans[0].t0 + pairs[0].spans[0].t1) / 2;
    await page.waitForFunction((v) => document.documentElement.dataset.cadclashTime === String(v), linked, { timeout: 10000 });
    // Play moves the time forward from the start; pause stops it.
    await page.click('#path-play');
    await page.waitForFunction(() => window.cadclashViewer.path.state().time > window.cadclashViewer.path.first, null, { timeout: 10000 });
    await page.click('#path-play');
    check(!(await page.evaluate(() => window.cadclashViewer.path.playing())), 'pause did not stop the playing');
    const paused = (await page.evaluate(() => window.cadclashViewer.path.state())).time;
    await page.waitForTimeout(300);
    check((await page.evaluate(() => window.cadclashViewer.path.state())).time === paused, 'the time moves while paused');
    console.log(`play/pause: paused at t = ${paused}; screenshot ${join(out, 'viewer.png')}`);
  } finally {
    await page.close();
  }
}

async function turnCase(browser, a, out) {
  const csv = join(out, 'path_turn.csv');
  const d = Math.PI / 180;
  writeFileSync(csv, [
    'step,instance_path,tx,ty,tz,qw,qx,qy,qz',
    '0,/box_near.obj/box_near,0,0,0,1,0,0,0',
    `1,/box_near.obj/box_near,0,0,0.5,${Math.cos(85 * d)},0,0,${Math.sin(85 * d)}`,
    // 250 degrees about z, written as -q: the shorter arc from 170 degrees is +80, not -280.
    `3,/box_near.obj/box_near,0.2,-0.1,0,${-Math.cos(125 * d)},0,0,${-Math.sin(125 * d)}`,
  ].join('\n') + '\n');
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  cadclash(a.cadclash, ['check', join(a.data, 'box_a.obj'), join(a.data, 'box_near.obj'), '--path', csv, '--continuous',
                        '--tolerance', '0.01', '--no-timings', '--json', json, '--html', html]);
  const report = JSON.parse(readFileSync(json, 'utf8'));
  check(report.timeline.pairs.every((p) => p.spans.length === 0), 'the turning box touches box_a: the case needs a free path');
  const path = readPath(csv);
  const page = await openPage(browser, html);
  try {
    for (const t of [0.37, 1, 1.5, 2.9]) {
      const state = await slideTo(page, t);
      checkPoses(state, path, t, `turning, t = ${t}`);
      check(state.coloured.length === 0, `turning, t = ${t}: ${state.coloured.length} surfaces coloured`);
    }
    console.log('turn: the box is drawn at the screw pose at t = 0.37, 1, 1.5, 2.9');
    await page.screenshot({ path: join(out, 'viewer.png') });
  } finally {
    await page.close();
  }
}

// box_a and box_touch touch and stay; box_near moves beside them, touching nothing. The timeline holds
// the pair that stays (in contact over the whole path): by default the page lists and colours only
// pairs with a part the path moves, so nothing; unticking the choice lists it and colours its faces.
async function stillCase(browser, a, out) {
  const csv = join(out, 'path_still.csv');
  writeFileSync(csv, ['step,instance_path,tx,ty,tz,qw,qx,qy,qz', '0,/box_near.obj/box_near,0,2,0,1,0,0,0',
                      '1,/box_near.obj/box_near,-0.5,2,0,1,0,0,0'].join('\n') + '\n');
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  cadclash(a.cadclash, ['check', join(a.data, 'box_a.obj'), join(a.data, 'box_touch.obj'), join(a.data, 'box_near.obj'),
                        '--path', csv, '--continuous', '--tolerance', '0.01', '--no-timings', '--json', json, '--html', html]);
  const report = JSON.parse(readFileSync(json, 'utf8'));
  const pairs = report.timeline.pairs;
  check(pairs.length === 1 && !pairs.some((p) => (p.a + p.b).includes('box_near')),
        `expected the timeline to hold box_a x box_touch alone: ${pairs.map((p) => p.a + ' x ' + p.b)}`);
  const page = await openPage(browser, html);
  try {
    const shown = () => page.$$eval('#timeline-pairs tr[data-pair]', (trs) => trs.filter((tr) => !tr.hidden).length);
    check(await page.isChecked('#timeline-moving'), 'the choice of pairs with a moving part is missing or not ticked');
    let state = await slideTo(page, 0.5);
    check(await shown() === 0, `${await shown()} rows of the pair that stays are listed by default`);
    check(state.coloured.length === 0, `the pair that stays is coloured by default: ${state.coloured.length} surfaces`);
    check(await colouredPixels(page) === 0, 'coloured pixels with only the pair that stays in contact');
    await page.uncheck('#timeline-moving');
    state = await slideTo(page, 0.25);
    check(await shown() === pairs[0].surfaces.length, `${await shown()} rows listed once unticked, expected ${pairs[0].surfaces.length}`);
    await checkColoured(page, report, state, 0.25, 'the pair that stays, shown');
    check(state.coloured.some((c) => c.state === 'contact'), 'the pair that stays is not coloured in contact once shown');
    console.log(`still: the pair that stays is hidden by default, listed and coloured (${state.coloured.length} surfaces) once unticked`);
  } finally {
    await page.close();
  }
}

async function plainCase(browser, a, out, csv) {
  const json = join(out, 'report.json'), html = join(out, 'report.html'), alone = join(out, 'alone.json');
  const common = ['check', join(a.data, 'box_a.obj'), join(a.data, 'box_near.obj'), '--path', csv, '--tolerance', '0.01', '--no-timings'];
  cadclash(a.cadclash, [...common, '--json', json, '--html', html]);
  cadclash(a.cadclash, [...common, '--json', alone]);
  check(readFileSync(json, 'utf8') === readFileSync(alone, 'utf8'), 'the JSON report differs with --html');
  const continuous = join(out, 'continuous.json'), continuousAlone = join(out, 'continuous_alone.json');
  cadclash(a.cadclash, [...common, '--continuous', '--json', continuous, '--html', join(out, 'continuous.html')]);
  cadclash(a.cadclash, [...common, '--continuous', '--json', continuousAlone]);
  check(readFileSync(continuous, 'utf8') === readFileSync(continuousAlone, 'utf8'), 'the --continuous JSON report differs with --html');
  const page = await openPage(browser, html);
  try {
    check(await page.evaluate(() => window.cadclashViewer.path === null), 'a path checked step by step has a slider');
    check(await page.isHidden('#path-bar') && await page.isHidden('#timeline'), 'the slider or the timeline list is shown');
    const counts = await page.evaluate(() => window.cadclashViewer.highlightCounts());
    check(Object.keys(counts).length > 0, 'the last step\'s classes are not coloured');
    console.log(`plain: no slider; class colours ${JSON.stringify(counts)}; JSON the same bytes with and without --html`);
  } finally {
    await page.close();
  }
}

async function main() {
  const a = args();
  const csv = join(a.data, 'path_ok.csv');
  for (const f of ['box_a.obj', 'box_near.obj', 'box_touch.obj', 'path_ok.csv'])
    if (!existsSync(join(a.data, f))) {
      console.log(`SKIP: ${join(a.data, f)} is missing`);
      return 77;
    }
  check(existsSync(CHROMIUM), `${CHROMIUM} is missing: run scripts/setup.sh (it installs Debian's chromium)`);
  const playwrightDir = join(a['viewer-dir'], 'node_modules', 'playwright-core');
  check(existsSync(playwrightDir), `${playwrightDir} is missing: run scripts/setup.sh (npm ci in viewer/)`);
  const { chromium } = createRequire(join(a['viewer-dir'], 'package.json'))('playwright-core');
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS });
  try {
    for (const [name, run] of [['path_contact', (o) => contactCase(browser, a, o, csv)], ['path_turn', (o) => turnCase(browser, a, o)],
                               ['path_still', (o) => stillCase(browser, a, o)], ['path_plain', (o) => plainCase(browser, a, o, csv)]]) {
      console.log(`--- ${name}`);
      const out = resolve(a.out, name);
      rmSync(out, { recursive: true, force: true });
      mkdirSync(out, { recursive: true });
      try {
        await run(out);
      } catch (e) {
        if (e instanceof Failure) e.message = `${name}: ${e.message}`;
        throw e;
      }
    }
  } finally {
    await browser.close();
  }
  return 0;
}

runTest(main);
