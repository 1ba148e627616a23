// End-to-end test of `cadclash check --html`: makes a report, opens it in headless Chromium
// (Debian's /usr/bin/chromium driven by playwright-core), clicks a row of the pair table and checks
// the selection panel against the JSON report of the same run, that the canvas shows the model and
// that clicking frames the pair; then filters the table (text and class toggles) and walks it with
// the keys, checking rows and panel against the JSON report. Saves a screenshot next to the report.
//
// Usage: node viewer_test.mjs --cadclash EXE --viewer-dir DIR --out DIR
//                             --case NAME INPUT... [--option CHECK_OPTION]... [--case ...]
// Each case is one report (its inputs form one scene, --option is passed to `cadclash check`),
// checked in one browser. A case whose input is missing is skipped with a message.
// Exit codes: 0 pass, 1 fail, 77 every case skipped.
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const CHROMIUM = '/usr/bin/chromium';
// Without the background-networking switches Chromium keeps calling home, which a closed network
// refuses; SwiftShader gives WebGL without a GPU.
const CHROMIUM_ARGS = [
  '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];

function parseArgs(argv) {
  const args = { cases: [] };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--case') args.cases.push({ name: argv[++i], inputs: [], options: [] });
    else if (a === '--option' && args.cases.length) args.cases.at(-1).options.push(argv[++i]);
    else if (a.startsWith('--')) args[a.slice(2)] = argv[++i];
    else if (args.cases.length) args.cases.at(-1).inputs.push(a);
    else throw new Error(`${a}: an input must follow --case NAME`);
  }
  for (const key of ['cadclash', 'viewer-dir', 'out'])
    if (!args[key]) throw new Error(`missing --${key}`);
  if (!args.cases.length) throw new Error('missing --case');
  return args;
}

class Failure extends Error {}
function check(condition, message) {
  if (!condition) throw new Failure(message);
}

async function main() {
  const args = parseArgs(process.argv.slice(2));
  const cases = args.cases.filter((c) => {
    const missing = c.inputs.find((input) => !existsSync(input));
    if (missing) console.log(`SKIP ${c.name}: ${missing} is missing (scripts/setup.sh fetches data/external)`);
    return !missing;
  });
  if (!cases.length) return 77;
  check(existsSync(CHROMIUM), `${CHROMIUM} is missing: run scripts/setup.sh (it installs Debian's chromium)`);
  const playwrightDir = join(args['viewer-dir'], 'node_modules', 'playwright-core');
  check(existsSync(playwrightDir), `${playwrightDir} is missing: run scripts/setup.sh (npm ci in viewer/)`);
  const { chromium } = createRequire(join(args['viewer-dir'], 'package.json'))('playwright-core');
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS });
  try {
    for (const c of cases) {
      console.log(`--- ${c.name}: ${c.inputs.join(' ')}`);
      try {
        await checkCase(browser, args, c);
      } catch (e) {
        if (e instanceof Failure) e.message = `${c.name}: ${e.message}`;
        throw e;
      }
    }
  } finally {
    await browser.close();
  }
  return 0;
}

