// A mesh arriving in parts (protocol.ts, 101): its positions, then its triangles, gathered into
// arrays of the whole, with the bytes come so far for the page's counter. The page's state and
// both workers gather the parts each (a copy of the whole held the page).
import type { MeshPart } from './protocol';

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

// Sends a copy of a part to a worker (the part's arrays view the whole response).
export function forwardPart(worker: Worker, part: MeshPart): void {
  const data = part.data.slice();
  worker.postMessage({ kind: 'part', part: { ...part, data } }, [data.buffer]);
}
