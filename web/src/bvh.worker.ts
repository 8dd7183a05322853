// Off the main thread: the picking BVH (three-mesh-bvh) of a mesh, seconds at a million
// triangles that held the page (and the painting meant to go on while the basis computes) when
// it was built after the first draw. Built indirect, so that it leaves the triangles' order as it
// is and serves the page's own geometry (MeshBVH.deserialize with setIndex: false). The mesh
// comes a part at a time, as it arrives (copying it whole held the page); `build` builds the
// BVH of the last one that arrived whole.
import { BufferAttribute, BufferGeometry } from 'three';
import { MeshBVH, type SerializedBVH } from 'three-mesh-bvh';
import { MeshArrival } from './arrival';
import type { MeshPart } from './protocol';

export type BvhRequest = { kind: 'part'; part: MeshPart } | { kind: 'build'; id: number };
export type BvhReply = { id: number; bvh: SerializedBVH };

const arrival = new MeshArrival();

self.onmessage = (e: MessageEvent<BvhRequest>) => {
  if (e.data.kind === 'part') return void arrival.add(e.data.part);
  const { id } = e.data;
  if (!arrival.whole) return; // a newer mesh is coming: its build follows
  const { indices, positions } = arrival.mesh!;
  const geometry = new BufferGeometry();
  geometry.setIndex(new BufferAttribute(indices, 1));
  geometry.setAttribute('position', new BufferAttribute(positions, 3));
  const bvh = MeshBVH.serialize(new MeshBVH(geometry, { indirect: true }), { cloneBuffers: false });
  const transfer: Transferable[] = [...bvh.roots];
  for (const array of [bvh.index, bvh.indirectBuffer]) if (array) transfer.push(array.buffer);
  (self as unknown as Worker).postMessage({ id, bvh } satisfies BvhReply, transfer);
};
