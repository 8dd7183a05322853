// Off the main thread: vertex normals of every frame (of the full mesh and of the coarse
// preview) and the brush (the vertices within a radius, along the surface or in space), so that
// the page keeps taking pointer events while a large mesh is processed.
import { Brush } from './brush';
import { vertexNormals } from './normals';

export type Slot = 'full' | 'preview';

export type WorkerRequest =
  | { kind: 'mesh'; slot: Slot; indices: Uint32Array; vertices: number }
  | { kind: 'normals'; slot: Slot; seq: number; positions: Float32Array }
  | { kind: 'brush'; id: number; vertex: number; center: [number, number, number]; radius: number; geodesic: boolean };

export type WorkerReply =
  | { kind: 'normals'; slot: Slot; seq: number; positions: Float32Array; normals: Float32Array }
  | { kind: 'brush'; id: number; vertices: Uint32Array };

interface Mesh {
  indices: Uint32Array;
  brush: Brush | null;
  positions: Float32Array; // the last positions given (the brush measures on them)
}

const meshes: Partial<Record<Slot, Mesh>> = {};
const post = (reply: WorkerReply, transfer: Transferable[]) =>
  (self as unknown as Worker).postMessage(reply, transfer);

self.onmessage = (e: MessageEvent<WorkerRequest>) => {
  const m = e.data;
  if (m.kind === 'mesh') {
    meshes[m.slot] = {
      indices: m.indices,
      brush: m.slot === 'full' ? new Brush(m.vertices, m.indices) : null,
      positions: new Float32Array(3 * m.vertices),
    };
  } else if (m.kind === 'normals') {
    const mesh = meshes[m.slot];
    if (!mesh || mesh.positions.length !== m.positions.length) return;
    mesh.positions.set(m.positions);
    const normals = new Float32Array(m.positions.length);
    vertexNormals(m.positions, mesh.indices, normals);
    post({ kind: 'normals', slot: m.slot, seq: m.seq, positions: m.positions, normals }, [m.positions.buffer, normals.buffer]);
  } else {
    const mesh = meshes.full;
    if (!mesh?.brush) return;
    const [x, y, z] = m.center;
    const vertices = m.geodesic
      ? mesh.brush.geodesic(mesh.positions, m.vertex, m.radius)
      : mesh.brush.euclidean(mesh.positions, x, y, z, m.radius);
    post({ kind: 'brush', id: m.id, vertices }, [vertices.buffer]);
  }
};
