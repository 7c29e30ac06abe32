// Runs the Khronos glTF-Validator (npm `gltf-validator`) on each file named on the command
// line (.glb, or .gltf with its resources beside it) and prints one JSON line per file:
// {file, errors, warnings, infos, messages}. The Rust test `tests/gltf.rs` asserts on it.
import fs from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await fs.readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: async (uri) =>
      new Uint8Array(await fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)))),
  });
  const issues = report.issues;
  console.log(JSON.stringify({
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    messages: issues.messages.map((m) => `${m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`),
    extensions: report.info?.extensionsUsed ?? [],
  }));
}
