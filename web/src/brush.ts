// Brush selection: the vertices within a radius of a point on the surface, measured in space
// (Euclidean) or along the mesh's edges (geodesic, Dijkstra over the edge graph, so the brush
// does not jump across a thin gap to another part of the shape); and by the edges alone: a
// connected piece, a ring around a region. Typed arrays throughout, and
// per-query work proportional to the region found, not to the mesh.
export class Brush {
  private readonly offsets: Int32Array; // CSR adjacency of the edge graph
  private readonly neighbours: Int32Array;
  private readonly distance: Float64Array; // Infinity outside the current query
  private readonly settled: Uint8Array;

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
    this.distance = new Float64Array(vertexCount).fill(Infinity);
    this.settled = new Uint8Array(vertexCount);
  }

  euclidean(positions: Float32Array, cx: number, cy: number, cz: number, radius: number): Uint32Array {
    const out: number[] = [];
    const r2 = radius * radius;
    for (let v = 0; 3 * v < positions.length; ++v) {
      const dx = positions[3 * v] - cx;
      const dy = positions[3 * v + 1] - cy;
      const dz = positions[3 * v + 2] - cz;
      if (dx * dx + dy * dy + dz * dz <= r2) out.push(v);
    }
    return Uint32Array.from(out);
  }

  // The vertices within `radius` of the nearest of `starts`, along the edges.
  geodesic(positions: Float32Array, starts: ArrayLike<number>, radius: number): Uint32Array {
    const { distance, settled, offsets, neighbours } = this;
    const heap = new Heap();
    const touched: number[] = Array.from(starts);
    const done: number[] = [];
    for (const start of touched) {
      distance[start] = 0;
      heap.push(0, start);
    }
    while (heap.size > 0) {
      const d = heap.topKey();
      const v = heap.pop();
      if (settled[v]) continue;
      settled[v] = 1;
      done.push(v);
      for (let k = offsets[v]; k < offsets[v + 1]; ++k) {
        const w = neighbours[k];
        if (settled[w]) continue;
        const dx = positions[3 * v] - positions[3 * w];
        const dy = positions[3 * v + 1] - positions[3 * w + 1];
        const dz = positions[3 * v + 2] - positions[3 * w + 2];
        const dw = d + Math.sqrt(dx * dx + dy * dy + dz * dz);
        if (dw <= radius && dw < distance[w]) {
          if (distance[w] === Infinity) touched.push(w);
          distance[w] = dw;
          heap.push(dw, w);
        }
      }
    }
    for (const v of touched) {
      distance[v] = Infinity;
      settled[v] = 0;
    }
    return Uint32Array.from(done);
  }

  // The vertices connected to `start` by edges: its piece of the mesh.
  linked(start: number): Uint32Array {
    const { offsets, neighbours } = this;
    const seen = new Uint8Array(offsets.length - 1);
    const out = [start];
    seen[start] = 1;
    for (let i = 0; i < out.length; ++i) {
      for (let k = offsets[out[i]]; k < offsets[out[i] + 1]; ++k) {
        const w = neighbours[k];
        if (!seen[w]) {
          seen[w] = 1;
          out.push(w);
        }
      }
    }
    return Uint32Array.from(out);
  }

  // The ring around a region: `grow`, the vertices outside it with a neighbour inside;
  // otherwise, the vertices inside with a neighbour outside.
  ring(inside: (v: number) => boolean, grow: boolean): number[] {
    const { offsets, neighbours } = this;
    const out: number[] = [];
    for (let v = 0; v + 1 < offsets.length; ++v) {
      if (inside(v) === grow) continue;
      for (let k = offsets[v]; k < offsets[v + 1]; ++k) {
        if (inside(neighbours[k]) !== inside(v)) {
          out.push(v);
          break;
        }
      }
    }
    return out;
  }
}

// A binary min-heap of (key, vertex) in two parallel arrays.
class Heap {
  private keys: number[] = [];
  private items: number[] = [];

  get size(): number {
    return this.items.length;
  }

  topKey(): number {
    return this.keys[0];
  }

  push(key: number, item: number): void {
    const { keys, items } = this;
    let i = items.length;
    keys.push(key);
    items.push(item);
    while (i > 0) {
      const parent = (i - 1) >> 1;
      if (keys[parent] <= key) break;
      keys[i] = keys[parent];
      items[i] = items[parent];
      i = parent;
    }
    keys[i] = key;
    items[i] = item;
  }

  pop(): number {
    const { keys, items } = this;
    const top = items[0];
    const key = keys.pop()!;
    const item = items.pop()!;
    const n = items.length;
    if (n > 0) {
      let i = 0;
      for (;;) {
        const l = 2 * i + 1;
        if (l >= n) break;
        const m = l + 1 < n && keys[l + 1] < keys[l] ? l + 1 : l;
        if (keys[m] >= key) break;
        keys[i] = keys[m];
        items[i] = items[m];
        i = m;
      }
      keys[i] = key;
      items[i] = item;
    }
    return top;
  }
}
