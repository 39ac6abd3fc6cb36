// node validate_gltf.mjs NODE_DIR FILE.glb...
// For each file: the Khronos glTF-Validator report (counts and every message) and a decode of
// every KHR_draco_mesh_compression primitive with Google's draco3d, checked against the
// accessors (decoded points vs attribute counts, 3 x decoded faces vs index count, attribute
// unique ids present). Prints one JSON document on stdout:
//   {"files": [{"file", "errors", "warnings", "infos", "hints", "messages": [...],
//               "draco_primitives", "draco_problems": [...]}]}
// Packages are loaded from NODE_DIR/node_modules (scripts/setup_npm_tools.sh installs them).
// Exit code 0 when it ran (the caller judges the report), 2 on usage errors.
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { join } from 'node:path';

const [nodeDir, ...files] = process.argv.slice(2);
if (!nodeDir || files.length === 0) {
  console.error('usage: node validate_gltf.mjs NODE_DIR FILE.glb...');
  process.exit(2);
}
const require = createRequire(join(nodeDir, 'package.json'));
const validator = require('gltf-validator');
const draco3d = require('draco3d');
const draco = await draco3d.createDecoderModule({});

// Splits a .glb into its JSON document and BIN chunk (glTF 2.0 "Binary glTF Layout").
function splitGlb(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let json = null, bin = null;
  for (let at = 12; at + 8 <= bytes.length;) {
    const length = view.getUint32(at, true), type = view.getUint32(at + 4, true);
    const chunk = bytes.subarray(at + 8, at + 8 + length);
    if (type === 0x4e4f534a) json = JSON.parse(new TextDecoder().decode(chunk));
    else if (type === 0x004e4942) bin = chunk;
    at += 8 + length;
  }
  return { json, bin };
}

function checkDraco(json, bin) {
  const problems = [];
  let primitives = 0;
  (json.meshes ?? []).forEach((mesh, mi) => (mesh.primitives ?? []).forEach((prim, pi) => {
    const ext = prim.extensions?.KHR_draco_mesh_compression;
    if (!ext) return;
    primitives++;
    const where = `mesh ${mi} primitive ${pi}`;
    const bv = json.bufferViews[ext.bufferView];
    const data = bin.subarray(bv.byteOffset ?? 0, (bv.byteOffset ?? 0) + bv.byteLength);
    const decoder = new draco.Decoder();
    const out = new draco.Mesh();
    const status = decoder.DecodeArrayToMesh(new Int8Array(data.buffer, data.byteOffset, data.byteLength),
                                             data.byteLength, out);
    if (!status.ok()) {
      problems.push(`${where}: draco3d cannot decode: ${status.error_msg()}`);
    } else {
      const points = out.num_points(), faces = out.num_faces();
      for (const [name, id] of Object.entries(ext.attributes ?? {})) {
        const attribute = decoder.GetAttributeByUniqueId(out, id);
        if (!attribute.ptr) problems.push(`${where}: ${name} unique id ${id} is not in the Draco data`);
        const accessor = json.accessors[prim.attributes?.[name]];
        if (!accessor) problems.push(`${where}: ${name} is in the extension but not in the primitive`);
        else if (accessor.count !== points)
          problems.push(`${where}: ${name} accessor count ${accessor.count} != ${points} decoded points`);
      }
      const indices = json.accessors[prim.indices];
      if (indices && indices.count !== 3 * faces)
        problems.push(`${where}: index count ${indices.count} != 3 x ${faces} decoded faces`);
    }
    draco.destroy(out);
    draco.destroy(decoder);
  }));
  return { primitives, problems };
}

const report = { files: [] };
for (const file of files) {
  const bytes = new Uint8Array(readFileSync(file));
  const result = await validator.validateBytes(bytes, { maxIssues: 0, writeTimestamp: false });
  const issues = result.issues;
  const severity = ['error', 'warning', 'info', 'hint'];
  const { json, bin } = splitGlb(bytes);
  const draco3dCheck = json && bin ? checkDraco(json, bin) : { primitives: 0, problems: ['not a .glb with a BIN chunk'] };
  report.files.push({
    file,
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages.map((m) => `${severity[m.severity]} ${m.code} ${m.pointer ?? ''}: ${m.message}`),
    draco_primitives: draco3dCheck.primitives,
    draco_problems: draco3dCheck.problems,
  });
}
console.log(JSON.stringify(report, null, 1));
