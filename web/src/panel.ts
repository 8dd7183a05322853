// The side panel and what is drawn over the viewport: status, the next step, counts, messages
// (errors stay until dismissed) and their log, the disconnected banner, progress with Cancel,
// and the confirmation before a mesh replaces unsaved work. Everything shown follows from the
// state (render()); the controls send requests through it.
import { Interaction, PivotMode, Tool } from './interaction';
import * as THREE from 'three';
import * as P from './protocol';
import type { Mode } from './transform';
import { renderKeymap } from './keymap';
import { EditorState, GROUP_HEX, PIN_HEX, stats } from './state';
import type { Navigation } from './viewer';

const $ = <T extends HTMLElement>(id: string) => document.getElementById(id) as T;

const HINTS: Record<Tool, string> = {
  handle: 'Handle: paint the part to move with the left button.',
  fixed: 'Fixed: paint what must stay at its rest position.',
  pin: 'Pin: paint what must stay where it is shown now (each stroke is one pin).',
  erase: 'Erase: paint to clear handles, fixed vertices and pins.',
  move: 'Move: drag a coloured handle or the gizmo at the pivot, or press G, R or S (then X/Y/Z, a value, Enter); Esc cancels.',
};

const MESH_FILE = /\.(obj|off|ply|stl|gltf|glb)$/i;
const NAVIGATION_KEY = 'specdeform.navigation';
// Counts as the page's locale writes them; made at load: the first number formatted otherwise
// waits for the locale's data (60 ms, while a large mesh is taken).
const numbers = new Intl.NumberFormat();
const kOrbitStep = 15; // degrees a numpad 4, 6, 8 or 2 turns the view (Blender's default)

// Keys typed into a text field stay there; every other control hands the keyboard back to the
// view once used, so that a key acts whatever was clicked last, as in Blender. A menu (a select)
// takes keys only while it is open (its popup has them then); closed, a key that reaches it acts
// on the view and never steps its value.
const TEXT_INPUTS = new Set(['text', 'number', 'search', 'email', 'password', 'url', 'tel']);
const typing = (t: EventTarget | null): boolean =>
  t instanceof HTMLTextAreaElement || (t instanceof HTMLInputElement && TEXT_INPUTS.has(t.type));
const MODIFIERS = new Set(['Shift', 'Control', 'Alt', 'Meta', 'CapsLock', 'NumLock']);
function releaseFocus(e: Event): void {
  const t = e.target;
  if (t instanceof HTMLElement && t !== document.body && !typing(t)) t.blur();
  else if (e.type === 'change' && t instanceof HTMLSelectElement) t.blur();
}

// A loading stage, with its fraction when it has one (a stage without one is reported as 1).
// Changed text only: each change repaints the window (in software, without a GPU).
function setText(element: HTMLElement, text: string): void {
  if (element.textContent !== text) element.textContent = text;
}

function progressText(phase: { stage: string; fraction: number }): string {
  return phase.fraction < 1 ? `${phase.stage}… ${Math.round(100 * phase.fraction)}%` : `${phase.stage}…`;
}

export class Panel {
  private shownNotes = 0; // notes already turned into toasts
  private lastPhase = '';
  private mirrorMesh: string | null = null; // the mesh whose X-mirror pairing is in use
  private transientToasts: HTMLElement[] = []; // removed when the request ends
  private offlineToasts: HTMLElement[] = []; // raised while disconnected: removed on reconnection

  constructor(private readonly s: EditorState, private readonly ui: Interaction) {
    s.subscribe(() => this.render());
    ui.onToolChange = () => this.render();
    this.bind();
    this.renderFields();
    setInterval(() => {
      this.renderTimings();
      this.renderMeasures();
    }, 500);
    setInterval(() => this.renderBanner(), 250);
    // The seconds counters move within a quarter of a second of each second (ticking once a
    // second, a counter stood up to two seconds).
    setInterval(() => this.renderStatus(), 250);
  }

  // Asks before replacing an edit that would be lost; resolves true to go on.
  confirmDiscard(action: string): Promise<boolean> {
    const c = this.s.counts();
    if (c.handles + c.fixed + c.pinned === 0 && !this.s.server?.undo) return Promise.resolve(true);
    const dialog = $<HTMLDialogElement>('confirm');
    $('confirm-text').textContent = `${action} replaces the current edit (${numbers.format(c.handles)} handle, ` +
      `${numbers.format(c.fixed)} fixed and ${numbers.format(c.pinned)} pinned vertices, and its undo history). ` +
      'Export the scene first to keep it.';
    dialog.showModal();
    return new Promise((resolve) => {
      const done = (answer: boolean) => {
        dialog.close();
        $('confirm-yes').onclick = $('confirm-no').onclick = null;
        resolve(answer);
      };
      $('confirm-yes').onclick = () => done(true);
      $('confirm-no').onclick = () => done(false);
      dialog.oncancel = () => done(false);
    });
  }

