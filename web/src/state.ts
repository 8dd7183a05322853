// The editor's state: the mesh as the server has it, the selection (a label per vertex) with
// the handle groups' transforms, and one explicit phase. Server messages come in here and
// nowhere else; what the page shows follows from this state (panel.ts) and the view.
import * as THREE from 'three';
import { Brush } from './brush';
import { Connection, ConnectionStatus } from './connection';
import type { Slot, WorkerReply, WorkerRequest } from './geometry.worker';
import { colorBytes } from './look';
import type { Measures } from './measures';
import * as P from './protocol';
import { Viewer } from './viewer';
import { MeshArrival, type WholeMesh } from './arrival';
import { dropHeld, loadHeld, meshKey, saveHeld } from './held';

// Per-vertex labels: 0 free, 1 fixed, 2 + g handle group g.
export const FREE = 0;
export const FIXED = 1;

export type Phase =
  | { kind: 'connecting' }
  | { kind: 'disconnected'; reason: string; retryAt: number | null }
  | { kind: 'empty' } // connected, no mesh open: open one or the demo
  | { kind: 'loading'; stage: string; fraction: number; cancellable: boolean }
  | { kind: 'busy'; what: string; expects: 'ready' | 'state' | 'file' }
  | { kind: 'ready' };

export interface Group {
  transform: THREE.Matrix4; // acting on rest positions
  pinned: boolean;
}

// `transient`: true while it holds (a file being sent), gone when the request ends.
// `offline`: raised while not connected (its message leaves the view on reconnection).
export type Note = { text: string; level: 'info' | 'error'; time: number; transient: boolean; offline: boolean };

// Drawing and response statistics (the timings panel and the end-to-end test).
export const stats = {
  framesDrawn: 0,
  framesReceived: 0,
  previewsDrawn: 0,
  latencies: [] as number[], // mouse event to its frame drawn (ms)
  receiveLatencies: [] as number[], // to its result received
  drawTimes: [] as number[],
  meshStarted: null as number | null, // performance.now() when the last mesh's first part came
  meshReceived: null as number | null, // its last part
  meshSeen: null as number | null, // when some of its triangles were first drawn
  meshShown: null as number | null, // when the last new mesh was first drawn whole
  meshDrawn: null as number | null, // and shaded with its normals
  detailedDrawn: null as number | null, // and when the last frame of the whole mesh was drawn
  pointerMoves: 0, // pointer moves over the view, and how many of them were acted on (coalesced)
  pointerActed: 0,
};

// Draws slower than this (ms, measured once per mesh) make drags show the preview mesh, sized
// to draw in about kPreviewMs; a mesh of fewer than kAlwaysWhole vertices never does: dragged
// whole, with its texture and detail, on any machine that draws the page (tens of milliseconds a
// frame without a GPU).
const kFullDrawBudgetMs = 25;
const kPreviewMs = 8;
const kAlwaysWhole = 50_000;
// A mesh's first draw slower than this is slow whatever its upload took (25 MB at a million
// vertices: a few milliseconds on a GPU).
const kUploadMs = 100;
const kProgressMs = 500; // a stage's progress shown this often at most
const kTaskMs = 30; // a mesh's parts are taken in tasks of about this long (ms)

// Resolves in a task of its own: the page draws and takes input in between.
const nextTask = () => new Promise<void>((resolve) => setTimeout(resolve));

export class EditorState {
  phase: Phase = { kind: 'connecting' };
  ready: P.ReadyMessage | null = null;
  server: P.StateMessage | null = null;
  detailSince = 0; // performance.now() when the transfer's factoring last began
  rest = new Float32Array(0);
  indices = new Uint32Array(0);
  labels = new Int16Array(0);
  groups: Group[] = [{ transform: new THREE.Matrix4(), pinned: false }];
  activeGroup = 0;
  frame: P.FrameResult | null = null; // the last one received
  measures: Measures | null = null; // of the full frame shown
  private measuresAwaited: number | null = null; // the full frame whose measures are on their way
  notes: Note[] = [];
  drawMs = 0; // the full mesh's draw time
  diagonal = 1; // of the mesh's bounding box
  // The mesh on screen is being prepared (its basis computed): it can be painted, and the
  // selection is held until it is ready.
  preparing = false;
  saving: string | null = null; // the basis file the server writes in the background
  private selectionHeld = false; // painted while preparing: sent when the mesh is ready
  private heldKey = ''; // the mesh's name in local storage (held.ts)
  private firstDraw: 'none' | 'shown' | 'drawn' = 'drawn'; // of a new mesh
  private wholeShown = true; // the new mesh drawn whole (stats.meshShown)
  previewWanted = false;
  private preview: P.PreviewMessage | null = null; // the coarse mesh of drags
  painting = false; // a brush stroke is on (interaction.ts)
  discardFrames = false; // count frame results without drawing them (measuring the server)
  private listeners: (() => void)[] = [];
  private seq = 0;
  private sentAt = new Map<number, number>();
  private pendingDraw: number | null = null;
  private outstanding: number | null = null; // the last frame sent, until a result as new arrives
  private lastDrawn = 0;
  private readonly arrival = new MeshArrival(); // the mesh's parts as they come
  private readonly worker: Worker; // the geometry worker (geometry.worker.ts)
  private arrivalShown = false; // drawn as it comes (a new mesh; the same one again when whole)
  private normalsBusy: Record<Slot, boolean> = { full: false, preview: false };
  private normalsQueued: Record<Slot, P.FrameResult | null> = { full: null, preview: null };
  private brushId = 0;
  private brushReplies = new Map<number, (vertices: Uint32Array) => void>();
  private wasOpen = false;
  private restoreChecked = true;
  private restoring = false; // the server sent an empty selection where this page has one
  private restoreSettings: P.ClientText | null = null;
  private awaitingStates = 0; // requests sent whose "state" (or "empty", or error) is to come
  private selectionsInFlight = 0; // selections sent, not answered yet
  private selectionWaiting = false; // a selection made since: sent when they are answered
  private restorePending = false; // a restored selection is on its way back

