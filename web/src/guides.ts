// What is drawn over the view during a move (as in Blender): the pivot's mark and a dashed line
// from it to the pointer while turning or scaling, and the region of influence's circle around
// the pivot (its radius where the pivot is), when there is one.
import * as THREE from 'three';
import type { Viewer } from './viewer';

export interface Guides {
  pivot: THREE.Vector3;
  pointer: { x: number; y: number } | null; // the dashed line's end (R, S), or none
  influence: number; // the region's radius in world units; 0: none
}

export function showGuides(viewer: Viewer, view: HTMLElement, g: Guides | null): void {
  const svg = document.getElementById('guides')!;
  svg.style.display = g ? 'block' : 'none';
  if (!g) return;
  const at = view.getBoundingClientRect();
  const c = viewer.toScreen(g.pivot);
  const [x, y] = [c.x - at.left, c.y - at.top];
  const set = (id: string, attributes: Record<string, number | string>) => {
    const el = document.getElementById(id)!;
    for (const [k, v] of Object.entries(attributes)) el.setAttribute(k, String(v));
  };
  set('pivot-mark', { cx: x, cy: y });
  const line = g.pointer ?? c;
  set('pivot-line', { x1: x, y1: y, x2: line.x - at.left, y2: line.y - at.top, visibility: g.pointer ? 'visible' : 'hidden' });
  // The radius on screen: the world radius across the view at the pivot's depth.
  const right = new THREE.Vector3().setFromMatrixColumn(viewer.camera.matrixWorld, 0);
  const edge = viewer.toScreen(g.pivot.clone().addScaledVector(right, g.influence));
  set('influence-circle', { cx: x, cy: y, r: Math.hypot(edge.x - c.x, edge.y - c.y), visibility: g.influence > 0 ? 'visible' : 'hidden' });
}
