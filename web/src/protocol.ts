// The editor's WebSocket messages, typed: the binary layouts of apps/server/protocol.h and the
// JSON messages of apps/server/editor_session.h (tests/server/web_protocol_test.cpp checks that
// the tags below match the server's). Little-endian, every array aligned to its element size,
// read with typed arrays in place.

export const Tag = {
  Selection: 1,
  Frame: 2,
  MeshFile: 3,
  SelectionFile: 4,
  SceneFile: 5,
  CompanionFile: 6,
  Mesh: 101,
  FrameResult: 102,
  File: 103,
  SelectionResult: 104,
  Preview: 105,
  Appearance: 106,
  Texture: 107,
} as const;

export type FileTag = typeof Tag.MeshFile | typeof Tag.SelectionFile | typeof Tag.SceneFile | typeof Tag.CompanionFile;

export type Matrix = number[]; // 4 x 4, row-major

export type Energy = 'linear' | 'arap';
export type Detail = 'none' | 'displacement' | 'frames' | 'transfer';
export type Constraints = 'soft' | 'hard';
export type Unconstrained = 'follow' | 'keep' | 'error';
export type View = 'detailed' | 'base';

export interface Settings {
  energy: Energy;
  ks: number;
  kb: number;
  detail: Detail;
  constraints: Constraints;
  unconstrained: Unconstrained; // pieces without a handle or fixed vertex
  influence: number; // the region of influence around the handles, of the diagonal (0: none)
  view: View;
}

// ---------------------------------------------------------------- JSON, server -> browser

// While a basis is prepared; a mesh being opened is sent before its first one (drawn, painted).
export interface ProgressMessage {
  type: 'progress';
  stage: string;
  fraction: number; // 1 for a stage without a fraction of its own ("setting up the solver")
  cancellable: boolean;
}

export interface ReadyMessage {
  type: 'ready';
  name: string;
  vertices: number;
  faces: number;
  diagonal: number;
  mesh_id: string;
  modes: number;
  pose: number;
  settings: Settings;
  basis: {
    seconds: number;
    source: 'computed' | 'cache' | 'reused';
    residual: number;
    approximate: boolean; // multilevel: M-orthonormal, not eigenvectors (the residual says how far)
    warning: string;
  };
  setup: { reduced_system: number; detail_factorization: number; selection: number };
  arap_clusters: number;
  rig: { morph_targets: number; skins: number }; // a glTF's, which Export carries with the surface
}

export interface StateMessage {
  type: 'state';
  request: string; // the request it answers ("open": the server's first mesh, unrequested)
  groups: { vertices: number; pinned: boolean; transform: Matrix }[];
  fixed: number;
  undo: boolean;
  redo: boolean;
  selection_seconds: number;
  pin_error: number;
  free_pieces: number; // pieces without a constrained vertex
  constrained_piece_modes: number[]; // the basis's modes on each piece with a handle or fixed vertex
  detail_pending: boolean; // the transfer's factorisation runs on the server: displacements meanwhile
  pose: number;
}

export interface ErrorMessage {
  type: 'error';
  message: string;
  request: string;
  cancelled: boolean;
}

export type ServerText =
  | MeshNotice
  | ProgressMessage
  | ReadyMessage
  | StateMessage
  | ErrorMessage
  | { type: 'empty'; request: string }
  | { type: 'note'; message: string } // what an export dropped or changed
  // The basis just computed, written to the cache in the background (after "ready"): once when
  // it starts, once when it is done (with its size and time, or the error).
  | { type: 'saving'; file: string; done: boolean; seconds?: number; bytes?: number; error?: string };

// A mesh to fetch (apps/server/editor_server.h): GET /mesh/ID, its parts (101) one after the
// other, `bytes` in all; /mesh/latest serves the last one, its id in X-Mesh-Id.
export interface MeshNotice {
  type: 'mesh';
  id: string;
  bytes: number;
}

// ---------------------------------------------------------------- JSON, browser -> server

export type ClientText =
  | { type: 'open_demo' | 'commit' | 'undo' | 'redo' | 'apply_pose' | 'export_scene' | 'cancel' }
  | ({ type: 'settings' } & Partial<Settings> & { modes?: number })
  | { type: 'preview'; vertices: number }
  | { type: 'export_mesh'; format?: ExportFormat; morph_targets?: 'turn' | 'keep'; joints?: 'follow' | 'keep' }; // none: the opened file's own; the rig follows

export type ExportFormat = 'obj' | 'off' | 'ply' | 'stl' | 'gltf' | 'glb';

// ---------------------------------------------------------------- binary

