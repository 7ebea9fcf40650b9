// Khronos' glTF-Validator on each file named: prints one line per file with its error and
// warning counts and the first messages, and exits non-zero when any file has an error.
// External resources (.bin, images) are read from beside the file.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 20,
    externalResourceFunction: (uri) =>
      readFile(path.join(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  const { numErrors, numWarnings, messages } = report.issues;
  const errors = messages.filter((m) => m.severity === 0).map((m) => `${m.code} at ${m.pointer}: ${m.message}`);
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings${errors.length ? '; ' + errors.slice(0, 3).join('; ') : ''}`);
  if (numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
