// Measures how fast a cadclash HTML report opens and redraws in headless Chromium (SwiftShader,
// i.e. software WebGL: a GPU is much faster). Not a test: docs/viewer.md quotes its output.
// Usage: node measure_load.mjs VIEWER_DIR REPORT.html [runs] [filter text]
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [viewerDir, report, runs = '3', filterText = 'bolt'] = process.argv.slice(2);
if (!report) {
  console.error('usage: node measure_load.mjs VIEWER_DIR REPORT.html [runs] [filter text]');
  process.exit(2);
}
const { chromium } = createRequire(join(viewerDir, 'package.json'))('playwright-core');
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
         '--disable-component-update', '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  for (let run = 0; run < Number(runs); ++run) {
    const page = await browser.newPage({ viewport: { width: 1400, height: 800 } });
    await page.goto(pathToFileURL(resolve(report)).href);
    await page.waitForSelector('html[data-cadclash-ready], html[data-cadclash-error]', { state: 'attached', timeout: 600000 });
    const error = await page.getAttribute('html', 'data-cadclash-error');
    if (error) throw new Error(error);
    const stats = await page.evaluate(() => window.cadclashViewer.stats);
    const frames = await page.evaluate(() => window.cadclashViewer.measureFrames(5));
    const selectMs = await page.evaluate(() => window.cadclashViewer.timeSelect(0));
    // The pair table: the filter text, a text no pair matches, no filter; then one Down key.
    const texts = [filterText, 'no such name', ''];
    const filters = await page.evaluate((ts) => ts.map((t) => window.cadclashViewer.timeFilter(t)), texts);
    const keyMs = await page.evaluate(() => window.cadclashViewer.timeKeyDown());
    const f = (v) => Math.round(v);
    console.log(`run ${run + 1}: ${stats.triangles} triangles drawn, ${stats.drawCalls} draw calls; ready ${f(stats.readyMs)} ms ` +
                `after navigation (script ${f(stats.scriptMs)}: parse ${f(stats.parseMs)}, build ${f(stats.buildMs)}, ` +
                `first frame ${f(stats.firstFrameMs)}); full frame ${f(frames.fullMs)} ms, while dragging ` +
                `${f(frames.draggingMs)} ms; select a pair and draw it ${f(selectMs)} ms`);
    console.log(`  ${stats.pairs} pairs: ` + texts.map((t, k) => `filter "${t}" ${filters[k].filterMs.toFixed(1)} ms ` +
                `(${filters[k].listed} listed) + frame ${f(filters[k].drawMs)} ms`).join(', ') +
                `; Down key + frame ${f(keyMs)} ms`);
    await page.close();
  }
} finally {
  await browser.close();
}
