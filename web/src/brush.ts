// Brush selection: the vertices within a radius of a point on the surface, measured in space
// (Euclidean) or along the mesh's edges (geodesic, Dijkstra over the edge graph, so the brush
// does not jump across a thin gap to another part of the shape).
export class Brush {
  private readonly offsets: Int32Array; // CSR adjacency of the edge graph
  private readonly neighbours: Int32Array;

  constructor(vertexCount: number, indices: Uint32Array) {
    const degree = new Int32Array(vertexCount + 1);
    for (let t = 0; t < indices.length; t += 3) {
      for (let k = 0; k < 3; ++k) degree[indices[t + k] + 1] += 2;
    }
    for (let i = 0; i < vertexCount; ++i) degree[i + 1] += degree[i];
    this.offsets = degree;
    this.neighbours = new Int32Array(degree[vertexCount]);
    const fill = degree.slice(0, vertexCount);
    for (let t = 0; t < indices.length; t += 3) {
      for (let k = 0; k < 3; ++k) {
        const a = indices[t + k];
        const b = indices[t + ((k + 1) % 3)];
        this.neighbours[fill[a]++] = b;
        this.neighbours[fill[b]++] = a;
      }
    }
  }

  euclidean(positions: Float32Array, cx: number, cy: number, cz: number, radius: number): number[] {
    const out: number[] = [];
    const r2 = radius * radius;
    for (let v = 0; 3 * v < positions.length; ++v) {
      const dx = positions[3 * v] - cx;
      const dy = positions[3 * v + 1] - cy;
      const dz = positions[3 * v + 2] - cz;
      if (dx * dx + dy * dy + dz * dz <= r2) out.push(v);
    }
    return out;
  }

  geodesic(positions: Float32Array, start: number, radius: number): number[] {
    const distance = new Map<number, number>([[start, 0]]);
    const heap: [number, number][] = [[0, start]];
    const done: number[] = [];
    const settled = new Set<number>();
    while (heap.length > 0) {
      const [d, v] = pop(heap);
      if (settled.has(v)) continue;
      settled.add(v);
      done.push(v);
      for (let k = this.offsets[v]; k < this.offsets[v + 1]; ++k) {
        const w = this.neighbours[k];
        if (settled.has(w)) continue;
        const dx = positions[3 * v] - positions[3 * w];
        const dy = positions[3 * v + 1] - positions[3 * w + 1];
        const dz = positions[3 * v + 2] - positions[3 * w + 2];
        const dw = d + Math.sqrt(dx * dx + dy * dy + dz * dz);
        if (dw <= radius && dw < (distance.get(w) ?? Infinity)) {
          distance.set(w, dw);
          push(heap, [dw, w]);
        }
      }
    }
    return done;
  }
}

function push(heap: [number, number][], item: [number, number]): void {
  heap.push(item);
  let i = heap.length - 1;
  while (i > 0) {
    const parent = (i - 1) >> 1;
    if (heap[parent][0] <= heap[i][0]) break;
    [heap[parent], heap[i]] = [heap[i], heap[parent]];
    i = parent;
  }
}

function pop(heap: [number, number][]): [number, number] {
  const top = heap[0];
  const last = heap.pop()!;
  if (heap.length > 0) {
    heap[0] = last;
    let i = 0;
    for (;;) {
      const l = 2 * i + 1;
      const r = l + 1;
      let m = i;
      if (l < heap.length && heap[l][0] < heap[m][0]) m = l;
      if (r < heap.length && heap[r][0] < heap[m][0]) m = r;
      if (m === i) break;
      [heap[m], heap[i]] = [heap[i], heap[m]];
      i = m;
    }
  }
  return top;
}