  private bind(): void {
    const s = this.s;
    document.querySelectorAll<HTMLButtonElement>('[data-tool]').forEach((b) =>
      b.addEventListener('click', () => this.ui.setTool(b.dataset.tool as Tool)),
    );
    $('reconnect').addEventListener('click', () => s.connection.connect());
    $('cancel').addEventListener('click', () => {
      s.connection.send({ type: 'cancel' });
      $('cancel').textContent = 'Cancelling…';
    });
    $('open-demo').addEventListener('click', async () => {
      if (await this.confirmDiscard('Opening the demo')) s.request({ type: 'open_demo' }, 'open the demo', 'state');
    });
    const fileInput = (id: string, tag: P.FileTag, what: string, confirm: string | null) => {
      $<HTMLInputElement>(id).addEventListener('change', async (e) => {
        const input = e.target as HTMLInputElement;
        const f = input.files?.[0];
        input.value = '';
        if (f) await this.openFile(f, tag, what, confirm);
      });
    };
    $<HTMLInputElement>('open-mesh').addEventListener('change', async (e) => {
      const input = e.target as HTMLInputElement;
      const files = [...(input.files ?? [])];
      input.value = '';
      await this.openMesh(files);
    });
    fileInput('open-selection', P.Tag.SelectionFile, 'load selection', 'Loading a selection');
    fileInput('open-scene', P.Tag.SceneFile, 'open scene', 'Opening a scene');
    $('wireframe').addEventListener('change', (e) => s.viewer.setWireframe((e.target as HTMLInputElement).checked));
    this.navigation(JSON.parse(localStorage.getItem(NAVIGATION_KEY) ?? 'null') ?? { scheme: 'blender', emulate3: false });
    const navigationChanged = () => this.navigation({
      scheme: $<HTMLSelectElement>('navigation').value as Navigation,
      emulate3: $<HTMLInputElement>('emulate3').checked,
    }, true);
    $('navigation').addEventListener('change', navigationChanged);
    $('emulate3').addEventListener('change', navigationChanged);
    $('show-look').addEventListener('change', (e) => s.viewer.showLook((e.target as HTMLInputElement).checked));
    $('show-base').addEventListener('change', (e) =>
      s.request({ type: 'settings', view: (e.target as HTMLInputElement).checked ? 'base' : 'detailed' }, 'view', 'ready'));
    // Fields: Enter applies and leaves the field (so that shortcuts work again), Escape puts the
    // server's value back. m is applied with its button: a new basis costs seconds.
    $('influence').addEventListener('change', (e) => {
      const v = Number((e.target as HTMLInputElement).value);
      if (Number.isFinite(v) && v >= 0) s.request({ type: 'settings', influence: v / 100 }, 'settings', 'ready');
    });
    for (const id of ['ks', 'kb']) {
      $(id).addEventListener('change', (e) => {
        const v = Number((e.target as HTMLInputElement).value);
        if (Number.isFinite(v)) s.request({ type: 'settings', [id]: v }, 'settings', 'ready');
      });
    }
    for (const id of ['energy', 'detail', 'constraints', 'unconstrained']) {
      $(id).addEventListener('change', (e) =>
        s.request({ type: 'settings', [id]: (e.target as HTMLSelectElement).value } as P.ClientText, 'settings', 'ready'));
    }
    $('modes').addEventListener('input', () => this.renderModes());
    $('apply-modes').addEventListener('click', () => {
      const m = Number($<HTMLInputElement>('modes').value);
      s.request({ type: 'settings', modes: m }, `basis with m = ${m}`, 'ready');
    });
    for (const field of document.querySelectorAll<HTMLInputElement | HTMLSelectElement>('#panel input, #panel select')) {
      field.addEventListener('keydown', (e) => {
        const k = (e as KeyboardEvent).key;
        if (k === 'Enter') {
          if (field.id === 'modes') $('apply-modes').click();
          field.blur();
        } else if (k === 'Escape') {
          this.renderFields();
          field.blur();
        }
      });
    }
    $('group').addEventListener('change', (e) => {
      s.activeGroup = Number((e.target as HTMLSelectElement).value);
      this.ui.placeGizmo();
      this.render();
    });
    $('new-group').addEventListener('click', () => {
      this.ui.newGroup(false);
      this.ui.setTool('handle');
    });
    $('radius').addEventListener('input', () => this.render());
    for (const mode of ['translate', 'rotate', 'scale'] as const) {
      $(`gizmo-${mode}`).addEventListener('click', () => {
        s.viewer.gizmo.setMode(mode);
        this.ui.setTool('move');
      });
    }
    $('pivot').addEventListener('change', (e) => {
      this.ui.pivotMode = (e.target as HTMLSelectElement).value as PivotMode;
      if (this.ui.pivotMode === 'cursor' && !this.ui.cursor) s.note('Shift+right-click on the surface places the 3D cursor');
      this.ui.placeGizmo();
    });
    $('select-linked').addEventListener('click', () => this.ui.armLinked());
    $('x-mirror').addEventListener('change', (e) => (this.ui.xMirror.on = (e.target as HTMLInputElement).checked));
    $('select-box').addEventListener('click', () => this.ui.armBox());
    $('xray').addEventListener('change', (e) => (this.ui.xray = (e.target as HTMLInputElement).checked));
    $('select-invert').addEventListener('click', () => this.ui.selectTopology('invert'));
    $('select-grow').addEventListener('click', () => this.ui.selectTopology('grow'));
    $('select-shrink').addEventListener('click', () => this.ui.selectTopology('shrink'));
    $('clear').addEventListener('click', () => {
      s.labels.fill(0);
      s.groups = [{ transform: s.groups[0].transform.identity(), pinned: false }];
      s.activeGroup = 0;
      s.paint();
      s.sendSelection();
      this.ui.placeGizmo();
    });
    $('undo').addEventListener('click', () => this.undo(false));
    $('redo').addEventListener('click', () => this.undo(true));
    $('reset').addEventListener('click', () => {
      for (const g of s.groups) if (!g.pinned) g.transform.identity();
      s.sendFrame(false);
      s.commit();
      this.ui.placeGizmo();
    });
    $('apply-pose').addEventListener('click', () => s.request({ type: 'apply_pose' }, 'apply pose', 'state'));
    $('export-mesh').addEventListener('click', () =>
      s.request({ type: 'export_mesh', ...exportFormat() }, 'export mesh', 'file'));
    const exportFormat = () => {
      const format = $<HTMLSelectElement>('export-format').value as P.ExportFormat | '';
      const rig = $<HTMLInputElement>('export-rig').checked
        ? {}
        : ({ morph_targets: 'keep', joints: 'keep' } as const);
      return format === '' ? rig : { format, ...rig };
    };
    $('export-format').addEventListener('change', () => this.render());
    $('export-scene').addEventListener('click', () => s.request({ type: 'export_scene' }, 'export scene', 'file'));

    renderKeymap($<HTMLTableElement>('keymap-table'));
    $('keymap-close').addEventListener('click', () => this.toggleKeymap());
    $('show-keymap').addEventListener('click', () => this.toggleKeymap());
    document.addEventListener('change', releaseFocus);
    document.addEventListener('click', releaseFocus);
    window.addEventListener('keydown', (e) => this.key(e));
    window.addEventListener('keyup', (e) => this.ui.modalKeyUp(e));
    window.addEventListener('dragover', (e) => {
      e.preventDefault();
      document.body.classList.add('drop');
    });
    window.addEventListener('dragleave', () => document.body.classList.remove('drop'));
    window.addEventListener('drop', (e) => {
      e.preventDefault();
      document.body.classList.remove('drop');
      const files = [...(e.dataTransfer?.files ?? [])];
      const f = files[0];
      if (!f) return;
      if (/\.(sel|dmat)$/i.test(f.name)) this.openFile(f, P.Tag.SelectionFile, 'load selection', 'Loading a selection');
      else if (/\.json$/i.test(f.name)) this.openFile(f, P.Tag.SceneFile, 'open scene', 'Opening a scene');
      else this.openMesh(files);
    });
  }