  // `connection`: to the server, maybe opened already; `started`: the geometry worker, reading the
  // open mesh since the page's start.
  constructor(readonly viewer: Viewer, readonly connection: Connection, started: StartedWorker) {
    this.worker = started.worker;
    viewer.takeMeshParts(started.bvhParts);
    viewer.freeColor = FREE_COLOR;
    connection.on = {
      status: (s) => this.onStatus(s),
      text: (m) => this.receive(() => this.onText(m), m.type === 'progress' || m.type === 'mesh'),
      binary: (b) => this.receive(() => this.onBinary(b), false),
    };
    this.worker.onmessage = (e: MessageEvent<WorkerReply>) => this.onWorker(e.data);
    void this.takeMesh(1, null);
    viewer.onRendered = () => this.onRendered();
    viewer.onDrawTimed = (ms, draw) => this.drawTimed(ms, draw);
  }

  private progressShown = -Infinity; // when the page last showed a change (changed())
  private progressLater: number | undefined; // a change of the progress to show then

  subscribe(listener: () => void): void {
    this.listeners.push(listener);
  }

  changed(): void {
    this.progressShown = performance.now();
    for (const l of this.listeners) l();
  }

  // A change shown now, or kProgressMs after the last one shown (a progress, a mesh's part).
  private changedSoon(): void {
    if (performance.now() - this.progressShown >= kProgressMs) return this.changed();
    this.progressLater ??= window.setTimeout(() => {
      this.progressLater = undefined;
      this.changed();
    }, kProgressMs);
  }

  get editable(): boolean {
    return this.phase.kind === 'ready';
  }

  // Handles and fixed parts can be painted: the mesh is ready, or on screen while its basis
  // is computed.
  get paintable(): boolean {
    return this.editable || (this.preparing && this.phase.kind === 'loading');
  }

  // Messages for the user: errors stay until dismissed (panel.ts), the last 30 are kept.
  note(text: string, level: Note['level'] = 'info', transient = false): void {
    if (!text) return;
    // Bytes of a garbage file quoted by the server's reader show as one '?' per run.
    text = text.replace(/[\u0000-\u0008\u000b-\u001f\u007f-\u009f\ufffd]+/g, '?');
    this.notes.push({ text, level, time: Date.now(), transient, offline: !this.connection.open });
    if (this.notes.length > 30) this.notes.shift();
    this.changed();
  }

  // ------------------------------------------------------------ requests

  // A request whose reply ends the busy phase: "ready" (settings), "state" (edits, a mesh, a
  // pose) or "file" (exports); an error always ends it.
  request(message: P.ClientText | ArrayBuffer, what: string, expects: 'ready' | 'state' | 'file'): boolean {
    if (!this.connection.open) {
      this.note(`${what}: not connected to the server`, 'error');
      return false;
    }
    this.connection.send(message);
    if (expects === 'state') ++this.awaitingStates;
    this.phase = { kind: 'busy', what, expects };
    this.changed();
    return true;
  }

  // `fit`: pinned groups whose transform the server fits; `echo`: it sends the selection back.
  // Strokes coalesce: a plain selection made while another is on its way waits, and only the
  // newest goes when the server answers (no queue of rebuilds behind the pointer).
  sendSelection(fit: Set<number> = new Set(), echo = false): void {
    if (this.preparing) {
      this.selectionHeld = true;
      saveHeld(this.heldKey, this.labels, this.groups);
      return;
    }
    if (fit.size === 0 && !echo && this.selectionsInFlight > 0) {
      this.selectionWaiting = true;
      return;
    }
    const s: P.Selection = {
      groups: this.groups.map((g, k) => ({
        vertices: new Uint32Array(0),
        transform: rowMajor(g.transform),
        pinned: g.pinned,
        fit: fit.has(k),
      })),
      fixed: new Uint32Array(0),
      echo,
    };
    const lists: number[][] = this.groups.map(() => []);
    const fixed: number[] = [];
    this.labels.forEach((l, v) => {
      if (l === FIXED) fixed.push(v);
      else if (l >= 2) lists[l - 2].push(v);
    });
    s.groups.forEach((g, k) => (g.vertices = Uint32Array.from(lists[k])));
    s.fixed = Uint32Array.from(fixed);
    if (this.connection.send(P.encodeSelection(s))) {
      ++this.awaitingStates;
      ++this.selectionsInFlight;
    } else this.note('the selection was not sent: not connected (it is sent again on reconnection)', 'error');
  }

  // Sends the transforms as they are now; `preview`: answered with the preview's vertices.
  sendFrame(preview = false): void {
    if (!this.hasHandles()) return;
    ++this.seq;
    this.sentAt.set(this.seq, performance.now());
    this.outstanding = this.seq;
    // The groups the server has (a new group is sent with its first vertices).
    const groups = this.groups.slice(0, this.server?.groups.length ?? this.groups.length);
    this.connection.send(P.encodeFrame(this.seq, groups.map((g) => rowMajor(g.transform)), preview));
  }

