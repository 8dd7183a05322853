// Off the main thread: the picking BVH (three-mesh-bvh) of a mesh, seconds at a million
// triangles that held the page (and the painting meant to go on while the basis computes) when
// it was built after the first draw. Built indirect, so that it leaves the triangles' order as it
// is and serves the page's own geometry (MeshBVH.deserialize with setIndex: false). The mesh
// comes a part at a time from the worker that reads it (a port of its own: copying it on the
// page held the page); `build` builds the BVH of the last one that arrived whole, once it has.
import { BufferAttribute, BufferGeometry } from 'three';
import { MeshBVH, type SerializedBVH } from 'three-mesh-bvh';
import { MeshArrival } from './arrival';
import type { MeshPart } from './protocol';

export type BvhRequest = { kind: 'parts'; port: MessagePort } | { kind: 'build'; id: number };
export type BvhReply = { id: number; bvh: SerializedBVH };

const arrival = new MeshArrival();
let pending: number | null = null; // a build asked for before its mesh came whole

self.onmessage = (e: MessageEvent<BvhRequest>) => {
  if (e.data.kind === 'parts') {
    e.data.port.onmessage = (p: MessageEvent<MeshPart>) => {
      if (arrival.add(p.data) === 'mesh' && pending !== null) build(pending);
    };
    return;
  }
  if (arrival.whole) build(e.data.id);
  else pending = e.data.id;
};

function build(id: number): void {
  pending = null;
  const { indices, positions } = arrival.mesh!;
  const geometry = new BufferGeometry();
  geometry.setIndex(new BufferAttribute(indices, 1));
  geometry.setAttribute('position', new BufferAttribute(positions, 3));
  const bvh = MeshBVH.serialize(new MeshBVH(geometry, { indirect: true }), { cloneBuffers: false });
  const transfer: Transferable[] = [...bvh.roots];
  for (const array of [bvh.index, bvh.indirectBuffer]) if (array) transfer.push(array.buffer);
  (self as unknown as Worker).postMessage({ id, bvh } satisfies BvhReply, transfer);
}