  // A mesh file and the files it names (an MTL and its textures, a .gltf's buffers), chosen or
  // dropped together: those first, as companions, then the mesh.
  private async openMesh(files: File[]): Promise<void> {
    const mesh = files.find((f) => MESH_FILE.test(f.name));
    if (!mesh) {
      if (files.length > 0) this.s.note(`no mesh among ${files.map((f) => f.name).join(', ')} (.obj .off .ply .stl .gltf .glb)`, 'error');
      return;
    }
    if (!(await this.confirmDiscard('Opening another mesh'))) return;
    for (const f of files) {
      if (f !== mesh) this.s.connection.send(P.encodeFile(P.Tag.CompanionFile, f.name, await f.arrayBuffer()));
    }
    await this.openFile(mesh, P.Tag.MeshFile, 'open mesh', null);
  }

  private async openFile(f: File, tag: P.FileTag, what: string, confirm: string | null): Promise<void> {
    if (confirm && !(await this.confirmDiscard(confirm))) return;
    // Shown while the request is on (busy), gone with its answer.
    if (this.s.request(P.encodeFile(tag, f.name, await f.arrayBuffer()), `${what} ${f.name}`, 'state')) {
      this.s.note(`sending ${f.name} (${(f.size / 1e6).toFixed(1)} MB)…`, 'info', true);
    }
  }

