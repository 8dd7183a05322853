// The three.js view: the shaded mesh (smooth normals, per-vertex selection colours, optional
// wireframe), a coarse preview mesh drawn instead during drags of large meshes, orbit / pan /
// zoom on the right and middle buttons (or Alt + left; the wheel zooms towards the pointer),
// view presets and an axis widget, a translate / rotate / scale gizmo at the pivot, the 3D
// cursor, the brush's circle, and picking with a BVH (three-mesh-bvh).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { MeshBVH } from 'three-mesh-bvh';
import type { BvhReply, BvhRequest } from './bvh.worker';
import { GpuArray } from './gpu';
import { visibleTriangles } from './hide';
import { colorBytes, FileLook } from './look';
import type { AppearanceMessage } from './protocol';

export interface Hit {
  point: THREE.Vector3;
  normal: THREE.Vector3;
  vertex: number; // the hit triangle's corner nearest to the point
}

export type Navigation = 'blender' | 'right';

export class Viewer {
  readonly renderer: THREE.WebGLRenderer;
  // The camera the controls move; numpad 5 draws and picks through an orthographic one that
  // follows it (`view`), its frame as high as the perspective one's at the orbit's target.
  readonly camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
  private readonly ortho = new THREE.OrthographicCamera();
  orthographic = false;
  readonly orbit: OrbitControls;
  navigation: Navigation = 'blender';
  readonly gizmo: TransformControls;
  readonly pivot = new THREE.Object3D(); // what the gizmo moves
  readonly look = new FileLook(); // the file's texture, colours and normals, when it has them
  freeColor = new THREE.Color(); // the colour of vertices no selection holds (the file's own show)
  private lookShown = true;
  onRendered: () => void = () => {};
  onDrawTimed: (ms: number, draw: number) => void = () => {}; // a full draw's time; `draw`: its number (draws)

  readonly scene = new THREE.Scene();
  private readonly geometry = new THREE.BufferGeometry(); // every triangle: picking, positions
  // What is drawn: the same vertex arrays and the shown triangles, in buffers filled a part at a
  // time (gpu.ts), for at most kUploadMs a task while a mesh arrives; the wireframe's own.
  private readonly drawn = new THREE.BufferGeometry();
  private readonly gpu: Record<'position' | 'normal' | 'color' | 'index', GpuArray>;
  private readonly wireGeometry = new THREE.BufferGeometry();
  // A new mesh's parts are coming, then its normals: uploads keep to tasks of their own.
  private arriving = false;
  private arrivingSphere: THREE.Sphere | null = null; // its bounding sphere
  private hiddenMask: Uint8Array | null = null; // per vertex: hidden (H), with its triangles
  private readonly surface: THREE.Mesh;
  // Smooth with the vertex normals; flat (each triangle's own, no normals needed) while a mesh
  // arrives and until its normals come.
  private readonly smooth = new THREE.MeshLambertMaterial({ vertexColors: true });
  private readonly flat = new THREE.MeshLambertMaterial({ vertexColors: true, flatShading: true });
  private readonly wireframe: THREE.Mesh;
  private readonly coarseGeometry = new THREE.BufferGeometry();
  private readonly coarse: THREE.Mesh;
  private brushRing: { point: THREE.Vector3; normal: THREE.Vector3; radius: number } | null = null;
  private readonly cursorMark: THREE.LineSegments;
  private readonly previewLabel: HTMLElement;
  private readonly axes: HTMLCanvasElement; // the axis widget
  private readonly raycaster = new THREE.Raycaster();
  private bvh: MeshBVH | null = null;
  private bvhStale = false;
  // The BVH is built by a worker (bvh.worker.ts); replies for an earlier mesh are dropped.
  private readonly bvhWorker = new Worker(new URL('./bvh.worker.ts', import.meta.url), { type: 'module' });
  private bvhRequest = 0;
  private coarseVertices = new Uint32Array(0); // mesh vertex of each preview vertex
  private coarseIndices = new Uint32Array(0); // the preview's triangles, hidden ones included
  private home = { position: new THREE.Vector3(), target: new THREE.Vector3() };
  private renderQueued = false;

