// What the viewer's browser tests share: Debian's Chromium and its switches, a failure that names
// what was expected, running cadclash, reading "--key value" arguments, and opening a report
// page offline (ready, no page errors, nothing fetched).
import { spawnSync } from 'node:child_process';
import { pathToFileURL } from 'node:url';

export const CHROMIUM = '/usr/bin/chromium';
// Without the background-networking switches Chromium keeps calling home, which a closed network
// refuses; SwiftShader gives WebGL without a GPU.
export const CHROMIUM_ARGS = [
  '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
];

export class Failure extends Error {}
export function check(condition, message) {
  if (!condition) throw new Failure(message);
}

// The command line's "--key value" pairs; each of `required` must be given.
export function keyArgs(required) {
  const out = {};
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i += 2) out[argv[i].replace(/^--/, '')] = argv[i + 1];
  for (const key of required) if (!out[key]) throw new Error(`missing --${key}`);
  return out;
}

// Runs cadclash; a non-zero exit is a failure showing its output.
export function cadclash(exe, argv) {
  const run = spawnSync(exe, argv, { encoding: 'utf8', timeout: 120000 });
  check(run.status === 0, `cadclash ${argv.join(' ')} exited ${run.status}:\n${run.stdout}\n${run.stderr}`);
  return run;
}

// The report `html` in a new page of `browser`, once the viewer says it is ready: a failure when
// it reports an error, the page logs one, or it fetches anything (the report must open offline).
// page.pageErrors keeps collecting the page's errors after that.
export async function openReport(browser, html, pageOptions = {}) {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 }, ...pageOptions });
  const errors = [], requests = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('request', (r) => { if (!r.url().startsWith('file:')) requests.push(r.url()); });
  await page.goto(pathToFileURL(html).href);
  await page.waitForSelector('html[data-cadclash-ready], html[data-cadclash-error]', { state: 'attached', timeout: 60000 });
  const failed = await page.getAttribute('html', 'data-cadclash-error');
  check(failed === null, `the viewer reported: ${failed}`);
  check(errors.length === 0, `page errors: ${errors.join('; ')}`);
  check(requests.length === 0, `the report fetched ${requests.join(', ')}`);
  page.pageErrors = errors;
  return page;
}

// Runs the test's async main: its exit code, or 1 with the failure's message (a Failure) or the
// error itself.
export function runTest(main) {
  main().then((code) => process.exit(code), (e) => {
    console.error(e instanceof Failure ? `FAIL: ${e.message}` : e);
    process.exit(1);
  });
}