  get lastSeq(): number {
    return this.seq;
  }

  // The transforms as they are now become an undo step.
  commit(): void {
    if (this.connection.send({ type: 'commit' })) ++this.awaitingStates;
  }

  hasHandles(): boolean {
    return this.labels.some((l) => l >= 2);
  }

  counts(): { handles: number; fixed: number; pinned: number; groups: number } {
    // Called on each change the panel shows (each progress message): one pass, nothing
    // allocated.
    const perLabel = this.perLabel.fill(0);
    const labels = this.labels;
    let top: number = FIXED;
    for (let v = 0; v < labels.length; ++v) {
      const l = labels[v];
      if (l <= FREE) continue;
      ++perLabel[l];
      if (l > top) top = l;
    }
    let handles = 0, pinned = 0, groups = 0;
    for (let l = FIXED + 1; l <= top; ++l) {
      if (perLabel[l] === 0) continue;
      if (this.kindOf(l) === 'pinned') pinned += perLabel[l];
      else [handles, groups] = [handles + perLabel[l], groups + 1];
    }
    return { handles, fixed: perLabel[FIXED], pinned, groups };
  }
  private perLabel = new Int32Array(1 << 15); // a count for every Int16 label

  // What a label stands for, as the colours and the counts read it: 0 free, 1 fixed, 2 + g the
  // handle group g, pinned or not (a label whose group is not known yet is a handle).
  private kindOf(label: number): 'free' | 'fixed' | 'pinned' | 'handle' {
    if (label === FREE) return 'free';
    if (label === FIXED) return 'fixed';
    return this.groups[label - 2]?.pinned ? 'pinned' : 'handle';
  }

  settled(): boolean {
    return this.unsettled().length === 0;
  }

  // What the page still waits for (automation's diagnostics).
  unsettled(): string[] {
    const waits: [boolean, string][] = [
      [this.outstanding !== null, `frame ${this.outstanding}'s result`], [this.pendingDraw !== null, 'a frame to draw'],
      [this.awaitingStates > 0, `${this.awaitingStates} states`], [this.selectionWaiting, 'a selection waiting'],
      [!!this.server?.detail_pending, 'the detail'], [this.painting, 'a stroke'], [this.normalsBusy.full, 'normals'],
      [this.phase.kind === 'busy', 'busy'], [this.selectionHeld, 'a held selection'],
      [this.selectionsInFlight > 0, `${this.selectionsInFlight} selections in flight`],
      [this.measuresAwaited !== null, `frame ${this.measuresAwaited}'s measures`],
      [this.viewer.meshComing, 'the mesh going up'], // its upload waits for the GPU's last draw
    ];
    return waits.filter(([on]) => on).map(([, what]) => what);
  }

  // The vertices a brush stroke reaches (computed by the worker).
  brush(vertex: number, center: THREE.Vector3, radius: number, geodesic: boolean): Promise<Uint32Array> {
    const id = ++this.brushId;
    const request: WorkerRequest = { kind: 'brush', id, vertex, center: [center.x, center.y, center.z], radius, geodesic };
    this.worker.postMessage(request);
    const delay = this.brushDelayMs;
    return new Promise((resolve) => this.brushReplies.set(id, delay ? (v) => setTimeout(() => resolve(v), delay) : resolve));
  }
  brushDelayMs = 0; // automation: the worker's replies held back this long (a large mesh's pace)

  // ------------------------------------------------------------ incoming

  // The socket's messages after a mesh's notice wait for the mesh (fetched over HTTP, it comes
  // after them), but for progress and another mesh; they are handled in order once it is taken.
  private waiting: (() => void)[] | null = null;

  private receive(handle: () => void, now: boolean): void {
    if (this.waiting && !now) this.waiting.push(handle);
    else handle();
  }

  private onStatus(s: ConnectionStatus): void {
    if (s.kind === 'open') {
      if (this.phase.kind === 'disconnected') this.note('reconnected to the server');
      if (this.lostOnDisconnect) this.note(`${this.lostOnDisconnect} was cancelled when the connection was lost: do it again`);
      this.lostOnDisconnect = null;
      this.phase = { kind: 'connecting' };
      this.outstanding = null;
      this.restoreChecked = !this.wasOpen; // after a reconnection: does the server still have the edit?
      this.wasOpen = true;
      this.awaitingStates = 1;
      this.selectionsInFlight = 0; // the server greets the connection ("hello"): no request
    } else if (s.kind === 'closed') {
      // The banner stays while disconnected; the log says when it started.
      if (this.phase.kind !== 'disconnected') this.note(`disconnected: ${s.reason}`);
      this.lostOnDisconnect ??= this.onConnectionLost();
      this.viewer.dropPreview();
      this.phase = { kind: 'disconnected', reason: s.reason, retryAt: s.retryAt };
      this.awaitingStates = 0;
      this.selectionsInFlight = 0;
    } else if (this.phase.kind !== 'disconnected') {
      this.phase = { kind: 'connecting' };
    }
    this.changed();
  }