// Handle groups (vertex lists in mesh numbering) with their transforms and flags, and the fixed
// vertices. `fit`: the server fits a pinned group's transform to where its vertices are shown.
export interface Selection {
  groups: { vertices: Uint32Array; transform: Matrix; pinned: boolean; fit?: boolean }[];
  fixed: Uint32Array;
  echo?: boolean; // the server sends it back (a restored edit)
}

// One of a mesh's parts: positions (of vertices [first, first + count)), then triangles.
export interface MeshPart {
  n: number;
  triangles: number;
  kind: 'positions' | 'triangles';
  first: number;
  data: Float32Array | Uint32Array; // 3 count
}

export interface PreviewMessage {
  vertices: Uint32Array; // mesh vertex of each preview vertex
  indices: Uint32Array; // 3 T, preview numbering
}

export interface FrameResult {
  seq: number;
  baseView: boolean;
  preview: boolean; // positions of the preview's vertices only
  foldZone: boolean; // the smooth base folded: details added as displacements there
  ms: { reducedSolve: number; inverseTransform: number; detail: number; total: number };
  error: { max: number; rms: number }; // the smooth base's miss of its targets, of the diagonal
  arap: { iterations: number; converged: boolean };
  // Positions are rest positions + scale * displacements (of the preview's vertices for a
  // preview): 16 bits a coordinate.
  scale: number;
  displacements: Int16Array; // 3 n
}

// The file's look (apps/server/appearance.h): the mesh's triangles over render vertices (a mesh
// vertex with one texture coordinate and normal group), sorted by material.
export interface AppearanceMessage {
  vertex: Uint32Array; // mesh vertex of each render vertex
  normalGroup: Uint32Array; // render vertices of a group share their normal
  indices: Uint32Array; // 3 T, render numbering
  materialStart: Uint32Array; // material m's triangles [start[m], start[m + 1]); the last: none
  baseColor: Float32Array; // RGBA of each material
  textured: Uint32Array; // 1: the material has an image (a texture message follows)
  materials: MaterialLook[];
  uv: Float32Array | null; // 2 per render vertex, v up
  rgba: Uint8Array | null; // 4 per render vertex
}

export const Wrap = { Repeat: 0, Clamp: 1, Mirror: 2 } as const;
export type Wrap = (typeof Wrap)[keyof typeof Wrap];

// How a material is drawn beyond its colour: shaded or not, and how its image is laid over the
// texture coordinates (read at transform * (u, v, 1), the wrap outside [0, 1]).
export interface MaterialLook {
  unlit: boolean;
  nearest: boolean;
  wrapU: Wrap;
  wrapV: Wrap;
  transform: Float32Array; // 2 rows of 3
}

export interface TextureMessage {
  material: number;
  mime: string;
  image: Uint8Array;
}

export interface NamedFile {
  name: string;
  data: Uint8Array;
}

export function tagOf(buffer: ArrayBuffer): number {
  return new Uint32Array(buffer, 0, 1)[0];
}

export function encodeSelection(s: Selection): ArrayBuffer {
  const G = s.groups.length;
  const total = s.fixed.length + s.groups.reduce((a, g) => a + g.vertices.length, 0);
  const head = 16 + 8 * G; // a multiple of 8: the transforms follow aligned
  const buffer = new ArrayBuffer(head + 128 * G + 4 * total);
  const u = new Uint32Array(buffer, 0, head / 4);
  u.set([Tag.Selection, G, s.fixed.length, s.echo ? 1 : 0]);
  s.groups.forEach((g, i) => {
    u[4 + i] = g.vertices.length;
    u[4 + G + i] = (g.pinned ? 1 : 0) | (g.fit ? 2 : 0);
  });
  const m = new Float64Array(buffer, head, 16 * G);
  s.groups.forEach((g, i) => m.set(g.transform, 16 * i));
  const lists = new Uint32Array(buffer, head + 128 * G, total);
  lists.set(s.fixed);
  let k = s.fixed.length;
  for (const g of s.groups) {
    lists.set(g.vertices, k);
    k += g.vertices.length;
  }
  return buffer;
}

export function decodeSelection(buffer: ArrayBuffer): Selection {
  const [, G, F] = new Uint32Array(buffer, 0, 4);
  const u = new Uint32Array(buffer, 0, 4 + 2 * G);
  const head = 16 + 8 * G;
  const m = new Float64Array(buffer, head, 16 * G);
  let k = (head + 128 * G) / 4;
  const all = new Uint32Array(buffer);
  const fixed = all.slice(k, k + F);
  k += F;
  const groups: Selection['groups'] = [];
  for (let g = 0; g < G; ++g) {
    groups.push({
      vertices: all.slice(k, k + u[4 + g]),
      transform: Array.from(m.subarray(16 * g, 16 * g + 16)),
      pinned: (u[4 + G + g] & 1) !== 0,
    });
    k += u[4 + g];
  }
  return { groups, fixed };
}

