// The pointer and the keyboard: painting with the brush, dragging handles (the mouse, the
// gizmo at the pivot, or Blender's modal G / R / S), the 3D cursor (Shift + right-click),
// orbiting only on the right button or with Alt, and the selection's shortcuts.
import * as THREE from 'three';
import { Brush } from './brush';
import { Point, corners, inPath, inRect, rectBetween, showRegion, verticesIn } from './boxselect';
import { showGuides } from './guides';
import { XMirror } from './mirror';
import { EditorState, FIXED, FREE, stats } from './state';
import { Mode, ModalTransform } from './transform';

export type Tool = 'handle' | 'fixed' | 'erase' | 'move' | 'pin';
// Rotations and scales turn about the active group's centroid (Blender's median point), the
// 3D cursor, or (G, R, S only) every movable group about its own centroid.
export type PivotMode = 'median' | 'cursor' | 'individual';

// How long the pointer rests before the full detail is asked for in place of the preview (ms):
// this, or twice the full mesh's draw when that is longer (a draw that holds the next moves back
// is not asked for between them).
const kRestMs = 200;

// How long a missed press's note stays at the pointer (ms).
const kPointerNoteMs = 1500;

interface Region {
  armed: boolean; // the next left drag draws it
  lasso: boolean;
  hide: boolean; // hides what it holds instead of selecting it (H)
  path: Point[];
}

interface Drag {
  group: number;
  start: THREE.Vector3; // the handle point grabbed (mouse), the gizmo's start or the pivot (G, R, S)
  transform: THREE.Matrix4; // the group's at the start
  pivot?: THREE.Matrix4; // the gizmo's at the start
  modal?: ModalTransform; // G, R or S from the keyboard
  others?: { group: number; transform: THREE.Matrix4; modal: ModalTransform }[]; // individual pivots
}

export class Interaction {
  tool: Tool = 'handle';
  paintTool: Tool = 'handle'; // the last tool that paints: Tab goes back to it from Move
  emulate3 = false; // Alt + left acts as the middle button (Blender's Emulate 3 Button Mouse)
  onToolChange: () => void = () => {};
  // The stroke being painted; one ended while its last brush query was out is `finishing`
  // (sent when the query is in) and no longer this.
  private stroke: Stroke | null = null;
  private brushing = false; // a brush query in flight
  private drag: Drag | null = null;
  private restTimer: number | undefined;
  private usedPreview = false;
  private pointer = { x: 0, y: 0 }; // the last position over the view
  private cursorPress: { x: number; y: number } | null = null; // a Shift + right press
  pivotMode: PivotMode = 'median';
  cursor: THREE.Vector3 | null = null; // the 3D cursor
  readonly xMirror = new XMirror();
  // B arms a box (drawn with the left button), H a box that hides; Ctrl + right-drag draws a lasso.
  private region: Region = { armed: false, lasso: false, hide: false, path: [] };
  xray = false; // box and lasso select through the surface
  private linkedArmed = false; // the Linked button: the next click picks the piece

  constructor(private readonly s: EditorState, private readonly view: HTMLElement) {
    const v = s.viewer;
    s.onAnotherMesh = () => this.forgetMesh();
    s.onConnectionLost = () => {
      if (!this.drag) return null;
      const mode = this.drag.modal?.mode;
      const what = mode ? `the ${mode === 'grab' ? 'move' : mode === 'rotate' ? 'turn' : 'scale'} (${mode[0].toUpperCase()})` : 'the drag';
      this.endDrag(false);
      return what;
    };
    // Capture phase: decides before the orbit controls what a press does.
    view.addEventListener('pointerdown', (e) => this.down(e), true);
    view.addEventListener('pointermove', (e) => this.move(e));
    view.addEventListener('pointerup', (e) => this.up(e));
    view.addEventListener('pointercancel', (e) => this.up(e));
    view.addEventListener('pointerleave', () => v.showBrush(null, 0));
    // The wheel during a drag or a modal transform changes the region of influence (when there
    // is one) instead of zooming, as Blender's proportional editing radius.
    view.addEventListener('wheel', (e) => this.wheel(e), { capture: true, passive: false });
    v.gizmo.addEventListener('dragging-changed', (e) => {
      if (e.value) this.beginGizmo();
      else this.endDrag(true);
    });
    v.gizmo.addEventListener('objectChange', () => this.gizmoMoved());
  }

  private wheel(e: WheelEvent): void {
    const influence = this.s.ready?.settings.influence ?? 0;
    if (!this.drag || !(influence > 0)) return;
    e.preventDefault();
    e.stopImmediatePropagation();
    const next = Math.min(10, Math.max(0.005, influence * (e.deltaY < 0 ? 1.15 : 1 / 1.15)));
    this.s.request({ type: 'settings', influence: next }, 'settings', 'ready');
    const region = `region of influence ${(100 * next).toFixed(1)}% of the diagonal`;
    this.influence = next; // the circle follows at once, before the server's answer
    this.showGuides();
    const modal = this.drag.modal;
    this.showHeader(modal ? `${modal.readout(this.pointer)} · ${region}` : region);
  }