  constructor(private readonly container: HTMLElement) {
    this.renderer = makeRenderer();
    // The shaders' logs read only in development: reading them waits for each program's compile
    // on the page's thread (0.2 s of the first draw at 692k in software).
    this.renderer.debug.checkShaderErrors = import.meta.env.DEV;
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.appendChild(this.renderer.domElement);
    this.scene.background = new THREE.Color(0xf2f3f5);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667080, 1.6));
    const light = new THREE.DirectionalLight(0xffffff, 1.8);
    light.position.set(0.5, 1, 1.5);
    this.camera.add(light);
    this.scene.add(this.camera);

    const gl = this.renderer.getContext() as WebGL2RenderingContext;
    this.renderer.resetState();
    this.gpu = {
      position: new GpuArray(gl, gl.ARRAY_BUFFER, 3, new Float32Array(0)),
      normal: new GpuArray(gl, gl.ARRAY_BUFFER, 3, new Float32Array(0)),
      color: new GpuArray(gl, gl.ARRAY_BUFFER, 3, new Uint8Array(0)),
      index: new GpuArray(gl, gl.ELEMENT_ARRAY_BUFFER, 1, new Uint32Array(0)),
    };
    this.surface = new THREE.Mesh(this.drawn, this.flat);
    // Both of its programs made at the page's start: three.js took 0.1 s of the page's thread to
    // build one as a mesh came, and the software renderer's linking held the uploads after it.
    for (const material of [this.smooth, this.flat]) {
      this.surface.material = material;
      this.renderer.compile(this.surface, this.camera, this.scene);
    }
    this.coarse = new THREE.Mesh(this.coarseGeometry, this.smooth);
    this.coarse.visible = false;
    this.wireframe = new THREE.Mesh(
      this.wireGeometry,
      new THREE.MeshBasicMaterial({ color: 0x20242c, wireframe: true, transparent: true, opacity: 0.25 }),
    );
    this.wireframe.visible = false;
    this.surface.frustumCulled = this.wireframe.frustumCulled = this.coarse.frustumCulled = false;
    // The 3D cursor: a red and white ring with a cross, drawn over the surface.
    const mark: THREE.Vector3[] = [];
    for (let i = 0; i < 16; ++i) {
      const a = (i * Math.PI) / 8, b = ((i + 1) * Math.PI) / 8;
      mark.push(new THREE.Vector3(Math.cos(a), Math.sin(a), 0), new THREE.Vector3(Math.cos(b), Math.sin(b), 0));
    }
    mark.push(new THREE.Vector3(-1.6, 0, 0), new THREE.Vector3(-0.6, 0, 0), new THREE.Vector3(0.6, 0, 0), new THREE.Vector3(1.6, 0, 0),
      new THREE.Vector3(0, -1.6, 0), new THREE.Vector3(0, -0.6, 0), new THREE.Vector3(0, 0.6, 0), new THREE.Vector3(0, 1.6, 0));
    const markColors = mark.map((_, i) => (Math.floor(i / 2) % 2 ? [1, 1, 1] : [0.85, 0.1, 0.1])).flat();
    const markGeometry = new THREE.BufferGeometry().setFromPoints(mark);
    markGeometry.setAttribute('color', new THREE.Float32BufferAttribute(markColors, 3));
    this.cursorMark = new THREE.LineSegments(markGeometry,
      new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false, transparent: true }));
    this.cursorMark.visible = false;
    this.cursorMark.renderOrder = 2;
    this.scene.add(this.surface, this.look.mesh, this.coarse, this.wireframe, this.pivot, this.cursorMark);
    // The surface's two programs compiled before the mesh comes (a first use waits for them).
    this.renderer.compile(this.scene, this.camera);
    this.previewLabel = Object.assign(document.createElement('div'), {
      id: 'preview-label', textContent: 'preview; detail on release', hidden: true });
    this.axes = Object.assign(document.createElement('canvas'), { id: 'axes', width: 96, height: 96,
      title: 'click an axis to look along it (numpad 1, 3, 7; Ctrl for the opposite side)' });
    this.axes.addEventListener('click', (e) => this.axisClicked(e));
    container.append(this.previewLabel, this.axes);

    this.orbit = new OrbitControls(this.camera, this.renderer.domElement);
    this.setNavigation('blender');
    this.orbit.zoomToCursor = true;
    this.orbit.addEventListener('change', () => this.requestRender());
    this.gizmo = new TransformControls(this.camera, this.renderer.domElement);
    this.gizmo.addEventListener('change', () => this.requestRender());
    this.gizmo.addEventListener('dragging-changed', (e) => (this.orbit.enabled = !e.value));
    this.scene.add(this.gizmo.getHelper());
    container.addEventListener('contextmenu', (e) => e.preventDefault());

    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    this.bvhWorker.onmessage = (e: MessageEvent<BvhReply>) => {
      if (e.data.id !== this.bvhRequest || this.bvh) return;
      // Built on the rest shape: refitted at the next pick if a frame moved it since (bvhStale).
      this.bvh = MeshBVH.deserialize(e.data.bvh, this.geometry, { setIndex: false });
    };
  }

  // The left button paints and drags. As Blender: the middle button orbits, with Shift pans,
  // with Ctrl zooms (which the interaction switches at the press); "right": the right button
  // orbits (Shift: pans), the middle one pans. OrbitControls pans a ROTATE button held with Shift.
  setNavigation(scheme: Navigation): void {
    this.navigation = scheme;
    const { ROTATE, PAN } = THREE.MOUSE;
    this.orbit.mouseButtons = scheme === 'blender' ? { LEFT: null, MIDDLE: ROTATE, RIGHT: null } : { LEFT: null, MIDDLE: PAN, RIGHT: ROTATE };
  }

  get canvas(): HTMLCanvasElement {
    return this.renderer.domElement;
  }

  // A new mesh as it arrives: its positions (framed at once), in the free colour, then its
  // triangles a part at a time (addTriangles), drawn flat until setMesh and its normals.
  // `positions` and `indices` are the arrays the parts fill; read until setMesh. `low`, `high`: the
  // positions' bounding box.
  beginMesh(positions: Float32Array, indices: Uint32Array, low: number[], high: number[]): void {
    const n = positions.length / 3;
    [this.arriving, this.uploaded, this.showFrame] = [true, false, null];
    this.renderer.resetState();
    this.gpu.position.set(positions);
    this.gpu.normal.fresh(new Float32Array(3 * n)); // not drawn until setPositions
    this.gpu.color.set(filled(n, this.freeColor));
    this.gpu.index.fresh(indices);
    [this.trianglesUp, this.shownTriangles] = [0, 0];
    this.drawn.setDrawRange(0, 0);
    this.bindDrawn();
    [this.hiddenMask, this.hiddenCount] = [null, 0];
    this.geometry.setIndex(null);
    this.bvh = null;
    this.look.set(null);
    this.shading = 'flat';
    this.showSurface();
    const box = new THREE.Box3(new THREE.Vector3(...low), new THREE.Vector3(...high));
    this.arrivingSphere = box.getBoundingSphere(new THREE.Sphere());
    this.frameMesh(this.arrivingSphere);
    this.uploadLater();
  }

  // The picking BVH's worker takes every part of every mesh from `port` (setMesh builds it).
  takeMeshParts(port: MessagePort): void {
    this.bvhWorker.postMessage({ kind: 'parts', port } satisfies BvhRequest, [port]);
  }

  // Triangles [first, first + count) of the arriving mesh came.
  addTriangles(first: number, count: number): void {
    this.gpu.index.update(3 * first, 3 * count);
    this.uploadLater();
  }

  // A new mesh; `keepCamera` for another pose of the same one; `arrived`: the mesh that
  // beginMesh and addTriangles showed as it came. The view reads both arrays and never writes
  // them (a frame brings arrays of its own: setPositions).
  setMesh(positions: Float32Array, indices: Uint32Array, keepCamera: boolean, arrived = false): void {
    const n = positions.length / 3;
    this.geometry.setIndex(new THREE.BufferAttribute(indices, 1));
    this.geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    // An arrived mesh's colours and normals are the arrays its GPU buffers were filled from.
    const colors = this.geometry.getAttribute('color');
    if (arrived) this.geometry.setAttribute('color', new THREE.BufferAttribute(this.gpu.color.array, 3, true));
    else if (!colors || colors.count !== n) {
      this.geometry.setAttribute('color', new THREE.BufferAttribute(filled(n, this.freeColor), 3, true));
    }
    this.geometry.setAttribute('normal', new THREE.BufferAttribute(arrived ? this.gpu.normal.array : new Float32Array(3 * n), 3));
    if (arrived && this.arrivingSphere) this.geometry.boundingSphere = this.arrivingSphere;
    else this.geometry.computeBoundingSphere();
    this.renderer.resetState();
    this.showFrame = null; // a frame of the old mesh on its way is dropped (set)
    this.gpu.position.set(positions, arrived);
    this.gpu.normal.set(this.normals(), true); // not drawn until setPositions uploads them
    this.gpu.color.set(this.colors, arrived);
    if (!keepCamera) [this.hiddenMask, this.hiddenCount] = [null, 0];
    this.showHidden(arrived);
    this.bindDrawn();
    this.bvh = null; // built by the worker (seconds for a million triangles)
    this.bvhStale = false;
    this.bvhWorker.postMessage({ kind: 'build', id: ++this.bvhRequest } satisfies BvhRequest);
    this.coarse.visible = false;
    this.shading = 'flat';
    if (!keepCamera && !arrived) this.look.set(null); // another mesh: its look, if any, follows
    this.showSurface();
    if (!keepCamera && !arrived) this.frameMesh(this.geometry.boundingSphere!);
    this.uploadLater();
  }

  // The camera framing a new mesh's bounding sphere, and there again on Home.
  private frameMesh(sphere: THREE.Sphere): void {
    this.camera.near = sphere.radius / 100;
    this.camera.far = sphere.radius * 100;
    this.camera.updateProjectionMatrix();
    this.frameSphere(sphere);
    this.home = { position: this.camera.position.clone(), target: this.orbit.target.clone() };
    this.gizmo.setSize(0.8);
  }

  // The drawn geometries take the GPU arrays' attributes (new ones with each new size).
  private bindDrawn(): void {
    this.drawn.setAttribute('position', this.gpu.position.drawn);
    this.drawn.setAttribute('normal', this.gpu.normal.drawn);
    this.drawn.setAttribute('color', this.gpu.color.drawn);
    this.drawn.setIndex(this.gpu.index.drawn);
    this.wireGeometry.setAttribute('position', this.gpu.position.drawn);
  }

  // Changed GPU arrays go up before the next draw, or, while a mesh arrives or a large frame goes
  // up, in tasks of their own (not a frame: a draw of the mesh coming would hold it); the view is
  // drawn as they go.
  private uploadLater(): void {
    const { position, normal, color, index } = this.gpu;
    const frame = position.framePending || normal.framePending;
    if (!this.arriving && !frame) return this.changedContent();
    if (this.uploadQueued) return;
    this.uploadQueued = true;
    setTimeout(() => {
      this.uploadQueued = false;
      if (this.drawing()) return this.uploadLater(); // an upload would wait behind the draw
      // 1 MB at a time, for as long as kUploadMs allows (a software renderer busy elsewhere
      // takes tens of milliseconds a megabyte, an idle one a few).
      const start = performance.now();
      do this.upload(this.arriving ? kUploadBytes : Infinity, kUploadBytes);
      while (performance.now() - start < kUploadMs && this.uploadsLeft);
      // A frame is drawn once both of its arrays are there.
      const ready = (a: GpuArray) => !a.framePending || a.frameReady;
      const swap = (position.framePending || normal.framePending) && ready(position) && ready(normal);
      if (swap) {
        for (const a of [position, normal]) if (a.frameReady) a.swap();
        this.bindDrawn();
        this.showFrame?.();
        this.showFrame = null;
      }
      const left = this.uploadsLeft;
      this.uploaded = this.geometry.index !== null && // setMesh came: arrived whole (flat)
        position.pendingBytes + color.pendingBytes + index.pendingBytes === 0;
      if (this.uploaded && this.shading === 'smooth' && !normal.framePending) { // and its normals
        this.arriving = false;
        this.showSurface();
      }
      // Drawn now and then as more of its triangles are up while its parts come (each draw costs
      // a software renderer as much as the whole mesh's, and holds the uploads), then once all of
      // it is up (flat, unless its normals are on their way: it is drawn with them), a frame once
      // it is there.
      const more = this.geometry.index === null
        ? this.trianglesUp > this.trianglesShown && performance.now() - this.lastDraw > kArrivalDrawMs
        : this.uploaded && !position.framePending && !normal.framePending && this.trianglesShown < this.drawnTriangles;
      if (swap || (this.arriving ? more : !left)) this.changedContent();
      if (left) this.uploadLater();
    });
  }
  private uploadQueued = false;

  // Whether changed ranges, or a frame not all up yet, wait (a frame all up waits only for its
  // partner's, which is not).
  private get uploadsLeft(): boolean {
    return Object.values(this.gpu).some((a) => a.pendingBytes > 0 || (a.framePending && !a.frameReady));
  }

  // Whether the GPU (a software renderer's threads) is still on the last draw: a GL call made
  // meanwhile may wait for it (most of a second for a large mesh without a GPU).
  private drawing(): boolean {
    const gl = this.renderer.getContext() as WebGL2RenderingContext;
    if (!this.drawFence || gl.getSyncParameter(this.drawFence, gl.SYNC_STATUS) !== gl.SIGNALED) return this.drawFence !== null;
    gl.deleteSync(this.drawFence);
    this.drawFence = null;
    return false;
  }
  private drawFence: WebGLSync | null = null; // after the last draw while a mesh arrives, until passed

  // Uploads changed ranges, at most `budget` bytes, and of pending frames at most `frames`.
  private upload(budget: number, frames = 0): void {
    const arrays = Object.values(this.gpu).filter((a) => a.pendingBytes > 0 || (frames > 0 && a.framePending));
    if (arrays.length === 0) return;
    this.renderer.resetState(); // three.js's GL state: bound vertex arrays and buffers
    for (const a of arrays) {
      const bytes = a.flush(budget);
      budget -= bytes;
      if (a === this.gpu.index) this.trianglesUp += bytes / 12;
    }
    // The arriving mesh's triangles are drawn as they are up (in order, after all positions
    // and colours), not those still zeros: a software renderer shades them all the same.
    if (this.arriving && this.geometry.index === null) this.drawn.setDrawRange(0, 3 * this.trianglesUp);
    for (const a of arrays) frames -= a.flushFrame(frames);
  }

  // Whether the mesh is drawn shaded with its normals.
  get shaded(): boolean {
    return this.shading === 'smooth' && !this.arriving;
  }

  // Whether a new mesh is still going up (its parts, then its normals).
  get meshComing(): boolean {
    return this.arriving;
  }

  // Whether the mesh is drawn whole: all of it arrived and uploaded.
  get whole(): boolean {
    return (this.uploaded || !this.arriving) && this.geometry.index !== null;
  }
  private uploaded = false; // an arriving mesh is whole on the GPU

  positions(): Float32Array {
    return this.geometry.getAttribute('position').array as Float32Array;
  }

  normals(): Float32Array {
    return this.geometry.getAttribute('normal').array as Float32Array;
  }

  // The file's look (after its mesh), or none.
  setAppearance(a: AppearanceMessage | null): void {
    this.look.set(a);
    this.look.setHidden(this.hiddenMask);
    this.look.setPositions(this.positions(), null);
    this.look.setColors(this.colors, this.freeColor);
    this.showSurface();
    this.changedContent();
  }

  async setTexture(material: number, mime: string, image: Uint8Array): Promise<void> {
    await this.look.setTexture(material, mime, image);
    this.changedContent();
  }

  // Whether the file's look is drawn (where it has one) or the plain surface.
  showLook(on: boolean): void {
    this.lookShown = on;
    this.showSurface();
    this.changedContent();
  }

  get drawingLook(): boolean {
    return this.look.mesh.visible;
  }

  // The mesh is drawn flat until its normals have come (setPositions), then smooth; its file's
  // look needs them.
  private showSurface(): void {
    const look = this.look.present && this.lookShown;
    const smooth = this.shading === 'smooth' && !this.arriving; // its normals uploaded
    this.look.mesh.visible = smooth && look;
    this.surface.visible = this.shading !== 'none' && !this.look.mesh.visible;
    this.surface.material = smooth ? this.smooth : this.flat;
  }
  private shading: 'none' | 'flat' | 'smooth' = 'none';

  // A full frame: positions and their normals (computed off the main thread, the view's from
  // here), and the file look's normals when it has one.
  setPositions(positions: Float32Array, normals: Float32Array, lookNormals: Float32Array | null = null): void {
    const p = this.geometry.getAttribute('position') as THREE.BufferAttribute;
    const nrm = this.geometry.getAttribute('normal') as THREE.BufferAttribute;
    // The same again (a frame at the rest shape while it is shown): nothing to upload or draw.
    // The rest shape's first frame brings only its normals.
    const samePositions = equal(p.array as Float32Array, positions);
    const same = samePositions && this.shading === 'smooth' && !this.coarse.visible &&
      equal(nrm.array as Float32Array, normals) && (lookNormals === null || this.look.hasNormals(lookNormals));
    if (same) {
      this.previewLabel.hidden = true;
      return this.requestRender(); // answered by onRendered, without a draw
    }
    // The frame's arrays are the view's from here (the worker made them). A large one goes up
    // beside the drawn one, a task at a time (uploadLater), and is shown (the preview of a drag
    // giving way to it) once it is all there.
    const large = 4 * (samePositions ? 0 : positions.length) + 4 * normals.length > kUploadBytes;
    const { position, normal } = this.gpu;
    if (!samePositions) {
      p.array = positions;
      if (large) position.frame(positions);
      else position.set(positions);
    }
    nrm.array = normals;
    if (large) normal.frame(normals);
    else normal.set(normals);
    this.bvhStale ||= !samePositions; // refitted at the next pick (150 ms at 692k)
    this.bindDrawn(); // set() makes new buffers where the length changed
    const show = () => {
      this.previewLabel.hidden = true;
      this.coarse.visible = false;
      this.shading = 'smooth';
      this.look.setPositions(positions, lookNormals);
      this.showSurface();
    };
    if (large) this.showFrame = show;
    else show();
    this.uploadLater();
  }
  private showFrame: (() => void) | null = null; // once the large frame on its way is all there

  // The vertices' colours (3 bytes each: colorBytes), which the caller changes in place and then
  // names (colorsChanged).
  get colors(): Uint8Array {
    return this.geometry.getAttribute('color').array as Uint8Array;
  }

  // The vertices listed (ascending) took new colours: only their runs are uploaded, runs
  // closer than kColorGap vertices as one (a stroke's vertices lie all over a large mesh's
  // numbering: their whole span is megabytes), and their whole span past kColorRuns runs.
  colorsChanged(vertices: ArrayLike<number>): void {
    const runs: [number, number][] = [];
    for (let i = 0; i < vertices.length;) {
      let j = i + 1;
      while (j < vertices.length && vertices[j] - vertices[j - 1] <= kColorGap) ++j;
      runs.push([vertices[i], vertices[j - 1] - vertices[i] + 1]);
      i = j;
    }
    if (runs.length > kColorRuns) runs.splice(0, Infinity, [vertices[0], vertices[vertices.length - 1] - vertices[0] + 1]);
    for (const [first, count] of runs) this.gpu.color.update(first, count);
    this.syncCoarseColors();
    this.look.setColors(this.colors, this.freeColor);
    this.uploadLater();
  }

  // The coarse mesh of drags: some mesh vertices and triangles between them.
  setPreview(vertices: Uint32Array, indices: Uint32Array): void {
    this.coarseVertices = vertices.slice();
    this.coarseIndices = indices.slice();
    const k = vertices.length;
    this.coarseGeometry.setIndex(new THREE.BufferAttribute(visibleTriangles(this.coarseIndices, this.hiddenMask, vertices), 1));
    this.coarseGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * k), 3));
    this.coarseGeometry.setAttribute('normal', new THREE.BufferAttribute(new Float32Array(3 * k), 3));
    this.coarseGeometry.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(3 * k), 3, true));
    this.syncCoarseColors();
  }

  get previewSize(): number {
    return this.coarseVertices.length;
  }

  showPreview(positions: Float32Array, normals: Float32Array): void {
    const p = this.coarseGeometry.getAttribute('position') as THREE.BufferAttribute;
    const nrm = this.coarseGeometry.getAttribute('normal') as THREE.BufferAttribute;
    if (!p || p.count * 3 !== positions.length) return;
    (p.array as Float32Array).set(positions);
    (nrm.array as Float32Array).set(normals);
    p.needsUpdate = nrm.needsUpdate = true;
    this.coarse.visible = true;
    this.surface.visible = false;
    this.look.mesh.visible = false;
    this.previewLabel.hidden = false;
    this.changedContent();
  }

  // Back to the full mesh as its last frame left it (the coarse preview and its label gone): a
  // drag whose frames can no longer come (the server went away).
  dropPreview(): void {
    if (!this.coarse.visible) return;
    this.coarse.visible = false;
    this.previewLabel.hidden = true;
    this.showSurface();
    this.changedContent();
  }

  get showingPreview(): boolean {
    return this.coarse.visible;
  }

  private syncCoarseColors(): void {
    const target = this.coarseGeometry.getAttribute('color') as THREE.BufferAttribute | undefined;
    if (!target) return;
    const source = this.colors;
    const out = target.array as Uint8Array;
    this.coarseVertices.forEach((v, i) => {
      out[3 * i] = source[3 * v];
      out[3 * i + 1] = source[3 * v + 1];
      out[3 * i + 2] = source[3 * v + 2];
    });
    target.needsUpdate = true;
  }

  // Hides `vertices` and the triangles around them (shown: false reveals them; no list: all),
  // from drawing and picking alike; returns how many vertices are hidden.
  setHidden(vertices: ArrayLike<number> | null, shown = false): number {
    const n = this.geometry.getAttribute('position')?.count ?? 0;
    if (!vertices) this.hiddenMask = shown ? null : new Uint8Array(n).fill(1);
    else {
      this.hiddenMask ??= new Uint8Array(n);
      for (let i = 0; i < vertices.length; ++i) this.hiddenMask[vertices[i]] = shown ? 0 : 1;
    }
    this.hiddenCount = this.hiddenMask?.reduce((a, h) => a + h, 0) ?? 0;
    if (this.hiddenCount === 0) this.hiddenMask = null;
    this.renderer.resetState();
    this.showHidden();
    this.uploadLater();
    return this.hiddenCount;
  }
  hiddenCount = 0;

  get drawnTriangles(): number {
    return this.gpu.index.array.length / 3;
  }

  get hidden(): Uint8Array | null {
    return this.hiddenMask;
  }

  // The shown triangles to the GPU (`uploaded`: all of them, there already or on their way).
  // The caller resets three.js's GL state first.
  private showHidden(uploaded = false): void {
    const index = this.geometry.index;
    if (!index) return;
    const hidden = this.hiddenMask;
    const shown = hidden ? visibleTriangles(index.array as Uint32Array, hidden) : index.array as Uint32Array;
    this.gpu.index.set(shown, uploaded && !hidden);
    this.drawn.setDrawRange(0, Infinity);
    this.drawn.setIndex(this.gpu.index.drawn);
    this.wireGeometry.setIndex(new THREE.BufferAttribute(shown, 1));
    // Behind a hidden part the inside of the surface shows, as in Blender.
    const side = hidden ? THREE.DoubleSide : THREE.FrontSide;
    for (const material of [this.smooth, this.flat]) {
      if (material.side !== side) [material.side, material.needsUpdate] = [side, true];
    }
    if (this.coarseIndices.length > 0) {
      this.coarseGeometry.setIndex(new THREE.BufferAttribute(visibleTriangles(this.coarseIndices, hidden, this.coarseVertices), 1));
    }
    this.look.setHidden(hidden);
  }

  setWireframe(on: boolean): void {
    this.wireframe.visible = on;
    this.changedContent();
  }

  // The brush's circle, on the surface's tangent plane at `hit`; null hides it. Drawn over the
  // view (#brush-ring), so that following the pointer redraws no mesh (0.6 s for 1.4M triangles
  // without a GPU); again after each draw, for the camera may have moved.
  showBrush(hit: Hit | null, radius: number): void {
    this.brushRing = hit && { point: hit.point.clone(), normal: hit.normal.clone(), radius };
    this.drawBrush();
  }

  private drawBrush(): void {
    const svg = document.getElementById('brush-ring')!;
    const b = this.brushRing;
    svg.style.display = b ? 'block' : 'none';
    if (!b) return;
    const turn = new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 0, 1), b.normal);
    const [u, v] = [new THREE.Vector3(1, 0, 0).applyQuaternion(turn), new THREE.Vector3(0, 1, 0).applyQuaternion(turn)];
    const at = svg.getBoundingClientRect();
    const points = Array.from({ length: 48 }, (_, i) => {
      const a = (i * Math.PI) / 24;
      const s = this.toScreen(b.point.clone().addScaledVector(u, b.radius * Math.cos(a)).addScaledVector(v, b.radius * Math.sin(a)));
      return `${(s.x - at.left).toFixed(1)},${(s.y - at.top).toFixed(1)}`;
    });
    svg.firstElementChild!.setAttribute('points', points.join(' '));
  }

  // The 3D cursor's mark at `point` (sized with the view), or none.
  showCursor(point: THREE.Vector3 | null): void {
    this.cursorMark.visible = point !== null;
    if (point) this.cursorMark.position.copy(point);
    this.changedContent();
  }

  pick(clientX: number, clientY: number): Hit | null {
    if (!this.geometry.index) return null;
    this.bvh ??= new MeshBVH(this.geometry, { indirect: true }); // picked before the worker was done
    if (this.bvhStale) {
      this.bvh.refit();
      this.bvhStale = false;
    }
    this.raycaster.setFromCamera(this.ndc(clientX, clientY), this.view);
    const hidden = this.hiddenMask;
    const hit = hidden
      ? this.bvh.raycast(this.raycaster.ray, THREE.DoubleSide).sort((a, b) => a.distance - b.distance)
        .find((h) => h.face && !hidden[h.face.a] && !hidden[h.face.b] && !hidden[h.face.c])
      : this.bvh.raycastFirst(this.raycaster.ray, THREE.DoubleSide);
    if (!hit || !hit.face) return null;
    const p = this.positions();
    let best = hit.face.a;
    let bestDistance = Infinity;
    for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
      const d = hit.point.distanceToSquared(new THREE.Vector3(p[3 * v], p[3 * v + 1], p[3 * v + 2]));
      if (d < bestDistance) [best, bestDistance] = [v, d];
    }
    const normal = hit.face.normal.clone();
    if (normal.dot(this.raycaster.ray.direction) > 0) normal.negate();
    return { point: hit.point.clone(), normal, vertex: best };
  }

  // A world point's position in client (CSS pixel) coordinates.
  toScreen(point: THREE.Vector3): { x: number; y: number } {
    const rect = this.canvas.getBoundingClientRect();
    const v = point.clone().project(this.view);
    return { x: rect.left + ((v.x + 1) / 2) * rect.width, y: rect.top + ((1 - v.y) / 2) * rect.height };
  }

  // The ray from the camera through (clientX, clientY).
  ray(clientX: number, clientY: number): THREE.Ray {
    this.raycaster.setFromCamera(this.ndc(clientX, clientY), this.view);
    return this.raycaster.ray.clone();
  }

  // The world point under (clientX, clientY) on the plane through `through` facing the camera.
  onViewPlane(clientX: number, clientY: number, through: THREE.Vector3): THREE.Vector3 | null {
    this.raycaster.setFromCamera(this.ndc(clientX, clientY), this.view);
    const normal = this.camera.getWorldDirection(new THREE.Vector3());
    const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, through);
    return this.raycaster.ray.intersectPlane(plane, new THREE.Vector3());
  }

  // Frames the given points (or the whole mesh) without turning the camera; the points' sphere
  // fills about a third of the view, the whole mesh all of it.
  frame(points?: THREE.Vector3[]): void {
    if (this.geometry.index) this.geometry.computeBoundingSphere(); // as drawn now
    const whole = this.geometry.boundingSphere ?? new THREE.Sphere();
    const sphere = points && points.length > 0 ? new THREE.Sphere().setFromPoints(points) : whole.clone();
    if (points && points.length > 0) sphere.radius = Math.min(whole.radius, Math.max(3 * sphere.radius, 0.15 * whole.radius));
    this.frameSphere(sphere, this.camera.position.clone().sub(this.orbit.target));
  }

  // Looks at the same target from the side `direction` points to, at the same distance, the
  // world's Y upwards (numpad 1 front, 3 right, 7 top; from above, -Z is up on screen).
  lookFrom(direction: THREE.Vector3): void {
    const distance = this.camera.position.distanceTo(this.orbit.target);
    const d = direction.clone().normalize();
    if (Math.abs(d.y) > 0.999) d.z += 1e-6; // straight down or up: the orbit's up stays Y
    this.camera.position.copy(this.orbit.target).add(d.normalize().multiplyScalar(distance));
    this.orbit.update();
    this.requestRender();
  }

  // Numpad 4, 6, 8, 2: orbits about the target by `degrees` across (right +) or up and down (up +),
  // as Blender's view orbit steps; numpad 9 (turn: 180 across) looks from the other side.
  orbitBy(across: number, up: number): void {
    const offset = this.camera.position.clone().sub(this.orbit.target);
    const s = new THREE.Spherical().setFromVector3(offset);
    s.theta -= THREE.MathUtils.degToRad(across);
    s.phi = THREE.MathUtils.clamp(s.phi - THREE.MathUtils.degToRad(up), 1e-4, Math.PI - 1e-4);
    this.camera.position.copy(this.orbit.target).add(new THREE.Vector3().setFromSpherical(s));
    this.orbit.update();
    this.requestRender();
  }

  resetCamera(): void {
    this.camera.position.copy(this.home.position);
    this.orbit.target.copy(this.home.target);
    this.orbit.update();
    this.requestRender();
  }

  private frameSphere(sphere: THREE.Sphere, direction = new THREE.Vector3(0.25, 0.35, 1)): void {
    const distance = sphere.radius / Math.sin(THREE.MathUtils.degToRad(this.camera.fov / 2));
    this.camera.position.copy(sphere.center).add(direction.normalize().multiplyScalar(1.15 * distance));
    this.orbit.target.copy(sphere.center);
    this.orbit.update();
    this.requestRender();
  }

  // Milliseconds until the GPU (or the software renderer's threads) has done what was submitted
  // so far, without waiting for it: a fence, polled every few milliseconds while the page goes on
  // taking events. Called right after a draw, it times that draw.
  private timeSubmitted(): Promise<number> {
    const gl = this.renderer.getContext() as WebGL2RenderingContext;
    const start = performance.now();
    const fence = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
    if (!fence) return Promise.resolve(0); // a lost context
    gl.flush();
    return new Promise((resolve) => {
      const poll = () => {
        if (gl.getSyncParameter(fence, gl.SYNC_STATUS) !== gl.SIGNALED) return void setTimeout(poll, 2);
        gl.deleteSync(fence);
        resolve(performance.now() - start);
      };
      setTimeout(poll);
    });
  }

  // What a draw would show: the canvas' size, the camera, the gizmo, the 3D cursor and the
  // version of the drawn content (changedContent); a requested draw that would show the same is
  // not made (a full draw of a million triangles takes most of a second without a GPU).
  private showing(): string {
    const c = this.view, g = this.gizmo as TransformControls & { dragging: boolean };
    const gizmo = g.object ? [g.mode, g.axis, g.dragging, g.size, g.space, ...this.pivot.position.toArray(),
      ...this.pivot.quaternion.toArray(), ...this.pivot.scale.toArray()] : [];
    const cursor = this.cursorMark.visible ? this.cursorMark.position.toArray() : [];
    return [this.canvas.width, this.canvas.height, ...c.position.toArray(), ...c.quaternion.toArray(),
      ...c.projectionMatrix.elements, this.contentVersion, gizmo.join(), cursor.join()].join();
  }
  private shown = '';
  private contentVersion = 0;

  private changedContent(): void {
    ++this.contentVersion;
    this.requestRender();
  }

  // Draws on the next animation frame (`again`: even if it would show the same, to time a
  // draw). A slow draw (the full large mesh without a GPU) is followed by as long without one,
  // so that pointer events, which wait for the frame being drawn, still come in at once half of
  // the time.
  requestRender(again = false): void {
    this.drawAgain ||= again;
    if (this.renderQueued) return;
    this.renderQueued = true;
    const draw = () => requestAnimationFrame(() => {
      this.renderQueued = false;
      const showing = this.showing();
      if (showing === this.shown && !this.drawAgain) {
        ++this.drawsSkipped;
        return this.onRendered(); // what was asked for is on the screen already
      }
      [this.shown, this.drawAgain] = [showing, false];
      if (!this.arriving) this.upload(Infinity);
      this.renderer.render(this.scene, this.view);
      if (this.arriving) {
        const gl = this.renderer.getContext() as WebGL2RenderingContext;
        if (this.drawFence) gl.deleteSync(this.drawFence);
        this.drawFence = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
        gl.flush();
      }
      this.lastDraw = performance.now();
      const drawnRange = Math.min(this.drawn.drawRange.count, this.drawn.index?.count ?? 0) / 3;
      this.shownTriangles = this.arriving && !this.uploaded ? Math.min(this.trianglesUp, drawnRange) : drawnRange;
      ++this.draws;
      // The full mesh's draws, timed one at a time, pace the next (a draw without it is quick).
      const full = this.surface.visible || this.look.mesh.visible;
      if (full) ++this.fullDraws;
      if (full && !this.timingDraw) {
        this.timingDraw = true;
        const draw = this.draws;
        void this.timeSubmitted().then((ms) => {
          [this.drawMs, this.timingDraw] = [ms, false];
          this.onDrawTimed(ms, draw);
        });
      }
      this.drawAxes();
      this.drawBrush();
      this.onRendered();
    });
    // The preview draws fast; a request that would show the same is answered at once.
    const slow = this.drawMs > kSlowDrawMs && !this.coarse.visible && this.showing() !== this.shown;
    const wait = slow ? this.lastDraw + this.drawMs - performance.now() : 0;
    if (wait > 0) setTimeout(draw, wait);
    else draw();
  }
  drawMs = 0; // the full mesh's last timed draw
  private timingDraw = false;
  draws = 0; // made so far, of whatever is shown
  fullDraws = 0; // of them, of the full mesh
  drawsSkipped = 0; // asked for, but they would have shown what was shown
  private drawAgain = false;
  private lastDraw = -Infinity;
  private trianglesUp = 0; // of an arriving mesh, uploaded so far
  private shownTriangles = 0;

  // Triangles the last draw showed: of an arriving mesh, those uploaded (in order).
  get trianglesShown(): number {
    return this.shownTriangles;
  }

  // The axis widget: the world axes as the camera sees them, +X red, +Y green, +Z blue.
  private axisEnds(): { axis: THREE.Vector3; x: number; y: number; depth: number; label: string; color: string }[] {
    const inverse = this.camera.quaternion.clone().invert();
    const names = ['X', 'Y', 'Z'];
    const colors = ['#d43d3d', '#4e9a28', '#2b6de8'];
    return [0, 1, 2].flatMap((k) => [1, -1].map((sign) => {
      const axis = new THREE.Vector3().setComponent(k, sign);
      const v = axis.clone().applyQuaternion(inverse);
      return { axis, x: 48 + 34 * v.x, y: 48 - 34 * v.y, depth: v.z, label: sign > 0 ? names[k] : '', color: colors[k] };
    }));
  }

  private drawAxes(): void {
    const ctx = this.axes.getContext('2d');
    if (!ctx) return;
    ctx.clearRect(0, 0, 96, 96);
    for (const e of this.axisEnds().sort((a, b) => a.depth - b.depth)) {
      if (e.label) {
        ctx.strokeStyle = e.color;
        ctx.lineWidth = 2;
        ctx.beginPath();
        ctx.moveTo(48, 48);
        ctx.lineTo(e.x, e.y);
        ctx.stroke();
      }
      ctx.fillStyle = e.label ? e.color : `${e.color}66`;
      ctx.beginPath();
      ctx.arc(e.x, e.y, e.label ? 8 : 6, 0, 2 * Math.PI);
      ctx.fill();
      if (e.label) {
        ctx.fillStyle = '#fff';
        ctx.font = 'bold 10px sans-serif'; // system-ui: the first draw looked it up for 60-170 ms
        ctx.textAlign = 'center';
        ctx.textBaseline = 'middle';
        ctx.fillText(e.label, e.x, e.y + 0.5);
      }
    }
  }

  // A click on an axis' end looks along it, from that side.
  private axisClicked(e: MouseEvent): void {
    const near = this.axisEnds().filter((a) => Math.hypot(a.x - e.offsetX, a.y - e.offsetY) < 10)
      .sort((a, b) => b.depth - a.depth)[0];
    if (!near) return;
    this.lookFrom(near.axis);
  }

  // Client coordinates in the camera's normalised device coordinates. The camera's matrices are
  // brought up to date first: a view key or a drag moves the camera before the next draw would.
  private ndc(clientX: number, clientY: number): THREE.Vector2 {
    const rect = this.canvas.getBoundingClientRect();
    return new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
  }

  // The camera that draws and picks, its matrices up to date (a view key or a drag moves the
  // camera before the next draw would): the perspective one, or the orthographic one placed as it.
  get view(): THREE.Camera {
    this.camera.updateMatrixWorld();
    if (!this.orthographic) return this.camera;
    const o = this.ortho;
    const half = this.camera.position.distanceTo(this.orbit.target) *
      Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2));
    [o.left, o.right, o.top, o.bottom] = [-half * this.camera.aspect, half * this.camera.aspect, half, -half];
    [o.near, o.far] = [this.camera.near, this.camera.far];
    o.position.copy(this.camera.position);
    o.quaternion.copy(this.camera.quaternion);
    o.updateProjectionMatrix();
    o.updateMatrixWorld();
    this.gizmo.camera = o;
    return o;
  }

  // Numpad 5: perspective or orthographic; returns the new one.
  toggleProjection(): 'orthographic' | 'perspective' {
    this.orthographic = !this.orthographic;
    if (!this.orthographic) this.gizmo.camera = this.camera;
    this.requestRender();
    return this.orthographic ? 'orthographic' : 'perspective';
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

// n colours, all `color`: a new mesh's, before it is painted.
function filled(n: number, color: THREE.Color): Uint8Array<ArrayBuffer> {
  const colors = new Uint8Array(3 * n);
  if (n === 0) return colors;
  colors.set(colorBytes(color));
  for (let done = 3; done < colors.length; done *= 2) colors.copyWithin(done, 0, Math.min(done, colors.length - done));
  return colors;
}

function equal(a: Float32Array, b: Float32Array): boolean {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; ++i) if (a[i] !== b[i]) return false;
  return true;
}

