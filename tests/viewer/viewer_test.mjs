// End-to-end test of `cadclash check --html`: makes a report, opens it in headless Chromium
// (Debian's /usr/bin/chromium driven by playwright-core), clicks a row of the pair table and checks
// the selection panel against the JSON report of the same run, that the canvas shows the model and
// that clicking frames the pair; then filters the table (text and class toggles) and walks it with
// the keys, checking rows and panel against the JSON report. Saves a screenshot next to the report.
// The panel and the table's "decided by" column show the certified decision (decided_by and the
// proven distance interval) of the JSON report.
//
// Usage: node viewer_test.mjs --cadclash EXE --viewer-dir DIR --out DIR
//                             --case NAME INPUT... [--option CHECK_OPTION]... [--tessellate]
//                             [--expect-class CLASS] [--case ...]
// Each case is one report (its inputs form one scene, --option is passed to `cadclash check`),
// checked in one browser. A case whose input is missing is skipped with a message.
// --tessellate: the inputs are first written to one .glb by `cadclash tessellate`, and the check
// reads that: its surfaces keep their deflection bands but have no exact geometry, so contacts
// within the bands cannot be proved (undecided pairs).
// --expect-class CLASS: the report must hold a pair of that class; one is clicked and checked too
// (row, chip colour, panel, its class toggle, and the 3D view's colouring).
// Exit codes: 0 pass, 1 fail, 77 every case skipped.
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, readFileSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { CHROMIUM, CHROMIUM_ARGS, Failure, check, openReport, runTest } from './browser_common.mjs';