  // How the mouse moves the view, kept in this browser.
  private navigation(n: { scheme: Navigation; emulate3: boolean }, save = false): void {
    const scheme: Navigation = n.scheme === 'right' ? 'right' : 'blender';
    this.s.viewer.setNavigation(scheme);
    this.ui.emulate3 = n.emulate3 === true;
    $<HTMLSelectElement>('navigation').value = scheme;
    $<HTMLInputElement>('emulate3').checked = this.ui.emulate3;
    $('help-navigation').textContent = scheme === 'blender'
      ? `Middle-drag: orbit · Shift+middle: pan · Ctrl+middle: zoom${this.ui.emulate3 ? ' (Alt+left: middle)' : ''}`
      : 'Right-drag or Alt+drag: orbit · middle or Shift+right-drag: pan';
    if (save) localStorage.setItem(NAVIGATION_KEY, JSON.stringify({ scheme, emulate3: this.ui.emulate3 }));
  }

  // N: the panel out of the way (the view takes its width) and back, as Blender's sidebar.
  private togglePanel(): void {
    const panel = $('panel');
    panel.hidden = !panel.hidden;
  }

  // ?: the key map over the view.
  private toggleKeymap(): void {
    const keymap = $('keymap');
    keymap.hidden = !keymap.hidden;
  }

  private undo(redo: boolean): void {
    const s = this.s;
    if (!s.editable) return;
    if (!(redo ? s.server?.redo : s.server?.undo)) return s.note(redo ? 'nothing to redo' : 'nothing to undo');
    s.request({ type: redo ? 'redo' : 'undo' }, redo ? 'redo' : 'undo', 'state');
  }

  // The key map (keymap.ts, docs/editor.md): digits pick tools, the numeric keypad's digits move
  // the view, as in Blender.
  private key(e: KeyboardEvent): void {
    if (typing(e.target)) return;
    if ($<HTMLDialogElement>('confirm').open) return;
    if (e.target instanceof HTMLSelectElement) {
      // Tab leaves it; Enter, Space and Alt+Down open it, as a keyboard user asks.
      if (e.key === 'Tab' || e.key === 'Enter' || e.key === ' ' || (e.altKey && e.key === 'ArrowDown')) return;
      e.preventDefault(); // no type-ahead, no arrow stepping a closed menu's value
      e.target.blur();
      if (e.key === 'Escape') return;
    }
    if (this.ui.modalKey(e)) return e.preventDefault();
    // An armed one-click mode ends with any other key than Esc (which cancels it below).
    if (this.ui.armed && !MODIFIERS.has(e.key) && e.key !== 'Escape') this.ui.disarm(`"${e.key}"`);
    const key = e.key.toLowerCase();
    const s = this.s;
    const ctrl = e.ctrlKey || e.metaKey;
    const views: Record<string, [number, number, number]> = { Numpad1: [0, 0, 1], Numpad3: [1, 0, 0], Numpad7: [0, 1, 0] };
    const turns: Record<string, [number, number]> = { Numpad4: [-kOrbitStep, 0], Numpad6: [kOrbitStep, 0],
      Numpad8: [0, kOrbitStep], Numpad2: [0, -kOrbitStep], Numpad9: [180, 0] };
    // Disconnected, only the view keys act.
    const viewKey = views[e.code] !== undefined || turns[e.code] !== undefined || e.code === 'NumpadDecimal' || e.code === 'Numpad5' ||
      e.key === 'Home' || e.key === 'Escape' || e.key === '?' || (key === 'n' && !e.shiftKey);
    if (s.phase.kind === 'disconnected' && !viewKey) {
      if (e.key.length === 1) s.note(`"${e.key}" does nothing while disconnected: the edit waits for the server`);
      return;
    }
    const tools: Record<string, Tool> = { Digit1: 'handle', Digit2: 'fixed', Digit3: 'erase', Digit4: 'move', Digit5: 'pin' };
    if (views[e.code]) {
      e.preventDefault();
      s.viewer.lookFrom(new THREE.Vector3(...views[e.code]).multiplyScalar(ctrl ? -1 : 1));
    } else if (turns[e.code]) {
      e.preventDefault();
      s.viewer.orbitBy(...turns[e.code]);
    } else if (e.code === 'Numpad5') {
      e.preventDefault();
      s.note(`${s.viewer.toggleProjection()} view (numpad 5 switches back)`);
    } else if (e.key === '?') {
      this.toggleKeymap();
    } else if (e.code === 'NumpadDecimal') {
      this.ui.frameSelection();
    } else if (ctrl && key === 'z') {
      e.preventDefault();
      this.undo(e.shiftKey);
    } else if (ctrl && key === 'y') {
      e.preventDefault();
      this.undo(true);
    } else if (ctrl && key === 'i') {
      e.preventDefault();
      this.ui.selectTopology('invert');
    } else if (ctrl && (e.code === 'NumpadAdd' || e.code === 'Equal')) {
      e.preventDefault();
      this.ui.selectTopology('grow');
    } else if (ctrl && (e.code === 'NumpadSubtract' || e.code === 'Minus')) {
      e.preventDefault();
      this.ui.selectTopology('shrink');
    } else if (e.altKey && key === 'z') {
      $<HTMLInputElement>('xray').click();
    } else if (e.altKey && key === 'a') {
      e.preventDefault();
      this.ui.selectTopology('none');
    } else if (e.altKey && key === 'h') {
      e.preventDefault();
      this.ui.reveal();
    } else if (e.shiftKey && key === 'h' && !ctrl) {
      this.ui.hideUnselected();
    } else if ((key === 'x' || e.key === 'Delete') && !ctrl && !e.altKey) {
      s.note('nothing is deleted here: Erase (3) clears labels, H or Shift+H hides, Alt+A clears the tool\'s label');
    } else if (e.key === 'Tab' && !ctrl && !e.altKey) {
      e.preventDefault(); // as Blender's Tab: between painting and moving
      this.ui.setTool(this.ui.tool === 'move' ? this.ui.paintTool : 'move');
    } else if (e.key === 'Escape') {
      if (!$('keymap').hidden) $('keymap').hidden = true;
      else this.ui.cancel();
    } else if (e.key === 'Home') {
      s.viewer.frame();
    } else if (!ctrl && !e.altKey) {
      const modes: Record<string, Mode> = { g: 'grab', r: 'rotate', s: 'scale' };
      if (tools[e.code]) this.ui.setTool(tools[e.code]);
      else if (modes[key]) this.ui.startModal(modes[key]);
      else if (key === 'n' && e.shiftKey) $('new-group').click();
      else if (key === 'n') this.togglePanel();
      else if (key === 'h') this.ui.armHide();
      else if (key === 'l') this.ui.selectTopology('linked');
      else if (key === 'b') this.ui.armBox();
      else if (key === 'a') this.ui.selectTopology('all');
      else if (key === 'f') this.ui.frameSelection();
    }
  }