  get radius(): number {
    const percent = Number((document.getElementById('radius') as HTMLInputElement).value);
    return (percent / 100) * this.s.diagonal;
  }

  private get geodesic(): boolean {
    return (document.getElementById('geodesic') as HTMLInputElement).checked;
  }

  setTool(t: Tool): void {
    this.disarm(`the ${t} tool`);
    if (t !== 'move') this.paintTool = t;
    this.tool = t;
    if (t !== 'move') this.s.viewer.gizmo.detach();
    this.placeGizmo();
    this.s.viewer.showBrush(null, 0);
    this.onToolChange();
  }

  // ------------------------------------------------------------ pointer

  private down(e: PointerEvent): void {
    const v = this.s.viewer;
    if (this.drag?.modal) {
      // A modal transform: the left button confirms, the others cancel; nothing orbits.
      e.stopPropagation();
      e.preventDefault();
      if (e.button === 0) this.endDrag(true);
      else this.cancel();
      return;
    }
    if (e.button === 2 && e.shiftKey) this.cursorPress = { x: e.clientX, y: e.clientY };
    if (this.linkedArmed && e.button === 0 && e.target === v.canvas) {
      e.stopPropagation();
      this.linkedArmed = false;
      this.showHeader('');
      this.pointer = { x: e.clientX, y: e.clientY };
      return this.selectTopology('linked');
    }
    const lasso = e.button === 2 && e.ctrlKey && this.s.paintable;
    if (e.target === v.canvas && ((this.region.armed && e.button === 0) || lasso)) {
      e.stopPropagation();
      this.region = { ...this.region, armed: true, lasso, hide: this.region.hide && !lasso, path: [{ x: e.clientX, y: e.clientY }] };
      this.view.setPointerCapture(e.pointerId);
      return;
    }
    // The view's buttons (Viewer.setNavigation); as Blender, Ctrl + middle zooms.
    const blender = v.navigation === 'blender';
    const orbit = blender && e.ctrlKey ? THREE.MOUSE.DOLLY : THREE.MOUSE.ROTATE;
    if (blender && e.button === 1) v.orbit.mouseButtons.MIDDLE = orbit;
    // Only presses on the model's canvas: not on what lies over it (messages, dialogs).
    if (e.button !== 0 || e.target !== v.canvas) return;
    const viewButton = e.altKey && (!blender || this.emulate3); // Alt + left: orbit (pan, zoom)
    v.orbit.mouseButtons.LEFT = viewButton ? orbit : null;
    if (viewButton || this.gizmoTakes()) return; // the view, or the gizmo's own drag
    e.stopPropagation();
    if (!(this.tool === 'move' ? this.s.editable : this.s.paintable)) {
      this.s.note(this.s.phase.kind === 'disconnected' ? 'not connected: the edit waits for the server'
        : this.s.paintable ? 'the basis is being computed: paint handles and fixed parts now, drag when it is ready'
          : 'the server is busy: wait for it to finish');
      return;
    }
    const hit = v.pick(e.clientX, e.clientY);
    if (this.tool === 'move') {
      const l = hit ? this.s.labels[hit.vertex] : FREE;
      if (!hit || l < 2 || this.s.groups[l - 2].pinned) {
        this.missed(hit ? 'press on a coloured handle to drag it, or use the gizmo'
          : this.nearGizmo(e.clientX, e.clientY) ? 'missed the gizmo: press on one of its arrows, rings or boxes (or use G, R, S)'
            : 'missed the model: press on a handle', e);
        return;
      }
      this.s.activeGroup = l - 2;
      this.drag = { group: l - 2, start: hit.point, transform: this.s.groups[l - 2].transform.clone() };
      this.usedPreview = false;
      this.s.changed();
    } else {
      if (!hit) {
        const orbit = this.s.viewer.navigation === 'blender' ? 'middle-drag orbits' : 'right-drag or Alt+drag orbits';
        this.missed(`missed the model: a stroke starts on the surface (${orbit})`, e);
        return;
      }
      let pin: number | null = null;
      let label = this.tool === 'handle' ? 2 + this.s.activeGroup : this.tool === 'fixed' ? FIXED : FREE;
      if (this.tool === 'pin') {
        pin = this.newGroup(true);
        label = 2 + pin;
      } else if (this.tool === 'handle' && this.s.groups[this.s.activeGroup].pinned) {
        this.s.activeGroup = this.newGroup(false);
        label = 2 + this.s.activeGroup;
      }
      this.stroke = { before: this.s.labels.slice(), touched: new Set(), label, pin, unpaired: 0 };
      this.s.painting = true;
      this.paintAt(e.clientX, e.clientY);
    }
    v.orbit.enabled = false;
    this.view.setPointerCapture(e.pointerId);
  }

