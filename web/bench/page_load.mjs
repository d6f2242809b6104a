// Time from navigation to the first drawn frame of both views of an HTML report, in headless
// Chromium with SwiftShader (software WebGL, as in CI; a GPU is faster). Prints each run and
// the median.
//
//   node web/bench/page_load.mjs REPORT.html [RUNS=3]
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const [file, runsText = '3'] = process.argv.slice(2);
if (!file) {
  console.error('usage: page_load.mjs REPORT.html [RUNS]');
  process.exit(2);
}
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
const times = [];
for (let run = 0; run < Number(runsText); ++run) {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  const start = performance.now();
  await page.goto(pathToFileURL(file).href, { timeout: 300000 });
  await page.waitForFunction(() => Number(document.body.dataset.frames ?? 0) >= 1, null, { timeout: 300000 });
  const ms = performance.now() - start;
  times.push(ms);
  // domInteractive: the page parsed and the viewer's script run (data decoded, geometry built),
  // before the first draw.
  const interactive = await page.evaluate(() => performance.getEntriesByType('navigation')[0].domInteractive);
  console.log(`run ${run + 1}: first frame after ${ms.toFixed(0)} ms (page parsed and data decoded after ${interactive.toFixed(0)} ms)`);
  await page.close();
}
times.sort((a, b) => a - b);
console.log(`median ${times[Math.floor(times.length / 2)].toFixed(0)} ms over ${times.length} runs`);
await browser.close();
