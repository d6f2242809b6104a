// End-to-end test of the HTML report in headless Chromium (Debian's /usr/bin/chromium, driven
// by playwright-core). Run by ctest (tests/CMakeLists.txt):
//
//   node web/tests/report_browser.mjs --cli build/bin/vertexflow --data data --work DIR [--shots]
//
// It writes two reports with the CLI (`enhance --html` on fandisk; `report` with a lowered
// display limit, so the decimated path is drawn too), opens each from file:// with every
// non-file request refused, and checks: no console errors or page errors, no network request,
// both canvases show a mesh (pixels that are not background), and on the first report: the
// wireframe toggle and each colour map change the picture, the curvature map has red and blue,
// and dragging one view turns the other. Prints one line per check and "N passed, M failed"; exit 1 on a failure.
import { execFileSync } from 'node:child_process';
import { mkdirSync, rmSync, statSync } from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const at = args.indexOf(name);
  return at >= 0 ? args[at + 1] : fallback;
};
const cli = option('--cli');
const dataDir = option('--data');
const work = option('--work');
const keepShots = args.includes('--shots');
const executablePath = option('--chromium', process.env.CHROMIUM ?? '/usr/bin/chromium');
if (!cli || !dataDir || !work) {
  console.error('usage: report_browser.mjs --cli VERTEXFLOW --data DATA_DIR --work DIR [--chromium PATH] [--shots]');
  process.exit(2);
}

let passed = 0;
let failed = 0;
function check(condition, what, detail = '') {
  if (condition) {
    ++passed;
    console.log(`ok: ${what}`);
  } else {
    ++failed;
    console.log(`FAILED: ${what}${detail ? ` (${detail})` : ''}`);
  }
}

rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const run = (...cliArgs) => execFileSync(cli, ['--quiet', ...cliArgs], { stdio: ['ignore', 'inherit', 'inherit'] });
const mesh = path.join(dataDir, 'fandisk.off');
const enhanced = path.join(work, 'fandisk_enhanced.ply');
const fullReport = path.join(work, 'fandisk.html');
const decimatedReport = path.join(work, 'fandisk_decimated.html');
run('enhance', mesh, enhanced, '--html', fullReport);
run('report', mesh, enhanced, decimatedReport, '--max-display-faces', '3000');

// Counts pixels of a PNG screenshot in the page itself (no PNG decoder needed in Node): those
// that differ from the white background, strongly red or blue ones, and (given a second PNG)
// those that differ between the two.
async function analyse(page, png, other = null) {
  return page.evaluate(async ([a, b]) => {
    const load = async (base64) => {
      const image = new Image();
      image.src = `data:image/png;base64,${base64}`;
      await image.decode();
      const canvas = document.createElement('canvas');
      canvas.width = image.width;
      canvas.height = image.height;
      const context = canvas.getContext('2d');
      context.drawImage(image, 0, 0);
      return context.getImageData(0, 0, image.width, image.height).data;
    };
    const pixels = await load(a);
    const second = b ? await load(b) : null;
    let foreground = 0, red = 0, blue = 0, changed = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      const [r, g, bl] = [pixels[i], pixels[i + 1], pixels[i + 2]];
      if (r < 245 || g < 245 || bl < 245) ++foreground;
      if (r > bl + 60 && r > g + 60) ++red;
      if (bl > r + 60 && bl > g + 30) ++blue;
      if (second) {
        const d = Math.abs(r - second[i]) + Math.abs(g - second[i + 1]) + Math.abs(bl - second[i + 2]);
        if (d > 30) ++changed;
      }
    }
    return { total: pixels.length / 4, foreground, red, blue, changed };
  }, [png.toString('base64'), other ? other.toString('base64') : null]);
}

async function frames(page) {
  return page.evaluate(() => Number(document.body.dataset.frames ?? 0));
}

// Runs `action`, then waits until the viewer has drawn a new frame of both views.
async function afterRedraw(page, action) {
  const before = await frames(page);
  await action();
  await page.waitForFunction((n) => Number(document.body.dataset.frames ?? 0) > n, before, { timeout: 10000 });
}

