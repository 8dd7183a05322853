// A mesh arriving in parts (protocol.ts, 101): its positions, then its triangles, gathered into
// arrays of the whole, with the bytes come so far for the page's counter. The geometry worker reads
// the mesh (readMesh) and hands each part on to the page and to the picking BVH's worker, which
// gather them each (the page's thread was held reading the mesh and copying it for the workers).
import { decodeMeshPart, type MeshPart } from './protocol';

export interface WholeMesh {
  positions: Float32Array<ArrayBuffer>; // 3 n
  indices: Uint32Array<ArrayBuffer>; // 3 T
  low: number[]; // the positions' bounding box, [x, y, z] (of those come so far)
  high: number[];
}

export class MeshArrival {
  mesh: WholeMesh | null = null; // of the latest parts, whole or coming
  private vertices = 0; // positions come so far
  private triangles = 0;

  // Takes a part (a mesh's first starts it); returns what it completed: the positions, the whole
  // mesh, or nothing. Parts come in order: one out of place is an error.
  add(p: MeshPart): 'positions' | 'mesh' | null {
    const positionsPart = p.kind === 'positions';
    if (positionsPart && p.first === 0) {
      this.mesh = { positions: new Float32Array(3 * p.n), indices: new Uint32Array(3 * p.triangles),
        low: [Infinity, Infinity, Infinity], high: [-Infinity, -Infinity, -Infinity] };
      [this.vertices, this.triangles] = [0, 0];
    }
    const m = this.mesh;
    const [target, at] = positionsPart ? [m?.positions, this.vertices] : [m?.indices, this.triangles];
    if (!m || !target || this.whole || p.first !== at || 3 * p.first + p.data.length > target.length ||
        3 * p.triangles !== m.indices.length || (!positionsPart && 3 * this.vertices !== m.positions.length)) {
      throw new Error(`the mesh's parts came out of order (${p.kind} from ${p.first})`);
    }
    target.set(p.data, 3 * p.first);
    const count = p.data.length / 3;
    if (positionsPart) {
      bound(m, p.data as Float32Array);
      this.vertices += count;
    } else this.triangles += count;
    if (this.whole) return 'mesh';
    return positionsPart && 3 * this.vertices === m.positions.length ? 'positions' : null;
  }

  get whole(): boolean {
    const m = this.mesh;
    return m !== null && 3 * this.vertices === m.positions.length && 3 * this.triangles === m.indices.length;
  }

  get bytes(): number {
    return 12 * (this.vertices + this.triangles);
  }

  get totalBytes(): number {
    return this.mesh ? 4 * (this.mesh.positions.length + this.mesh.indices.length) : 0;
  }
}

// Widens the mesh's bounding box to the positions (3 floats each): a part at a time, as the page's
// one pass over a large mesh held it.
function bound(m: WholeMesh, positions: Float32Array): void {
  const { low, high } = m;
  for (let i = 0; i < positions.length; i += 3) {
    for (let k = 0; k < 3; ++k) {
      const x = positions[i + k];
      if (x < low[k]) low[k] = x;
      if (x > high[k]) high[k] = x;
    }
  }
}

// Reads the mesh body at `url` (the server's parts one after another), handing each part to
// `onPart` as it completes, while `current()` holds (a newer reading takes over); returns the
// mesh's id (X-Mesh-Id), or null where the server has none there (404).
export async function readMesh(url: string, onPart: (p: MeshPart) => void, current: () => boolean): Promise<string | null> {
  const response = await fetch(url);
  if (response.status === 404) return null;
  if (!response.ok || !response.body) throw new Error(`${response.status} ${response.statusText}`);
  const reader = response.body.getReader();
  const bytes = new Uint8Array(Number(response.headers.get('Content-Length')));
  let [end, at] = [0, 0];
  for (;;) {
    const { done, value } = await reader.read();
    if (!current()) {
      await reader.cancel();
      break;
    }
    if (done) break;
    if (end + value.length > bytes.length) throw new Error('more bytes than announced');
    bytes.set(value, end);
    end += value.length;
    for (let next; (next = decodeMeshPart(bytes.buffer, at, end)); at += next[1]) onPart(next[0]);
  }
  if (current() && at !== bytes.length) throw new Error(`${at} of ${bytes.length} bytes`);
  return response.headers.get('X-Mesh-Id');
}

// A copy of a part for another thread, and what to transfer (the part's arrays view the whole
// body).
export function partCopy(part: MeshPart): [MeshPart, Transferable[]] {
  const data = part.data.slice();
  return [{ ...part, data }, [data.buffer]];
}
