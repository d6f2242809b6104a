// What the headless-Chromium tests share: their command line (--cli, --data, --work,
// --chromium), a page that may not leave file://, one line per check, and the closing
// "N passed, M failed" with its exit code.
import { mkdirSync, rmSync } from 'node:fs';

/// Parses the common options; prints `usage` and exits 2 when --cli, --data or --work is missing.
/// Empties and creates the work directory.
export function testSetup(usage) {
  const args = process.argv.slice(2);
  const option = (name, fallback) => {
    const at = args.indexOf(name);
    return at >= 0 ? args[at + 1] : fallback;
  };
  const setup = {
    args,
    cli: option('--cli'),
    dataDir: option('--data'),
    work: option('--work'),
    executablePath: option('--chromium', process.env.CHROMIUM ?? '/usr/bin/chromium'),
  };
  if (!setup.cli || !setup.dataDir || !setup.work) {
    console.error(`usage: ${usage}`);
    process.exit(2);
  }
  rmSync(setup.work, { recursive: true, force: true });
  mkdirSync(setup.work, { recursive: true });
  return setup;
}

/// A new context of `browser` with `viewport` and a page in it. Every request other than file:// is
/// refused and recorded in `requests`; console errors and page errors are recorded in `errors`.
/// The caller checks both and closes `context`.
export async function offlinePage(browser, viewport) {
  const context = await browser.newContext({ viewport });
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
  return { context, page, requests, errors };
}

let passed = 0;
let failed = 0;

/// Records one check and prints "ok: what" or "FAILED: what (detail)".
export function check(condition, what, detail = '') {
  if (condition) {
    ++passed;
    console.log(`ok: ${what}`);
  } else {
    ++failed;
    console.log(`FAILED: ${what}${detail ? ` (${detail})` : ''}`);
  }
}

/// Prints the summary line and exits 1 if any check failed, else 0.
export function finish() {
  console.log(`${passed} passed, ${failed} failed`);
  process.exit(failed === 0 ? 0 : 1);
}