  private onText(m: P.ServerText): void {
    switch (m.type) {
      case 'progress': {
        const stage = this.phase.kind === 'loading' ? this.phase.stage : null;
        this.phase = { kind: 'loading', stage: m.stage, fraction: m.fraction, cancellable: m.cancellable };
        // A stage's progress is shown every kProgressMs at most: each change of the page costs
        // a software renderer a composite of the whole window (30% of a core at 10 a second).
        if (stage === m.stage) return this.changedSoon();
        break;
      }
      case 'ready':
        this.adoptReady(m);
        if (this.phase.kind !== 'busy' || this.phase.expects === 'ready') this.phase = { kind: 'ready' };
        break;
      case 'state':
        this.adoptState(m);
        if (this.phase.kind !== 'busy' || this.phase.expects !== 'file') this.phase = { kind: 'ready' };
        break;
      case 'note':
        this.note(m.message);
        break;
      case 'mesh':
        return void this.fetchMesh(m);
      case 'saving':
        this.saving = m.done ? null : m.file;
        if (m.done) {
          this.note(m.error ? `the basis was not saved for next time: ${m.error}`
            : `saved the basis for next time (${((m.bytes ?? 0) / 1e6).toFixed(0)} MB in ${(m.seconds ?? 0).toFixed(1)} s)`,
          m.error ? 'error' : 'info');
        }
        break;
      case 'empty':
        if (STATE_REQUESTS.has(m.request)) this.awaitingStates = Math.max(0, this.awaitingStates - 1);
        this.phase = { kind: 'empty' };
        this.ready = null;
        break;
      case 'error':
        if (STATE_REQUESTS.has(m.request)) this.awaitingStates = Math.max(0, this.awaitingStates - 1);
        if (m.request === 'selection') this.selectionAnswered();
        if (m.request === 'frame') this.outstanding = null; // answered, if not by a frame
        this.note(m.cancelled || m.message.startsWith(`${m.request}:`) ? m.message : `${requestName(m.request)}: ${m.message}`,
          m.cancelled ? 'info' : 'error');
        this.phase = this.ready ? { kind: 'ready' } : { kind: 'empty' };
        break;
    }
    this.changed();
  }

  private onBinary(buffer: ArrayBuffer): void {
    switch (P.tagOf(buffer)) {
      case P.Tag.Preview: {
        const p = P.decodePreview(buffer);
        this.viewer.setPreview(p.vertices, p.indices);
        this.preview = { vertices: p.vertices.slice(), indices: p.indices.slice() };
        return this.postPreview(this.preview);
      }
      case P.Tag.FrameResult: {
        const r = P.decodeFrameResult(buffer);
        const sent = this.sentAt.get(r.seq);
        if (sent !== undefined) stats.receiveLatencies.push(performance.now() - sent);
        stats.framesReceived++;
        if (this.outstanding !== null && r.seq >= this.outstanding) this.outstanding = null;
        if (this.discardFrames) return;
        this.frame = r;
        const slot: Slot = r.preview ? 'preview' : 'full';
        if (this.normalsBusy[slot]) this.normalsQueued[slot] = r; // latest wins
        else this.computeFrame(slot, r.seq, r.scale, r.displacements);
        return;
      }
      case P.Tag.File: {
        const f = P.decodeFile(buffer);
        const a = document.createElement('a');
        a.href = URL.createObjectURL(new Blob([f.data as BlobPart]));
        a.download = f.name;
        a.click();
        setTimeout(() => URL.revokeObjectURL(a.href), 10000);
        if (this.phase.kind === 'busy' && this.phase.expects === 'file') this.phase = { kind: 'ready' };
        return this.note(`saved ${f.name}`);
      }
      case P.Tag.SelectionResult:
        return this.adoptSelection(P.decodeSelection(buffer));
      case P.Tag.Appearance: {
        const a = P.decodeAppearance(buffer);
        this.viewer.setAppearance(a);
        const flat = this.viewer.look.flat;
        if (flat) this.note(`the file's ${flat} material shows no shading: untick "file's look" to see the shape`);
        this.post({ kind: 'look', vertex: a.vertex.slice(), group: a.normalGroup.slice(), indices: a.indices.slice() });
        // The shown frame again, with the look's normals.
        const f = this.frame;
        if (f && !f.preview && f.displacements.length === this.rest.length) {
          return this.computeFrame('full', f.seq, f.scale, f.displacements);
        }
        return this.showRest();
      }
      case P.Tag.Texture: {
        const t = P.decodeTexture(buffer);
        this.viewer.setTexture(t.material, t.mime, t.image.slice()).catch((e) => this.note(`texture: ${e}`, 'error'));
        return;
      }
    }
  }

  // The worker makes the positions and their normals (a copy of the displacements goes: the
  // message's buffer holds other fields too).
  private computeFrame(slot: Slot, seq: number, scale: number, displacements: Int16Array, copy = true): void {
    this.normalsBusy[slot] = true;
    if (slot === 'full') this.measuresAwaited = seq;
    this.post({ kind: 'frame', slot, seq, scale, displacements: copy ? displacements.slice() : displacements });
  }

  // The rest shape, as a frame without displacements.
  private showRest(): void {
    this.computeFrame('full', this.seq, 1, new Int16Array(this.rest.length), false);
  }

