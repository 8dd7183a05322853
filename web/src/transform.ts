// Blender's modal transforms of a handle group about a pivot: G moves, R rotates, S scales,
// following the pointer until a click or Enter confirms (Esc or a right-click cancels); X, Y or
// Z locks to a global axis, the same key again to the group's own axis, Shift + the key to the
// plane across it; a typed number is exact (`R Z 90` turns by exactly 90 degrees); Ctrl snaps.
import * as THREE from 'three';
import type { Viewer } from './viewer';

export type Mode = 'grab' | 'rotate' | 'scale';

interface Lock {
  axis: number; // 0, 1, 2
  local: boolean;
  plane: boolean; // every direction but the axis
}

type Point = { x: number; y: number };

const NAMES: Record<Mode, string> = { grab: 'Move', rotate: 'Rotate', scale: 'Scale' };

export class ModalTransform {
  lock: Lock | null = null;
  typed = '';
  snap = false;
  private readonly local: THREE.Vector3[]; // the group's axes

  constructor(
    readonly mode: Mode,
    readonly pivot: THREE.Vector3, // in world space
    readonly start: THREE.Matrix4, // the group's transform before
    private readonly from: Point, // the pointer when it began
    private readonly viewer: Viewer,
    private readonly step: number, // a grab's snapping step
  ) {
    const [x, y, z] = [new THREE.Vector3(), new THREE.Vector3(), new THREE.Vector3()];
    start.extractBasis(x, y, z);
    x.normalize();
    y.sub(x.clone().multiplyScalar(x.dot(y))).normalize();
    this.local = [x, y, x.clone().cross(y)];
  }

  // An axis key: global, then local, then none; with Shift, the plane across it.
  setAxis(axis: number, plane: boolean): void {
    const l = this.lock;
    if (!l || l.axis !== axis || l.plane !== plane) this.lock = { axis, local: false, plane };
    else if (!l.local) l.local = true;
    else this.lock = null;
  }

  // A key of a typed value: digits, '.', '-' (flips the sign), Backspace; returns whether used.
  type(key: string): boolean {
    if (/^[0-9.]$/.test(key)) this.typed += key;
    else if (key === '-') this.typed = this.typed.startsWith('-') ? this.typed.slice(1) : `-${this.typed}`;
    else if (key === 'Backspace') this.typed = this.typed.slice(0, -1);
    else return false;
    return true;
  }

  private get value(): number | null {
    const v = Number(this.typed);
    return this.typed.replace('-', '') !== '' && Number.isFinite(v) ? v : null;
  }

  private axisVector(): THREE.Vector3 {
    const l = this.lock!;
    return l.local ? this.local[l.axis].clone() : new THREE.Vector3().setComponent(l.axis, 1);
  }

  // The group's transform for the pointer at `to` (or the typed value).
  matrix(to: Point): THREE.Matrix4 {
    return this.measure(to).delta.multiply(this.start);
  }

  // The transform of space that the group undergoes, and what the header says of it.
  private measure(to: Point): { delta: THREE.Matrix4; text: string } {
    const typed = this.value;
    const p = this.pivot;
    const about = (m: THREE.Matrix4) =>
      new THREE.Matrix4().makeTranslation(p.x, p.y, p.z).multiply(m).multiply(new THREE.Matrix4().makeTranslation(-p.x, -p.y, -p.z));
    if (this.mode === 'grab') {
      let t: THREE.Vector3;
      if (typed !== null) t = (this.lock ? this.axisVector() : new THREE.Vector3(1, 0, 0)).multiplyScalar(typed);
      else {
        t = this.dragTranslation(to);
        if (this.snap) t.set(...(t.toArray().map((c) => Math.round(c / this.step) * this.step) as [number, number, number]));
      }
      const text = `D: ${[t.x, t.y, t.z].map((c) => fixed(c, 4)).join(', ')}`;
      return { delta: new THREE.Matrix4().makeTranslation(t.x, t.y, t.z), text };
    }
    if (this.mode === 'rotate') {
      const toViewer = this.viewer.camera.getWorldDirection(new THREE.Vector3()).negate();
      const axis = this.lock ? this.axisVector() : toViewer;
      let degrees: number;
      if (typed !== null) degrees = typed;
      else {
        degrees = THREE.MathUtils.radToDeg(this.screenAngle(to)) * (axis.dot(toViewer) < 0 ? -1 : 1);
        if (this.snap) degrees = Math.round(degrees / 5) * 5;
      }
      return { delta: about(rotation(axis, degrees)), text: `${fixed(degrees, 2)}°` };
    }
    let f: number;
    if (typed !== null) f = typed;
    else {
      const c = this.viewer.toScreen(p);
      f = Math.hypot(to.x - c.x, to.y - c.y) / Math.max(1, Math.hypot(this.from.x - c.x, this.from.y - c.y));
      if (this.snap) f = Math.round(f * 10) / 10;
    }
    const s = new THREE.Matrix4().makeScale(f, f, f);
    if (this.lock) {
      // Along the axis only: I + (f - 1) a a^T; in the plane: f I + (1 - f) a a^T.
      const a = this.axisVector();
      const k = this.lock.plane ? 1 - f : f - 1;
      const d = this.lock.plane ? f : 1;
      const e = a.toArray();
      s.set(d + k * e[0] * e[0], k * e[0] * e[1], k * e[0] * e[2], 0,
        k * e[1] * e[0], d + k * e[1] * e[1], k * e[1] * e[2], 0,
        k * e[2] * e[0], k * e[2] * e[1], d + k * e[2] * e[2], 0, 0, 0, 0, 1);
    }
    if (f === 0) s.elements[0] = s.elements[5] = s.elements[10] = 1e-6; // never singular
    return { delta: about(s), text: `${fixed(f, 3)}` };
  }

