// The editor: connects the view, the brush and the server (`specdeform edit`).
import * as THREE from 'three';
import './style.css';
import { Brush } from './brush';
import { History } from './history';
import * as P from './protocol';
import { Viewer } from './viewer';

type Tool = 'handle' | 'fixed' | 'erase' | 'move';

// Per-vertex labels: 0 free, 1 fixed, 2 + g handle group g.
const FREE = 0;
const FIXED = 1;
const GROUP_COLORS = [0xf28e2b, 0x59a14f, 0xb07aa1, 0x76b7b2, 0xedc948, 0xe15759, 0x9c755f];
const FREE_COLOR = new THREE.Color(0xc9ccd3);
const FIXED_COLOR = new THREE.Color(0x4e79a7);

interface Snapshot {
  labels: Int16Array;
  transforms: THREE.Matrix4[]; // of each handle group, acting on rest positions
}

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;
const viewer = new Viewer($('view'));
const history = new History<Snapshot>();

let socket: WebSocket;
let rest = new Float32Array(0); // rest positions
let indices = new Uint32Array(0);
let brush: Brush | null = null;
let labels = new Int16Array(0);
let transforms: THREE.Matrix4[] = [new THREE.Matrix4()];
let activeGroup = 0;
let tool: Tool = 'handle';
let diagonal = 1;
let ready = false;
let seq = 0;
const sentAt = new Map<number, number>();
let pendingDraw: number | null = null; // seq of a result waiting to be drawn
let lastDrawn = 0;
// latencies: mouse event to its frame drawn; receiveLatencies: to its result received (ms).
const stats = {
  framesDrawn: 0,
  framesReceived: 0,
  latencies: [] as number[],
  receiveLatencies: [] as number[],
  drawTimes: [] as number[],
};
let serverMs: P.FrameResult['ms'] | null = null;
let constraintError = 0;
let basisInfo = '';
let selectionSeconds = 0;

// ---------------------------------------------------------------- connection

function connect(): void {
  socket = new WebSocket(`ws://${location.host}/ws`);
  socket.binaryType = 'arraybuffer';
  socket.onmessage = (e) => (typeof e.data === 'string' ? onText(JSON.parse(e.data)) : onBinary(e.data));
  socket.onclose = (e) => {
    ready = false;
    if (e.code === 1009) {
      say('the file is larger than the server accepts (specdeform edit --max-upload-mb)');
      setTimeout(connect, 500);
    } else {
      say(`disconnected${e.reason ? ': ' + e.reason : ''} — reload the page to reconnect`);
    }
  };
}

function send(data: ArrayBuffer | object): void {
  if (socket.readyState !== WebSocket.OPEN) return;
  socket.send(data instanceof ArrayBuffer ? data : JSON.stringify(data));
}

function onText(m: any): void {
  switch (m.type) {
    case 'progress':
      $('progress').hidden = false;
      $('progress-stage').textContent = `${m.stage}… ${Math.round(100 * m.fraction)}%`;
      $<HTMLProgressElement>('progress-bar').value = m.fraction;
      break;
    case 'ready':
      $('progress').hidden = true;
      diagonal = m.diagonal;
      $('mesh-name').textContent = `${m.name}: ${m.vertices.toLocaleString()} vertices, ${m.faces.toLocaleString()} triangles`;
      $<HTMLInputElement>('modes').value = m.modes;
      $<HTMLInputElement>('ks').value = m.settings.ks;
      $<HTMLInputElement>('kb').value = m.settings.kb;
      $<HTMLSelectElement>('detail').value = m.settings.detail;
      $<HTMLSelectElement>('constraints').value = m.settings.constraints;
      $<HTMLInputElement>('show-base').checked = m.settings.view === 'base';
      basisInfo = `${m.basis.seconds.toFixed(2)} s (${m.basis.source}, m = ${m.modes})`;
      ready = true;
      say(m.basis.warning, true);
      updateTimings();
      break;
    case 'selection':
      selectionSeconds = m.seconds;
      updateTimings();
      break;
    case 'error':
      $('progress').hidden = true;
      ready = rest.length > 0; // a failed change leaves the previous state in place
      say(m.message);
      break;
  }
}

