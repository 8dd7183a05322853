// The pointer and the keyboard: painting with the brush, dragging handles (the mouse or the
// gizmo), orbiting only on the right button or with Alt, and the shortcuts.
import * as THREE from 'three';
import { EditorState, FIXED, FREE } from './state';

export type Tool = 'handle' | 'fixed' | 'pin' | 'erase' | 'move';

// How long the pointer rests before the full detail is asked for in place of the preview (ms).
const kRestMs = 200;

interface Drag {
  group: number;
  start: THREE.Vector3; // the handle point grabbed (mouse) or the gizmo's start
  transform: THREE.Matrix4; // the group's at the start
  pivot?: THREE.Matrix4; // the gizmo's at the start
}

export class Interaction {
  tool: Tool = 'handle';
  onToolChange: () => void = () => {};
  private stroke: { before: Int16Array; touched: Set<number>; label: number; pin: number | null } | null = null;
  private brushing = false; // a brush query in flight
  private nextBrush: { x: number; y: number } | null = null;
  private drag: Drag | null = null;
  private restTimer: number | undefined;
  private usedPreview = false;
  private hoverQueued: { x: number; y: number } | null = null;

  constructor(private readonly s: EditorState, private readonly view: HTMLElement) {
    const v = s.viewer;
    // Capture phase: decides before the orbit controls what a press does.
    view.addEventListener('pointerdown', (e) => this.down(e), true);
    view.addEventListener('pointermove', (e) => this.move(e));
    view.addEventListener('pointerup', () => this.up());
    view.addEventListener('pointercancel', () => this.up());
    view.addEventListener('pointerleave', () => v.showBrush(null, 0));
    v.gizmo.addEventListener('dragging-changed', (e) => {
      if (e.value) this.beginGizmo();
      else this.endDrag(true);
    });
    v.gizmo.addEventListener('objectChange', () => this.gizmoMoved());
  }

  get radius(): number {
    const percent = Number((document.getElementById('radius') as HTMLInputElement).value);
    return (percent / 100) * (this.s.ready?.diagonal ?? 1);
  }

  private get geodesic(): boolean {
    return (document.getElementById('geodesic') as HTMLInputElement).checked;
  }

  setTool(t: Tool): void {
    this.tool = t;
    if (t !== 'move') this.s.viewer.gizmo.detach();
    this.placeGizmo();
    this.s.viewer.showBrush(null, 0);
    this.onToolChange();
  }

  // ------------------------------------------------------------ pointer

