// End-to-end test of the HTML report in headless Chromium (Debian's /usr/bin/chromium, driven
// by playwright-core). Run by ctest (tests/CMakeLists.txt):
//
//   node web/tests/report_browser.mjs --cli build/bin/vertexflow --data data --work DIR [--shots]
//
// It writes four reports with the CLI: `enhance --html` on fandisk; `report` with a lowered
// display limit, so the decimated path is drawn too; and the same two for an `--edge-flips`
// result, which has faces of its own. It opens each from file:// with every non-file request
// refused, and checks: no console errors or page errors, no network request, both canvases
// show a mesh (pixels that are not background), each view draws its own mesh's display faces,
// and on the first report: the wireframe toggle and each colour map change both views, the
// curvature map has red and blue, and dragging the input view turns the result view too; on
// the edge-flip report: the per-face quality map changes both views. Two more reports of spot
// (texture coordinates), full and decimated: the checker-texture toggle and its squares box
// change both views and unchecking takes the texture off; fandisk's reports (no texture
// coordinates) hide the checker controls. Prints one line per check and "N passed, M failed";
// exit 1 on a failure.
import { execFileSync } from 'node:child_process';
import { statSync } from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';
import { check, finish, offlinePage, testSetup } from './harness.mjs';

const { args, cli, dataDir, work, executablePath } = testSetup(
  'report_browser.mjs --cli VERTEXFLOW --data DATA_DIR --work DIR [--chromium PATH] [--shots]');
const keepShots = args.includes('--shots');
const run = (...cliArgs) => execFileSync(cli, ['--quiet', ...cliArgs], { stdio: ['ignore', 'inherit', 'inherit'] });
const mesh = path.join(dataDir, 'fandisk.off');
const enhanced = path.join(work, 'fandisk_enhanced.ply');
const fullReport = path.join(work, 'fandisk.html');
const decimatedReport = path.join(work, 'fandisk_decimated.html');
const flipped = path.join(work, 'fandisk_flipped.ply');
const flipsReport = path.join(work, 'fandisk_flips.html');
const flipsDecimatedReport = path.join(work, 'fandisk_flips_decimated.html');
run('enhance', mesh, enhanced, '--html', fullReport);
run('report', mesh, enhanced, decimatedReport, '--max-display-faces', '3000');
run('enhance', mesh, flipped, '--edge-flips', '--html', flipsReport);
run('report', mesh, flipped, flipsDecimatedReport, '--max-display-faces', '3000');
const spot = path.join(dataDir, 'spot.obj');
const spotEnhanced = path.join(work, 'spot_enhanced.obj');
const spotReport = path.join(work, 'spot.html');
const spotDecimatedReport = path.join(work, 'spot_decimated.html');
run('enhance', spot, spotEnhanced, '--html', spotReport);
run('report', spot, spotEnhanced, spotDecimatedReport, '--max-display-faces', '2000');

// One screenshot of the strip holding both canvases (few screenshots: each costs a software
// render and a PNG round trip), and where each canvas lies in it.
async function shoot(page, tag) {
  const boxes = await Promise.all(['#view-input', '#view-result'].map((id) => page.locator(id).boundingBox()));
  const x = Math.floor(boxes[0].x), y = Math.floor(Math.min(boxes[0].y, boxes[1].y));
  const clip = { x, y, width: Math.ceil(boxes[1].x + boxes[1].width) - x, height: Math.ceil(boxes[0].height) };
  const png = await page.screenshot({ clip });
  if (keepShots) await page.screenshot({ clip, path: path.join(work, `${tag}.png`) });
  const rects = boxes.map((b) => ({
    x: Math.ceil(b.x - x) + 1, y: Math.ceil(b.y - y) + 1, width: Math.floor(b.width) - 2, height: Math.floor(b.height) - 2,
  }));
  return { png, rects };
}

