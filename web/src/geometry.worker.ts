// Off the main thread: the mesh's body read as it comes, a part at a time handed on to the page
// and to the picking BVH's worker (a port of its own); the positions of every frame from its
// 16-bit displacements, their vertex normals (of the full mesh and of the coarse preview), the
// full frames' area, volume and stretch against the input (measures.ts), and the brush (the
// vertices within a radius, along the surface or in space), so that the page keeps taking
// pointer events while a large mesh is processed.
import { MeshArrival, partCopy, readMesh } from './arrival';
import { Brush } from './brush';
import { groupNormals } from './look';
import { Measures, MeshMeasures } from './measures';
import { vertexNormals } from './normals';
import type { MeshPart } from './protocol';

export type Slot = 'full' | 'preview';

export type WorkerRequest =
  // The mesh at `url` read (a newer `fetch` drops an older one), its parts handed on as they come
  // (`part` replies, then `fetched`); `adopt` makes the last one that came whole the full slot's.
  | { kind: 'fetch'; fetch: number; url: string }
  | { kind: 'bvh'; port: MessagePort } // where the parts go besides the page
  | { kind: 'adopt' }
  | { kind: 'preview'; indices: Uint32Array; rest: Float32Array } // the coarse mesh of drags
  // The full mesh's file look: render vertices (their mesh vertex and normal group) and triangles.
  | { kind: 'look'; vertex: Uint32Array; group: Uint32Array; indices: Uint32Array }
  | { kind: 'frame'; slot: Slot; seq: number; scale: number; displacements: Int16Array }
  | { kind: 'brush'; id: number; vertex: number; center: [number, number, number]; radius: number; geodesic: boolean };

export type WorkerReply =
  | { kind: 'part'; fetch: number; part: MeshPart }
  // The mesh's id, null where the server has none there; `error`: why it did not come.
  | { kind: 'fetched'; fetch: number; id: string | null; error: string | null }
  | { kind: 'frame'; slot: Slot; seq: number; positions: Float32Array; normals: Float32Array;
      lookNormals: Float32Array | null }
  | { kind: 'measures'; seq: number; measures: Measures | null } // of the full frame `seq`
  | { kind: 'brush'; id: number; vertices: Uint32Array };

// The brush's graph and the measures' rest lengths are made when first used, not before the
// mesh's first frame (a second at a million vertices).
interface Mesh {
  indices: Uint32Array;
  rest: Float32Array;
  brush: Brush | null;
  measures: MeshMeasures | null;
  positions: Float32Array; // the last frame's (the brush measures on them)
}

interface Look {
  vertex: Uint32Array;
  group: Uint32Array;
  indices: Uint32Array;
  sums: Float32Array; // 3 per group
}

const meshes: Partial<Record<Slot, Mesh>> = {};
const arrival = new MeshArrival();
let fetching = 0; // the last fetch asked for
let bvhPort: MessagePort | null = null;
let look: Look | null = null;
const post = (reply: WorkerReply, transfer: Transferable[]) =>
  (self as unknown as Worker).postMessage(reply, transfer);

self.onmessage = (e: MessageEvent<WorkerRequest>) => {
  const m = e.data;
  if (m.kind === 'fetch') {
    fetching = m.fetch;
    const handOn = (part: MeshPart) => {
      arrival.add(part);
      bvhPort?.postMessage(...partCopy(part));
      const [copy, transfer] = partCopy(part);
      post({ kind: 'part', fetch: m.fetch, part: copy }, transfer);
    };
    readMesh(m.url, handOn, () => fetching === m.fetch).then(
      (id) => post({ kind: 'fetched', fetch: m.fetch, id, error: null }, []),
      (e: unknown) => post({ kind: 'fetched', fetch: m.fetch, id: null, error: e instanceof Error ? e.message : String(e) }, []));
  } else if (m.kind === 'bvh') {
    bvhPort = m.port;
  } else if (m.kind === 'adopt') {
    if (!arrival.whole) return;
    const { indices, positions } = arrival.mesh!;
    look = null; // its look, if any, follows
    meshes.full = { indices, rest: positions, brush: null, measures: null, positions: positions.slice() };
  } else if (m.kind === 'look') {
    let groups = 0;
    for (const g of m.group) groups = Math.max(groups, g + 1);
    look = { vertex: m.vertex, group: m.group, indices: m.indices, sums: new Float32Array(3 * groups) };
  } else if (m.kind === 'preview') {
    meshes.preview = { indices: m.indices, rest: m.rest, brush: null, measures: null, positions: m.rest.slice() };
  } else if (m.kind === 'frame') {
    const mesh = meshes[m.slot];
    if (!mesh || mesh.rest.length !== m.displacements.length) return;
    const { rest, positions } = mesh;
    const d = m.displacements;
    for (let i = 0; i < d.length; ++i) positions[i] = rest[i] + m.scale * d[i];
    const normals = new Float32Array(positions.length);
    vertexNormals(positions, mesh.indices, normals);
    let lookNormals: Float32Array | null = null;
    if (m.slot === 'full' && look) {
      lookNormals = new Float32Array(3 * look.vertex.length);
      groupNormals(positions, look.vertex, look.group, look.indices, look.sums, lookNormals);
    }
    const copy = positions.slice();
    const transfer = lookNormals ? [copy.buffer, normals.buffer, lookNormals.buffer] : [copy.buffer, normals.buffer];
    post({ kind: 'frame', slot: m.slot, seq: m.seq, positions: copy, normals, lookNormals }, transfer);
    if (m.slot !== 'full') return;
    // Measured once the frame is on its way (the first takes a second at a million vertices);
    // the rest shape has nothing to measure.
    const moved = d.some((x) => x !== 0);
    if (moved) mesh.measures ??= new MeshMeasures(mesh.indices, mesh.rest);
    post({ kind: 'measures', seq: m.seq, measures: moved ? mesh.measures!.of(positions) : null }, []);
  } else {
    const mesh = meshes.full;
    if (!mesh) return;
    mesh.brush ??= new Brush(mesh.rest.length / 3, mesh.indices);
    const [x, y, z] = m.center;
    const vertices = m.geodesic
      ? mesh.brush.geodesic(mesh.positions, [m.vertex], m.radius)
      : mesh.brush.euclidean(mesh.positions, x, y, z, m.radius);
    post({ kind: 'brush', id: m.id, vertices }, [vertices.buffer]);
  }
};
