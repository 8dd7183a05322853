// The editor's WebSocket messages; the layouts are documented in apps/server/protocol.h.
// Little-endian, every array aligned to its element size, read with typed arrays in place.

export const Tag = {
  Selection: 1,
  Frame: 2,
  MeshFile: 3,
  SelectionFile: 4,
  Mesh: 101,
  FrameResult: 102,
  File: 103,
  SelectionResult: 104,
} as const;

export interface Selection {
  handles: number[][]; // vertex indices of each handle group
  fixed: number[];
}

export interface MeshMessage {
  positions: Float32Array; // 3 n
  indices: Uint32Array; // 3 T
}

export interface FrameResult {
  seq: number;
  baseView: boolean;
  ms: { reducedSolve: number; inverseTransform: number; detail: number; total: number };
  error: { max: number; rms: number };
  positions: Float32Array; // 3 n
}

export interface NamedFile {
  name: string;
  data: Uint8Array;
}

export function tagOf(buffer: ArrayBuffer): number {
  return new Uint32Array(buffer, 0, 1)[0];
}

export function encodeSelection(s: Selection): ArrayBuffer {
  const total = s.fixed.length + s.handles.reduce((a, g) => a + g.length, 0);
  const out = new Uint32Array(3 + s.handles.length + total);
  out[0] = Tag.Selection;
  out[1] = s.handles.length;
  out[2] = s.fixed.length;
  s.handles.forEach((g, i) => (out[3 + i] = g.length));
  let k = 3 + s.handles.length;
  for (const v of s.fixed) out[k++] = v;
  for (const g of s.handles) for (const v of g) out[k++] = v;
  return out.buffer;
}

export function decodeSelection(buffer: ArrayBuffer): Selection {
  const u = new Uint32Array(buffer);
  const groups = u[1];
  let k = 3 + groups;
  const fixed = Array.from(u.subarray(k, k + u[2]));
  k += u[2];
  const handles: number[][] = [];
  for (let g = 0; g < groups; ++g) {
    handles.push(Array.from(u.subarray(k, k + u[3 + g])));
    k += u[3 + g];
  }
  return { handles, fixed };
}

// `transforms`: one 4 x 4 matrix per handle group, row-major.
export function encodeFrame(seq: number, transforms: number[][]): ArrayBuffer {
  const buffer = new ArrayBuffer(16 + transforms.length * 128);
  const head = new Uint32Array(buffer, 0, 4);
  head[0] = Tag.Frame;
  head[1] = seq;
  head[2] = transforms.length;
  const m = new Float64Array(buffer, 16);
  transforms.forEach((t, g) => m.set(t, 16 * g));
  return buffer;
}

export function encodeFile(tag: number, name: string, data: ArrayBuffer): ArrayBuffer {
  const nameBytes = new TextEncoder().encode(name);
  const padded = Math.ceil(nameBytes.length / 4) * 4;
  const out = new Uint8Array(8 + padded + data.byteLength);
  new DataView(out.buffer).setUint32(0, tag, true);
  new DataView(out.buffer).setUint32(4, nameBytes.length, true);
  out.set(nameBytes, 8);
  out.set(new Uint8Array(data), 8 + padded);
  return out.buffer;
}

export function decodeFile(buffer: ArrayBuffer): NamedFile {
  const length = new DataView(buffer).getUint32(4, true);
  const name = new TextDecoder().decode(new Uint8Array(buffer, 8, length));
  return { name, data: new Uint8Array(buffer, 8 + Math.ceil(length / 4) * 4) };
}

export function decodeMesh(buffer: ArrayBuffer): MeshMessage {
  const [, n, triangles] = new Uint32Array(buffer, 0, 3);
  return {
    positions: new Float32Array(buffer, 12, 3 * n),
    indices: new Uint32Array(buffer, 12 + 12 * n, 3 * triangles),
  };
}

export function decodeFrameResult(buffer: ArrayBuffer): FrameResult {
  const u = new Uint32Array(buffer, 0, 4);
  const f = new Float32Array(buffer, 16, 6);
  return {
    seq: u[1],
    baseView: u[3] === 1,
    ms: { reducedSolve: f[0], inverseTransform: f[1], detail: f[2], total: f[3] },
    error: { max: f[4], rms: f[5] },
    positions: new Float32Array(buffer, 40, 3 * u[2]),
  };
}
