// Off the main thread: the picking BVH (three-mesh-bvh) of a mesh, seconds at a million
// triangles that held the page (and the painting meant to go on while the basis computes) when
// it was built after the first draw. Built indirect, so that it leaves the triangles' order as it
// is and serves the page's own geometry (MeshBVH.deserialize with setIndex: false).
import { BufferAttribute, BufferGeometry } from 'three';
import { MeshBVH, type SerializedBVH } from 'three-mesh-bvh';

export type BvhRequest = { id: number; indices: Uint32Array; positions: Float32Array };
export type BvhReply = { id: number; bvh: SerializedBVH };

self.onmessage = (e: MessageEvent<BvhRequest>) => {
  const { id, indices, positions } = e.data;
  const geometry = new BufferGeometry();
  geometry.setIndex(new BufferAttribute(indices, 1));
  geometry.setAttribute('position', new BufferAttribute(positions, 3));
  const bvh = MeshBVH.serialize(new MeshBVH(geometry, { indirect: true }), { cloneBuffers: false });
  const transfer: Transferable[] = [...bvh.roots];
  for (const array of [bvh.index, bvh.indirectBuffer]) if (array) transfer.push(array.buffer);
  (self as unknown as Worker).postMessage({ id, bvh } satisfies BvhReply, transfer);
};