async function testReport(browser, file, { decimated, interact }) {
  const name = path.basename(file);
  const context = await browser.newContext({ viewport: { width: 1000, height: 760 } });
  const requests = [];
  await context.route('**/*', (route) => {
    const url = route.request().url();
    if (url.startsWith('file:')) return route.continue();
    requests.push(url);
    return route.abort();
  });
  const page = await context.newPage();
  const errors = [];
  page.on('console', (message) => {
    if (message.type() === 'error') errors.push(message.text());
  });
  page.on('pageerror', (error) => errors.push(error.message));

  const start = Date.now();
  await page.goto(pathToFileURL(file).href);
  await page.waitForFunction(
    () => document.body.dataset.ready === 'error' || Number(document.body.dataset.frames ?? 0) >= 1, null,
    { timeout: 30000 });
  const loadMs = Date.now() - start;
  console.log(`${name}: ${(statSync(file).size / 1e6).toFixed(2)} MB, first frame after ${loadMs} ms`);
  check(await page.evaluate(() => document.body.dataset.ready === '1'), `${name}: viewer started (WebGL available)`);

  const input = page.locator('#view-input');
  const result = page.locator('#view-result');
  for (const [label, canvas] of [['input', input], ['result', result]]) {
    const stats = await analyse(page, await canvas.screenshot());
    check(stats.foreground > 0.03 * stats.total, `${name}: ${label} canvas shows a mesh`,
      `${stats.foreground} of ${stats.total} pixels not background`);
  }

  if (interact) await testInteraction(page, name, input, result, page.locator('#views'));

  const note = await page.locator('#decimation-note').count();
  check(note === (decimated ? 1 : 0), `${name}: decimation note ${decimated ? 'shown' : 'absent'}`);
  check((await page.locator('#histogram-chart rect').count()) >= 20, `${name}: quality histogram drawn`);
  check((await page.locator('#metrics-table tbody tr').count()) > 5, `${name}: metrics table filled`);
  check(errors.length === 0, `${name}: no console errors`, errors.join(' | '));
  check(requests.length === 0, `${name}: no network requests`, requests.join(' '));
  await context.close();
}

// Toggles and orbiting change the picture.
async function testInteraction(page, name, input, result, views) {
  const shot = async (tag) => {
    const png = await views.screenshot();
    if (keepShots) await views.screenshot({ path: path.join(work, `${name}.${tag}.png`) });
    return png;
  };
  const plain = await shot('plain');

  await afterRedraw(page, () => page.locator('#wireframe').check());
  const wire = await shot('wireframe');
  const wireStats = await analyse(page, wire, plain);
  check(wireStats.changed > 0.01 * wireStats.total, `${name}: wireframe toggle changes the picture`,
    `${wireStats.changed} pixels changed`);
  await afterRedraw(page, () => page.locator('#wireframe').uncheck());
  const back = await analyse(page, await shot('plain-again'), plain);
  check(back.changed < 0.001 * back.total, `${name}: wireframe off restores the picture`, `${back.changed} pixels differ`);

  for (const map of ['mean_curvature', 'quality', 'displacement']) {
    await afterRedraw(page, () => page.locator('#colormap').selectOption(map));
    const stats = await analyse(page, await shot(map), plain);
    check(stats.changed > 0.01 * stats.total, `${name}: colour map ${map} changes the picture`,
      `${stats.changed} pixels changed`);
    if (map === 'mean_curvature')
      check(stats.red > 100 && stats.blue > 100, `${name}: mean curvature map has red (convex) and blue (concave)`,
        `red ${stats.red}, blue ${stats.blue}`);
    if (map === 'displacement') check(stats.red > 100, `${name}: displacement map has red (moved) vertices`);
  }
  await afterRedraw(page, () => page.locator('#colormap').selectOption('none'));

  // Orbit the input view; the result view must turn with it.
  const resultBefore = await result.screenshot();
  const box = await input.boundingBox();
  await afterRedraw(page, async () => {
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 + 150, box.y + box.height / 2 + 40, { steps: 5 });
    await page.mouse.up();
  });
  const turned = await analyse(page, await result.screenshot(), resultBefore);
  check(turned.changed > 0.01 * turned.total, `${name}: dragging the input view turns the result view`,
    `${turned.changed} pixels changed`);
}

// Root (as in CI) needs --no-sandbox; SwiftShader gives WebGL without a GPU; a small /dev/shm
// (containers) must not starve the renderer.
const browser = await chromium.launch({
  executablePath,
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  await testReport(browser, fullReport, { decimated: false, interact: true });
  await testReport(browser, decimatedReport, { decimated: true, interact: false });
} catch (error) {
  check(false, 'browser test ran to the end', error.stack ?? String(error));
} finally {
  await browser.close();
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