  // Pointer moves coalesce: the latest position is acted on once per animation frame, so that
  // no event waits for a draw (a large mesh takes hundreds of milliseconds to draw without a GPU).
  private move(e: PointerEvent): void {
    this.pointer = { x: e.clientX, y: e.clientY };
    const r = this.region;
    if (r.lasso && r.path.length > 0) r.path.push({ ...this.pointer }); // every point of the lasso
    this.moveButtons = e.buttons;
    stats.pointerMoves++;
    if (this.moveQueued) return;
    this.moveQueued = true;
    requestAnimationFrame(() => this.flushMove());
  }
  private moveQueued = false;
  private moveButtons = 0;

  // The last pointer move, if one waits (before a release acts on where the pointer is).
  private flushMove(): void {
    if (!this.moveQueued) return;
    this.moveQueued = false;
    stats.pointerActed++;
    const v = this.s.viewer;
    const { x, y } = this.pointer;
    if (this.drag?.modal) return this.modalMoved();
    const r = this.region;
    if (r.path.length > 0) return showRegion(this.view, r.lasso ? r.path : corners(rectBetween(r.path[0], this.pointer)));
    if (this.stroke) return this.paintAt(x, y);
    if (this.drag && !this.drag.pivot) {
      const p = v.onViewPlane(x, y, this.drag.start);
      if (!p) return;
      const d = p.sub(this.drag.start);
      this.s.groups[this.drag.group].transform = new THREE.Matrix4().makeTranslation(d.x, d.y, d.z).multiply(this.drag.transform);
      this.dragged();
      return;
    }
    if (this.tool !== 'move' && this.moveButtons === 0) this.hover(x, y);
  }

  private up(e: PointerEvent): void {
    this.flushMove();
    const press = this.cursorPress;
    this.cursorPress = null;
    if (press && e.button === 2 && Math.hypot(e.clientX - press.x, e.clientY - press.y) < 5) this.placeCursor(e.clientX, e.clientY);
    if (this.drag?.modal) return;
    const r = this.region;
    if (r.path.length > 0 && e.button === (r.lasso ? 2 : 0)) {
      this.endRegion(r.lasso ? inPath(r.path) : inRect(rectBetween(r.path[0], { x: e.clientX, y: e.clientY })));
      return;
    }
    this.s.viewer.orbit.enabled = true;
    this.s.viewer.orbit.mouseButtons.LEFT = null;
    if (this.stroke) this.endStroke(true);
    if (this.drag && !this.drag.pivot) this.endDrag(true);
  }

  // The brush circle follows the pointer.
  private hover(x: number, y: number): void {
    this.s.viewer.showBrush(this.s.paintable ? this.s.viewer.pick(x, y) : null, this.radius);
  }

  // ------------------------------------------------------------ painting

  // One brush query is out at a time; the latest point of each stroke waits for it.
  private paintAt(x: number, y: number, stroke: Stroke | null = this.stroke): void {
    if (this.brushing) {
      if (stroke) this.waiting = [...this.waiting.filter((w) => w.stroke !== stroke), { x, y, stroke }];
      return;
    }
    const hit = this.s.viewer.pick(x, y);
    this.s.viewer.showBrush(hit, this.radius);
    if (!stroke) return;
    if (!hit) return this.brushDone(stroke);
    this.brushing = true;
    this.s.brush(hit.vertex, hit.point, this.radius, this.geodesic).then((vertices) => {
      this.brushing = false;
      // Painted into the stroke that asked, which may have ended and another begun meanwhile.
      const labels = this.s.labels;
      const changed: number[] = [];
      const { pairs, unpaired } = this.xMirror.on && stroke.pin === null && !stroke.cancelled
        ? this.xMirror.paired(this.s, vertices, stroke.label) : { pairs: [], unpaired: 0 };
      stroke.unpaired += unpaired;
      const hidden = this.s.viewer.hidden;
      for (const [v, label] of stroke.cancelled ? [] : [...Array.from(vertices, (v) => [v, stroke.label]), ...pairs]) {
        // A pin stroke claims free, fixed and handle vertices; other tools leave pins alone
        // except Erase. Hidden vertices keep their labels.
        if (hidden?.[v]) continue;
        const l = labels[v];
        const isPin = l >= 2 && this.s.groups[l - 2]?.pinned;
        if (isPin && label !== FREE && l !== label) continue;
        if (l !== label) {
          labels[v] = label;
          changed.push(v);
          stroke.touched.add(v);
        }
      }
      this.s.paint(changed);
      this.brushDone(stroke);
    });
  }
  private waiting: { x: number; y: number; stroke: Stroke }[] = [];

