// How much the result differs from the input, as a whole: the change of surface area, of
// enclosed volume (closed meshes only: an open surface encloses nothing) and the largest
// stretch of an edge. Typed arrays, one pass over the triangles per frame.
export interface Measures {
  area: number; // relative change, 0 = unchanged
  volume: number | null; // relative change; null for an open or non-manifold mesh
  stretch: number; // the largest relative lengthening of an edge
}

export class MeshMeasures {
  private readonly restArea: number;
  private readonly restVolume: number;
  private readonly restLength: Float32Array; // of each triangle's three edges
  private readonly closed: boolean;

  constructor(private readonly indices: Uint32Array, rest: Float32Array) {
    [this.restArea, this.restVolume] = areaVolume(indices, rest);
    this.restLength = new Float32Array(indices.length);
    forEdges(indices, rest, (e, length) => (this.restLength[e] = length));
    this.closed = everyEdgeTwice(indices, rest.length / 3);
  }

  of(positions: Float32Array): Measures {
    const [area, volume] = areaVolume(this.indices, positions);
    let stretch = 0;
    forEdges(this.indices, positions, (e, length) => {
      const r = this.restLength[e];
      if (r > 0) stretch = Math.max(stretch, length / r - 1);
    });
    return {
      area: area / this.restArea - 1,
      volume: this.closed && this.restVolume !== 0 ? volume / this.restVolume - 1 : null,
      stretch,
    };
  }
}

// The total area and the signed enclosed volume (the divergence theorem over the triangles).
function areaVolume(indices: Uint32Array, p: Float32Array): [number, number] {
  let area = 0, volume = 0;
  for (let t = 0; t < indices.length; t += 3) {
    const a = 3 * indices[t], b = 3 * indices[t + 1], c = 3 * indices[t + 2];
    const ux = p[b] - p[a], uy = p[b + 1] - p[a + 1], uz = p[b + 2] - p[a + 2];
    const vx = p[c] - p[a], vy = p[c + 1] - p[a + 1], vz = p[c + 2] - p[a + 2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    area += Math.sqrt(nx * nx + ny * ny + nz * nz) / 2;
    volume += (p[a] * nx + p[a + 1] * ny + p[a + 2] * nz) / 6;
  }
  return [area, volume];
}

function forEdges(indices: Uint32Array, p: Float32Array, f: (edge: number, length: number) => void): void {
  for (let e = 0; e < indices.length; ++e) {
    const a = 3 * indices[e], b = 3 * indices[e - (e % 3) + ((e + 1) % 3)];
    f(e, Math.hypot(p[b] - p[a], p[b + 1] - p[a + 1], p[b + 2] - p[a + 2]));
  }
}

// Whether every edge has exactly two triangles (a closed manifold surface).
function everyEdgeTwice(indices: Uint32Array, n: number): boolean {
  const keys = new Float64Array(indices.length);
  for (let e = 0; e < indices.length; ++e) {
    const a = indices[e], b = indices[e - (e % 3) + ((e + 1) % 3)];
    keys[e] = Math.min(a, b) * n + Math.max(a, b);
  }
  keys.sort();
  for (let i = 0; i < keys.length; i += 2) {
    if (keys[i] !== keys[i + 1] || keys[i + 2] === keys[i]) return false;
  }
  return true;
}