  // The status over the viewport; a stage that lasts says for how long, so that its line moves
  // at least once a second (the 1 s timer) even where the server reports no fraction.
  private renderStatus(): void {
    const s = this.s;
    const phase = s.phase;
    const r = s.ready;
    const mb = (bytes: number) => (bytes / 1e6).toFixed(1);
    const receiving = s.receiving && `receiving the mesh… ${mb(s.receiving.bytes)} of ${mb(s.receiving.total)} MB`;
    const [text, cls] = (() => {
      switch (phase.kind) {
        case 'connecting': return [s.connection.open ? `Connected: ${receiving ?? 'receiving the mesh…'}` : 'Connecting to the server…', 'busy'];
        case 'disconnected': return ['Disconnected — edits are paused', 'down'];
        case 'empty': return ['No mesh is open: open one (Open mesh…, or drop a file) or the Demo', 'busy'];
        case 'loading': return [`${receiving ? `${receiving} · ` : ''}${this.aged(phase.stage, progressText(phase))}${s.preparing ? ' · paint handles and fixed parts meanwhile' : ''}`, 'busy'];
        case 'busy': return [`${phase.what}: waiting for the server…`, 'busy'];
        case 'ready': return s.server?.detail_pending
          ? [`${r ? `${r.name}: ` : ''}working: factoring the transfer's details (displacements until then)`, 'busy']
          : s.saving ? [`${r ? `${r.name}: ` : ''}ready · saving the basis for next time`, 'ready']
            : [r ? `${r.name}: ready` : 'ready', 'ready'];
      }
    })();
    const working = cls === 'busy' && phase.kind !== 'loading' && phase.kind !== 'empty';
    const factoring = phase.kind === 'ready' && !!s.server?.detail_pending;
    setText($('status'), working ? this.aged(text, text, factoring ? s.detailSince : undefined) : text);
    $('status').className = cls;
    if (phase.kind === 'loading') setText($('progress-stage'), this.aged(phase.stage, progressText(phase)));
  }