  // A brush query of `stroke` is in: the stroke is sent if it ended and has none waiting, and
  // the next waiting point is painted.
  private brushDone(stroke: Stroke): void {
    if (stroke.finishing && !this.waiting.some((w) => w.stroke === stroke)) this.finishStroke(stroke);
    const next = this.waiting.shift();
    if (next) this.paintAt(next.x, next.y, next.stroke);
  }

  // `keep`: send the stroke to the server (an undo step), once its brush queries are in;
  // otherwise restore what it painted.
  private endStroke(keep: boolean): void {
    const stroke = this.stroke;
    if (!stroke) return;
    this.stroke = null;
    if (keep && this.brushing) {
      stroke.finishing = true;
      return;
    }
    if (keep) return this.finishStroke(stroke);
    stroke.cancelled = true;
    this.waiting = this.waiting.filter((w) => w.stroke !== stroke);
    for (const v of stroke.touched) this.s.labels[v] = stroke.before[v];
    this.s.paint([...stroke.touched]);
    if (stroke.pin !== null) this.dropEmptyGroup(stroke.pin);
    this.s.painting = this.waiting.length > 0 || this.brushing;
    this.s.changed();
  }

  private finishStroke(stroke: Stroke): void {
    this.s.painting = this.stroke !== null || this.waiting.length > 0;
    if (stroke.touched.size === 0) {
      if (stroke.pin !== null) this.dropEmptyGroup(stroke.pin);
      return this.s.changed();
    }
    this.s.sendSelection(stroke.pin !== null ? new Set([stroke.pin]) : new Set());
    this.noteUnpaired(stroke.unpaired);
    if (stroke.label >= 2 && stroke.pin === null && this.oneSided(stroke.label)) {
      this.s.note('the handle covers only the side facing you: its centre is on the surface, not in the part, so turns ' +
        'and scales shift it. Paint through with X-ray (Alt+Z, then B for a box), or orbit and paint around');
    }
    this.s.changed();
  }

  // Whether the vertices labelled `label` (nearly all) face the camera while as many again face
  // away right behind them (across the view, within their reach; along it, within 30% of the
  // diagonal): one side of a thin part.
  private oneSided(label: number): boolean {
    const v = this.s.viewer;
    const p = v.positions();
    const nrm = v.normals();
    const d = v.camera.getWorldDirection(new THREE.Vector3());
    const facing = (k: number) => nrm[3 * k] * d.x + nrm[3 * k + 1] * d.y + nrm[3 * k + 2] * d.z;
    const members: number[] = [];
    this.s.labels.forEach((l, k) => l === label && members.push(k));
    if (members.length === 0 || members.filter((k) => facing(k) > 0.1).length > 0.1 * members.length) return false;
    const c = new THREE.Vector3();
    for (const k of members) c.add(new THREE.Vector3().fromArray(p, 3 * k));
    c.divideScalar(members.length);
    const q = new THREE.Vector3();
    const offset = (k: number) => {
      q.fromArray(p, 3 * k).sub(c);
      const along = q.dot(d);
      return { along, across: q.addScaledVector(d, -along).length() };
    };
    const reach = Math.max(...members.map((k) => offset(k).across));
    let behind = 0;
    this.s.labels.forEach((l, k) => {
      if (l === label || facing(k) < 0.3) return;
      const o = offset(k);
      if (o.across < reach && o.along > 0 && o.along < 0.3 * this.s.diagonal) ++behind;
    });
    return behind > 0.5 * members.length;
  }

  // A new handle group (a pin: held where it is shown); returns its index.
  newGroup(pinned: boolean): number {
    const groups = this.s.groups;
    // An unused, unpinned group is reused.
    const used = new Set<number>();
    this.s.labels.forEach((l) => l >= 2 && used.add(l - 2));
    let g = groups.findIndex((x, k) => !used.has(k) && !x.pinned && k !== this.s.activeGroup);
    if (g < 0 || pinned) {
      groups.push({ transform: new THREE.Matrix4(), pinned });
      g = groups.length - 1;
    }
    if (!pinned) this.s.activeGroup = g;
    this.s.changed();
    return g;
  }

  private dropEmptyGroup(g: number): void {
    if (g === this.s.groups.length - 1 && !this.s.labels.some((l) => l === 2 + g)) this.s.groups.pop();
  }

  // ------------------------------------------------------------ dragging

  private dragged(): void {
    if (this.drag) this.xMirror.follow(this.s, this.drag.group);
    this.showGuides();
    const preview = this.s.previewWanted;
    this.usedPreview ||= preview;
    this.s.sendFrame(preview);
    clearTimeout(this.restTimer);
    // The pointer rests: the full detail, the preview again on the next move.
    const rest = Math.max(kRestMs, 2 * this.s.viewer.drawMs);
    if (preview) this.restTimer = window.setTimeout(() => this.s.sendFrame(false), rest);
  }

