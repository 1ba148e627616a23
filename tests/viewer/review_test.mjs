// The HTML report's clash review in headless Chromium (docs/review.md, viewer/src/review.js):
// as1 checked against a baseline holding only the plate's clashes (so clashes are new and active)
// with an approvals file (an id entry and a rule), then in the page: the status/approval counts
// match the JSON report, the toggles list exactly the pairs of the clashes they keep, a clash is
// approved (by the name and reason typed) and an id-approved one unapproved, a rule-approved one
// offers no unapprove, and the exported approvals file, given back to `cadclash check --approvals`,
// approves exactly what the page showed.
//
// Usage: node review_test.mjs --cadclash EXE --viewer-dir DIR --out DIR --as1 FILE
// Exit codes: 0 pass, 1 fail, 77 skipped (as1 missing).
import { existsSync, mkdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { CHROMIUM, CHROMIUM_ARGS, Failure, cadclash, check, keyArgs, openReport, runTest } from './browser_common.mjs';

const TODAY = '2026-06-01';

function args() {
  return keyArgs(['cadclash', 'viewer-dir', 'out', 'as1']);
}

// The listed pair indices the table would hold with these toggles, from the JSON report alone.
function expectedPairs(report, keep) {
  const out = [];
  report.clashes.forEach((c) => {
    if (c.status === 'resolved' || !keep(c)) return;
    for (const s of c.surface_pairs) out.push(s.pair);
  });
  return out.sort((x, y) => x - y);
}

async function setToggle(page, name, on) {
  await page.setChecked(`#review-bar input[data-review="${name}"]`, on);
}

async function listedCount(page) {
  return Number((await page.innerText('#filter-count')).split(' ')[0].replace(/,/g, ''));
}

async function main() {
  const a = args();
  if (!existsSync(a.as1)) {
    console.log(`SKIP: ${a.as1} is missing (scripts/setup.sh fetches data/external)`);
    return 77;
  }
  check(existsSync(CHROMIUM), `${CHROMIUM} is missing: run scripts/setup.sh`);
  const out = resolve(a.out, 'review');
  rmSync(out, { recursive: true, force: true });
  mkdirSync(out, { recursive: true });
  const base = join(out, 'baseline.json'), approvals = join(out, 'approvals.json');
  cadclash(a.cadclash, ['check', a.as1, '--select-a', '/as1/PLATE', '--no-timings', '--json', base]);
  const baseline = JSON.parse(readFileSync(base, 'utf8'));
  // Approve one plate clash by id (not a bolt/nut one, which the rule below covers too).
  const byId = baseline.clashes.find((c) => !/BOLT|NUT/.test(c.a.instance + c.b.instance));
  check(byId, 'no plate clash without a bolt or nut');
  writeFileSync(approvals, JSON.stringify({ schema: 'cadclash-approvals', version: 1, approvals: [
    { id: byId.id, reason: 'seated', by: 'file', date: '2026-01-01' },
    { a: '**/BOLT', b: '**/NUT::3', classes: ['touching'], reason: 'bolt in its nut', by: 'file', date: '2026-01-01' }] }));
  const json = join(out, 'report.json'), html = join(out, 'report.html');
  cadclash(a.cadclash, ['check', a.as1, '--baseline', base, '--approvals', approvals, '--today', TODAY, '--no-timings',
                        '--json', json, '--html', html]);
  const report = JSON.parse(readFileSync(json, 'utf8'));
  const s = report.review.summary;
  check(s.new > 0 && s.active > 0 && s.approved > 1, `the scenario needs new, active and approved clashes: ${JSON.stringify(s)}`);

  const { chromium } = createRequire(join(a['viewer-dir'], 'package.json'))('playwright-core');
  const browser = await chromium.launch({ executablePath: CHROMIUM, headless: true, args: CHROMIUM_ARGS });
  try {
    const page = await openReport(browser, html, { viewport: { width: 1400, height: 800 }, acceptDownloads: true });

    // Counts per status and approval, as the JSON report has them.
    const count = async (f) => Number(await page.innerText(`[data-review-count="${f}"]`));
    const current = report.clashes.filter((c) => c.status !== 'resolved');
    for (const f of ['new', 'active', 'changed'])
      check(await count(f) === s[f], `${f}: the page counts ${await count(f)}, the report ${s[f]}`);
    check(await count('approved') === s.approved, `approved: ${await count('approved')} vs ${s.approved}`);
    check(await count('unapproved') === current.length - s.approved, 'unapproved count');

    // Toggles: hiding new clashes lists the active ones' pairs; hiding approved lists the rest.
    await setToggle(page, 'new', false);
    const active = expectedPairs(report, (c) => c.status !== 'new');
    check(await listedCount(page) === active.length, `without new: ${await listedCount(page)} listed, expected ${active.length}`);
    const drawn = await page.$$eval('#pairs tbody tr[data-index]', (trs) => trs.map((tr) => Number(tr.dataset.index)));
    check(drawn.length > 0 && drawn.every((i, k) => i === active[k]), `without new the table shows ${drawn.slice(0, 5)}`);
    await setToggle(page, 'new', true);
    await setToggle(page, 'approved', false);
    const unapproved = expectedPairs(report, (c) => c.approval === null);
    check(await listedCount(page) === unapproved.length, `without approved: ${await listedCount(page)}, expected ${unapproved.length}`);
    await setToggle(page, 'approved', true);
    check(await listedCount(page) === report.pairs.length, 'all toggles on: every pair listed');

    // Approve a new clash in the page.
    const target = current.find((c) => c.status === 'new' && c.approval === null);
    await page.evaluate((i) => window.cadclashViewer.selectPair(i), target.surface_pairs[0].pair);
    check(await page.innerText('[data-field="clash-id"]') === target.id, 'the panel shows another clash');
    check(await page.innerText('[data-field="clash-approval"]') === 'not approved', 'a new clash shows as approved');
    await page.fill('#review-by', 'tester');
    await page.fill('#review-reason', 'checked in the viewer');
    await page.click('#approve-clash');
    check((await page.innerText('[data-field="clash-approval"]')).startsWith('approved by tester (checked in the viewer)'),
          `after approving: ${await page.innerText('[data-field="clash-approval"]')}`);
    check(await count('approved') === s.approved + 1, 'the approved count did not grow');
    // Unapprove the id-approved clash; a rule-approved one offers no unapprove.
    const idClash = report.clashes.find((c) => c.id === byId.id);
    await page.evaluate((i) => window.cadclashViewer.selectPair(i), idClash.surface_pairs[0].pair);
    await page.click('#unapprove-clash');
    check(await page.innerText('[data-field="clash-approval"]') === 'not approved', 'unapprove did not take');
    const ruled = report.clashes.find((c) => c.approval === 1);
    check(ruled, 'the rule approved nothing');
    await page.evaluate((i) => window.cadclashViewer.selectPair(i), ruled.surface_pairs[0].pair);
    check(await page.locator('#unapprove-clash').count() === 0, 'a rule-approved clash offers unapprove');

    // Export, and give the file back to the CLI.
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-approvals')]);
    const exported = join(out, 'exported.json');
    await download.saveAs(exported);
    const file = JSON.parse(readFileSync(exported, 'utf8'));
    check(file.approvals.length === 2 && file.approvals[1].id === target.id && file.approvals[1].by === 'tester' &&
          file.approvals[1].date === TODAY && file.approvals[0].b === '**/NUT::3', `exported ${JSON.stringify(file)}`);
    const again = join(out, 'again.json');
    cadclash(a.cadclash, ['check', a.as1, '--approvals', exported, '--today', TODAY, '--no-timings', '--json', again]);
    const after = JSON.parse(readFileSync(again, 'utf8'));
    for (const c of after.clashes) {
      const was = report.clashes.find((r) => r.id === c.id);
      const expected = c.id === target.id || (c.id !== byId.id && was.approval === 1);
      check((c.approval !== null) === expected, `clash ${c.id}: approved ${c.approval !== null} by the exported file, expected ${expected}`);
    }
    check(page.pageErrors.length === 0, `page errors: ${page.pageErrors.join('; ')}`);
    await page.screenshot({ path: join(out, 'review.png') });
    console.log(`review: ${JSON.stringify(s)}; approved ${target.id} and unapproved ${byId.id} in the page; export checked by the CLI`);
  } finally {
    await browser.close();
  }
  return 0;
}

runTest(main);
