// The file's look (apps/server/appearance.h): the mesh drawn over render vertices with the file's
// texture coordinates, base colour images (laid as the file's samplers say), vertex colours and
// normal groups (hard edges stay hard: the worker sums the faces' normals per group), unlit
// materials unshaded. Handles and fixed vertices are drawn in their colours over it (over the
// texture too: a label attribute replaces the material's colour), free vertices in the file's own.
import * as THREE from 'three';
import { Wrap, type AppearanceMessage, type MaterialLook } from './protocol';
import { visibleTriangles } from './hide';

type LookMaterial = THREE.MeshLambertMaterial | THREE.MeshBasicMaterial;

const wrapping = {
  [Wrap.Repeat]: THREE.RepeatWrapping,
  [Wrap.Clamp]: THREE.ClampToEdgeWrapping,
  [Wrap.Mirror]: THREE.MirroredRepeatWrapping,
};

// The material's colour (image x base colour x vertex colour) replaced by the vertex's label
// colour where it has one (label.a = 1), striped (every other 5 pixels along the screen's
// diagonal half as bright): a label stays visible on any texture, an orange handle on a tan print too.
function drawLabels(shader: THREE.WebGLProgramParametersWithUniforms): void {
  shader.vertexShader = `attribute vec4 label;\nvarying vec4 vLabel;\n${shader.vertexShader}`.replace(
    '#include <begin_vertex>', '#include <begin_vertex>\n  vLabel = label;');
  shader.fragmentShader = `varying vec4 vLabel;\n${shader.fragmentShader}`.replace(
    '#include <color_fragment>', `#include <color_fragment>
  float stripe = step(0.5, fract((gl_FragCoord.x + gl_FragCoord.y) / 10.0));
  diffuseColor.rgb = mix(diffuseColor.rgb, vLabel.rgb * (1.0 - 0.5 * stripe), vLabel.a);`);
}

// A colour as the mesh vertices' colours hold it: 3 bytes, 255 for 1 (in three.js's working
// colour space, linear).
export function colorBytes(c: THREE.Color): [number, number, number] {
  return [Math.round(255 * c.r), Math.round(255 * c.g), Math.round(255 * c.b)];
}

export class FileLook {
  readonly mesh: THREE.Mesh;
  private readonly geometry = new THREE.BufferGeometry();
  private materials: LookMaterial[] = [];
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

  // Why the file's look may show no shape: a material with triangles drawn unlit, or black
  // without an image (empty: none).
  get flat(): string {
    const a = this.appearance;
    if (!a) return '';
    for (let m = 0; m < a.materials.length; ++m) {
      if (a.materialStart[m + 1] === a.materialStart[m]) continue;
      if (a.materials[m].unlit) return 'unlit';
      const c = a.baseColor.subarray(4 * m, 4 * m + 3);
      if (!a.textured[m] && 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2] < 0.01) return 'black';
    }
    return '';
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
    this.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * R), 3));
    this.geometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3 * R), 3));
    const color = new Float32Array(3 * R).fill(1);
    if (a.rgba) for (let i = 0; i < R; ++i) for (let k = 0; k < 3; ++k) color[3 * i + k] = a.rgba[4 * i + k] / 255;
    this.geometry.setAttribute('color', new THREE.BufferAttribute(color, 3));
    this.geometry.setAttribute('label', new THREE.BufferAttribute(new Uint8Array(4 * R), 4, true));
    if (a.uv) this.geometry.setAttribute('uv', new THREE.BufferAttribute(a.uv.slice(), 2));
    else this.geometry.deleteAttribute('uv');
    const M = a.textured.length;
    for (let m = 0; m <= M; ++m) {
      const color = m < M ? new THREE.Color().setRGB(a.baseColor[4 * m], a.baseColor[4 * m + 1], a.baseColor[4 * m + 2])
        : new THREE.Color(1, 1, 1);
      const options = { color, vertexColors: true, side: THREE.DoubleSide };
      const material = m < M && a.materials[m].unlit ? new THREE.MeshBasicMaterial(options) : new THREE.MeshLambertMaterial(options);
      material.onBeforeCompile = drawLabels;
      this.materials.push(material);
    }
    this.mesh.material = this.materials;
    this.setHidden(null);
  }

  // Leaves out the triangles with a hidden mesh vertex (Viewer.setHidden), material by material.
  setHidden(hidden: Uint8Array | null): void {
    const a = this.appearance;
    if (!a) return;
    const parts: Uint32Array[] = [];
    this.geometry.clearGroups();
    let start = 0;
    for (let m = 0; m + 1 < a.materialStart.length; ++m) {
      const part = visibleTriangles(a.indices.subarray(3 * a.materialStart[m], 3 * a.materialStart[m + 1]), hidden, a.vertex);
      if (part.length > 0) this.geometry.addGroup(start, part.length, m);
      parts.push(part);
      start += part.length;
    }
    const index = new Uint32Array(start);
    parts.reduce((at, part) => (index.set(part, at), at + part.length), 0);
    this.geometry.setIndex(new THREE.BufferAttribute(index, 1));
  }

  // Material m's base colour image (v up, as the texture coordinates are), laid as it says.
  async setTexture(material: number, mime: string, image: Uint8Array): Promise<void> {
    const target = this.materials[material];
    const look: MaterialLook | undefined = this.appearance?.materials[material];
    if (!target || !look) return;
    const bitmap = await createImageBitmap(new Blob([image as BlobPart], { type: mime }), { imageOrientation: 'flipY' });
    if (this.materials[material] !== target) return; // another file meanwhile
    const texture = new THREE.Texture(bitmap);
    texture.flipY = false; // the bitmap is turned already
    texture.colorSpace = THREE.SRGBColorSpace;
    texture.wrapS = wrapping[look.wrapU];
    texture.wrapT = wrapping[look.wrapV];
    if (look.nearest) texture.magFilter = THREE.NearestFilter;
    texture.matrixAutoUpdate = false;
    const t = look.transform;
    texture.matrix.set(t[0], t[1], t[2], t[3], t[4], t[5], 0, 0, 1);
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

  // Whether the render vertices' normals are these already.
  hasNormals(normals: Float32Array): boolean {
    const n = this.geometry.getAttribute('normal')?.array as Float32Array | undefined;
    return !this.appearance || (n !== undefined && n.length === normals.length && n.every((x, i) => x === normals[i]));
  }

  // The selection's colours (3 bytes per mesh vertex): `free` where the file's own colour shows.
  setColors(colors: Uint8Array, free: THREE.Color): void {
    const a = this.appearance;
    if (!a) return;
    const l = this.geometry.getAttribute('label') as THREE.BufferAttribute;
    const out = l.array as Uint8Array;
    const [r, g, b] = colorBytes(free);
    for (let i = 0; i < a.vertex.length; ++i) {
      const v = 3 * a.vertex[i];
      const selected = colors[v] !== r || colors[v + 1] !== g || colors[v + 2] !== b;
      for (let k = 0; k < 3; ++k) out[4 * i + k] = selected ? colors[v + k] : 0;
      out[4 * i + 3] = selected ? 255 : 0;
    }
    l.needsUpdate = true;
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
