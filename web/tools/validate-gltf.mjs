// The Khronos glTF Validator on files: `node tools/validate-gltf.mjs FILE...` prints one JSON
// line per file: {"file", "errors", "warnings", "infos", "hints"} (each a list of issue codes,
// one entry per issue), "unresolved" (the uris it could not read) and "error" (a file it could
// not validate at all). External buffers and images are read beside the file, their uris
// percent-decoded. Exits 0 whatever it found: comparing inputs and outputs is the caller's part.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const SEVERITIES = ['errors', 'warnings', 'infos', 'hints'];

async function validate(file) {
  const unresolved = [];
  const report = await validator.validateBytes(new Uint8Array(await readFile(file)), {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: async (uri) => {
      try {
        return new Uint8Array(await readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))));
      } catch (e) {
        unresolved.push(uri);
        throw e;
      }
    },
  });
  const out = { file, unresolved };
  for (const s of SEVERITIES) out[s] = [];
  for (const m of report.issues.messages) out[SEVERITIES[m.severity]].push(m.code);
  return out;
}

for (const file of process.argv.slice(2)) {
  try {
    console.log(JSON.stringify(await validate(file)));
  } catch (e) {
    console.log(JSON.stringify({ file, error: String(e && e.message ? e.message : e) }));
  }
}