function onBinary(buffer: ArrayBuffer): void {
  switch (P.tagOf(buffer)) {
    case P.Tag.Mesh:
      return adoptMesh(P.decodeMesh(buffer));
    case P.Tag.FrameResult: {
      const r = P.decodeFrameResult(buffer);
      const sent = sentAt.get(r.seq);
      if (sent !== undefined) stats.receiveLatencies.push(performance.now() - sent);
      stats.framesReceived++;
      viewer.setPositions(r.positions);
      serverMs = r.ms;
      constraintError = r.error.max;
      pendingDraw = r.seq;
      return;
    }
    case P.Tag.File: {
      const f = P.decodeFile(buffer);
      const a = document.createElement('a');
      a.href = URL.createObjectURL(new Blob([f.data as BlobPart]));
      a.download = f.name;
      a.click();
      setTimeout(() => URL.revokeObjectURL(a.href), 10000);
      return say(`saved ${f.name}`, true);
    }
    case P.Tag.SelectionResult:
      return adoptSelection(P.decodeSelection(buffer));
  }
}

viewer.onRendered = () => {
  if (pendingDraw === null) return;
  const t = sentAt.get(pendingDraw);
  const now = performance.now();
  if (t !== undefined) stats.latencies.push(now - t);
  for (const s of sentAt.keys()) if (s <= pendingDraw) sentAt.delete(s);
  stats.framesDrawn++;
  stats.drawTimes.push(now);
  lastDrawn = pendingDraw;
  pendingDraw = null;
  updateTimings();
};

// ---------------------------------------------------------------- state

function adoptMesh(m: P.MeshMessage): void {
  const same = m.indices.length === indices.length && m.indices.every((v, i) => v === indices[i]) &&
    m.positions.every((v, i) => v === rest[i]);
  // The same mesh again (a settings change rebuilt the server's solver): keep the view, the
  // selection and the shown frame.
  if (same) return;
  rest = m.positions.slice();
  indices = m.indices.slice();
  viewer.setMesh(rest, indices);
  brush = new Brush(rest.length / 3, indices);
  labels = new Int16Array(rest.length / 3);
  transforms = [new THREE.Matrix4()];
  activeGroup = 0;
  history.reset(snapshot());
  refreshGroups();
  paint();
}

function snapshot(): Snapshot {
  return { labels: labels.slice(), transforms: transforms.map((t) => t.clone()) };
}

function restore(s: Snapshot): void {
  labels = s.labels.slice();
  transforms = s.transforms.map((t) => t.clone());
  activeGroup = Math.min(activeGroup, transforms.length - 1);
  refreshGroups();
  paint();
  sendSelection();
}

// Records the state after a change; a gesture that changed nothing adds no undo step.
function commit(): void {
  const last = history.current();
  const same = last && last.transforms.length === transforms.length &&
    last.transforms.every((t, g) => t.equals(transforms[g])) && last.labels.every((l, v) => l === labels[v]);
  if (!same) history.push(snapshot());
}

function selection(): P.Selection {
  const s: P.Selection = { handles: transforms.map(() => []), fixed: [] };
  labels.forEach((l, v) => {
    if (l === FIXED) s.fixed.push(v);
    else if (l >= 2) s.handles[l - 2].push(v);
  });
  return s;
}

function hasHandles(): boolean {
  return labels.some((l) => l >= 2);
}

function sendSelection(): void {
  send(P.encodeSelection(selection()));
  if (hasHandles()) sendFrame();
  else viewer.setPositions(rest);
  placeGizmo();
}

function sendFrame(): void {
  if (!hasHandles()) return;
  ++seq;
  sentAt.set(seq, performance.now());
  send(P.encodeFrame(seq, transforms.map((t) => t.clone().transpose().toArray())));
}

function adoptSelection(s: P.Selection): void {
  labels.fill(FREE);
  s.fixed.forEach((v) => (labels[v] = FIXED));
  s.handles.forEach((g, k) => g.forEach((v) => (labels[v] = 2 + k)));
  transforms = Array.from({ length: Math.max(1, s.handles.length) }, () => new THREE.Matrix4());
  activeGroup = 0;
  refreshGroups();
  commit();
  paint();
  sendSelection();
}