  private beginGizmo(): void {
    const g = this.s.activeGroup;
    this.s.viewer.pivot.updateMatrix();
    this.drag = { group: g, start: this.s.viewer.pivot.position.clone(), transform: this.s.groups[g].transform.clone(),
      pivot: this.s.viewer.pivot.matrix.clone() };
    this.usedPreview = false;
  }

  private gizmoMoved(): void {
    const d = this.drag;
    if (!d?.pivot) return;
    const v = this.s.viewer;
    v.pivot.updateMatrix();
    // The group moves as the gizmo does relative to where it started.
    const delta = v.pivot.matrix.clone().multiply(d.pivot.clone().invert());
    this.s.groups[d.group].transform = delta.multiply(d.transform);
    this.dragged();
  }

  // `keep`: an undo step; otherwise the group goes back to where the drag started.
  private endDrag(keep: boolean): void {
    const d = this.drag;
    if (!d) return;
    this.drag = null;
    clearTimeout(this.restTimer);
    if (d.modal) {
      this.showHeader('');
      this.s.viewer.orbit.enabled = true;
    }
    if (!keep) {
      this.s.groups[d.group].transform = d.transform;
      for (const o of d.others ?? []) this.s.groups[o.group].transform = o.transform;
    }
    this.xMirror.follow(this.s, d.group);
    this.influence = null;
    this.showGuides();
    if (this.usedPreview || !keep) this.s.sendFrame(false);
    if (keep) this.s.commit();
    this.placeGizmo();
    this.s.changed();
  }

  // The pivot's mark, with a dashed line to the pointer while turning or scaling, and the region
  // of influence's circle, during a move.
  private influence: number | null = null; // the region's radius asked for with the wheel
  private showGuides(): void {
    const d = this.drag;
    const influence = (this.influence ?? this.s.ready?.settings.influence ?? 0) * this.s.diagonal;
    const turning = d?.modal && d.modal.mode !== 'grab';
    const pivot = d ? (d.modal ? d.start : this.pivotPoint()) : null;
    showGuides(this.s.viewer, this.view, d && pivot && (turning || influence > 0)
      ? { pivot, pointer: turning ? this.pointer : null, influence } : null);
  }

  // The active group's centroid at rest (null if it has no vertices).
  private restCentroid(g: number): THREE.Vector3 | null {
    const rest = this.s.rest;
    const c = new THREE.Vector3();
    let count = 0;
    this.s.labels.forEach((l, k) => {
      if (l !== 2 + g) return;
      c.x += rest[3 * k];
      c.y += rest[3 * k + 1];
      c.z += rest[3 * k + 2];
      ++count;
    });
    return count > 0 ? c.divideScalar(count) : null;
  }

  // Where the active group turns and scales about: its centroid where its transform takes it,
  // or the 3D cursor.
  pivotPoint(): THREE.Vector3 | null {
    const g = this.s.activeGroup;
    const c = this.restCentroid(g);
    if (!c) return null;
    return this.pivotMode === 'cursor' && this.cursor ? this.cursor.clone() : c.applyMatrix4(this.s.groups[g].transform);
  }

  // The gizmo sits at the pivot (the Move tool, a movable active group). The view stays where it
  // is (F or numpad . frames the group): it moves only when asked.
  placeGizmo(): void {
    const v = this.s.viewer;
    const group = this.s.groups[this.s.activeGroup];
    const at = this.tool === 'move' && group && !group.pinned && this.s.editable && !this.drag?.modal ? this.pivotPoint() : null;
    if (!at) {
      v.gizmo.detach();
      v.requestRender();
      return;
    }
    if (this.drag?.pivot) return; // the gizmo moves itself while dragged
    v.pivot.position.copy(at);
    v.pivot.quaternion.identity();
    v.pivot.scale.set(1, 1, 1);
    v.pivot.updateMatrix();
    v.gizmo.attach(v.pivot);
    v.requestRender();
  }

  // Whether a press goes to the gizmo: one of its parts is under the pointer, but not an arrow
  // pointing nearly along the view (its picker then covers the handle around the pivot: a
  // press there moves the handle in the view plane).
  private gizmoTakes(): boolean {
    const v = this.s.viewer;
    const axis = v.gizmo.axis;
    if (axis === null) return false;
    const k = ['X', 'Y', 'Z'].indexOf(axis);
    if (k < 0 || v.gizmo.mode !== 'translate') return true;
    const view = v.camera.getWorldDirection(new THREE.Vector3());
    return Math.abs(view.getComponent(k)) < 0.8;
  }

  private nearGizmo(x: number, y: number): boolean {
    const v = this.s.viewer;
    if (!v.gizmo.object) return false;
    const c = v.toScreen(v.pivot.position);
    return Math.hypot(x - c.x, y - c.y) < 140;
  }

