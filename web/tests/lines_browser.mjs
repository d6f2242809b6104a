// The SVG of `vertexflow lines` in headless Chromium (issue 17): it opens without errors, its
// groups and polylines are in the DOM, and a screenshot shows the lines drawn. Run by ctest:
//
//   node web/tests/lines_browser.mjs --cli build/bin/vertexflow --data data --work DIR
//
// Checks: no console or page errors and no network request while loading; one <g> per line
// type with polylines in each; the screenshot has dark (contour and suggestive contour) pixels,
// red (ridge) and blue (valley) pixels, and is mostly white; and the same SVG drawn without its
// lines (the groups removed in the page) has no dark pixel, so the pixels come from the lines.
// Prints one line per check and "N passed, M failed"; exit 1 on a failure.
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';
import { check, finish, offlinePage, testSetup } from './harness.mjs';

const { cli, dataDir, work, executablePath } = testSetup(
  'lines_browser.mjs --cli VERTEXFLOW --data DATA_DIR --work DIR [--chromium PATH]');
const svg = path.join(work, 'bunny.svg');
execFileSync(cli, ['--quiet', 'lines', path.join(dataDir, 'bunny_uniform.off'), svg, '--size', '800x600'],
  { stdio: ['ignore', 'inherit', 'inherit'] });

// Dark, red, blue and white pixels of a PNG screenshot, decoded in the page (no PNG decoder in Node).
async function count(page, png) {
  return page.evaluate(async (base64) => {
    const image = new Image();
    image.src = `data:image/png;base64,${base64}`;
    await image.decode();
    // The page is an SVG document, without HTML's canvas element: an OffscreenCanvas decodes.
    const canvas = new OffscreenCanvas(image.width, image.height);
    const context = canvas.getContext('2d');
    context.drawImage(image, 0, 0);
    const data = context.getImageData(0, 0, image.width, image.height).data;
    let dark = 0, red = 0, blue = 0, white = 0;
    for (let i = 0; i < data.length; i += 4) {
      const [r, g, b] = [data[i], data[i + 1], data[i + 2]];
      if (r < 100 && g < 100 && b < 100) ++dark;
      if (r > b + 50 && r > g + 50) ++red;
      if (b > r + 50 && b > g + 30) ++blue;
      if (r > 245 && g > 245 && b > 245) ++white;
    }
    return { total: data.length / 4, dark, red, blue, white };
  }, png.toString('base64'));
}

const browser = await chromium.launch({
  executablePath,
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage'],
});
try {
  const { context, page, requests, errors } = await offlinePage(browser, { width: 800, height: 600 });
  const response = await page.goto(pathToFileURL(svg).href);
  check(response !== null && response.ok(), 'the SVG loads');
  const groups = await page.evaluate(() =>
    [...document.querySelectorAll('svg > g')].map((g) => [g.id, g.querySelectorAll('polyline').length]));
  const ids = groups.map(([id]) => id).join(',');
  check(ids === 'contours,suggestive-contours,ridges,valleys', 'one group per line type', ids);
  check(groups.every(([, n]) => n > 0), 'every group has polylines', JSON.stringify(groups));
  const drawn = await count(page, await page.screenshot());
  console.log(`screenshot: ${JSON.stringify(drawn)}`);
  check(drawn.dark > 2000, 'contours and suggestive contours are drawn (dark pixels)', `${drawn.dark}`);
  check(drawn.red > 100 && drawn.blue > 100, 'ridges (red) and valleys (blue) are drawn', `${drawn.red}, ${drawn.blue}`);
  check(drawn.white > 0.8 * drawn.total, 'the background is white', `${drawn.white} of ${drawn.total}`);
  await page.evaluate(() => document.querySelectorAll('svg > g').forEach((g) => g.remove()));
  const empty = await count(page, await page.screenshot());
  check(empty.dark === 0 && empty.red === 0, 'without its lines the drawing is blank', JSON.stringify(empty));
  check(errors.length === 0, 'no console errors', errors.join(' | '));
  check(requests.length === 0, 'no network requests', requests.join(' '));
  await context.close();
} catch (error) {
  check(false, 'browser test ran to the end', error.stack ?? String(error));
} finally {
  await browser.close();
}
finish();