  // `text` with the seconds since `stage` began (from 1 s on), or since `since` where the state
  // knows when the wait began.
  private aged(stage: string, text: string, since?: number): string {
    const now = performance.now();
    if (stage !== this.stage.name) this.stage = { name: stage, since: now };
    const seconds = Math.floor((now - (since ?? this.stage.since)) / 1000);
    return seconds >= 1 ? `${text} · ${seconds} s` : text;
  }
  private stage = { name: '', since: 0 };

  // ------------------------------------------------------------ rendering

  private render(): void {
    const s = this.s;
    const phase = s.phase;
    const connected = s.connection.open;
    const editable = s.editable;
    const r = s.ready;

    this.renderStatus();
    const c = s.counts();
    $('hint').textContent = s.paintable ? this.nextStep(c) : '';
    // The page's own counts from the first stroke on, painted while the basis computes too; the
    // server's (free pieces, held vertices, modes per piece) once it is ready.
    const served = !!r && editable;
    $('counts').textContent = served || s.paintable
      ? `handles: ${numbers.format(c.handles)} vertices in ${c.groups} group${c.groups === 1 ? '' : 's'} · ` +
        `fixed: ${numbers.format(c.fixed)} · pinned: ${numbers.format(c.pinned)}` +
        (served && s.server?.free_pieces ? ` · ${s.server.free_pieces} piece(s) without handles ${s.ready?.settings.unconstrained === 'keep' ? 'held in place' : 'follow the surface'}` : '') +
        (served && s.influenceHeld ? ` · ${numbers.format(s.influenceHeld)} held beyond the region of influence (grey)` : '') +
        (s.viewer.hiddenCount ? ` · hidden: ${numbers.format(s.viewer.hiddenCount)} (Alt+H shows them)` : '') +
        (served && (s.server?.constrained_piece_modes?.length ?? 0) > 1 ? ` · modes per constrained piece: ${s.server!.constrained_piece_modes.join(', ')}` : '')
      : '';
    this.renderNotes();

    // Progress with Cancel.
    const loading = phase.kind === 'loading';
    $('progress').hidden = !loading;
    $('progress').classList.toggle('aside', s.preparing); // the mesh it prepares is painted meanwhile
    if (loading) {
      $<HTMLProgressElement>('progress-bar').value = phase.fraction;
      $<HTMLButtonElement>('cancel').hidden = !phase.cancellable;
    } else {
      $('cancel').textContent = 'Cancel';
    }

    // The panel: what can be done now.
    $('mesh-name').textContent = r
      ? `${r.name}: ${numbers.format(r.vertices)} vertices, ${numbers.format(r.faces)} triangles`
      : phase.kind === 'empty' ? 'no mesh open' : phase.kind === 'loading' ? 'preparing the mesh…' : 'connecting…';
    const enable = (id: string, on: boolean) => ($<HTMLButtonElement>(id).disabled = !on);
    for (const id of ['undo', 'redo', 'reset', 'apply-pose', 'export-mesh', 'export-scene', 'clear', 'new-group',
      'energy', 'ks', 'kb', 'detail', 'constraints', 'unconstrained', 'influence', 'modes', 'show-base', 'group', 'export-format', 'gizmo-translate',
      'gizmo-rotate', 'gizmo-scale', 'pivot', 'select-linked', 'select-invert', 'select-grow', 'select-shrink', 'select-box', 'xray']) {
      enable(id, editable);
    }
    enable('open-demo', connected && phase.kind !== 'loading' && phase.kind !== 'busy');
    document.querySelectorAll<HTMLLabelElement>('label.button').forEach((l) => {
      const input = l.querySelector('input')!;
      const on = connected && (phase.kind === 'ready' || (phase.kind === 'empty' && input.id === 'open-mesh'));
      input.disabled = !on;
      l.classList.toggle('disabled', !on);
    });
    enable('undo', editable && !!s.server?.undo);
    enable('redo', editable && !!s.server?.redo);
    enable('export-scene', editable && (r?.pose ?? 0) === 0 && s.hasHandles());
    // The rig follows a glTF written as a glTF ("as opened" or either container).
    const gltf = ['', 'gltf', 'glb'].includes($<HTMLSelectElement>('export-format').value);
    $('export-rig-row').hidden = !r || !gltf || (r.rig.morph_targets === 0 && r.rig.skins === 0);
    enable('export-rig', editable);
    enable('apply-pose', editable && s.hasHandles());
    $('pose').textContent = r && r.pose > 0 ? `pose ${r.pose} applied` : '';
    document.querySelectorAll<HTMLButtonElement>('[data-tool]').forEach((b) => {
      b.setAttribute('aria-checked', String(b.dataset.tool === this.ui.tool));
      b.disabled = !(b.dataset.tool === 'move' ? editable : s.paintable);
    });
    const select = $<HTMLSelectElement>('group');
    const groups = s.groups.map((g, k) => ({ g, k })).filter(({ g }) => !g.pinned);
    select.replaceChildren(...groups.map(({ k }) => new Option(`${k + 1}`, `${k}`, false, k === s.activeGroup)));
    const active = s.groups[s.activeGroup];
    select.style.color = `#${(active?.pinned ? PIN_HEX : GROUP_HEX[s.activeGroup % GROUP_HEX.length]).toString(16).padStart(6, '0')}`;
    $('radius-value').textContent = `${$<HTMLInputElement>('radius').value}% of the diagonal`;
    if (phase.kind !== this.lastPhase && (phase.kind === 'ready' || phase.kind === 'empty')) this.renderFields();
    const mesh = r ? `${r.name}:${r.vertices}:${r.faces}` : null;
    if (mesh && mesh !== this.mirrorMesh) {
      this.mirrorMesh = mesh;
      this.ui.xMirror.restore(mesh);
      $<HTMLInputElement>('x-mirror').checked = this.ui.xMirror.on;
    }
    if (phase.kind !== 'busy') this.transientToasts.splice(0).forEach((t) => t.remove());
    if (connected) this.offlineToasts.splice(0).forEach((t) => t.remove());
    this.lastPhase = phase.kind;
    if (!connected || !editable) s.viewer.gizmo.detach();
    else if (this.ui.tool === 'move' && !s.viewer.gizmo.object) this.ui.placeGizmo();
  }