function parseArgs(argv) {
  const args = { cases: [] };
  for (let i = 0; i < argv.length; ++i) {
    const a = argv[i];
    if (a === '--case') args.cases.push({ name: argv[++i], inputs: [], options: [] });
    else if (a === '--option' && args.cases.length) args.cases.at(-1).options.push(argv[++i]);
    else if (a === '--tessellate' && args.cases.length) args.cases.at(-1).tessellate = true;
    else if (a === '--expect-class' && args.cases.length) args.cases.at(-1).expectClass = argv[++i];
    else if (a.startsWith('--')) args[a.slice(2)] = argv[++i];
    else if (args.cases.length) args.cases.at(-1).inputs.push(a);
    else throw new Error(`${a}: an input must follow --case NAME`);
  }
  for (const key of ['cadclash', 'viewer-dir', 'out'])
    if (!args[key]) throw new Error(`missing --${key}`);
  if (!args.cases.length) throw new Error('missing --case');
  return args;
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

async function checkCase(browser, args, { name, inputs, options, tessellate, expectClass }) {
  const out = resolve(args.out, name);
  rmSync(out, { recursive: true, force: true });
  mkdirSync(out, { recursive: true });
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  if (tessellate) {
    const glb = join(out, 'model.glb');
    const run = spawnSync(args.cadclash, ['tessellate', ...inputs, '-o', glb], { encoding: 'utf8', timeout: 120000 });
    check(run.status === 0, `cadclash tessellate exited ${run.status}:\n${run.stderr}`);
    inputs = [glb];
  }
  const run = spawnSync(args.cadclash, ['check', ...inputs, ...options, '--no-timings', '--json', json, '--html', html],
                        { encoding: 'utf8', timeout: 120000 });
  check(run.status === 0, `cadclash check exited ${run.status}:\n${run.stderr}`);
  const report = JSON.parse(readFileSync(json, 'utf8'));
  const pairs = report.pairs;
  check(pairs.length > 0, 'the input gives no pairs; the test needs at least one');
  const byClass = {};
  for (const p of pairs) byClass[p.class] = (byClass[p.class] || 0) + 1;
  console.log(`pairs by class: ${JSON.stringify(byClass)}; decided by: ${JSON.stringify(report.summary.decided_by)}`);
  if (expectClass) check(byClass[expectClass] > 0, `the report has no ${expectClass} pair`);

  // 900 px high: with the clash review bar and clash line the table still shows 8 rows, so a filter
  // listing up to 20 pairs has every row drawn (visible rows plus the table's overscan of 12).
  const page = await openReport(browser, html);
  try {
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
    // The header names every column a row has (the "decided by" column included).
    const columns = await page.$$eval('#pairs thead th', (ths) => ths.map((th) => th.textContent));
    const cells = await page.$eval('#pairs tbody tr[data-index]', (tr) => tr.cells.length);
    check(columns.includes('decided by') && columns.length === cells, `header ${columns}, rows of ${cells} cells`);
    // Every class has its toggle (whether or not the report has pairs of it).
    for (const c of CLASSES)
      check(await page.locator(`#class-toggles input[data-class="${c}"]`).count() === 1, `no class toggle for ${c}`);
    await page.evaluate((i) => window.cadclashViewer.scrollToPair(i), pairs.length - 1);
    check((await rowsDrawn()).includes(pairs.length - 1), 'scrolling to the last pair does not draw its row');

    // The canvas shows the assembly: a good share of it is not background.
    const all = await page.evaluate(() => window.cadclashViewer.coveredPixels({}));
    console.log(`whole assembly covers ${all.covered} of ${all.total} pixels`);
    check(all.covered > all.total * 0.01, 'the canvas is blank (is WebGL working?)');

    if (expectClass) await checkClass(page, pairs, expectClass);

    // A pair in the middle of the table (so the click needs scrolling), with both surfaces named.
    let index = pairs.length >> 1;
    while (index < pairs.length - 1 && (pairs[index].a.surface === undefined || pairs[index].b.surface === undefined)) ++index;
    const pair = pairs[index];
    check(await page.evaluate((i) => window.cadclashViewer.scrollToPair(i), index), `row ${index} is not listed`);
    await page.locator(`#pairs tbody tr[data-index="${index}"]`).click();
    await checkSelected(page, pairs, index, 'the click');
    await checkRow(page, pairs, index, 'the click');

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

// The classes of docs/report-schema.md, their colours in the page (viewer/src/classes.js) and the
// order in which a surface in several pairs takes a class: an undecided pair may be a contact, so
// it wins over touching.
const CLASSES = ['penetrating', 'touching', 'clearance', 'containment', 'undecided'];
const CLASS_RGB = {
  penetrating: 'rgb(224, 32, 42)', touching: 'rgb(255, 140, 26)', clearance: 'rgb(242, 210, 27)',
  containment: 'rgb(155, 77, 202)', undecided: 'rgb(240, 50, 230)',
};
const SEVERITY = ['clearance', 'touching', 'undecided', 'containment', 'penetrating'];

// The JSON report's distance interval as the page writes it: 4 significant digits, null (an
// infinite bound) as ∞.
const numberText = (v) => (v === null ? '∞' : v === 0 ? '0' : Number(v.toPrecision(4)).toString());
const intervalText = (pair) => `[${numberText(pair.distance_interval[0])}, ${numberText(pair.distance_interval[1])}] mm`;

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
    // ε and its source, as the JSON side has them (a whole part has neither).
    const eps = side.surface === undefined ? '–' : `${numberText(side.uncertainty)} mm (${side.uncertainty_source})`;
    check(await field(`${key}-uncertainty`) === eps, `${key}: uncertainty ${await field(`${key}-uncertainty`)}, expected ${eps}`);
  }
  check((await field('class')).trim() === pair.class, `class ${await field('class')}, expected ${pair.class}`);
  check(await field('decided-by') === pair.decided_by, `decided by ${await field('decided-by')}, expected ${pair.decided_by}`);
  const within = pair.contact_within ?? '–';
  check(await field('within') === within, `contact within ${await field('within')}, expected ${within}`);
  check(await field('interval') === intervalText(pair),
        `exact distance in ${await field('interval')}, expected ${intervalText(pair)} (${JSON.stringify(pair.distance_interval)})`);
  console.log(`${what}: row ${index + 1}: ${pair.class} (${pair.decided_by}, ${intervalText(pair)}) ` +
              `${pair.a.instance} ${stepText(pair.a)} x ${pair.b.instance} ${stepText(pair.b)}`);
}

// The pair's drawn row shows its class, in the class's colour, and what decided it.
async function checkRow(page, pairs, index, what) {
  const pair = pairs[index];
  const row = await page.$eval(`#pairs tbody tr[data-index="${index}"]`, (tr) => ({
    cls: tr.querySelector('td.cls').textContent,
    by: tr.querySelector('td.by').textContent,
    chip: getComputedStyle(tr.querySelector('td.cls .chip')).backgroundColor,
  }));
  check(row.cls === pair.class, `${what}: row ${index + 1} shows class ${row.cls}, expected ${pair.class}`);
  check(row.by === pair.decided_by, `${what}: row ${index + 1} shows decided by ${row.by}, expected ${pair.decided_by}`);
  check(row.chip === CLASS_RGB[pair.class], `${what}: row ${index + 1}'s ${pair.class} chip is ${row.chip}, expected ${CLASS_RGB[pair.class]}`);
}

// A pair of class `cls` is listed, clicked and shown like any other; the toggle counts the class;
// the 3D view colours with it exactly the surfaces whose most severe pair is of that class.
async function checkClass(page, pairs, cls) {
  const of = pairs.map((p, i) => i).filter((i) => pairs[i].class === cls);
  const index = of[of.length >> 1];
  check(await page.evaluate((i) => window.cadclashViewer.scrollToPair(i), index), `${cls} row ${index} is not listed`);
  await page.locator(`#pairs tbody tr[data-index="${index}"]`).click();
  await checkSelected(page, pairs, index, `the click on a ${cls} pair`);
  await checkRow(page, pairs, index, `the ${cls} pair`);
  const chip = await page.$eval(`#selection [data-field="class"] .chip`, (e) => getComputedStyle(e).backgroundColor);
  check(chip === CLASS_RGB[cls], `the panel's ${cls} chip is ${chip}, expected ${CLASS_RGB[cls]}`);
  const shown = await page.innerText(`#class-toggles [data-count="${cls}"]`);
  check(shown === count(of.length), `the ${cls} toggle says ${shown}, expected ${of.length}`);
  if (pairs.some((p) => p.class === 'containment')) return;  // a containment colours whole instances
  const worst = new Map();
  for (const p of pairs)
    for (const side of [p.a, p.b]) {
      const key = `${side.instance}\n${side.surface}\n${side.face_index}`;
      const was = worst.get(key);
      if (was === undefined || SEVERITY.indexOf(p.class) > SEVERITY.indexOf(was)) worst.set(key, p.class);
    }
  const expected = [...worst.values()].filter((c) => c === cls).length;
  const drawn = (await page.evaluate(() => window.cadclashViewer.highlightCounts()))[cls] || 0;
  check(drawn === expected, `the 3D view colours ${drawn} surfaces ${cls}, expected ${expected}`);
  console.log(`${cls}: ${of.length} pairs, ${drawn} surfaces coloured ${cls}`);
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

runTest(main);