// ---------------------------------------------------------------- colours, groups, gizmo

function paint(): void {
  const colors = new Float32Array(3 * labels.length);
  const group = GROUP_COLORS.map((c) => new THREE.Color(c));
  labels.forEach((l, v) => {
    const c = l === FREE ? FREE_COLOR : l === FIXED ? FIXED_COLOR : group[(l - 2) % group.length];
    colors.set([c.r, c.g, c.b], 3 * v);
  });
  viewer.setColors(colors);
}

function refreshGroups(): void {
  const select = $<HTMLSelectElement>('group');
  select.replaceChildren(
    ...transforms.map((_, g) => new Option(`${g + 1}`, `${g}`, false, g === activeGroup)),
  );
  select.style.color = `#${GROUP_COLORS[activeGroup % GROUP_COLORS.length].toString(16).padStart(6, '0')}`;
}

function centroid(group: number): THREE.Vector3 | null {
  const c = new THREE.Vector3();
  let count = 0;
  labels.forEach((l, v) => {
    if (l === 2 + group) {
      c.x += rest[3 * v];
      c.y += rest[3 * v + 1];
      c.z += rest[3 * v + 2];
      ++count;
    }
  });
  return count > 0 ? c.divideScalar(count) : null;
}

// The gizmo sits on the active group's centroid, carried by the group's transform.
function placeGizmo(): void {
  const c = centroid(activeGroup);
  if (!c || tool !== 'move') {
    viewer.gizmo.detach();
    viewer.requestRender();
    return;
  }
  const m = transforms[activeGroup].clone().multiply(new THREE.Matrix4().makeTranslation(c.x, c.y, c.z));
  m.decompose(viewer.pivot.position, viewer.pivot.quaternion, viewer.pivot.scale);
  viewer.pivot.updateMatrix();
  viewer.gizmo.attach(viewer.pivot);
  viewer.requestRender();
}

viewer.gizmo.addEventListener('objectChange', () => {
  const c = centroid(activeGroup);
  if (!c) return;
  viewer.pivot.updateMatrix();
  transforms[activeGroup] = viewer.pivot.matrix.clone().multiply(new THREE.Matrix4().makeTranslation(-c.x, -c.y, -c.z));
  sendFrame();
});
viewer.gizmo.addEventListener('dragging-changed', (e) => {
  if (!e.value) commit();
});

// ---------------------------------------------------------------- pointer: brush and drag

let painting = false;
let dragging: { group: number; start: THREE.Vector3; transform: THREE.Matrix4 } | null = null;

function brushAt(clientX: number, clientY: number): boolean {
  const hit = viewer.pick(clientX, clientY);
  if (!hit || !brush) return false;
  const positions = viewer.positions();
  const radius = (Number($<HTMLInputElement>('radius').value) / 100) * diagonal;
  const vertices = $<HTMLInputElement>('geodesic').checked
    ? brush.geodesic(positions, hit.vertex, radius)
    : brush.euclidean(positions, hit.point.x, hit.point.y, hit.point.z, radius);
  const label = tool === 'handle' ? 2 + activeGroup : tool === 'fixed' ? FIXED : FREE;
  for (const v of vertices) labels[v] = label;
  paint();
  return true;
}

// Capture phase: decides before the orbit controls whether a press paints or drags.
$('view').addEventListener(
  'pointerdown',
  (e) => {
    if (!ready || e.button !== 0 || e.altKey || viewer.gizmo.axis !== null) return;
    if (tool === 'move') {
      const hit = viewer.pick(e.clientX, e.clientY);
      const l = hit ? labels[hit.vertex] : FREE;
      if (!hit || l < 2) return;
      activeGroup = l - 2;
      refreshGroups();
      dragging = { group: activeGroup, start: hit.point, transform: transforms[activeGroup].clone() };
    } else if (brushAt(e.clientX, e.clientY)) {
      painting = true;
    } else {
      return;
    }
    viewer.orbit.enabled = false;
    $('view').setPointerCapture(e.pointerId);
  },
  true,
);