  // What to do next, from what is selected.
  private nextStep(c: ReturnType<EditorState['counts']>): string {
    const tool = HINTS[this.ui.tool];
    if (c.handles === 0) return `${tool} Next: paint a handle (1), paint what must stay (2), then drag it (4).`;
    if (c.fixed + c.pinned === 0) return `${tool} Next: paint what must stay (Fixed, 2), or drag now (Move, 4).`;
    if (this.ui.tool !== 'move') return `${tool} Next: drag the handle (Move, 4).`;
    return `${tool} Then: Export, or Apply pose to edit from this shape.`;
  }

  // Fields show the server's values (after every "ready", and after a rejected change).
  private renderFields(): void {
    const r = this.s.ready;
    if (!r) {
      // Nothing known yet: placeholders, not a default that looks like a setting.
      for (const id of ['modes', 'energy', 'ks', 'kb', 'detail', 'constraints', 'unconstrained', 'influence']) $<HTMLInputElement>(id).value = '';
      $<HTMLInputElement>('show-base').checked = false;
      return this.renderModes();
    }
    $<HTMLInputElement>('modes').value = String(r.modes);
    $<HTMLSelectElement>('energy').value = r.settings.energy;
    $<HTMLInputElement>('ks').value = String(r.settings.ks);
    $<HTMLInputElement>('kb').value = String(r.settings.kb);
    $<HTMLSelectElement>('detail').value = r.settings.detail;
    $<HTMLSelectElement>('constraints').value = r.settings.constraints;
    $<HTMLSelectElement>('unconstrained').value = r.settings.unconstrained;
    $<HTMLInputElement>('influence').value = String(+(100 * r.settings.influence).toFixed(2));
    $<HTMLInputElement>('show-base').checked = r.settings.view === 'base';
    this.renderModes();
  }

  // The Apply button of m, with what a new basis would cost.
  private renderModes(): void {
    const r = this.s.ready;
    const m = Number($<HTMLInputElement>('modes').value);
    const changed = r !== null && Number.isInteger(m) && m >= 1 && m !== r.modes;
    $<HTMLButtonElement>('apply-modes').disabled = !changed || !this.s.editable;
    let cost = '';
    if (changed && r) {
      cost = r.basis.source === 'computed'
        ? `about ${Math.max(0.1, (r.basis.seconds * m) / r.modes).toFixed(1)} s to compute (m = ${r.modes} took ${r.basis.seconds.toFixed(1)} s); Cancel stops it`
        : `a new basis of ${numbers.format(r.vertices)} vertices (seconds to minutes); Cancel stops it`;
    }
    $('modes-cost').textContent = cost;
  }

  private renderNotes(): void {
    const s = this.s;
    const notes = $('notes');
    for (; this.shownNotes < s.notes.length; ++this.shownNotes) {
      const note = s.notes[this.shownNotes];
      const el = document.createElement('div');
      el.className = `note ${note.level}`;
      el.setAttribute('role', note.level === 'error' ? 'alert' : 'status');
      const text = document.createElement('span');
      text.textContent = note.text;
      const close = document.createElement('button');
      close.textContent = '×';
      close.title = 'dismiss';
      close.onclick = () => el.remove();
      el.append(text, close);
      notes.append(el);
      // Information fades; errors stay until dismissed.
      if (note.transient) this.transientToasts.push(el);
      else if (note.offline) this.offlineToasts.push(el);
      else if (note.level === 'info') setTimeout(() => el.remove(), 6000);
      while (notes.children.length > 4) notes.firstElementChild!.remove();
      const li = document.createElement('li');
      li.className = note.level;
      li.textContent = `${new Date(note.time).toLocaleTimeString()} ${note.text}`;
      $('log').append(li);
      while ($('log').children.length > 30) $('log').firstElementChild!.remove();
    }
    if (s.notes.length < this.shownNotes) this.shownNotes = s.notes.length;
  }