async function checkCase(browser, args, { name, inputs, options }) {
  const out = resolve(args.out, name);
  rmSync(out, { recursive: true, force: true });
  mkdirSync(out, { recursive: true });
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  const run = spawnSync(args.cadclash, ['check', ...inputs, ...options, '--no-timings', '--json', json, '--html', html],
                        { encoding: 'utf8', timeout: 120000 });
  check(run.status === 0, `cadclash check exited ${run.status}:\n${run.stderr}`);
  const report = JSON.parse(readFileSync(json, 'utf8'));
  const pairs = report.pairs;
  check(pairs.length > 0, 'the input gives no pairs; the test needs at least one');

  const page = await browser.newPage({ viewport: { width: 1400, height: 800 } });
  try {
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    // The report must open offline: any request other than the file itself is a failure.
    const requests = [];
    page.on('request', (r) => { if (!r.url().startsWith('file:')) requests.push(r.url()); });

    await page.goto(pathToFileURL(html).href);
    await page.waitForSelector('html[data-cadclash-ready], html[data-cadclash-error]', { state: 'attached', timeout: 60000 });
    const failed = await page.getAttribute('html', 'data-cadclash-error');
    check(failed === null, `the viewer reported: ${failed}`);
    check(errors.length === 0, `page errors: ${errors.join('; ')}`);
    check(requests.length === 0, `the report fetched ${requests.join(', ')}`);
    const stats = await page.evaluate(() => window.cadclashViewer.stats);
    console.log(`viewer stats: ${JSON.stringify(stats)}`);
    // Every pair is listed; the table draws only the rows around the visible ones, but scrolls the
    // whole list (its height is that of every row).
    const rowsDrawn = () => page.$$eval('#pairs tbody tr[data-index]', (trs) => trs.map((tr) => Number(tr.dataset.index)));
    check(await page.innerText('#filter-count') === `${count(pairs.length)} of ${count(pairs.length)} pairs`,
          `the table says "${await page.innerText('#filter-count')}" with no filter, for ${pairs.length} pairs`);
    const firstRows = await rowsDrawn();
    check(firstRows.length > 0 && firstRows.every((v, k) => v === k), `the table starts with rows ${firstRows.slice(0, 5)}`);
    const heights = await page.evaluate(() => ({
      scroll: document.getElementById('pairs-wrap').scrollHeight,
      row: document.querySelector('#pairs tbody tr[data-index]').getBoundingClientRect().height,
    }));
    check(heights.scroll >= pairs.length * heights.row - 1, `the table is ${heights.scroll} px high, for ${pairs.length} rows of ${heights.row} px`);
    await page.evaluate((i) => window.cadclashViewer.scrollToPair(i), pairs.length - 1);
    check((await rowsDrawn()).includes(pairs.length - 1), 'scrolling to the last pair does not draw its row');

    // The canvas shows the assembly: a good share of it is not background.
    const all = await page.evaluate(() => window.cadclashViewer.coveredPixels({}));
    console.log(`whole assembly covers ${all.covered} of ${all.total} pixels`);
    check(all.covered > all.total * 0.01, 'the canvas is blank (is WebGL working?)');

    // A pair in the middle of the table (so the click needs scrolling), with both surfaces named.
    let index = pairs.length >> 1;
    while (index < pairs.length - 1 && (pairs[index].a.surface === undefined || pairs[index].b.surface === undefined)) ++index;
    const pair = pairs[index];
    check(await page.evaluate((i) => window.cadclashViewer.scrollToPair(i), index), `row ${index} is not listed`);
    await page.locator(`#pairs tbody tr[data-index="${index}"]`).click();
    await checkSelected(page, pairs, index, 'the click');

    // Both selected surfaces are drawn, and clicking framed them: they cover more of the canvas
    // than when the whole assembly is in view.
    const only = (sides) => page.evaluate((s) => window.cadclashViewer.coveredPixels({ context: false, highlights: false, sides: s }), sides);
    const framedA = await only([true, false]), framedB = await only([false, true]);
    await page.evaluate(() => window.cadclashViewer.frameAll());
    const wholeAB = await only([true, true]);
    await page.locator(`#pairs tbody tr[data-index="${index}"]`).click();
    const framedAB = await only([true, true]);
    console.log(`selection pixels: A ${framedA.covered}, B ${framedB.covered}, A+B framed ${framedAB.covered}, A+B whole view ${wholeAB.covered}`);
    check(framedA.covered > 0 && framedB.covered > 0, 'a selected surface is not drawn');
    check(framedAB.covered > wholeAB.covered, 'clicking the row did not frame the pair');

    await checkFilterAndKeys(page, pairs, index);

    const png = join(out, 'viewer.png');
    await page.screenshot({ path: png });
    console.log(`screenshot: ${png}`);
  } finally {
    await page.close();
  }
}

const count = (n) => n.toLocaleString('en');
const stepText = (side) => (side.step_id === undefined ? '–' : `#${side.step_id}`);

// The selected pair is `index`, and the panel shows that pair of the JSON report.
async function checkSelected(page, pairs, index, what) {
  const selected = await page.getAttribute('html', 'data-cadclash-selected');
  check(selected === String(index), `after ${what} pair ${selected} is selected, expected ${index}`);
  const pair = pairs[index];
  const field = (key) => page.locator(`#selection [data-field="${key}"]`).innerText();
  check(await field('index') === String(index + 1), `after ${what} the panel shows pair ${await field('index')}, expected ${index + 1}`);
  for (const [key, side] of [['a', pair.a], ['b', pair.b]]) {
    check(await field(`${key}-step`) === stepText(side), `${key}: STEP id ${await field(`${key}-step`)}, expected ${stepText(side)}`);
    check(await field(`${key}-path`) === side.instance, `${key}: path ${await field(`${key}-path`)}, expected ${side.instance}`);
    check(await field(`${key}-part`) === side.part, `${key}: part ${await field(`${key}-part`)}, expected ${side.part}`);
  }
  check((await field('class')).trim() === pair.class, `class ${await field('class')}, expected ${pair.class}`);
  console.log(`${what}: row ${index + 1}: ${pair.class} ${pair.a.instance} ${stepText(pair.a)} x ${pair.b.instance} ${stepText(pair.b)}`);
}

