// What the headless-Chromium tests share: their command line (--cli, --data, --work,
// --chromium), one line per check, and the closing "N passed, M failed" with its exit code.
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