  // The header: what is done, by how much, along what, and the keys.
  readout(to: Point): string {
    const l = this.lock;
    const along = l ? ` along ${l.plane ? 'the plane across ' : ''}${l.local ? 'local' : 'global'} ${'XYZ'[l.axis]}` : '';
    const typed = this.typed ? ` [${this.typed}|]` : '';
    return `${NAMES[this.mode]} ${this.measure(to).text}${typed}${along} · X/Y/Z axis (twice: local), ` +
      'type a value, Ctrl snaps · click or Enter confirms, Esc or right-click cancels';
  }

  // The pointer's motion on the view plane, along the axis or on the plane across it.
  private dragTranslation(to: Point): THREE.Vector3 {
    const v = this.viewer;
    if (!this.lock) {
      const a = v.onViewPlane(this.from.x, this.from.y, this.pivot);
      const b = v.onViewPlane(to.x, to.y, this.pivot);
      return a && b ? b.sub(a) : new THREE.Vector3();
    }
    const axis = this.axisVector();
    if (this.lock.plane) {
      const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(axis, this.pivot);
      const a = v.ray(this.from.x, this.from.y).intersectPlane(plane, new THREE.Vector3());
      const b = v.ray(to.x, to.y).intersectPlane(plane, new THREE.Vector3());
      return a && b ? b.sub(a) : new THREE.Vector3();
    }
    const along = (q: Point) => closestOnLine(v.ray(q.x, q.y), this.pivot, axis);
    return axis.multiplyScalar(along(to) - along(this.from));
  }

  // The angle the pointer turned about the pivot on screen, counterclockwise.
  private screenAngle(to: Point): number {
    const c = this.viewer.toScreen(this.pivot);
    return Math.atan2(-(to.y - c.y), to.x - c.x) - Math.atan2(-(this.from.y - c.y), this.from.x - c.x);
  }
}

// The rotation about a unit axis through the origin, with exact sines and cosines at multiples
// of 90 degrees (a typed 90 is exactly a quarter turn).
export function rotation(axis: THREE.Vector3, degrees: number): THREE.Matrix4 {
  const quarter = degrees / 90;
  const [s, c] = Number.isInteger(quarter)
    ? [[0, 1], [1, 0], [0, -1], [-1, 0]][((quarter % 4) + 4) % 4]
    : [Math.sin(THREE.MathUtils.degToRad(degrees)), Math.cos(THREE.MathUtils.degToRad(degrees))];
  const [x, y, z] = axis.clone().normalize().toArray();
  const t = 1 - c;
  return new THREE.Matrix4().set(
    t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0,
    t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0,
    t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0,
    0, 0, 0, 1);
}

// The parameter along the line (origin o, unit direction d) of its point nearest to the ray.
function closestOnLine(ray: THREE.Ray, o: THREE.Vector3, d: THREE.Vector3): number {
  const w = o.clone().sub(ray.origin);
  const b = d.dot(ray.direction);
  const denominator = 1 - b * b;
  if (denominator < 1e-9) return 0; // the axis points at the viewer
  return (b * w.dot(ray.direction) - w.dot(d)) / denominator;
}

function fixed(x: number, digits: number): string {
  return Number(x.toFixed(digits)).toString();
}