  private onWorker(m: WorkerReply): void {
    if (m.kind === 'part' || m.kind === 'fetched') {
      if (m.fetch !== this.meshFetches) return;
      this.meshReplies.push(m);
      return this.meshReplied?.();
    }
    if (m.kind === 'brush') {
      this.brushReplies.get(m.id)?.(m.vertices);
      this.brushReplies.delete(m.id);
      return;
    }
    if (m.kind === 'measures') {
      if (m.seq === this.lastDrawn || m.seq === this.pendingDraw) this.measures = m.measures;
      if (this.measuresAwaited !== null && m.seq >= this.measuresAwaited) this.measuresAwaited = null;
      return this.changed();
    }
    this.normalsBusy[m.slot] = false;
    const newer = m.slot === 'full' || !this.fullAfter(m.seq);
    // A frame of the mesh before (computed while another one was taken) is dropped.
    const current = m.slot !== 'full' || m.positions.length === this.rest.length;
    if (current && m.slot === 'full' && this.firstDraw === 'none') this.firstDraw = 'shown';
    if (current && m.slot === 'full') {
      this.viewer.setPositions(m.positions, m.normals, m.lookNormals);
    }
    else if (current && newer) this.viewer.showPreview(m.positions, m.normals);
    if (current) this.pendingDraw = Math.max(this.pendingDraw ?? 0, m.seq);
    const queued = this.normalsQueued[m.slot];
    this.normalsQueued[m.slot] = null;
    if (queued) this.computeFrame(m.slot, queued.seq, queued.scale, queued.displacements);
  }

  // Whether a full frame newer than `seq` is already shown or on its way.
  private fullAfter(seq: number): boolean {
    const f = this.normalsQueued.full;
    return (f !== null && f.seq > seq) || (!this.viewer.showingPreview && this.lastDrawn > seq);
  }

  private postPreview(p: P.PreviewMessage): void {
    const rest = new Float32Array(3 * p.vertices.length);
    p.vertices.forEach((v, i) => rest.set(this.rest.subarray(3 * v, 3 * v + 3), 3 * i));
    this.post({ kind: 'preview', indices: p.indices.slice(), rest });
  }

  private post(request: WorkerRequest): void {
    const buffers = request.kind === 'frame' ? [request.displacements.buffer] : [];
    this.worker.postMessage(request, buffers);
  }

  private onRendered(): void {
    if (stats.meshSeen === null && stats.meshStarted !== null && this.viewer.trianglesShown > 0) {
      stats.meshSeen = performance.now();
    }
    if (!this.wholeShown && this.viewer.whole) {
      this.wholeShown = true;
      stats.meshShown = performance.now();
    }
    if (this.firstDraw === 'shown' && this.viewer.shaded) {
      this.firstDraw = 'drawn';
      stats.meshDrawn = performance.now();
      this.previewFrom = this.viewer.draws;
    }
    if (this.pendingDraw === null) return;
    const t = this.sentAt.get(this.pendingDraw);
    const now = performance.now();
    if (t !== undefined) stats.latencies.push(now - t);
    for (const s of this.sentAt.keys()) if (s <= this.pendingDraw) this.sentAt.delete(s);
    stats.framesDrawn++;
    if (this.viewer.showingPreview) stats.previewsDrawn++;
    else stats.detailedDrawn = now;
    stats.drawTimes.push(now);
    if (stats.drawTimes.length > 2000) stats.drawTimes.splice(0, 1000);
    this.lastDrawn = this.pendingDraw;
    this.pendingDraw = null;
  }

  // Called as another mesh replaces the shown one (the interaction's part: interaction.ts).
  onAnotherMesh: () => void = () => {};
  // Called as the connection drops: ends what cannot go on without the server (a drag), naming
  // it, to be said on reconnection.
  onConnectionLost: () => string | null = () => null;
  private lostOnDisconnect: string | null = null;

  // The bytes of the mesh come so far, and of all of it, while it comes.
  get receiving(): { bytes: number; total: number } | null {
    const a = this.arrival;
    return a.mesh && !a.whole ? { bytes: a.bytes, total: a.totalBytes } : null;
  }

  // Fetches the mesh of a notice, unless it is the one fetched or on its way.
  private async fetchMesh(m: P.MeshNotice): Promise<void> {
    if ((await this.meshId) === m.id) return;
    const fetching = ++this.meshFetches;
    this.post({ kind: 'fetch', fetch: fetching, url: `/mesh/${m.id}` });
    return this.takeMesh(fetching, m);
  }

  // Takes the parts of a fetch (by number) as the worker reads them (the page's thread was held
  // reading them) and hands them on, a task at a time; a newer fetch drops it. The socket's other
  // messages wait meanwhile. Without a notice: the fetch of the latest mesh, from the page's start.
  private async takeMesh(fetching: number, m: P.MeshNotice | null): Promise<void> {
    this.waiting ??= [];
    let named = (_: string | null) => {};
    this.meshId = new Promise((resolve) => (named = resolve));
    this.meshReplies = [];
    this.meshReplied?.(); // an older fetch's wait ends
    try {
      let task = performance.now();
      for (let reply; (reply = await this.nextMeshReply(fetching));) {
        if (reply.kind === 'fetched') {
          named(reply.id);
          if (reply.error) throw new Error(reply.error);
          // Without a notice, none may be open yet; with one, another was opened since.
          if (m && reply.id === null) throw new Error('the server no longer has it');
          break;
        }
        await this.meshPart(reply.part);
        if (performance.now() - task > kTaskMs) {
          await nextTask();
          task = performance.now();
        }
      }
      if (fetching !== this.meshFetches) return;
    } catch (e) {
      named(null);
      if (fetching !== this.meshFetches) return;
      this.arrival.mesh = null;
      this.note(`the mesh did not arrive: ${e instanceof Error ? e.message : e}`, 'error');
    }
    const waiting = this.waiting ?? [];
    this.waiting = null;
    for (const handle of waiting) handle();
    this.changed();
  }
  private meshId: Promise<string | null> | null = null; // of the last fetch, once it answered
  private meshFetches = 1; // asked of the worker, the first by startWorker
  private meshReplies: MeshReply[] = []; // of the last fetch, not taken yet
  private meshReplied: (() => void) | undefined; // wakes the fetch waiting for them

