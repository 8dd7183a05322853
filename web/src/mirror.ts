// X-mirror symmetry across the plane x = c through the middle of the bounding box: each
// vertex's counterpart (the nearest vertex to its mirror image, within 2% of the diagonal:
// exact on symmetric meshes, near on scanned ones; none where nothing is near), and a handle group's transform mirrored for
// its counterpart group; XMirror, the editor's switch, pairs the groups.
import * as THREE from 'three';
import type { EditorState } from './state';

export interface Mirror {
  flip: THREE.Matrix4; // the reflection x -> 2c - x
  of: Int32Array; // each vertex's counterpart, -1: none
}

// F T F with F the reflection: the mirror image of a transform.
export function mirrored(t: THREE.Matrix4, m: Mirror): THREE.Matrix4 {
  return m.flip.clone().multiply(t).multiply(m.flip);
}

// The counterparts, found on a grid of cells of the tolerance.
export function mirror(rest: Float32Array, diagonal: number): Mirror {
  const n = rest.length / 3;
  let lo = Infinity, hi = -Infinity;
  for (let v = 0; v < n; ++v) [lo, hi] = [Math.min(lo, rest[3 * v]), Math.max(hi, rest[3 * v])];
  const c = (lo + hi) / 2;
  const tolerance = 0.02 * diagonal;
  const cell = (x: number) => Math.floor(x / tolerance);
  const key = (i: number, j: number, k: number) => `${i},${j},${k}`;
  const grid = new Map<string, number[]>();
  for (let v = 0; v < n; ++v) {
    const k = key(cell(rest[3 * v]), cell(rest[3 * v + 1]), cell(rest[3 * v + 2]));
    const list = grid.get(k);
    if (list) list.push(v);
    else grid.set(k, [v]);
  }
  const out = new Int32Array(n).fill(-1);
  for (let v = 0; v < n; ++v) {
    const [x, y, z] = [2 * c - rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]];
    let best = tolerance * tolerance;
    for (let i = -1; i <= 1; ++i) {
      for (let j = -1; j <= 1; ++j) {
        for (let k = -1; k <= 1; ++k) {
          for (const w of grid.get(key(cell(x) + i, cell(y) + j, cell(z) + k)) ?? []) {
            const d = (rest[3 * w] - x) ** 2 + (rest[3 * w + 1] - y) ** 2 + (rest[3 * w + 2] - z) ** 2;
            if (d <= best) [best, out[v]] = [d, w];
          }
        }
      }
    }
  }
  return { flip: new THREE.Matrix4().set(-1, 0, 0, 2 * c, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1), of: out };
}

// The X mirror of painting and moves: a painted handle's counterparts go to a group of their
// own (made on first use), which moves mirrored. The switch and the pairing are kept in the
// tab's session storage, by mesh: a reload keeps them.
export class XMirror {
  private switched = false;
  private symmetry: { rest: Float32Array; mirror: Mirror } | null = null;
  private partner = new Map<number, number>(); // handle group -> its mirror image's group
  private key: string | null = null; // of the session storage

  get on(): boolean {
    return this.switched;
  }

  set on(on: boolean) {
    this.switched = on;
    this.save();
  }

  // The switch and pairing kept for `mesh` (a name for the mesh open).
  restore(mesh: string): void {
    this.key = `specdeform-x-mirror:${mesh}`;
    const saved = JSON.parse(sessionStorage.getItem(this.key) ?? 'null') as { on: boolean; pairs: [number, number][] } | null;
    this.switched = saved?.on ?? false;
    this.partner = new Map(saved?.pairs ?? []);
  }

  private save(): void {
    if (this.key) sessionStorage.setItem(this.key, JSON.stringify({ on: this.switched, pairs: [...this.partner] }));
  }

  private mirrorOf(s: EditorState): Mirror {
    if (this.symmetry?.rest !== s.rest) this.symmetry = { rest: s.rest, mirror: mirror(s.rest, s.diagonal) };
    return this.symmetry.mirror;
  }

  // The counterparts of painted vertices with the label each gets, and how many have none (no
  // vertex within 2% of the diagonal of their mirror image).
  paired(s: EditorState, vertices: ArrayLike<number>, label: number): { pairs: [number, number][]; unpaired: number } {
    const m = this.mirrorOf(s);
    let target = label;
    if (label >= 2) {
      const g = label - 2;
      let p = this.partner.get(g);
      if (p === undefined || !s.groups[p] || s.groups[p].pinned) {
        s.groups.push({ transform: mirrored(s.groups[g].transform, m), pinned: false });
        p = s.groups.length - 1;
        this.partner.set(g, p);
        this.partner.set(p, g);
        this.save();
      }
      target = 2 + p;
    }
    const pairs: [number, number][] = [];
    let unpaired = 0;
    for (let i = 0; i < vertices.length; ++i) {
      const v = vertices[i];
      if (m.of[v] < 0) ++unpaired;
      else if (m.of[v] !== v) pairs.push([m.of[v], target]);
    }
    return { pairs, unpaired };
  }

  // Group g's counterpart takes the mirror image of its transform.
  follow(s: EditorState, g: number): void {
    const p = this.partner.get(g);
    const groups = s.groups;
    if (this.on && p !== undefined && groups[p]) groups[p].transform = mirrored(groups[g].transform, this.mirrorOf(s));
  }
}