  private renderBanner(): void {
    const phase = this.s.phase;
    const banner = $('banner');
    banner.hidden = phase.kind !== 'disconnected';
    if (phase.kind !== 'disconnected') return;
    const wait = phase.retryAt === null ? null : Math.max(0, Math.ceil((phase.retryAt - performance.now()) / 1000));
    $('banner-text').textContent = `Disconnected: ${phase.reason}. ` +
      (wait === null ? 'Edits are paused.' : `Reconnecting in ${wait} s; edits are paused.`);
  }

  // The result against the input: area, volume (closed meshes), the largest stretch.
  private renderMeasures(): void {
    const m = this.s.editable ? this.s.measures : null;
    const percent = (x: number) => `${x >= 0 ? '+' : ''}${(100 * x).toFixed(1)}%`;
    const rows: [string, string][] = [
      ['area change', m ? percent(m.area) : '–'],
      ['volume change', m ? (m.volume === null ? 'open surface: no volume' : percent(m.volume)) : '–'],
      ['largest edge stretch', m ? percent(m.stretch) : '–'],
    ];
    $('measures').replaceChildren(...rows.map(([k, v]) => {
      const tr = document.createElement('tr');
      tr.append(Object.assign(document.createElement('td'), { textContent: k }),
        Object.assign(document.createElement('td'), { textContent: v }));
      return tr;
    }));
  }

  private renderTimings(): void {
    const s = this.s;
    const r = s.ready;
    const f = s.frame;
    const now = performance.now();
    const lastSecond = stats.drawTimes.filter((t) => now - t < 1000).length;
    const median = (v: number[]) => (v.length ? [...v].sort((a, b) => a - b)[Math.floor(v.length / 2)] : NaN);
    // The readouts of drawing say their age once nothing has been drawn for two seconds.
    const last = stats.drawTimes.at(-1);
    const idle = last === undefined ? 0 : (now - last) / 1000;
    const age = idle < 2 ? '' : ` (last drawn ${idle < 60 ? `${idle.toFixed(0)} s` : `${(idle / 60).toFixed(0)} min`} ago)`;
    const rows: [string, string][] = [
      ['basis', r ? `${r.basis.seconds.toFixed(2)} s (${r.basis.source}, m = ${r.modes}${
        r.basis.approximate ? `, approximate: multilevel; its modes are only close to the true frequencies ` +
          `(residual ${r.basis.residual.toPrecision(2)}: how far each is from an exact eigenvector, relative to its frequency)` : ''})` : '–'],
      ['selection', s.server ? `${(1000 * s.server.selection_seconds).toFixed(1)} ms` : '–'],
      ['solve (server)', f ? `${f.ms.total.toFixed(1)} ms` : '–'],
      ['· reduced / inverse / detail', f
        ? `${f.ms.reducedSolve.toFixed(1)} / ${f.ms.inverseTransform.toFixed(1)} / ${f.ms.detail.toFixed(1)}${
          f.foldZone ? ' (the smooth base folded: details added as displacements there)' : ''}` : '–'],
      ['ARAP iterations', r?.settings.energy === 'arap' && f
        ? `${f.arap.iterations}${f.arap.converged ? '' : ' (not converged)'} · ${r.arap_clusters} clusters` : '–'],
      ['drag → drawn (median)', stats.latencies.length ? `${median(stats.latencies.slice(-30)).toFixed(0)} ms${age}` : '–'],
      ['updates drawn per second', `${lastSecond}${age}`],
      ['full draw / preview', s.drawMs ? `${s.drawMs.toFixed(0)} ms / ${s.previewWanted ? `${numbers.format(s.viewer.previewSize)} vertices` : 'off'}` : '–'],
      ['smooth base misses the handles by', f ? `${(100 * f.error.max).toPrecision(2)}% of the diagonal` : '–'],
    ];
    $('timings').replaceChildren(...rows.map(([k, v]) => {
      const tr = document.createElement('tr');
      tr.append(Object.assign(document.createElement('td'), { textContent: k }),
        Object.assign(document.createElement('td'), { textContent: v }));
      return tr;
    }));
  }
}
