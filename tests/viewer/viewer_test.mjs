// End-to-end test of `cadclash check --html`: makes a report, opens it in headless Chromium
// (Debian's /usr/bin/chromium driven by playwright-core), clicks a row of the pair table and checks
// the selection panel against the JSON report of the same run, that the canvas shows the model and
// that clicking frames the pair. Saves a screenshot next to the report (a test artefact).
//
// Usage: node viewer_test.mjs --cadclash EXE --viewer-dir DIR --out DIR --case NAME INPUT... [--case ...]
// Each case is one report (its inputs form one scene), checked in one browser. A case whose input
// is missing is skipped with a message. Exit codes: 0 pass, 1 fail, 77 every case skipped.
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
    if (a === '--case') args.cases.push({ name: argv[++i], inputs: [] });
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

async function checkCase(browser, args, { name, inputs }) {
  const out = resolve(args.out, name);
  rmSync(out, { recursive: true, force: true });
  mkdirSync(out, { recursive: true });
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  const run = spawnSync(args.cadclash, ['check', ...inputs, '--no-timings', '--json', json, '--html', html],
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
    check(await page.locator('#pairs tbody tr').count() === pairs.length, 'the table does not list every pair');

    // The canvas shows the assembly: a good share of it is not background.
    const all = await page.evaluate(() => window.cadclashViewer.coveredPixels({}));
    console.log(`whole assembly covers ${all.covered} of ${all.total} pixels`);
    check(all.covered > all.total * 0.01, 'the canvas is blank (is WebGL working?)');

    // A pair in the middle of the table (so the click needs scrolling), with both surfaces named.
    let index = pairs.length >> 1;
    while (index < pairs.length - 1 && (pairs[index].a.surface === undefined || pairs[index].b.surface === undefined)) ++index;
    const pair = pairs[index];
    await page.locator(`#pairs tbody tr[data-index="${index}"]`).click();
    check(await page.getAttribute('html', 'data-cadclash-selected') === String(index), 'the click did not select the row');
    const field = (key) => page.locator(`#selection [data-field="${key}"]`).innerText();
    const stepText = (side) => (side.step_id === undefined ? '–' : `#${side.step_id}`);
    for (const [key, side] of [['a', pair.a], ['b', pair.b]]) {
      check(await field(`${key}-step`) === stepText(side), `${key}: STEP id ${await field(`${key}-step`)}, expected ${stepText(side)}`);
      check(await field(`${key}-path`) === side.instance, `${key}: path ${await field(`${key}-path`)}, expected ${side.instance}`);
      check(await field(`${key}-part`) === side.part, `${key}: part ${await field(`${key}-part`)}, expected ${side.part}`);
    }
    check((await field('class')).trim() === pair.class, `class ${await field('class')}, expected ${pair.class}`);
    console.log(`row ${index + 1}: ${pair.class} ${pair.a.instance} ${stepText(pair.a)} x ${pair.b.instance} ${stepText(pair.b)}`);

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

    const png = join(out, 'viewer.png');
    await page.screenshot({ path: png });
    console.log(`screenshot: ${png}`);
  } finally {
    await page.close();
  }
}

main().then((code) => process.exit(code), (e) => {
  console.error(e instanceof Failure ? `FAIL: ${e.message}` : e);
  process.exit(1);
});
