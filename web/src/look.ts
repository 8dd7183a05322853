// The file's look (apps/server/appearance.h): the mesh drawn over render vertices with the file's
// texture coordinates, base colour images, vertex colours and normal groups (hard edges stay
// hard: the worker sums the faces' normals per group). Handles and fixed vertices are drawn in
// their colours over it, free vertices in the file's own.
import * as THREE from 'three';
import type { AppearanceMessage } from './protocol';

export class FileLook {
  readonly mesh: THREE.Mesh;
  private readonly geometry = new THREE.BufferGeometry();
  private materials: THREE.MeshLambertMaterial[] = [];
  private appearance: AppearanceMessage | null = null;

  constructor() {
    this.mesh = new THREE.Mesh(this.geometry, []);
    this.mesh.visible = false;
    this.mesh.frustumCulled = false;
  }

  get present(): boolean {
    return this.appearance !== null;
  }

  get textures(): number {
    return this.materials.filter((m) => m.map).length;
  }

  // A new file's look, or none (the plain mesh).
  set(a: AppearanceMessage | null): void {
    for (const m of this.materials) {
      m.map?.dispose();
      m.dispose();
    }
    this.materials = [];
    this.appearance = a;
    this.geometry.clearGroups();
    if (!a) {
      this.mesh.visible = false;
      return;
    }
    const R = a.vertex.length;
    this.geometry.setIndex(new THREE.BufferAttribute(a.indices.slice(), 1));
    this.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * R), 3));
    this.geometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3 * R), 3));
    this.geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * R).fill(1), 3));
    if (a.uv) this.geometry.setAttribute('uv', new THREE.BufferAttribute(a.uv.slice(), 2));
    else this.geometry.deleteAttribute('uv');
    const M = a.textured.length;
    for (let m = 0; m <= M; ++m) {
      const color = m < M ? new THREE.Color().setRGB(a.baseColor[4 * m], a.baseColor[4 * m + 1], a.baseColor[4 * m + 2])
        : new THREE.Color(1, 1, 1);
      this.materials.push(new THREE.MeshLambertMaterial({ color, vertexColors: true, side: THREE.DoubleSide }));
      const first = a.materialStart[m], count = a.materialStart[m + 1] - first;
      if (count > 0) this.geometry.addGroup(3 * first, 3 * count, m);
    }
    this.mesh.material = this.materials;
  }

  // Material m's base colour image (v up, as the texture coordinates are).
  async setTexture(material: number, mime: string, image: Uint8Array): Promise<void> {
    const target = this.materials[material];
    if (!target) return;
    const bitmap = await createImageBitmap(new Blob([image as BlobPart], { type: mime }), { imageOrientation: 'flipY' });
    if (this.materials[material] !== target) return; // another file meanwhile
    const texture = new THREE.Texture(bitmap);
    texture.flipY = false; // the bitmap is turned already
    texture.colorSpace = THREE.SRGBColorSpace;
    texture.needsUpdate = true;
    target.map = texture;
    target.needsUpdate = true;
  }

  // The mesh's positions and the render vertices' normals (from the worker).
  setPositions(positions: Float32Array, normals: Float32Array | null): void {
    const a = this.appearance;
    if (!a) return;
    const p = this.geometry.getAttribute('position') as THREE.BufferAttribute;
    const out = p.array as Float32Array;
    for (let i = 0; i < a.vertex.length; ++i) {
      const v = 3 * a.vertex[i];
      out[3 * i] = positions[v];
      out[3 * i + 1] = positions[v + 1];
      out[3 * i + 2] = positions[v + 2];
    }
    p.needsUpdate = true;
    const n = this.geometry.getAttribute('normal') as THREE.BufferAttribute;
    if (normals && normals.length === n.array.length) {
      (n.array as Float32Array).set(normals);
      n.needsUpdate = true;
    }
  }

  // The selection's colours (3 per mesh vertex): `free` where the file's own colour shows.
  setColors(colors: Float32Array, free: THREE.Color): void {
    const a = this.appearance;
    if (!a) return;
    const c = this.geometry.getAttribute('color') as THREE.BufferAttribute;
    const out = c.array as Float32Array;
    for (let i = 0; i < a.vertex.length; ++i) {
      const v = 3 * a.vertex[i];
      const selected = colors[v] !== free.r || colors[v + 1] !== free.g || colors[v + 2] !== free.b;
      for (let k = 0; k < 3; ++k) {
        out[3 * i + k] = selected ? colors[v + k] : a.rgba ? a.rgba[4 * i + k] / 255 : 1;
      }
    }
    c.needsUpdate = true;
  }
}

// The render vertices' normals: each group's faces' normals summed (area-weighted) over the
// render triangles, normalised.
export function groupNormals(positions: Float32Array, vertex: Uint32Array, group: Uint32Array,
  indices: Uint32Array, groups: Float32Array, out: Float32Array): void {
  groups.fill(0);
  const p = positions;
  for (let t = 0; t < indices.length; t += 3) {
    const i = indices[t], j = indices[t + 1], k = indices[t + 2];
    const a = 3 * vertex[i], b = 3 * vertex[j], c = 3 * vertex[k];
    const ux = p[b] - p[a], uy = p[b + 1] - p[a + 1], uz = p[b + 2] - p[a + 2];
    const vx = p[c] - p[a], vy = p[c + 1] - p[a + 1], vz = p[c + 2] - p[a + 2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    for (const r of [i, j, k]) {
      const g = 3 * group[r];
      groups[g] += nx;
      groups[g + 1] += ny;
      groups[g + 2] += nz;
    }
  }
  for (let r = 0; r < vertex.length; ++r) {
    const g = 3 * group[r];
    const l = Math.hypot(groups[g], groups[g + 1], groups[g + 2]) || 1;
    out[3 * r] = groups[g] / l;
    out[3 * r + 1] = groups[g + 1] / l;
    out[3 * r + 2] = groups[g + 2] / l;
  }
}