// Draws slower than this are spaced out (requestRender).
const kSlowDrawMs = 50;
// Uploaded at a time while a mesh arrives (1 MB: tens of milliseconds of the page's thread on a
// software renderer with the server's basis computing beside it), again while a task has been
// at it for less than kUploadMs.
const kUploadBytes = 1 << 20;
const kUploadMs = 20;
const kArrivalDrawMs = 500; // a mesh coming is drawn this often at most
const kColorGap = 64; // vertices between two painted runs uploaded as one
const kColorRuns = 1024; // runs uploaded one by one at most

// The renderer, without multisampling where the context is a software renderer (no GPU: it
// would spend most of a frame on it), with it otherwise. One context is made there (a second
// costs 0.7 s at the opening), two on a GPU.
function makeRenderer(): THREE.WebGLRenderer {
  const canvas = document.createElement('canvas');
  const attributes = { alpha: false, depth: true, stencil: false, premultipliedAlpha: true, preserveDrawingBuffer: true };
  const context = canvas.getContext('webgl2', { ...attributes, antialias: false });
  const info = context?.getExtension('WEBGL_debug_renderer_info');
  const name = info ? String(context!.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  if (context && /swiftshader|llvmpipe|software/i.test(name)) {
    return new THREE.WebGLRenderer({ canvas, context, ...attributes });
  }
  context?.getExtension('WEBGL_lose_context')?.loseContext();
  return new THREE.WebGLRenderer({ ...attributes, antialias: true });
}
