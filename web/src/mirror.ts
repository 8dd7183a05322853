// X-mirror symmetry across the plane x = c through the middle of the bounding box: each
// vertex's counterpart (the nearest vertex to its mirror image, within 2% of the diagonal:
// exact on symmetric meshes, near on scanned ones; none where nothing is near), and a handle group's transform mirrored for
// its counterpart group.
import * as THREE from 'three';

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
