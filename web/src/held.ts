// A selection painted while a mesh's basis is computed is held by the page until the server can
// take it. It is also kept in the browser's local storage, by mesh, so that a reload or a second
// window of the same mesh gets it back; it is dropped once sent. Labels are stored as runs.
import * as THREE from 'three';

const PREFIX = 'specdeform-held:';
const MAX_AGE_MS = 6 * 3600 * 1000; // an older one is stale: the mesh has long been ready

export interface Held {
  labels: Int16Array<ArrayBuffer>;
  groups: { transform: number[]; pinned: boolean }[]; // column-major 4 x 4
  time: number; // Date.now() when saved
}

// A name for the mesh: its sizes and a hash of a sample of its positions and triangles.
export function meshKey(rest: Float32Array, indices: Uint32Array): string {
  let h = 2166136261;
  const mix = (x: number) => (h = Math.imul(h ^ x, 16777619) >>> 0);
  const words = new Uint32Array(rest.buffer, rest.byteOffset, rest.length);
  const step = Math.max(1, Math.floor(words.length / 4096));
  for (let i = 0; i < words.length; i += step) mix(words[i]);
  for (let i = 0; i < indices.length; i += step) mix(indices[i]);
  return `${PREFIX}${rest.length / 3}:${indices.length / 3}:${h.toString(16)}`;
}

export function saveHeld(key: string, labels: Int16Array, groups: { transform: THREE.Matrix4; pinned: boolean }[]): void {
  const runs: number[] = []; // start, length, label of each run of painted vertices
  for (let v = 0; v < labels.length;) {
    let w = v + 1;
    while (w < labels.length && labels[w] === labels[v]) ++w;
    if (labels[v] !== 0) runs.push(v, w - v, labels[v]);
    v = w;
  }
  const value = JSON.stringify({ runs, n: labels.length, time: Date.now(),
    groups: groups.map((g) => ({ transform: g.transform.toArray(), pinned: g.pinned })) });
  try {
    localStorage.setItem(key, value);
  } catch {
    // Over the storage's quota: held by this page only.
  }
}

export function loadHeld(key: string, n: number): Held | null {
  try {
    const saved = JSON.parse(localStorage.getItem(key) ?? 'null');
    if (!saved || saved.n !== n || Date.now() - saved.time > MAX_AGE_MS) return null;
    const labels = new Int16Array(n);
    for (let i = 0; i + 2 < saved.runs.length; i += 3) labels.fill(saved.runs[i + 2], saved.runs[i], saved.runs[i] + saved.runs[i + 1]);
    return { labels, groups: saved.groups, time: saved.time };
  } catch {
    return null;
  }
}

export function dropHeld(key: string): void {
  localStorage.removeItem(key);
}
