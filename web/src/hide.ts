// Hiding part of the mesh (H, Alt+H) to paint behind it: a vertex hidden takes its triangles
// with it, from the drawing and from picking.

// The triangles none of whose corners is hidden; `vertex`: the mesh vertex of each index.
export function visibleTriangles(indices: Uint32Array, hidden: Uint8Array | null, vertex?: Uint32Array): Uint32Array {
  if (!hidden) return indices;
  const at = vertex ? (i: number) => vertex[i] : (i: number) => i;
  const out = new Uint32Array(indices.length);
  let k = 0;
  for (let t = 0; t < indices.length; t += 3) {
    const [a, b, c] = [indices[t], indices[t + 1], indices[t + 2]];
    if (hidden[at(a)] || hidden[at(b)] || hidden[at(c)]) continue;
    out[k++] = a;
    out[k++] = b;
    out[k++] = c;
  }
  return out.slice(0, k);
}
