// The editor (`specdeform edit`): the view, the state and its connection, the pointer and the
// panel, put together; and a read-only window onto them for automation (the end-to-end test
// and the picture script).
import * as THREE from 'three';
import './style.css';
import { Connection } from './connection';
import { Interaction } from './interaction';
import { Panel } from './panel';
import * as P from './protocol';
import { EditorState, rowMajor, startWorker, stats } from './state';
import { Viewer } from './viewer';

// The mesh's reading and the socket first: they come while the page makes its view (a second
// without a GPU).
const worker = startWorker();
const connection = new Connection(`ws://${location.host}/ws`);
connection.connect();
const view = document.getElementById('view')!;
const state = new EditorState(new Viewer(view), connection, worker);
const interaction = new Interaction(state, view);
new Panel(state, interaction);
interaction.setTool('handle');

const viewer = state.viewer;
(window as unknown as { specdeformEditor: unknown }).specdeformEditor = {
  get ready() {
    return state.editable;
  },
  get phase() {
    return state.phase.kind;
  },
  get paintable() {
    return state.paintable;
  },
  // The server's counts of the edit ("state"): what it applied of the page's selection.
  serverCounts: () => state.server && {
    handles: state.server.groups.reduce((a, g) => a + g.vertices, 0),
    fixed: state.server.fixed,
  },
  stats,
  draws: () => viewer.draws,
  fullDraws: () => viewer.fullDraws,
  drawsSkipped: () => viewer.drawsSkipped,
  restPositions: () => Array.from(state.rest),
  positions: () => Array.from(viewer.positions()),
  labels: () => Array.from(state.labels),
  vertices: () => state.labels.length, // of the mesh shown
  counts: () => state.counts(), // of the labels painted
  slowBrush: (ms: number) => (state.brushDelayMs = ms),
  transforms: () => state.groups.map((g) => rowMajor(g.transform)),
  vertexOnScreen: (v: number) => viewer.toScreen(new THREE.Vector3().fromArray(viewer.positions(), 3 * v)),
  diagonal: () => state.diagonal,
  tool: () => interaction.tool,
  activeGroup: () => state.activeGroup,
  onModel: (x: number, y: number) => viewer.pick(x, y) !== null,
  hidden: () => (viewer.hidden ? Array.from(viewer.hidden.keys()).filter((v) => viewer.hidden![v]) : []),
  drawnTriangles: () => viewer.drawnTriangles,
  settled: () => state.settled(),
  unsettled: () => ({ phase: state.phase.kind, ready: state.editable, waits: state.unsettled() }),
  previewSize: () => (state.previewWanted ? viewer.previewSize : 0),
  notes: () => state.notes.map((n) => ({ ...n })),
  cameraPosition: () => viewer.camera.position.toArray(),
  cameraTarget: () => viewer.orbit.target.toArray(),
  projection: () => (viewer.orthographic ? 'orthographic' : 'perspective'),
  measures: () => state.measures,
  look: () => ({ present: viewer.look.present, drawn: viewer.drawingLook, textures: viewer.look.textures }),
  cursor: () => interaction.cursor?.toArray() ?? null,
  gizmoOnScreen: () => (viewer.gizmo.object ? viewer.toScreen(viewer.pivot.position) : null),
  setView: (direction: [number, number, number], zoom = 1, at?: [number, number, number]) => {
    const target = viewer.orbit.target;
    const distance = viewer.camera.position.distanceTo(target) / zoom;
    if (at) target.set(...at);
    viewer.camera.position.copy(target).add(new THREE.Vector3(...direction).normalize().multiplyScalar(distance));
    viewer.orbit.update();
    viewer.requestRender();
  },
  // The server's rate alone: frames of the current transforms sent `hz` times a second for
  // `seconds`, their results counted and not drawn (resolves to results per second); then one
  // more, drawn.
  measureServer: (seconds: number, hz = 60) => new Promise<number>((resolve) => {
    const received = stats.framesReceived;
    const transforms = state.groups.map((g) => rowMajor(g.transform));
    const seq = state.lastSeq; // the frame shown again: results arriving late change nothing
    state.discardFrames = true;
    const timer = setInterval(() => state.connection.send(P.encodeFrame(seq, transforms, false)), 1000 / hz);
    setTimeout(() => {
      clearInterval(timer);
      state.discardFrames = false;
      resolve((stats.framesReceived - received) / seconds);
      // The server's last result shown (ARAP, warm-started, moves on a little each time).
      state.sendFrame(false);
    }, 1000 * seconds);
  }),
};