  // Another mesh is shown: nothing of the old one stays on screen (a drag, a stroke, an armed
  // mode, the gizmo at its handle, the 3D cursor on its surface).
  private forgetMesh(): void {
    if (this.drag) this.endDrag(false);
    if (this.stroke) this.endStroke(false);
    this.endRegion(null);
    this.linkedArmed = false;
    this.showHeader('');
    this.cursor = null;
    this.s.viewer.showCursor(null);
    this.s.viewer.gizmo.detach();
    this.s.viewer.requestRender();
  }

  // Shift + right-click on the surface: the 3D cursor goes there.
  private placeCursor(x: number, y: number): void {
    const hit = this.s.viewer.pick(x, y);
    if (!hit) return this.missed('missed the model: the 3D cursor goes on the surface', { clientX: x, clientY: y });
    this.cursor = hit.point;
    this.s.viewer.showCursor(hit.point);
    this.placeGizmo();
  }

  // ------------------------------------------------------------ modal transforms

  // G, R or S: the active group follows the pointer (or a typed value) until confirmed.
  startModal(mode: Mode): void {
    const s = this.s;
    const g = s.activeGroup;
    const group = s.groups[g];
    const pivot = this.pivotPoint();
    if (!s.editable || this.stroke || this.drag || !group || group.pinned || !pivot) {
      if (s.editable && !this.stroke && !this.drag) s.note('paint a handle first: G, R and S move the active handle group');
      return;
    }
    const diagonal = s.ready?.diagonal ?? 1;
    const step = 10 ** Math.floor(Math.log10(diagonal / 20)); // Ctrl snaps a move to this
    const modalOf = (k: number, at: THREE.Vector3) =>
      new ModalTransform(mode, at, s.groups[k].transform.clone(), { ...this.pointer }, s.viewer, step);
    const others = this.pivotMode !== 'individual' ? [] : s.groups.flatMap((x, k) => {
      const c = k !== g && !x.pinned ? this.restCentroid(k) : null;
      return c ? [{ group: k, transform: x.transform.clone(), modal: modalOf(k, c.applyMatrix4(x.transform)) }] : [];
    });
    this.drag = { group: g, start: pivot, transform: group.transform.clone(), modal: modalOf(g, pivot), others };
    this.usedPreview = false;
    s.viewer.gizmo.detach();
    s.viewer.orbit.enabled = false;
    this.modalMoved();
  }

  // A key during a modal transform; returns whether it was one of its keys.
  modalKey(e: KeyboardEvent): boolean {
    const modal = this.drag?.modal;
    if (!modal) return false;
    const axis = ['KeyX', 'KeyY', 'KeyZ'].indexOf(e.code);
    if (e.key === 'Enter' || e.key === 'NumpadEnter') this.endDrag(true);
    else if (e.key === 'Escape') this.cancel();
    else if (axis >= 0) modal.setAxis(axis, e.shiftKey);
    else if (e.key === 'Control') modal.snap = true;
    else if (!modal.type(e.key)) return false;
    if (this.drag?.modal) this.modalMoved();
    return true;
  }

  modalKeyUp(e: KeyboardEvent): void {
    const modal = this.drag?.modal;
    if (modal && e.key === 'Control') {
      modal.snap = false;
      this.modalMoved();
    }
  }

  private modalMoved(): void {
    const d = this.drag!;
    const m = d.modal!;
    this.s.groups[d.group].transform = m.matrix(this.pointer);
    for (const o of d.others ?? []) {
      // The same axis, value and snapping, each about its own centroid and along its own axes.
      Object.assign(o.modal, { lock: m.lock && { ...m.lock }, typed: m.typed, snap: m.snap });
      this.s.groups[o.group].transform = o.modal.matrix(this.pointer);
    }
    this.showHeader(d.modal!.readout(this.pointer));
    this.dragged();
  }

  // A press that found nothing to act on: said at the pointer (for a moment) and in the messages.
  private missed(text: string, at: { clientX: number; clientY: number }): void {
    this.s.note(text);
    const tip = document.getElementById('pointer-note')!;
    const view = this.view.getBoundingClientRect();
    tip.textContent = text.split(':')[0];
    tip.style.left = `${at.clientX - view.left + 14}px`;
    tip.style.top = `${at.clientY - view.top + 14}px`;
    tip.hidden = false;
    clearTimeout(this.tipTimer);
    this.tipTimer = window.setTimeout(() => (tip.hidden = true), kPointerNoteMs);
  }
  private tipTimer: number | undefined;

  private showHeader(text: string): void {
    const header = document.getElementById('header')!;
    header.textContent = text;
    header.hidden = text === '';
  }

  // ------------------------------------------------------------ selection by topology

  private get graph(): Brush {
    return this.s.graph();
  }

  // The Linked button: the next left click selects the piece under it (L does it at once).
  armLinked(): void {
    if (!this.s.paintable || this.stroke || this.drag) return;
    this.linkedArmed = true;
    this.showHeader('Select linked: click the piece to select; Esc cancels');
  }