$('view').addEventListener('pointermove', (e) => {
  if (painting) brushAt(e.clientX, e.clientY);
  if (dragging) {
    const p = viewer.onViewPlane(e.clientX, e.clientY, dragging.start);
    if (!p) return;
    const d = p.sub(dragging.start);
    transforms[dragging.group] = new THREE.Matrix4().makeTranslation(d.x, d.y, d.z).multiply(dragging.transform);
    placeGizmo();
    sendFrame();
  }
});

$('view').addEventListener('pointerup', () => {
  if (painting) {
    painting = false;
    commit();
    sendSelection();
  }
  if (dragging) {
    dragging = null;
    commit();
  }
  viewer.orbit.enabled = true;
});

// ---------------------------------------------------------------- panel

function say(text: string, info = false): void {
  $('message').textContent = text;
  $('message').className = info ? 'info' : '';
}

function setTool(t: Tool): void {
  tool = t;
  document.querySelectorAll<HTMLButtonElement>('[data-tool]').forEach((b) =>
    b.setAttribute('aria-checked', String(b.dataset.tool === t)),
  );
  placeGizmo();
}

function median(values: number[]): number {
  if (values.length === 0) return NaN;
  const s = [...values].sort((a, b) => a - b);
  return s[Math.floor(s.length / 2)];
}

function updateTimings(): void {
  const now = performance.now();
  const lastSecond = stats.drawTimes.filter((t) => now - t < 1000).length;
  const rows: [string, string][] = [
    ['basis', basisInfo],
    ['selection', `${(1000 * selectionSeconds).toFixed(1)} ms`],
    ['solve (server)', serverMs ? `${serverMs.total.toFixed(1)} ms` : '–'],
    ['· reduced / inverse / detail', serverMs
      ? `${serverMs.reducedSolve.toFixed(1)} / ${serverMs.inverseTransform.toFixed(1)} / ${serverMs.detail.toFixed(1)}`
      : '–'],
    ['drag → drawn (median)', stats.latencies.length ? `${median(stats.latencies.slice(-30)).toFixed(0)} ms` : '–'],
    ['updates per second', `${lastSecond}`],
    ['handle error / diagonal', constraintError.toExponential(1)],
  ];
  $('timings').replaceChildren(
    ...rows.map(([k, v]) => {
      const tr = document.createElement('tr');
      tr.append(Object.assign(document.createElement('td'), { textContent: k }),
        Object.assign(document.createElement('td'), { textContent: v }));
      return tr;
    }),
  );
}
setInterval(updateTimings, 500);

async function openFile(file: File, tag: number): Promise<void> {
  say(`sending ${file.name}…`, true);
  if (tag === P.Tag.MeshFile) ready = false;
  send(P.encodeFile(tag, file.name, await file.arrayBuffer()));
}