  // The last fetch's next reply from the worker, once it came; null once a newer fetch began.
  private async nextMeshReply(fetching: number): Promise<MeshReply | null> {
    while (this.meshReplies.length === 0 && fetching === this.meshFetches) {
      await new Promise<void>((resolve) => (this.meshReplied = resolve));
    }
    return fetching === this.meshFetches ? this.meshReplies.shift()! : null;
  }

  // Takes a part; the last one's mesh is taken in a few tasks (the promise).
  private async meshPart(p: P.MeshPart): Promise<void> {
    if (p.kind === 'positions' && p.first === 0) {
      [stats.meshStarted, stats.meshSeen] = [performance.now(), null];
      this.arrivalShown = 3 * p.n !== this.rest.length || 3 * p.triangles !== this.indices.length;
    }
    const done = this.arrival.add(p);
    if (done) await nextTask(); // what follows takes a task of its own
    const { positions, indices, low, high } = this.arrival.mesh!;
    if (this.arrivalShown && p.kind === 'positions' && done) this.viewer.beginMesh(positions, indices, low, high);
    if (this.arrivalShown && p.kind === 'triangles') this.viewer.addTriangles(p.first, p.data.length / 3);
    if (done === 'mesh') {
      stats.meshReceived = performance.now();
      this.changed();
      return this.adoptMesh(this.arrival.mesh!, this.arrivalShown);
    }
    if (done) this.changed();
    else this.changedSoon();
  }

  // A whole mesh; `shown`: drawn as it came (beginMesh). Its arrays are the state's from here.
  // Taken in three tasks (a 692k mesh's passes held the page half a second): the state (with a
  // selection held for it) and the view, then the worker's mesh and the rest shape, then the
  // colours.
  private async adoptMesh(m: WholeMesh, shown: boolean): Promise<void> {
    const sameTriangles = m.indices.length === this.indices.length && m.indices.every((v, i) => v === this.indices[i]);
    const samePositions = sameTriangles && m.positions.every((v, i) => v === this.rest[i]);
    if (samePositions) return; // a reconnection: keep the view and what is shown
    this.rest = m.positions;
    const n = this.rest.length / 3;
    this.viewer.setMesh(this.rest, m.indices, sameTriangles, shown);
    if (!sameTriangles) {
      // Another mesh: the selection goes (the server says so too), the preview is measured again
      // once it is drawn. It is painted while its basis is computed. What belonged to the old one
      // on screen (the gizmo, the 3D cursor, a drag, an armed mode) goes with it.
      this.onAnotherMesh();
      this.indices = m.indices;
      this.labels = new Int16Array(n);
      this.groups = [{ transform: new THREE.Matrix4(), pinned: false }];
      this.activeGroup = 0;
      this.previewWanted = false;
      this.preview = null;
      this.drawMs = 0;
      this.preparing = true;
      this.selectionHeld = false;
      this.firstDraw = 'none';
      this.wholeShown = false;
      this.previewFrom = null;
      this.heldTime = 0; // another mesh: any held selection of it is newer than none
      this.heldKey = meshKey(this.rest, this.indices);
      this.selectionHeld = this.adoptHeld();
    }
    await nextTask();
    this.post({ kind: 'adopt' }); // the parts it was sent
    this.showRest();
    if (sameTriangles && this.preview) this.postPreview(this.preview); // another pose
    if (sameTriangles) return;
    await nextTask();
    this.diagonal = Math.hypot(...m.high.map((h, k) => h - m.low[k])) || 1;
    // A mesh shown as it came is drawn in the free colour, which its labels are (a held
    // selection painted itself): no pass over its vertices.
    if (!shown) this.paint();
  }

  // The selection held for this mesh in local storage (a reload, another window), if newer than
  // what is shown; returns whether there was one.
  private adoptHeld(): boolean {
    const held = loadHeld(this.heldKey, this.labels.length);
    if (!held || held.time <= this.heldTime) return held !== null;
    this.heldTime = held.time;
    this.labels = held.labels;
    this.groups = held.groups.map((g) => ({ transform: new THREE.Matrix4().fromArray(g.transform), pinned: g.pinned }));
    this.activeGroup = Math.min(this.activeGroup, this.groups.length - 1);
    this.paint();
    return true;
  }
  private heldTime = 0;

  private adoptReady(m: P.ReadyMessage): void {
    const previous = this.ready;
    const newMesh = !previous || previous.mesh_id !== m.mesh_id;
    if (!this.restoreChecked && previous && !newMesh &&
        (previous.modes !== m.modes || JSON.stringify(previous.settings) !== JSON.stringify(m.settings))) {
      this.restoreSettings = { type: 'settings', modes: previous.modes, ...previous.settings };
    }
    this.ready = m;
    this.preparing = false;
    if (previous?.settings.influence !== m.settings.influence) this.paint();
    if (m.basis.warning) this.note(m.basis.warning, 'error');
  }

