// Runs Khronos' glTF-Validator (the npm package `gltf-validator`) on each file named on the
// command line and prints one line per file: errors, warnings, and the first messages. Exits 1 if
// any file has an error. Used by .ci/run on the LOD chains lodeval exports (tests/integration/
// export.rs writes them to a folder named by LODEVAL_GLTF_EXPORTS).
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const validator = require(process.env.GLTF_VALIDATOR || "gltf-validator");

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const full = path.resolve(path.dirname(file), decodeURIComponent(uri));
        fs.readFile(full, (err, data) => (err ? reject(err.toString()) : resolve(new Uint8Array(data))));
      }),
  });
  const { numErrors, numWarnings, messages } = report.issues;
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings`);
  for (const m of messages.filter((m) => m.severity <= 1).slice(0, 10)) {
    console.log(`  ${m.severity === 0 ? "error" : "warning"} ${m.code} ${m.pointer ?? ""}: ${m.message}`);
  }
  if (numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
