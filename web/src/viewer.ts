// The three.js view: the shaded mesh (smooth normals, per-vertex selection colours, optional
// wireframe), orbit / pan / zoom, and a translate / rotate gizmo on the active handle group.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { vertexNormals } from './normals';

export interface Hit {
  point: THREE.Vector3;
  vertex: number; // the hit triangle's corner nearest to the point
}

export class Viewer {
  readonly renderer: THREE.WebGLRenderer;
  readonly camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
  readonly orbit: OrbitControls;
  readonly gizmo: TransformControls;
  readonly pivot = new THREE.Object3D(); // what the gizmo moves
  onRendered: () => void = () => {};

  readonly scene = new THREE.Scene();
  private readonly geometry = new THREE.BufferGeometry();
  private readonly surface: THREE.Mesh;
  private readonly wireframe: THREE.Mesh;
  private readonly raycaster = new THREE.Raycaster();
  private renderQueued = false;
  private boundsStale = false;

  constructor(private readonly container: HTMLElement) {
    // A software renderer (no GPU) spends most of a frame on multisampling: it goes without.
    this.renderer = new THREE.WebGLRenderer({ antialias: !softwareRenderer(), preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.appendChild(this.renderer.domElement);
    this.scene.background = new THREE.Color(0xf2f3f5);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667080, 1.6));
    const light = new THREE.DirectionalLight(0xffffff, 1.8);
    light.position.set(0.5, 1, 1.5);
    this.camera.add(light);
    this.scene.add(this.camera);

    this.surface = new THREE.Mesh(
      this.geometry,
      new THREE.MeshLambertMaterial({ vertexColors: true }),
    );
    this.wireframe = new THREE.Mesh(
      this.geometry,
      new THREE.MeshBasicMaterial({ color: 0x20242c, wireframe: true, transparent: true, opacity: 0.25 }),
    );
    this.wireframe.visible = false;
    this.surface.frustumCulled = this.wireframe.frustumCulled = false;
    this.scene.add(this.surface, this.wireframe, this.pivot);

    this.orbit = new OrbitControls(this.camera, this.renderer.domElement);
    this.orbit.addEventListener('change', () => this.requestRender());
    this.gizmo = new TransformControls(this.camera, this.renderer.domElement);
    this.gizmo.addEventListener('change', () => this.requestRender());
    this.gizmo.addEventListener('dragging-changed', (e) => (this.orbit.enabled = !e.value));
    this.scene.add(this.gizmo.getHelper());

    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  get canvas(): HTMLCanvasElement {
    return this.renderer.domElement;
  }

  setMesh(positions: Float32Array, indices: Uint32Array): void {
    const n = positions.length / 3;
    this.geometry.setIndex(new THREE.BufferAttribute(indices.slice(), 1));
    this.geometry.setAttribute('position', new THREE.BufferAttribute(positions.slice(), 3));
    this.geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    this.geometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    this.updateNormals();
    this.geometry.computeBoundingSphere();
    const sphere = this.geometry.boundingSphere!;
    const distance = sphere.radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2));
    this.camera.near = sphere.radius / 100;
    this.camera.far = sphere.radius * 100;
    this.camera.position.copy(sphere.center).add(new THREE.Vector3(0.25, 0.35, 1).normalize().multiplyScalar(1.05 * distance));
    this.camera.updateProjectionMatrix();
    this.orbit.target.copy(sphere.center);
    this.orbit.update();
    this.gizmo.setSize(0.9);
    this.requestRender();
  }

  positions(): Float32Array {
    return this.geometry.getAttribute('position').array as Float32Array;
  }

  setPositions(positions: Float32Array): void {
    const attribute = this.geometry.getAttribute('position') as THREE.BufferAttribute;
    (attribute.array as Float32Array).set(positions);
    attribute.needsUpdate = true;
    this.updateNormals();
    this.boundsStale = true;
    this.requestRender();
  }

  private updateNormals(): void {
    const normals = this.geometry.getAttribute('normal') as THREE.BufferAttribute;
    vertexNormals(this.positions(), this.geometry.index!.array as Uint32Array, normals.array as Float32Array);
    normals.needsUpdate = true;
  }

  // colours: 3 floats per vertex.
  setColors(colors: Float32Array): void {
    const attribute = this.geometry.getAttribute('color') as THREE.BufferAttribute;
    (attribute.array as Float32Array).set(colors);
    attribute.needsUpdate = true;
    this.requestRender();
  }

  setWireframe(on: boolean): void {
    this.wireframe.visible = on;
    this.requestRender();
  }

  pick(clientX: number, clientY: number): Hit | null {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(
      ((clientX - rect.left) / rect.width) * 2 - 1,
      -((clientY - rect.top) / rect.height) * 2 + 1,
    );
    this.raycaster.setFromCamera(ndc, this.camera);
    if (this.boundsStale) {
      this.geometry.computeBoundingSphere();
      this.boundsStale = false;
    }
    const hit = this.raycaster.intersectObject(this.surface, false)[0];
    if (!hit || !hit.face) return null;
    const p = this.positions();
    let best = hit.face.a;
    let bestDistance = Infinity;
    for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
      const d = hit.point.distanceToSquared(new THREE.Vector3(p[3 * v], p[3 * v + 1], p[3 * v + 2]));
      if (d < bestDistance) [best, bestDistance] = [v, d];
    }
    return { point: hit.point.clone(), vertex: best };
  }

  // A world point's position in client (CSS pixel) coordinates.
  toScreen(point: THREE.Vector3): { x: number; y: number } {
    const rect = this.canvas.getBoundingClientRect();
    const v = point.clone().project(this.camera);
    return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height };
  }

  // The world point under (clientX, clientY) on the plane through `through` facing the camera.
  onViewPlane(clientX: number, clientY: number, through: THREE.Vector3): THREE.Vector3 | null {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(
      ((clientX - rect.left) / rect.width) * 2 - 1,
      -((clientY - rect.top) / rect.height) * 2 + 1,
    );
    this.raycaster.setFromCamera(ndc, this.camera);
    const normal = this.camera.getWorldDirection(new THREE.Vector3());
    const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, through);
    return this.raycaster.ray.intersectPlane(plane, new THREE.Vector3());
  }

  requestRender(): void {
    if (this.renderQueued) return;
    this.renderQueued = true;
    requestAnimationFrame(() => {
      this.renderQueued = false;
      this.renderer.render(this.scene, this.camera);
      this.onRendered();
    });
  }

  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0) return;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }
}

function softwareRenderer(): boolean {
  const gl = document.createElement('canvas').getContext('webgl2');
  const info = gl?.getExtension('WEBGL_debug_renderer_info');
  const name = info ? String(gl!.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  gl?.getExtension('WEBGL_lose_context')?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}
