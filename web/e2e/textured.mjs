// Textured test files for the end-to-end test, made here (a checkout without the shared meshes
// has none): a cube with a normal and texture coordinates per side and a 2 x 2 checker image,
// as a .glb (the image inside) and as an OBJ with its MTL and PNG beside it.
import { writeFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { crc32, deflateSync } from 'node:zlib';

// A 2 x 2 RGB checker PNG.
export function checkerPng() {
  const chunk = (type, data) => {
    const out = Buffer.alloc(12 + data.length);
    out.writeUInt32BE(data.length, 0);
    out.write(type, 4, 'latin1');
    data.copy(out, 8);
    out.writeUInt32BE(crc32(Buffer.concat([Buffer.from(type, 'latin1'), data])), 8 + data.length);
    return out;
  };
  const header = Buffer.alloc(13);
  header.writeUInt32BE(2, 0);
  header.writeUInt32BE(2, 4);
  header[8] = 8; // bit depth
  header[9] = 2; // RGB
  const rows = Buffer.from([0, 230, 60, 40, 250, 250, 250, 0, 250, 250, 250, 40, 90, 220]);
  return Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', header),
    chunk('IDAT', deflateSync(rows)), chunk('IEND', Buffer.alloc(0))]);
}

// The cube's sides: 4 vertices each (position, normal, uv), 2 triangles.
function cube() {
  const position = [], normal = [], uv = [], index = [];
  for (let axis = 0; axis < 3; ++axis) {
    for (const sign of [-1, 1]) {
      const n = [0, 0, 0];
      n[axis] = sign;
      const u = [0, 0, 0];
      u[(axis + 1) % 3] = sign;
      const v = [n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]];
      const first = position.length / 3;
      for (const [a, b] of [[-1, -1], [1, -1], [1, 1], [-1, 1]]) {
        for (let k = 0; k < 3; ++k) position.push(n[k] + a * u[k] + b * v[k]);
        normal.push(...n);
        uv.push((a + 1) / 2, (b + 1) / 2);
      }
      index.push(first, first + 1, first + 2, first, first + 2, first + 3);
    }
  }
  return { position, normal, uv, index };
}

export function writeTexturedGlb(path) {
  const c = cube();
  const png = checkerPng();
  const parts = [new Float32Array(c.position), new Float32Array(c.normal),
    new Float32Array(c.uv.map((x, i) => (i % 2 ? 1 - x : x))), new Uint16Array(c.index)];
  const views = [];
  const chunks = [];
  let offset = 0;
  for (const data of [...parts.map((p) => Buffer.from(p.buffer)), png]) {
    views.push({ buffer: 0, byteOffset: offset, byteLength: data.length });
    const padded = Buffer.alloc(Math.ceil(data.length / 4) * 4);
    data.copy(padded);
    chunks.push(padded);
    offset += padded.length;
  }
  const json = {
    asset: { version: '2.0', generator: 'specdeform e2e' },
    scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0, name: 'Cube', translation: [0, 1, 0] }],
    meshes: [{ name: 'Cube', primitives: [{ attributes: { POSITION: 0, NORMAL: 1, TEXCOORD_0: 2 }, indices: 3, material: 0 }] }],
    materials: [{ name: 'Checker', pbrMetallicRoughness: { baseColorTexture: { index: 0 } } }],
    textures: [{ source: 0 }], images: [{ bufferView: 4, mimeType: 'image/png' }],
    accessors: [
      { bufferView: 0, componentType: 5126, count: 24, type: 'VEC3', min: [-1, -1, -1], max: [1, 1, 1] },
      { bufferView: 1, componentType: 5126, count: 24, type: 'VEC3' },
      { bufferView: 2, componentType: 5126, count: 24, type: 'VEC2' },
      { bufferView: 3, componentType: 5123, count: 36, type: 'SCALAR' },
    ],
    bufferViews: views, buffers: [{ byteLength: offset }],
  };
  let text = Buffer.from(JSON.stringify(json));
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const bin = Buffer.concat(chunks);
  const head = Buffer.alloc(12);
  head.write('glTF', 0, 'latin1');
  head.writeUInt32LE(2, 4);
  head.writeUInt32LE(12 + 8 + text.length + 8 + bin.length, 8);
  const chunkHead = (length, type) => {
    const b = Buffer.alloc(8);
    b.writeUInt32LE(length, 0);
    b.writeUInt32LE(type, 4);
    return b;
  };
  writeFileSync(path, Buffer.concat([head, chunkHead(text.length, 0x4e4f534a), text, chunkHead(bin.length, 0x004e4942), bin]));
}

// cube.obj, cube.mtl and checker.png in `dir`; returns their paths.
export function writeTexturedObj(dir) {
  const c = cube();
  // The positions once each (8): the sides' vertices name them, with their own uv and normal.
  const key = (i) => c.position.slice(3 * i, 3 * i + 3).join(' ');
  const positions = [...new Set(c.position.map((_, i) => i).filter((i) => i < 24).map(key))];
  let obj = '# a textured cube\nmtllib cube.mtl\no Cube\n';
  for (const p of positions) obj += `v ${p}\n`;
  for (let i = 0; i < c.uv.length; i += 2) obj += `vt ${c.uv[i]} ${c.uv[i + 1]}\n`;
  for (let i = 0; i < c.normal.length; i += 3) obj += `vn ${c.normal.slice(i, i + 3).join(' ')}\n`;
  obj += 'usemtl Checker\ns off\n';
  for (let t = 0; t < c.index.length; t += 3) {
    const corner = (v) => `${positions.indexOf(key(v)) + 1}/${v + 1}/${v + 1}`;
    obj += `f ${c.index.slice(t, t + 3).map(corner).join(' ')}\n`;
  }
  const paths = ['cube.obj', 'cube.mtl', 'checker.png'].map((f) => resolve(dir, f));
  writeFileSync(paths[0], obj);
  writeFileSync(paths[1], 'newmtl Checker\nKd 1 1 1\nmap_Kd checker.png\n');
  writeFileSync(paths[2], checkerPng());
  return paths;
}
