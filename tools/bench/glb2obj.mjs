// Decodes a .glb (Draco, meshopt, quantized) to an OBJ of its scene's triangles in world space.
import { createRequire } from 'module';
const require = createRequire(process.env.NODE_DIR + '/node_modules/');
const { NodeIO } = require('@gltf-transform/core');
const { ALL_EXTENSIONS } = require('@gltf-transform/extensions');
const draco3d = require('draco3d');
const { MeshoptDecoder } = require('meshoptimizer');
import fs from 'fs';
await MeshoptDecoder.ready;
const io = new NodeIO().registerExtensions(ALL_EXTENSIONS).registerDependencies({
  'draco3d.decoder': await draco3d.createDecoderModule(), 'meshopt.decoder': MeshoptDecoder });
const doc = await io.read(process.argv[2]);
const scene = doc.getRoot().getDefaultScene() || doc.getRoot().listScenes()[0];
let out = [], base = 1;
scene.traverse((node) => {
  const mesh = node.getMesh(); if (!mesh) return;
  const m = node.getWorldMatrix();
  for (const prim of mesh.listPrimitives()) {
    const pos = prim.getAttribute('POSITION'); const idx = prim.getIndices();
    const n = pos.getCount(); const el = [];
    for (let i = 0; i < n; ++i) {
      pos.getElement(i, el);
      const x = m[0]*el[0]+m[4]*el[1]+m[8]*el[2]+m[12], y = m[1]*el[0]+m[5]*el[1]+m[9]*el[2]+m[13], z = m[2]*el[0]+m[6]*el[1]+m[10]*el[2]+m[14];
      out.push(`v ${x} ${y} ${z}`);
    }
    const count = idx ? idx.getCount() : n;
    for (let i = 0; i + 2 < count; i += 3) {
      const a = idx ? idx.getScalar(i) : i, b = idx ? idx.getScalar(i+1) : i+1, c = idx ? idx.getScalar(i+2) : i+2;
      out.push(`f ${a+base} ${b+base} ${c+base}`);
    }
    base += n;
  }
});
fs.writeFileSync(process.argv[3], out.join('\n') + '\n');