// The filter rules of docs/viewer.md, written again here from the JSON report: whitespace-separated
// terms, each a substring (any case) of a side's instance path, part, surface name, own name or
// "#id"; a term "#<digits>" is that STEP id exactly.
function expectedRows(pairs, query, hiddenClass) {
  const terms = query.toLowerCase().split(/\s+/).filter(Boolean);
  const sideMatches = (side, term) => {
    if (/^#\d+$/.test(term)) return side.step_id === Number(term.slice(1));
    return [side.instance, side.part, side.surface ?? '', side.source_name ?? '', stepText(side)]
      .some((f) => f.toLowerCase().includes(term));
  };
  const rows = [];
  pairs.forEach((p, i) => {
    if (p.class !== hiddenClass && terms.every((t) => sideMatches(p.a, t) || sideMatches(p.b, t))) rows.push(i);
  });
  return rows;
}

// Waits until the page has applied the filter text (it applies after a pause in typing).
async function waitFilter(page, query) {
  try {
    await page.waitForFunction((q) => document.documentElement.dataset.cadclashFilter === q, query, { timeout: 10000 });
  } catch {
    throw new Failure(`the filter "${query}" was never applied (data-cadclash-filter is ` +
                      `"${await page.getAttribute('html', 'data-cadclash-filter')}")`);
  }
}

// The count line and the drawn rows are those the filter rules give; each drawn row shows the text
// it matched (the ellipsis cuts only what is painted).
async function checkListed(page, pairs, expected, what, mustShow) {
  const shown = await page.innerText('#filter-count');
  check(shown === `${count(expected.length)} of ${count(pairs.length)} pairs`,
        `${what}: the table says "${shown}", expected ${expected.length} of ${pairs.length} pairs`);
  const rows = await page.$$eval('#pairs tbody tr[data-index]', (trs) => trs.map((tr) => [Number(tr.dataset.index), tr.innerText]));
  const want = new Set(expected);
  check(rows.every(([i]) => want.has(i)), `${what}: rows ${rows.map(([i]) => i).filter((i) => !want.has(i))} are listed but do not match`);
  check(rows.every(([i], k) => k === 0 || i > rows[k - 1][0]), `${what}: the rows are not in report order`);
  if (expected.length <= 20) check(rows.length === expected.length, `${what}: ${rows.length} rows drawn, expected ${expected.length}`);
  else check(rows.length >= 10, `${what}: only ${rows.length} of ${expected.length} rows drawn`);
  for (const [i, text] of rows)
    check(mustShow.every((t) => text.toLowerCase().includes(t)), `${what}: row ${i + 1} shows no "${mustShow}": ${text}`);
  console.log(`${what}: ${expected.length} of ${pairs.length} pairs listed, ${rows.length} rows drawn`);
}

async function typeFilter(page, query) {
  await page.locator('#filter').fill('');
  await page.locator('#filter').pressSequentially(query);
  await waitFilter(page, query);
}

async function checkFilterAndKeys(page, pairs, index) {
  const before = await page.getAttribute('html', 'data-cadclash-selected');
  const pair = pairs[index];
  // The least frequent class: toggling it off leaves rows of the others when there are others.
  const byClass = {};
  for (const p of pairs) byClass[p.class] = (byClass[p.class] || 0) + 1;
  const rare = Object.keys(byClass).sort((x, y) => byClass[x] - byClass[y])[0];
  // A fragment of an instance path of a pair of that class, in the other case: matches ignore case.
  const rarePair = pairs.find((p) => p.class === rare);
  const leaf = rarePair.a.instance.split('/').filter(Boolean).at(-1);
  const fragment = [...leaf].map((c) => (c === c.toUpperCase() ? c.toLowerCase() : c.toUpperCase())).join('');

  // Typed into the box, j, k and the arrows edit the text: no selection moves.
  await page.locator('#filter').click();
  await page.keyboard.type('jk');
  await page.keyboard.press('ArrowDown');
  await page.keyboard.press('ArrowUp');
  await waitFilter(page, 'jk');
  check(await page.getAttribute('html', 'data-cadclash-selected') === before, 'keys typed into the filter box moved the selection');

  const queries = [];
  if (pair.a.step_id !== undefined) {
    queries.push([`#${pair.a.step_id}`, [`#${pair.a.step_id}`]]);
    // Digits alone are a substring: they may match an id through another field (a surface name).
    queries.push([String(pair.a.step_id), []]);
  } else {
    queries.push([pair.a.surface, [pair.a.surface.toLowerCase()]]);
  }
  queries.push([`${fragment}  ${pair.a.part}`, [fragment.toLowerCase(), pair.a.part.toLowerCase()]]);
  queries.push([fragment, [fragment.toLowerCase()]]);
  for (const [query, mustShow] of queries) {
    await typeFilter(page, query);
    await checkListed(page, pairs, expectedRows(pairs, query, null), `filter "${query}"`, mustShow);
  }
  const matched = expectedRows(pairs, fragment, null);

  // Class toggles: the counts are those of the pairs matching the text.
  for (const c of Object.keys(byClass)) {
    const n = matched.filter((i) => pairs[i].class === c).length;
    const shown = await page.innerText(`#class-toggles [data-count="${c}"]`);
    check(shown === count(n), `filter "${fragment}": the ${c} toggle says ${shown}, expected ${n}`);
  }
  await page.locator(`#class-toggles input[data-class="${rare}"]`).uncheck();
  let listed = expectedRows(pairs, fragment, rare);
  await checkListed(page, pairs, listed, `filter "${fragment}" without ${rare}`, [fragment.toLowerCase()]);
  if (!listed.length) {  // a single class: the keys need rows
    await page.locator(`#class-toggles input[data-class="${rare}"]`).check();
    listed = matched;
  }

  // Enter leaves the box and selects the first listed pair (the selection is not listed) or
  // frames the selection; then Down twice, k once.
  await page.locator('#filter').press('Enter');
  check(await page.evaluate(() => document.activeElement.id !== 'filter'), 'Enter did not leave the filter box');
  let pos = Math.max(listed.indexOf(index), 0);
  await checkSelected(page, pairs, listed[pos], 'Enter in the filter box');
  await page.keyboard.press('ArrowDown');
  await page.keyboard.press('ArrowDown');
  pos = Math.min(pos + 2, listed.length - 1);
  await checkSelected(page, pairs, listed[pos], 'Down twice');
  await page.keyboard.press('k');
  pos = Math.max(pos - 1, 0);
  await checkSelected(page, pairs, listed[pos], 'k');
  const inView = await page.evaluate(() => {
    const tr = document.querySelector('#pairs tbody tr.selected');
    if (!tr) return false;
    const wrap = document.getElementById('pairs-wrap').getBoundingClientRect(), row = tr.getBoundingClientRect();
    return row.top >= wrap.top && row.bottom <= wrap.bottom + 1;
  });
  check(inView, 'the selected row is not scrolled into view');

  // f frames the selection again after the view was moved away.
  const only = () => page.evaluate(() => window.cadclashViewer.coveredPixels({ context: false, highlights: false, sides: [true, true] }));
  await page.evaluate(() => window.cadclashViewer.frameAll());
  const whole = await only();
  await page.keyboard.press('f');
  const framed = await only();
  check(framed.covered > whole.covered, `f did not frame the pair (${framed.covered} pixels, ${whole.covered} in the whole view)`);

  // "/" goes to the filter box; Escape there clears the text (the class toggles stay).
  await page.keyboard.press('/');
  check(await page.evaluate(() => document.activeElement.id === 'filter'), '/ did not focus the filter box');
  await page.keyboard.press('Escape');
  await waitFilter(page, '');
  check(await page.inputValue('#filter') === '', 'Escape did not clear the filter box');
  const rareShown = await page.isChecked(`#class-toggles input[data-class="${rare}"]`);
  await checkListed(page, pairs, expectedRows(pairs, '', rareShown ? null : rare), 'after Escape', []);
}

main().then((code) => process.exit(code), (e) => {
  console.error(e instanceof Failure ? `FAIL: ${e.message}` : e);
  process.exit(1);
});
