// Box selection: the vertices whose image on screen lies in a rectangle, all of them (X-ray,
// through the surface) or only those the camera sees (the first surface along the ray to the
// vertex is the vertex's own).
import * as THREE from 'three';
import type { Viewer } from './viewer';

export interface Rect {
  left: number;
  top: number;
  right: number;
  bottom: number; // client coordinates
}

export function verticesInRect(viewer: Viewer, rect: Rect, xray: boolean, diagonal: number): number[] {
  const p = viewer.positions();
  const camera = viewer.camera;
  const bounds = viewer.canvas.getBoundingClientRect();
  const v = new THREE.Vector3();
  const out: number[] = [];
  for (let k = 0; 3 * k < p.length; ++k) {
    v.set(p[3 * k], p[3 * k + 1], p[3 * k + 2]).project(camera);
    if (v.z > 1) continue; // behind the camera
    const x = bounds.left + ((v.x + 1) / 2) * bounds.width;
    const y = bounds.top + ((1 - v.y) / 2) * bounds.height;
    if (x < rect.left || x > rect.right || y < rect.top || y > rect.bottom) continue;
    if (!xray) {
      const hit = viewer.pick(x, y);
      const at = new THREE.Vector3(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
      if (!hit || hit.point.distanceTo(camera.position) < at.distanceTo(camera.position) - 2e-3 * diagonal) continue;
    }
    out.push(k);
  }
  return out;
}
