#!/usr/bin/env node
// Validates glTF 2.0 files (.gltf or .glb) with the Khronos glTF Validator (npm gltf-validator,
// installed in web/node_modules by scripts/setup.sh).
// Usage: node scripts/validate_gltf.mjs FILE...
// Prints one line per file, "FILE: N errors, M warnings", then its first errors; exits 1 when any
// file has an error or cannot be read, 2 on a usage error. External buffers and images are
// read relative to the file, so a missing .bin or image is reported as an error.
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const MAX_MESSAGES = 5;

const here = path.dirname(fileURLToPath(import.meta.url));
const web = path.resolve(here, '..', 'web');
let validator;
try {
  validator = createRequire(path.join(web, 'package.json'))('gltf-validator');
} catch (e) {
  console.error(`validate_gltf: gltf-validator is not installed in ${web}/node_modules ` +
                `(run scripts/setup.sh): ${e.message}`);
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node scripts/validate_gltf.mjs FILE.gltf|FILE.glb...');
  process.exit(2);
}

async function validate(file) {
  const bytes = new Uint8Array(await readFile(file));
  const dir = path.dirname(path.resolve(file));
  return validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0, // count every issue
    writeTimestamp: false,
    externalResourceFunction: async (uri) =>
      new Uint8Array(await readFile(path.resolve(dir, decodeURIComponent(uri)))),
  });
}

let failed = false;
for (const file of files) {
  let report;
  try {
    report = await validate(file);
  } catch (e) {
    // Unreadable file, or the validator could not tell glTF from GLB.
    console.log(`${file}: cannot be validated: ${e && e.message ? e.message : e}`);
    failed = true;
    continue;
  }
  const { numErrors, numWarnings, messages } = report.issues;
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings`);
  if (numErrors > 0) {
    failed = true;
    for (const m of messages.filter((m) => m.severity === 0).slice(0, MAX_MESSAGES)) {
      console.log(`  ${m.code} ${m.pointer ?? (m.offset !== undefined ? `@${m.offset}` : '')}: ${m.message}`);
    }
    if (numErrors > MAX_MESSAGES) console.log(`  ... and ${numErrors - MAX_MESSAGES} more errors`);
  }
}
process.exit(failed ? 1 : 0);