  // B: the next left drag draws a rectangle; its vertices get the tool's label.
  armBox(): void {
    if (!this.s.paintable || this.stroke || this.drag) return;
    this.region = { armed: true, lasso: false, hide: false, path: [] };
    this.showHeader(`Box select (${this.xray ? 'X-ray: through the surface' : 'visible vertices only'}): ` +
      'drag a rectangle with the left button; Esc cancels');
  }

  // H: the next left drag draws a rectangle; its vertices (those seen, or with X-ray all) and
  // their triangles are hidden, to paint what is behind them. Alt+H reveals them.
  armHide(): void {
    if (!this.s.ready || this.stroke || this.drag) return;
    this.region = { armed: true, lasso: false, hide: true, path: [] };
    this.showHeader(`Hide (${this.xray ? 'X-ray: through the surface' : 'visible vertices only'}): ` +
      'drag a rectangle over what to hide; Esc cancels; Alt+H reveals');
  }

  // Shift+H, Blender's hide unselected: every vertex without a label (and its triangles) hidden,
  // to see and paint among the labelled parts. Alt+H reveals them.
  hideUnselected(): void {
    if (!this.s.ready || this.stroke || this.drag) return;
    const free: number[] = [];
    this.s.labels.forEach((l, v) => l === FREE && free.push(v));
    if (free.length === this.s.labels.length) {
      return this.s.note('nothing is labelled: Shift+H hides what is not (paint a handle or a fixed part first)');
    }
    if (free.length === 0) return this.s.note('every vertex is labelled: nothing to hide');
    const total = this.s.viewer.setHidden(free);
    this.s.note(`${free.length.toLocaleString()} unlabelled vertices hidden (${total.toLocaleString()} in all; Alt+H reveals them)`);
    this.s.changed();
  }

  // Whether a one-click mode (box select, hide, select linked) waits for its click or drag.
  get armed(): boolean {
    return this.region.armed || this.linkedArmed;
  }

  // Ends an armed one-click mode because of `by` (a key, another tool), saying so.
  disarm(by: string): void {
    if (!this.armed) return;
    const what = this.linkedArmed ? 'select linked' : this.region.hide ? 'hide' : 'box select';
    this.cancel();
    this.s.note(`${what} disarmed by ${by}`);
  }

  reveal(): void {
    const v = this.s.viewer;
    if (v.hiddenCount === 0) return this.s.note('nothing is hidden');
    const count = v.hiddenCount;
    v.setHidden(null, true);
    this.s.note(`${count.toLocaleString()} hidden vertices shown again`);
    this.s.changed();
  }

  // Ends the box or lasso, selecting what `contains` (null: cancelled); returns whether one was on.
  private endRegion(contains: ((x: number, y: number) => boolean) | null): boolean {
    if (!this.region.armed) return false;
    const hide = this.region.hide;
    this.region = { armed: false, lasso: false, hide: false, path: [] };
    showRegion(this.view, null);
    this.showHeader('');
    if (!contains) return true;
    if (hide) {
      const vertices = verticesIn(this.s.viewer, contains, this.xray, this.s.diagonal);
      if (vertices.length === 0) {
        this.s.note('no vertex in the rectangle: nothing hidden');
        return true;
      }
      const total = this.s.viewer.setHidden(vertices);
      this.s.note(`${vertices.length.toLocaleString()} vertices hidden (${total.toLocaleString()} in all; Alt+H reveals them)`);
      this.s.changed();
      return true;
    }
    const label = this.toolLabel();
    if (label === null) {
      this.s.note('Pin paints one pinned region per stroke: pick Handle, Fixed or Erase');
      return true;
    }
    this.relabel(verticesIn(this.s.viewer, contains, this.xray, this.s.diagonal), () => label);
    return true;
  }

  // The label the current tool paints (null for Pin: pins are painted stroke by stroke).
  private toolLabel(): number | null {
    if (this.tool === 'pin') return null;
    if (this.tool === 'fixed') return FIXED;
    if (this.tool === 'erase') return FREE;
    if (this.s.groups[this.s.activeGroup].pinned) this.s.activeGroup = this.newGroup(false);
    return 2 + this.s.activeGroup;
  }