export function encodeFrame(seq: number, transforms: Matrix[], preview: boolean): ArrayBuffer {
  const buffer = new ArrayBuffer(16 + transforms.length * 128);
  new Uint32Array(buffer, 0, 4).set([Tag.Frame, seq, transforms.length, preview ? 1 : 0]);
  const m = new Float64Array(buffer, 16);
  transforms.forEach((t, g) => m.set(t, 16 * g));
  return buffer;
}

export function encodeFile(tag: FileTag, name: string, data: ArrayBuffer): ArrayBuffer {
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

// The part at byte `at` (a multiple of 4) of `buffer`, and its length in bytes, once all of it is
// within `end`; null before.
export function decodeMeshPart(buffer: ArrayBuffer, at: number, end: number): [MeshPart, number] | null {
  if (end - at < 24) return null;
  const [, n, triangles, kind, first, count] = new Uint32Array(buffer, at, 6);
  const length = 24 + 12 * count;
  if (end - at < length) return null;
  const part: MeshPart = kind === 0
    ? { n, triangles, kind: 'positions', first, data: new Float32Array(buffer, at + 24, 3 * count) }
    : { n, triangles, kind: 'triangles', first, data: new Uint32Array(buffer, at + 24, 3 * count) };
  return [part, length];
}

export function decodePreview(buffer: ArrayBuffer): PreviewMessage {
  const [, k, triangles] = new Uint32Array(buffer, 0, 3);
  return {
    vertices: new Uint32Array(buffer, 12, k),
    indices: new Uint32Array(buffer, 12 + 4 * k, 3 * triangles),
  };
}

export function decodeFrameResult(buffer: ArrayBuffer): FrameResult {
  const u = new Uint32Array(buffer, 0, 12);
  const f = new Float32Array(buffer, 16, 6);
  return {
    seq: u[1],
    baseView: (u[3] & 1) !== 0,
    preview: (u[3] & 2) !== 0,
    foldZone: (u[3] & 4) !== 0,
    ms: { reducedSolve: f[0], inverseTransform: f[1], detail: f[2], total: f[3] },
    error: { max: f[4], rms: f[5] },
    arap: { iterations: u[10], converged: u[11] === 1 },
    scale: new Float32Array(buffer, 48, 1)[0],
    // At rest (bit 3) none follow: zeros.
    displacements: u[3] & 8 ? new Int16Array(3 * u[2]) : new Int16Array(buffer, 52, 3 * u[2]),
  };
}

export function decodeAppearance(buffer: ArrayBuffer): AppearanceMessage {
  const [, R, T, M, flags] = new Uint32Array(buffer, 0, 5);
  let at = 20;
  const u32 = (count: number) => {
    const a = new Uint32Array(buffer, at, count);
    at += 4 * count;
    return a;
  };
  const vertex = u32(R), normalGroup = u32(R), indices = u32(3 * T), materialStart = u32(M + 2);
  const baseColor = new Float32Array(buffer, at, 4 * M);
  at += 16 * M;
  const textured = u32(M);
  const materials: MaterialLook[] = [];
  for (let m = 0; m < M; ++m) {
    const [flags] = u32(1);
    const transform = new Float32Array(buffer, at, 6);
    at += 24;
    materials.push({ unlit: (flags & 1) !== 0, nearest: (flags & 2) !== 0, wrapU: ((flags >> 2) & 3) as Wrap, wrapV: ((flags >> 4) & 3) as Wrap, transform });
  }
  let uv: Float32Array | null = null;
  if (flags & 1) {
    uv = new Float32Array(buffer, at, 2 * R);
    at += 8 * R;
  }
  const rgba = flags & 2 ? new Uint8Array(buffer, at, 4 * R) : null;
  return { vertex, normalGroup, indices, materialStart, baseColor, textured, materials, uv, rgba };
}

export function decodeTexture(buffer: ArrayBuffer): TextureMessage {
  const [, material, length] = new Uint32Array(buffer, 0, 3);
  const mime = new TextDecoder().decode(new Uint8Array(buffer, 12, length));
  return { material, mime, image: new Uint8Array(buffer, 12 + Math.ceil(length / 4) * 4) };
}
