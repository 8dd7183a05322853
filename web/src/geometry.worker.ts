// Off the main thread: the positions of every frame from its 16-bit displacements, their
// vertex normals (of the full mesh and of the coarse preview), the full frames' area, volume
// and stretch against the input (measures.ts), and the brush (the vertices within a radius, along the surface or in space), so that
// the page keeps taking pointer events while a large mesh is processed.
import { Brush } from './brush';
import { Measures, MeshMeasures } from './measures';
import { vertexNormals } from './normals';

export type Slot = 'full' | 'preview';

export type WorkerRequest =
  | { kind: 'mesh'; slot: Slot; indices: Uint32Array; rest: Float32Array }
  | { kind: 'frame'; slot: Slot; seq: number; scale: number; displacements: Int16Array }
  | { kind: 'brush'; id: number; vertex: number; center: [number, number, number]; radius: number; geodesic: boolean };

export type WorkerReply =
  | { kind: 'frame'; slot: Slot; seq: number; positions: Float32Array; normals: Float32Array; measures: Measures | null }
  | { kind: 'brush'; id: number; vertices: Uint32Array };

interface Mesh {
  indices: Uint32Array;
  rest: Float32Array;
  brush: Brush | null;
  measures: MeshMeasures | null;
  positions: Float32Array; // the last frame's (the brush measures on them)
}

const meshes: Partial<Record<Slot, Mesh>> = {};
const post = (reply: WorkerReply, transfer: Transferable[]) =>
  (self as unknown as Worker).postMessage(reply, transfer);

self.onmessage = (e: MessageEvent<WorkerRequest>) => {
  const m = e.data;
  if (m.kind === 'mesh') {
    meshes[m.slot] = {
      indices: m.indices,
      rest: m.rest,
      brush: m.slot === 'full' ? new Brush(m.rest.length / 3, m.indices) : null,
      measures: m.slot === 'full' ? new MeshMeasures(m.indices, m.rest) : null,
      positions: m.rest.slice(),
    };
  } else if (m.kind === 'frame') {
    const mesh = meshes[m.slot];
    if (!mesh || mesh.rest.length !== m.displacements.length) return;
    const { rest, positions } = mesh;
    const d = m.displacements;
    for (let i = 0; i < d.length; ++i) positions[i] = rest[i] + m.scale * d[i];
    const normals = new Float32Array(positions.length);
    vertexNormals(positions, mesh.indices, normals);
    const copy = positions.slice();
    const measures = mesh.measures?.of(positions) ?? null;
    post({ kind: 'frame', slot: m.slot, seq: m.seq, positions: copy, normals, measures }, [copy.buffer, normals.buffer]);
  } else {
    const mesh = meshes.full;
    if (!mesh?.brush) return;
    const [x, y, z] = m.center;
    const vertices = m.geodesic
      ? mesh.brush.geodesic(mesh.positions, [m.vertex], m.radius)
      : mesh.brush.euclidean(mesh.positions, x, y, z, m.radius);
    post({ kind: 'brush', id: m.id, vertices }, [vertices.buffer]);
  }
};