  // A draw of the full mesh was timed (the viewer times them without waiting: the page keeps
  // painting). The new mesh's first decides whether drags show a preview that draws in about
  // kPreviewMs; it included the upload, so one between the budget and kUploadMs waits for the
  // next draw's time.
  private drawTimed(ms: number, draw: number): void {
    if (this.previewFrom === null) return;
    // An earlier draw's time: the viewer times one draw at a time, so the mesh's first was not.
    if (draw < this.previewFrom) return this.viewer.requestRender(true);
    if (draw === this.previewFrom && ms > kFullDrawBudgetMs && ms < kUploadMs) {
      this.previewFrom = draw + 1;
      return this.viewer.requestRender(true);
    }
    this.previewFrom = null;
    this.drawMs = ms;
    const n = this.rest.length / 3;
    const wanted = this.drawMs > kFullDrawBudgetMs && n >= kAlwaysWhole;
    const size = Math.round(Math.max(2000, Math.min(n / 3, (n * kPreviewMs) / this.drawMs)));
    this.previewWanted = wanted;
    if (wanted && this.viewer.previewSize !== size) this.previewRequest = { type: 'preview', vertices: size };
    if (!this.preparing) this.sendPreviewRequest();
    this.changed();
  }
  private previewFrom: number | null = null; // the new mesh's first draw, while its preview is chosen

  // The server sets the preview's deformer up (seconds at a million vertices) after the
  // selection painted while the mesh was prepared, not before it.
  // The server's state; a factoring of the transfer that begins now is timed from now (a
  // counter carried on from the last one said "35 s" 3 s in).
  private adoptServer(m: P.StateMessage): void {
    if (m.detail_pending && !this.server?.detail_pending) this.detailSince = performance.now();
    this.server = m;
  }

  private sendPreviewRequest(): void {
    if (this.previewRequest) this.connection.send(this.previewRequest);
    this.previewRequest = null;
  }
  private previewRequest: P.ClientText | null = null;

  private adoptSelection(s: P.Selection): void {
    const empty = s.groups.length === 0 && s.fixed.length === 0;
    if (this.selectionHeld && empty) return; // the new mesh's: what was painted meanwhile stays
    if (this.restorePending) {
      if (empty) return; // an earlier reply: the restored selection follows
      this.restorePending = false;
    }
    // A reply to a request sent before the selection on its way (the "hello" of a page that
    // painted while the basis was computed): that selection is newer.
    if (this.selectionsInFlight > 0) return;
    if (!this.restoreChecked && empty && this.labels.some((l) => l !== FREE)) {
      this.restoring = true; // decided on the "state" that follows
      return;
    }
    this.labels.fill(FREE);
    s.fixed.forEach((v) => (this.labels[v] = FIXED));
    s.groups.forEach((g, k) => g.vertices.forEach((v) => (this.labels[v] = 2 + k)));
    this.groups = s.groups.map((g) => ({ transform: fromRowMajor(g.transform), pinned: g.pinned }));
    if (this.groups.length === 0) this.groups = [{ transform: new THREE.Matrix4(), pinned: false }];
    this.activeGroup = Math.min(this.activeGroup, this.groups.length - 1);
    if (!this.hasHandles()) this.showRest();
    this.paint();
  }

  private selectionAnswered(): void {
    this.selectionsInFlight = Math.max(0, this.selectionsInFlight - 1);
    if (this.selectionWaiting && this.selectionsInFlight === 0) {
      this.selectionWaiting = false;
      this.sendSelection();
    }
  }

  private adoptState(m: P.StateMessage): void {
    if (STATE_REQUESTS.has(m.request)) this.awaitingStates = Math.max(0, this.awaitingStates - 1);
    if (m.request === 'selection') this.selectionAnswered();
    if (this.selectionHeld && !this.preparing) {
      this.selectionHeld = false;
      this.adoptHeld(); // another window's strokes since
      this.sendSelection();
      dropHeld(this.heldKey);
    }
    if (!this.preparing) this.sendPreviewRequest();
    if (!this.restoreChecked) {
      this.restoreChecked = true;
      const restarted = m.groups.length === 0 && m.fixed === 0 && !m.undo;
      const restoring = this.restoring;
      const settings = this.restoreSettings;
      this.restoring = false;
      this.restoreSettings = null;
      if (restarted && (restoring || settings)) {
        // The server restarted on the mesh this page has: it gets this page's edit back.
        this.adoptServer(m);
        if (settings) this.connection.send(settings);
        // Echoed: the replies to a hello sent before, with its empty selection, come first.
        if (restoring) {
          this.restorePending = true;
          this.sendSelection(new Set(), true);
        }
        this.note('the server restarted: your settings, selection and handles were restored');
        return;
      }
      if (restoring) this.adoptSelection({ groups: [], fixed: new Uint32Array(0) });
    }
    this.adoptServer(m);
    m.groups.forEach((g, k) => {
      if (!this.groups[k]) this.groups[k] = { transform: new THREE.Matrix4(), pinned: false };
      this.groups[k].pinned = g.pinned;
      if (g.pinned) this.groups[k].transform = fromRowMajor(g.transform);
    });
    if (m.pin_error > 0.002) {
      this.note(`the pinned region bends: it holds its place within ${(100 * m.pin_error).toFixed(2)}% ` +
        'of the diagonal (Apply pose holds it exactly)');
    }
  }

  // The mesh's edge graph, for selections by topology and the region of influence.
  graph(): Brush {
    if (this.topology?.indices !== this.indices) {
      this.topology = { indices: this.indices, brush: new Brush(this.labels.length, this.indices) };
    }
    return this.topology.brush;
  }
  private topology: { indices: Uint32Array; brush: Brush } | null = null;
  influenceHeld = 0; // free vertices the region of influence holds (as drawn)