document.querySelectorAll<HTMLButtonElement>('[data-tool]').forEach((b) =>
  b.addEventListener('click', () => setTool(b.dataset.tool as Tool)),
);
$('open-demo').addEventListener('click', () => {
  ready = false;
  send({ type: 'open_demo' });
});
$<HTMLInputElement>('open-mesh').addEventListener('change', (e) => {
  const f = (e.target as HTMLInputElement).files?.[0];
  if (f) openFile(f, P.Tag.MeshFile);
  (e.target as HTMLInputElement).value = '';
});
$<HTMLInputElement>('open-selection').addEventListener('change', (e) => {
  const f = (e.target as HTMLInputElement).files?.[0];
  if (f) openFile(f, P.Tag.SelectionFile);
  (e.target as HTMLInputElement).value = '';
});
$('wireframe').addEventListener('change', (e) => viewer.setWireframe((e.target as HTMLInputElement).checked));
$('show-base').addEventListener('change', (e) =>
  send({ type: 'settings', view: (e.target as HTMLInputElement).checked ? 'base' : 'detailed' }),
);
// Solver settings rebuild the server's deformer: busy until its "ready".
function sendSettings(settings: object): void {
  ready = false;
  send({ type: 'settings', ...settings });
}
for (const id of ['modes', 'ks', 'kb']) {
  $(id).addEventListener('change', (e) => {
    const v = Number((e.target as HTMLInputElement).value);
    if (Number.isFinite(v)) sendSettings({ [id]: v });
  });
}
for (const id of ['detail', 'constraints']) {
  $(id).addEventListener('change', (e) => sendSettings({ [id]: (e.target as HTMLSelectElement).value }));
}
$('group').addEventListener('change', (e) => {
  activeGroup = Number((e.target as HTMLSelectElement).value);
  refreshGroups();
  placeGizmo();
});
function newGroup(): void {
  transforms.push(new THREE.Matrix4());
  activeGroup = transforms.length - 1;
  refreshGroups();
  setTool('handle');
}
$('new-group').addEventListener('click', newGroup);
const radiusLabel = () => ($('radius-value').textContent = `${$<HTMLInputElement>('radius').value}% of the diagonal`);
$('radius').addEventListener('input', radiusLabel);
radiusLabel();
$('gizmo-translate').addEventListener('click', () => viewer.gizmo.setMode('translate'));
$('gizmo-rotate').addEventListener('click', () => viewer.gizmo.setMode('rotate'));
$('clear').addEventListener('click', () => {
  labels.fill(FREE);
  transforms = [new THREE.Matrix4()];
  activeGroup = 0;
  refreshGroups();
  commit();
  paint();
  sendSelection();
});
const undo = () => history.undo() && restore(history.current());
const redo = () => history.redo() && restore(history.current());
$('undo').addEventListener('click', undo);
$('redo').addEventListener('click', redo);
$('reset').addEventListener('click', () => {
  transforms = transforms.map(() => new THREE.Matrix4());
  commit();
  placeGizmo();
  sendFrame();
});
$('export-mesh').addEventListener('click', () =>
  send({ type: 'export_mesh', format: $<HTMLSelectElement>('export-format').value }),
);
$('export-scene').addEventListener('click', () => send({ type: 'export_scene' }));

window.addEventListener('keydown', (e) => {
  if (e.target instanceof HTMLInputElement || e.target instanceof HTMLSelectElement) return;
  const key = e.key.toLowerCase();
  if ((e.ctrlKey || e.metaKey) && key === 'z') {
    e.preventDefault();
    e.shiftKey ? redo() : undo();
  } else if ((e.ctrlKey || e.metaKey) && key === 'y') {
    e.preventDefault();
    redo();
  } else if (!e.ctrlKey && !e.metaKey) {
    const tools: Record<string, Tool> = { '1': 'handle', '2': 'fixed', '3': 'erase', '4': 'move' };
    if (tools[key]) setTool(tools[key]);
    if (key === 'n') newGroup();
    if (key === 't') viewer.gizmo.setMode('translate');
    if (key === 'r') viewer.gizmo.setMode('rotate');
  }
});

window.addEventListener('dragover', (e) => {
  e.preventDefault();
  document.body.classList.add('drop');
});
window.addEventListener('dragleave', () => document.body.classList.remove('drop'));
window.addEventListener('drop', (e) => {
  e.preventDefault();
  document.body.classList.remove('drop');
  const f = e.dataTransfer?.files[0];
  if (!f) return;
  const selectionFile = /\.(sel|dmat)$/i.test(f.name);
  openFile(f, selectionFile ? P.Tag.SelectionFile : P.Tag.MeshFile);
});

// Read-only state for automation (the end-to-end test and the picture script).
(window as any).specdeformEditor = {
  get ready() {
    return ready;
  },
  stats,
  restPositions: () => Array.from(rest),
  positions: () => Array.from(viewer.positions()),
  labels: () => Array.from(labels),
  transforms: () => transforms.map((t) => t.clone().transpose().toArray()),
  vertexOnScreen: (v: number) =>
    viewer.toScreen(new THREE.Vector3().fromArray(viewer.positions(), 3 * v)),
  diagonal: () => diagonal,
  settled: () => lastDrawn === seq && pendingDraw === null,
  cameraPosition: () => viewer.camera.position.toArray(),
  setView: (direction: [number, number, number], zoom = 1) => {
    const target = viewer.orbit.target;
    const distance = viewer.camera.position.distanceTo(target) / zoom;
    viewer.camera.position.copy(target).add(new THREE.Vector3(...direction).normalize().multiplyScalar(distance));
    viewer.orbit.update();
    viewer.requestRender();
  },
};

setTool('handle');
connect();