// Per canvas (input, result): pixels that are not the white background, strongly red or blue
// ones, and (given an earlier shot) pixels that changed. Decoded in the page itself, so Node
// needs no PNG decoder.
async function analyse(page, shot, earlier = null) {
  return page.evaluate(async ([a, b, rects]) => {
    const load = async (base64) => {
      const image = new Image();
      image.src = `data:image/png;base64,${base64}`;
      await image.decode();
      const canvas = document.createElement('canvas');
      canvas.width = image.width;
      canvas.height = image.height;
      const context = canvas.getContext('2d');
      context.drawImage(image, 0, 0);
      return { data: context.getImageData(0, 0, image.width, image.height).data, width: image.width };
    };
    const first = await load(a);
    const second = b ? await load(b) : null;
    return rects.map((rect) => {
      let foreground = 0, red = 0, blue = 0, changed = 0;
      for (let row = rect.y; row < rect.y + rect.height; ++row) {
        for (let col = rect.x; col < rect.x + rect.width; ++col) {
          const i = 4 * (row * first.width + col);
          const [r, g, bl] = [first.data[i], first.data[i + 1], first.data[i + 2]];
          if (r < 245 || g < 245 || bl < 245) ++foreground;
          if (r > bl + 60 && r > g + 60) ++red;
          if (bl > r + 60 && bl > g + 30) ++blue;
          if (second) {
            const o = second.data;
            if (Math.abs(r - o[i]) + Math.abs(g - o[i + 1]) + Math.abs(bl - o[i + 2]) > 30) ++changed;
          }
        }
      }
      return { total: rect.width * rect.height, foreground, red, blue, changed };
    });
  }, [shot.png.toString('base64'), earlier ? earlier.png.toString('base64') : null, shot.rects]);
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

const VIEWS = ['input', 'result'];

async function testReport(browser, file, { decimated, interact, ownFaces, quality = false, checker = false }) {
  const name = path.basename(file);
  const { context, page, requests, errors } = await offlinePage(browser, { width: 900, height: 700 });

  const start = Date.now();
  await page.goto(pathToFileURL(file).href);
  await page.waitForFunction(
    () => document.body.dataset.ready === 'error' || Number(document.body.dataset.frames ?? 0) >= 1, null,
    { timeout: 30000 });
  const loadMs = Date.now() - start;
  console.log(`${name}: ${(statSync(file).size / 1e6).toFixed(2)} MB, first frame after ${loadMs} ms`);
  check(await page.evaluate(() => document.body.dataset.ready === '1'), `${name}: viewer started (WebGL available)`);

  const plain = await shoot(page, `${name}.plain`);
  (await analyse(page, plain)).forEach((stats, k) =>
    check(stats.foreground > 0.03 * stats.total, `${name}: ${VIEWS[k]} canvas shows a mesh`,
      `${stats.foreground} of ${stats.total} pixels not background`));

  // The faces each view draws: the input's display faces, and the result's own when it has them.
  const display = await page.evaluate(() => JSON.parse(document.getElementById('vertexflow-data').textContent).display);
  check((display.result_indices !== undefined) === ownFaces,
    `${name}: the result ${ownFaces ? 'has its own faces' : 'shares the input\'s faces'}`);
  const drawn = await page.evaluate(() => document.body.dataset.faces);
  check(drawn === `${display.faces} ${display.result_faces ?? display.faces}`,
    `${name}: each view draws its own mesh's faces`, `drawn ${drawn}`);

  if (interact) await testInteraction(page, name, plain);
  const controls = await page.locator('#checker-controls').isVisible();
  check(controls === checker, `${name}: checker-texture controls ${checker ? 'shown' : 'hidden'}`);
  if (checker) await testChecker(page, name, plain);
  if (quality) {
    await afterRedraw(page, () => page.locator('#colormap').selectOption('quality'));
    const stats = await analyse(page, await shoot(page, `${name}.quality`), plain);
    check(stats.every((s) => s.changed > 0.01 * s.total), `${name}: colour map quality changes both views`,
      stats.map((s) => s.changed).join(' and '));
  }

  const note = await page.locator('#decimation-note').count();
  check(note === (decimated ? 1 : 0), `${name}: decimation note ${decimated ? 'shown' : 'absent'}`);
  check((await page.locator('#histogram-chart rect').count()) >= 20, `${name}: quality histogram drawn`);
  check((await page.locator('#metrics-table tbody tr').count()) > 5, `${name}: metrics table filled`);
  check(errors.length === 0, `${name}: no console errors`, errors.join(' | '));
  check(requests.length === 0, `${name}: no network requests`, requests.join(' '));
  await context.close();
}

// Toggles and orbiting change the picture of both views.
async function testInteraction(page, name, plain) {
  const changedBoth = (stats) => stats.every((s) => s.changed > 0.01 * s.total);
  const changes = (stats) => stats.map((s) => s.changed).join(' and ');

  await afterRedraw(page, () => page.locator('#wireframe').check());
  const wire = await analyse(page, await shoot(page, `${name}.wireframe`), plain);
  check(changedBoth(wire), `${name}: wireframe toggle changes both views`, `${changes(wire)} pixels changed`);
  await afterRedraw(page, () => page.locator('#wireframe').uncheck());

  for (const map of ['mean_curvature', 'quality', 'displacement']) {
    await afterRedraw(page, () => page.locator('#colormap').selectOption(map));
    const stats = await analyse(page, await shoot(page, `${name}.${map}`), plain);
    check(changedBoth(stats), `${name}: colour map ${map} changes both views`, `${changes(stats)} pixels changed`);
    if (map === 'mean_curvature')
      check(stats.every((s) => s.red > 100 && s.blue > 100),
        `${name}: mean curvature map has red (convex) and blue (concave)`,
        stats.map((s) => `red ${s.red}, blue ${s.blue}`).join('; '));
    if (map === 'displacement') check(stats.every((s) => s.red > 100), `${name}: displacement map has red (moved) vertices`);
  }
  await afterRedraw(page, () => page.locator('#colormap').selectOption('none'));

  // Orbit the input view; the result view must turn with it. Back to plain shading, the
  // picture before the drag is `plain`.
  const box = await page.locator('#view-input').boundingBox();
  await afterRedraw(page, async () => {
    await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
    await page.mouse.down();
    await page.mouse.move(box.x + box.width / 2 + 150, box.y + box.height / 2 + 40, { steps: 5 });
    await page.mouse.up();
  });
  const turned = await analyse(page, await shoot(page, `${name}.turned`), plain);
  check(changedBoth(turned), `${name}: dragging the input view turns both views`, `${changes(turned)} pixels changed`);
}

// The checker texture (render --texture checker's view): toggling it, and changing its squares,
// change both views; unchecking it gives the plain picture back.
async function testChecker(page, name, plain) {
  const changedBoth = (stats) => stats.every((s) => s.changed > 0.05 * s.foreground);
  const changes = (stats) => stats.map((s) => s.changed).join(' and ');
  await afterRedraw(page, () => page.locator('#checker').check());
  const textured = await shoot(page, `${name}.checker`);
  const on = await analyse(page, textured, plain);
  check(changedBoth(on), `${name}: checker texture changes both views`, `${changes(on)} pixels changed`);
  await afterRedraw(page, async () => {
    await page.locator('#checker-squares').fill('4');
    await page.locator('#checker-squares').dispatchEvent('change');
  });
  const coarse = await analyse(page, await shoot(page, `${name}.checker4`), textured);
  check(changedBoth(coarse), `${name}: checker squares change both views`, `${changes(coarse)} pixels changed`);
  await afterRedraw(page, () => page.locator('#checker').uncheck());
  const off = await analyse(page, await shoot(page, `${name}.checker-off`), plain);
  check(off.every((s) => s.changed < 0.01 * s.total), `${name}: unchecking gives the plain picture back`,
    `${changes(off)} pixels differ`);
}

// Root (as in CI) needs --no-sandbox; SwiftShader gives WebGL without a GPU; a small /dev/shm
// (containers) must not starve the renderer.
const browser = await chromium.launch({
  executablePath,
  headless: true,
  args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  await testReport(browser, fullReport, { decimated: false, interact: true, ownFaces: false });
  await testReport(browser, decimatedReport, { decimated: true, interact: false, ownFaces: false });
  await testReport(browser, flipsReport, { decimated: false, interact: false, ownFaces: true, quality: true });
  await testReport(browser, flipsDecimatedReport, { decimated: true, interact: false, ownFaces: true });
  await testReport(browser, spotReport, { decimated: false, interact: false, ownFaces: false, checker: true });
  await testReport(browser, spotDecimatedReport, { decimated: true, interact: false, ownFaces: false, checker: true });
} catch (error) {
  check(false, 'browser test ran to the end', error.stack ?? String(error));
} finally {
  await browser.close();
}
finish();