  // L: the piece under the pointer; invert: the tool's label and the free vertices swap;
  // grow / shrink: by one ring of neighbours; all / none (A, Alt+A): every vertex gets the tool's
  // label / the tool's label is cleared. One undo step each.
  selectTopology(op: 'linked' | 'invert' | 'grow' | 'shrink' | 'all' | 'none'): void {
    const s = this.s;
    if (!s.paintable || this.stroke || this.drag) return;
    const label = this.toolLabel();
    if (label === null) return s.note('Pin paints one pinned region per stroke: pick Handle, Fixed or Erase');
    const labels = s.labels;
    let targets: number[];
    if (op === 'linked') {
      const hit = s.viewer.pick(this.pointer.x, this.pointer.y);
      if (!hit) return this.missed('missed the model: L selects the piece under the pointer', { clientX: this.pointer.x, clientY: this.pointer.y });
      targets = Array.from(this.graph.linked(hit.vertex), (v) => v);
    } else if (op === 'all') {
      targets = Array.from(labels.keys());
    } else if (op === 'none') {
      if (label === FREE) return s.note('Alt+A clears the tool\'s label: pick Handle or Fixed');
      targets = [];
      labels.forEach((l, v) => l === label && targets.push(v));
    } else if (op === 'invert') {
      if (label === FREE) return s.note('invert swaps the tool\'s label with the free vertices: pick Handle or Fixed');
      targets = [];
      labels.forEach((l, v) => (l === label || l === FREE) && targets.push(v));
    } else {
      const inside = (v: number) => labels[v] === label;
      targets = this.graph.ring(inside, op === 'grow');
    }
    const freed = op === 'shrink' || op === 'none';
    // All, none and invert treat both sides alike already: X mirror has nothing to add.
    const mirror = op === 'linked' || op === 'grow' || op === 'shrink';
    this.relabel(targets, (l) => (op === 'invert' ? (l === label ? FREE : label) : freed ? FREE : label), mirror);
  }

  // Gives each of `targets` its new label (pins stay unless erased), and with X mirror (`mirror`)
  // each counterpart outside the targets the mirror of it: one undo step.
  private relabel(targets: number[], next: (label: number) => number, mirror = true): void {
    const s = this.s;
    const labels = s.labels;
    const changed: number[] = [];
    const hidden = s.viewer.hidden;
    const set = (v: number, to: number) => {
      if (hidden?.[v]) return; // as Blender: hidden vertices are not selected
      const l = labels[v];
      if (l >= 2 && s.groups[l - 2]?.pinned && to !== FREE) return;
      if (l !== to) {
        labels[v] = to;
        changed.push(v);
      }
    };
    for (const v of targets) set(v, next(labels[v]));
    if (mirror && this.xMirror.on) {
      // Each changed vertex's counterpart takes the mirror of its new label.
      const chosen = new Set(targets);
      const byLabel = new Map<number, number[]>();
      for (const v of changed) {
        const list = byLabel.get(labels[v]);
        if (list) list.push(v);
        else byLabel.set(labels[v], [v]);
      }
      let unpaired = 0;
      for (const [to, vertices] of byLabel) {
        const mirrored = this.xMirror.paired(s, vertices, to);
        unpaired += mirrored.unpaired;
        for (const [w, l] of mirrored.pairs) if (!chosen.has(w)) set(w, l);
      }
      this.noteUnpaired(unpaired);
    }
    if (changed.length === 0) return s.note('nothing changed');
    s.paint(changed);
    s.sendSelection();
    this.placeGizmo();
    s.changed();
  }

  private noteUnpaired(unpaired: number): void {
    if (unpaired > 0) {
      this.s.note(`X mirror: ${unpaired} of the vertices selected have no counterpart (no vertex within 2% of the ` +
        'diagonal of their mirror image): the mesh is not symmetric there; they were selected alone');
    }
  }

  // ------------------------------------------------------------ keyboard

  // Escape: cancels a drag or a stroke; returns whether there was one.
  cancel(): boolean {
    if (this.endRegion(null)) return true;
    if (this.linkedArmed) {
      this.linkedArmed = false;
      this.showHeader('');
      return true;
    }
    if (this.drag) {
      const gizmo = this.drag.pivot !== undefined;
      const modal = this.drag.modal !== undefined;
      this.endDrag(false);
      if (gizmo) this.s.viewer.gizmo.detach(), this.placeGizmo();
      this.s.note(modal ? 'transform cancelled' : 'drag cancelled');
      return true;
    }
    if (this.stroke) {
      this.endStroke(false);
      this.s.note('stroke cancelled');
      return true;
    }
    return false;
  }

  // F: the active group (or the selection, or the whole mesh) in the middle of the view.
  frameSelection(): void {
    const p = this.s.viewer.positions();
    const points: THREE.Vector3[] = [];
    const g = this.s.activeGroup;
    const pick = (want: (l: number) => boolean) => {
      this.s.labels.forEach((l, k) => want(l) && points.push(new THREE.Vector3().fromArray(p, 3 * k)));
    };
    pick((l) => l === 2 + g);
    if (points.length === 0) pick((l) => l !== FREE);
    this.s.viewer.frame(points);
  }
}

interface Stroke {
  before: Int16Array; // the labels when it began
  touched: Set<number>;
  label: number;
  pin: number | null; // the pinned group it paints, if a Pin stroke
  unpaired: number; // brushed vertices X mirror found no counterpart for (counted per query)
  finishing?: boolean; // ended while a brush query was out
  cancelled?: boolean;
}