  // Free vertices that the region of influence holds (the server's rule, for drawing): beyond
  // its radius from every handle vertex, along the edges; null when there is no region.
  private heldByInfluence(): Uint8Array | null {
    const radius = (this.ready?.settings.influence ?? 0) * this.diagonal;
    this.influenceHeld = 0;
    if (!(radius > 0)) return null;
    const handles: number[] = [];
    for (let v = 0; v < this.labels.length; ++v) if (this.labels[v] >= 2) handles.push(v);
    if (handles.length === 0) return null;
    const held = new Uint8Array(this.labels.length).fill(1);
    for (const v of this.graph().geodesic(this.rest, handles, radius)) held[v] = 0;
    this.labels.forEach((l, v) => l === FREE && held[v] && ++this.influenceHeld);
    return held;
  }

  // Colours from labels, for all vertices or the ones listed (all when a region of influence is
  // drawn: a stroke moves its border).
  paint(vertices?: ArrayLike<number>): void {
    const n = this.labels.length;
    const colors = this.viewer.colors;
    if (colors.length !== 3 * n) return; // the view has another mesh (one arriving)
    const held = this.heldByInfluence();
    if (held) vertices = undefined;
    // Each label's colour as the buffer holds it (0 free, 1 fixed, 2 + g group g), then the
    // held free vertices': no per-vertex object or rounding (the first paint covers 692k).
    // The table covers every group's label and those of the vertices painted (a stroke's
    // repaint reads only its own vertices' labels).
    const labels = this.labels;
    let top = this.groups.length + 1;
    if (vertices) for (let i = 0; i < vertices.length; ++i) top = Math.max(top, labels[vertices[i]]);
    else for (let v = 0; v < n; ++v) if (labels[v] > top) top = labels[v];
    const table = new Uint8Array(3 * (top + 2));
    for (let l = 0; l <= top; ++l) {
      const kind = this.kindOf(l);
      const c = kind === 'free' ? FREE_COLOR : kind === 'fixed' ? FIXED_COLOR
        : kind === 'pinned' ? PIN_COLOR : GROUP_COLORS[(l - 2) % GROUP_COLORS.length];
      table.set(colorBytes(c), 3 * l);
    }
    const heldAt = 3 * (top + 1);
    table.set(colorBytes(HELD_COLOR), heldAt);
    const changed: number[] = [];
    const count = vertices ? vertices.length : n;
    for (let i = 0; i < count; ++i) {
      const v = vertices ? vertices[i] : i;
      const k = labels[v] === FREE && held?.[v] ? heldAt : 3 * labels[v];
      if (colors[3 * v] === table[k] && colors[3 * v + 1] === table[k + 1] && colors[3 * v + 2] === table[k + 2]) continue;
      colors[3 * v] = table[k];
      colors[3 * v + 1] = table[k + 1];
      colors[3 * v + 2] = table[k + 2];
      changed.push(v);
    }
    // The same colours again (the selection as the server confirms it) redraw nothing: a draw
    // of a million triangles costs a second of CPU without a GPU.
    if (changed.length > 0) this.viewer.colorsChanged(vertices ? Uint32Array.from(changed).sort() : changed);
  }
}

export const GROUP_HEX = [0xf28e2b, 0x59a14f, 0xb07aa1, 0x76b7b2, 0xedc948, 0xe15759, 0x9c755f];
const GROUP_COLORS = GROUP_HEX.map((c) => new THREE.Color(c));
const FREE_COLOR = new THREE.Color(0xc9ccd3);
const FIXED_COLOR = new THREE.Color(0x4e79a7);
const HELD_COLOR = new THREE.Color(0x9a9aa3); // held by the region of influence: grey, darker than free
export const PIN_HEX = 0x1f3b63;
const PIN_COLOR = new THREE.Color(PIN_HEX);

export function rowMajor(m: THREE.Matrix4): P.Matrix {
  return m.clone().transpose().toArray();
}

export function fromRowMajor(a: P.Matrix): THREE.Matrix4 {
  return new THREE.Matrix4().fromArray(a).transpose();
}

// Requests answered with "state" (or "empty"), or with an error naming them.
const STATE_REQUESTS = new Set(['selection', 'commit', 'hello', 'undo', 'redo', 'apply_pose', 'open_demo',
  'mesh_file', 'selection_file', 'scene_file']);

type MeshReply = Extract<WorkerReply, { kind: 'part' | 'fetched' }>;

// The geometry worker, reading the latest mesh at once (fetch 1): its bytes come while the page
// makes its view (seconds without a GPU). The parts it reads go to the page and to `bvhParts`
// (held there until the picking BVH's worker takes them).
export interface StartedWorker {
  worker: Worker;
  bvhParts: MessagePort;
}

export function startWorker(): StartedWorker {
  const worker = new Worker(new URL('./geometry.worker.ts', import.meta.url), { type: 'module' });
  const channel = new MessageChannel();
  worker.postMessage({ kind: 'bvh', port: channel.port1 } satisfies WorkerRequest, [channel.port1]);
  worker.postMessage({ kind: 'fetch', fetch: 1, url: '/mesh/latest' } satisfies WorkerRequest);
  return { worker, bvhParts: channel.port2 };
}

function requestName(request: string): string {
  const names: Record<string, string> = {
    mesh_file: 'open mesh', selection_file: 'load selection', scene_file: 'open scene',
    open_demo: 'open the demo', apply_pose: 'apply pose', export_mesh: 'export mesh', export_scene: 'export scene',
    selection: 'selection', frame: 'drag', settings: 'settings', undo: 'undo', redo: 'redo', open: 'open',
  };
  return names[request] ?? request;
}