  private down(e: PointerEvent): void {
    const v = this.s.viewer;
    // Only presses on the model's canvas: not on what lies over it (messages, dialogs).
    if (e.button !== 0 || e.target !== v.canvas) return; // right: orbit, middle: pan
    v.orbit.mouseButtons.LEFT = e.altKey ? THREE.MOUSE.ROTATE : null;
    if (e.altKey || v.gizmo.axis !== null) return; // orbit, or the gizmo's own drag
    e.stopPropagation();
    if (!this.s.editable) {
      this.s.note(this.s.phase.kind === 'disconnected' ? 'not connected: the edit waits for the server'
        : 'the server is busy: wait for it to finish');
      return;
    }
    const hit = v.pick(e.clientX, e.clientY);
    if (this.tool === 'move') {
      const l = hit ? this.s.labels[hit.vertex] : FREE;
      if (!hit || l < 2 || this.s.groups[l - 2].pinned) {
        this.s.note(hit ? 'press on a coloured handle to drag it, or use the gizmo' : 'missed the model: press on a handle');
        return;
      }
      this.s.activeGroup = l - 2;
      this.drag = { group: l - 2, start: hit.point, transform: this.s.groups[l - 2].transform.clone() };
      this.usedPreview = false;
      this.s.changed();
    } else {
      if (!hit) {
        this.s.note('missed the model: a stroke starts on the surface (right-drag or Alt+drag orbits)');
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
      this.stroke = { before: this.s.labels.slice(), touched: new Set(), label, pin };
      this.s.painting = true;
      this.paintAt(e.clientX, e.clientY);
    }
    v.orbit.enabled = false;
    this.view.setPointerCapture(e.pointerId);
  }

  private move(e: PointerEvent): void {
    const v = this.s.viewer;
    if (this.stroke) return this.paintAt(e.clientX, e.clientY);
    if (this.drag && !this.drag.pivot) {
      const p = v.onViewPlane(e.clientX, e.clientY, this.drag.start);
      if (!p) return;
      const d = p.sub(this.drag.start);
      this.s.groups[this.drag.group].transform = new THREE.Matrix4().makeTranslation(d.x, d.y, d.z).multiply(this.drag.transform);
      this.dragged();
      return;
    }
    if (this.tool !== 'move' && e.buttons === 0) this.hover(e.clientX, e.clientY);
  }

  private up(): void {
    this.s.viewer.orbit.enabled = true;
    this.s.viewer.orbit.mouseButtons.LEFT = null;
    if (this.stroke) this.endStroke(true);
    if (this.drag && !this.drag.pivot) this.endDrag(true);
  }

  // The brush circle follows the pointer, one pick per drawn frame.
  private hover(x: number, y: number): void {
    if (this.hoverQueued) {
      this.hoverQueued = { x, y };
      return;
    }
    this.hoverQueued = { x, y };
    requestAnimationFrame(() => {
      const q = this.hoverQueued!;
      this.hoverQueued = null;
      if (this.tool === 'move' || this.stroke) return;
      this.s.viewer.showBrush(this.s.editable ? this.s.viewer.pick(q.x, q.y) : null, this.radius);
    });
  }

  // ------------------------------------------------------------ painting

  private paintAt(x: number, y: number): void {
    if (this.brushing) {
      this.nextBrush = { x, y };
      return;
    }
    const hit = this.s.viewer.pick(x, y);
    this.s.viewer.showBrush(hit, this.radius);
    if (!hit || !this.stroke) return;
    this.brushing = true;
    this.s.brush(hit.vertex, hit.point, this.radius, this.geodesic).then((vertices) => {
      this.brushing = false;
      const stroke = this.stroke;
      if (stroke) {
        const labels = this.s.labels;
        const changed: number[] = [];
        for (const v of vertices) {
          // A pin stroke claims free, fixed and handle vertices; other tools leave pins alone
          // except Erase.
          const l = labels[v];
          const isPin = l >= 2 && this.s.groups[l - 2]?.pinned;
          if (isPin && stroke.label !== FREE && l !== stroke.label) continue;
          if (l !== stroke.label) {
            labels[v] = stroke.label;
            changed.push(v);
            stroke.touched.add(v);
          }
        }
        this.s.paint(changed);
      }
      const next = this.nextBrush;
      this.nextBrush = null;
      if (next && this.stroke) this.paintAt(next.x, next.y);
      else if (this.finishPending) this.endStroke(true);
    });
  }
  private finishPending = false;

  // `keep`: send the stroke to the server (an undo step); otherwise restore what it painted.
  private endStroke(keep: boolean): void {
    const stroke = this.stroke;
    if (!stroke) return;
    if (this.brushing && keep) {
      this.finishPending = true; // the last brush query first
      return;
    }
    this.finishPending = false;
    this.stroke = null;
    this.s.painting = false;
    if (!keep || stroke.touched.size === 0) {
      this.s.labels.set(stroke.before);
      this.s.paint([...stroke.touched]);
      if (stroke.pin !== null) this.dropEmptyGroup(stroke.pin);
      this.s.changed();
      return;
    }
    this.s.sendSelection(stroke.pin !== null ? new Set([stroke.pin]) : new Set());
    this.s.changed();
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
    const preview = this.s.previewWanted;
    this.usedPreview ||= preview;
    this.s.sendFrame(preview);
    clearTimeout(this.restTimer);
    // The pointer rests: the full detail, the preview again on the next move.
    if (preview) this.restTimer = window.setTimeout(() => this.s.sendFrame(false), kRestMs);
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
    if (!keep) this.s.groups[d.group].transform = d.transform;
    if (this.usedPreview || !keep) this.s.sendFrame(false);
    if (keep) this.s.commit();
    this.placeGizmo();
    this.s.changed();
  }

  // The gizmo sits beside the active group (off its surface, so that the handle stays
  // visible and grabbable), moved with the group's transform.
  placeGizmo(): void {
    const v = this.s.viewer;
    const g = this.s.activeGroup;
    const group = this.s.groups[g];
    if (this.tool !== 'move' || !group || group.pinned || !this.s.editable) {
      v.gizmo.detach();
      v.requestRender();
      return;
    }
    const rest = this.s.rest;
    const centroid = new THREE.Vector3();
    let count = 0;
    this.s.labels.forEach((l, k) => {
      if (l !== 2 + g) return;
      centroid.x += rest[3 * k];
      centroid.y += rest[3 * k + 1];
      centroid.z += rest[3 * k + 2];
      ++count;
    });
    if (count === 0) {
      v.gizmo.detach();
      v.requestRender();
      return;
    }
    centroid.divideScalar(count);
    let radius = 0;
    this.s.labels.forEach((l, k) => {
      if (l === 2 + g) radius = Math.max(radius, centroid.distanceTo(new THREE.Vector3().fromArray(rest, 3 * k)));
    });
    // Beside the group, away from the model's centre as seen from the camera, by the group's
    // size plus the gizmo's reach (TransformControls scales itself with the distance to the
    // camera: its arrows reach about 0.1 of it).
    const at = centroid.clone().applyMatrix4(group.transform);
    const view = v.camera.getWorldDirection(new THREE.Vector3());
    const away = at.clone().sub(v.orbit.target).projectOnPlane(view);
    if (away.lengthSq() < 1e-12 * at.lengthSq() + 1e-30) away.setFromMatrixColumn(v.camera.matrixWorld, 0);
    at.add(away.normalize().multiplyScalar(radius + 0.15 * at.distanceTo(v.camera.position)));
    if (this.drag?.pivot) return; // the gizmo moves itself while dragged
    v.pivot.position.copy(at);
    v.pivot.quaternion.identity();
    v.pivot.scale.set(1, 1, 1);
    v.pivot.updateMatrix();
    v.gizmo.attach(v.pivot);
    v.requestRender();
  }

  // ------------------------------------------------------------ keyboard

  // Escape: cancels a drag or a stroke; returns whether there was one.
  cancel(): boolean {
    if (this.drag) {
      const gizmo = this.drag.pivot !== undefined;
      this.endDrag(false);
      if (gizmo) this.s.viewer.gizmo.detach(), this.placeGizmo();
      this.s.note('drag cancelled');
      return true;
    }
    if (this.stroke) {
      this.endStroke(false);
      this.s.note('stroke cancelled');
      return true;
    }
    return false;
  }

  // F: the active group (or the selection, or the whole mesh) fills the view.
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
