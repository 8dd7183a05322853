// Box and lasso selection: the vertices whose image on screen lies in a rectangle or a closed
// path, all of them (X-ray, through the surface) or only those the camera sees (the first
// surface along the ray to the vertex is the vertex's own).
import * as THREE from 'three';
import type { Viewer } from './viewer';

export interface Rect {
  left: number;
  top: number;
  right: number;
  bottom: number; // client coordinates
}

export type Point = { x: number; y: number };

export const inRect = (r: Rect) => (x: number, y: number) => x >= r.left && x <= r.right && y >= r.top && y <= r.bottom;

// Inside the closed path (even-odd rule).
export const inPath = (path: Point[]) => (x: number, y: number) => {
  let inside = false;
  for (let i = 0, j = path.length - 1; i < path.length; j = i++) {
    const [a, b] = [path[i], path[j]];
    if ((a.y > y) !== (b.y > y) && x < ((b.x - a.x) * (y - a.y)) / (b.y - a.y) + a.x) inside = !inside;
  }
  return inside;
};

export function rectBetween(a: Point, b: Point): Rect {
  return { left: Math.min(a.x, b.x), top: Math.min(a.y, b.y), right: Math.max(a.x, b.x), bottom: Math.max(a.y, b.y) };
}

// The rectangle or the lasso drawn over the view (#region), or none.
export function showRegion(view: HTMLElement, path: Point[] | null): void {
  const svg = document.getElementById('region')!;
  svg.style.display = path ? 'block' : 'none';
  if (!path) return;
  const at = view.getBoundingClientRect();
  svg.querySelector('polygon')!.setAttribute('points', path.map((p) => `${p.x - at.left},${p.y - at.top}`).join(' '));
}

export function corners(r: Rect): Point[] {
  return [{ x: r.left, y: r.top }, { x: r.right, y: r.top }, { x: r.right, y: r.bottom }, { x: r.left, y: r.bottom }];
}

export function verticesIn(viewer: Viewer, contains: (x: number, y: number) => boolean, xray: boolean, diagonal: number): number[] {
  const p = viewer.positions();
  const camera = viewer.view;
  const forward = viewer.camera.getWorldDirection(new THREE.Vector3());
  const depth = (q: THREE.Vector3) => q.clone().sub(camera.position).dot(forward); // along the view
  const bounds = viewer.canvas.getBoundingClientRect();
  const v = new THREE.Vector3();
  const out: number[] = [];
  const hidden = viewer.hidden;
  for (let k = 0; 3 * k < p.length; ++k) {
    if (hidden?.[k]) continue;
    v.set(p[3 * k], p[3 * k + 1], p[3 * k + 2]).project(camera);
    if (v.z > 1) continue; // behind the camera
    const x = bounds.left + ((v.x + 1) / 2) * bounds.width;
    const y = bounds.top + ((1 - v.y) / 2) * bounds.height;
    if (!contains(x, y)) continue;
    if (!xray) {
      const hit = viewer.pick(x, y);
      const at = new THREE.Vector3(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
      if (!hit || depth(hit.point) < depth(at) - 2e-3 * diagonal) continue;
    }
    out.push(k);
  }
  return out;
}
