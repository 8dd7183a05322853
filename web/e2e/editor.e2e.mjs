// End-to-end test of the browser editor in real Chromium (Debian's chromium, driven by
// playwright-core) at 1280 x 800: start `specdeform edit`, and as a user would:
//  - a rejected setting (kb = 0) shows its error over the viewport and the field the server's
//    value; the next valid setting is applied (the page never waits forever); hard then soft;
//  - typing m and Enter leaves the field: "2" then picks the Fixed tool instead of typing;
//  - paint a handle and a fixed region with the brush, drag the handle with the mouse, check
//    what the server sent back and what was drawn, and measure the drawn updates per second
//    against the server's own results per second (frames sent at 60 Hz, results not drawn);
//  - export the mesh (in the file's numbering, unused vertices included), undo and redo, change
//    the detail method;
//  - reload the page: the selection, transforms, deformation and undo come back;
//  - restart the server: the page reconnects by itself and gives the new server its edit back;
//  - Blender's modal transforms with typed values: G X d, R Z 90 and S X 1.5 give exactly that
//    transform about the handle's centroid (the server's result follows it), Esc and a
//    right-click cancel; the area, volume and stretch readouts; the numpad's views; select
//    linked, invert, grow and shrink;
//  - open another mesh, confirming that the edit is discarded;
//  - open a textured .glb (its texture drawn), export it as opened: the same file; open an OBJ
//    with its MTL and image chosen together: textured too.
//
//   node e2e/editor.e2e.mjs [--mesh FILE] [--seconds S] [--out DIR] [--quick] [--min-ratio R]
//
// Without --mesh it uses the built-in demo model. --quick: the drag and the rates only (large
// meshes). --min-ratio R: fail unless drawn updates per second >= R x the server's results per
// second. Prints one JSON line of measurements and writes editor.json and editor.png to --out.
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { basename, dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseArgs } from 'node:util';
import { check, launchChromium, log, startEditor } from './harness.mjs';
import { writeTexturedGlb, writeTexturedObj } from './textured.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const { values: args } = parseArgs({
  options: {
    mesh: { type: 'string' },
    seconds: { type: 'string', default: '2' },
    out: { type: 'string', default: 'e2e-output' },
    binary: { type: 'string', default: resolve(here, '../../build/bin/specdeform') },
    chromium: { type: 'string', default: process.env.CHROMIUM ?? '/usr/bin/chromium' },
    quick: { type: 'boolean', default: false },
    'min-ratio': { type: 'string' },
  },
});
const meshArgs = args.mesh ? [args.mesh] : [];

const percentile = (values, p) => {
  const s = [...values].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(p * s.length))];
};

let editor = startEditor(args.binary, meshArgs);
const url = await editor.url;
const port = Number(new URL(url).port);
const browser = await launchChromium(args.chromium);
mkdirSync(args.out, { recursive: true });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(url);
  const waitReady = (timeout = 180000) =>
    page.waitForFunction(() => window.specdeformEditor?.ready && window.specdeformEditor.settled(), null, { timeout });
  await waitReady();
  const api = (fn, arg) => page.evaluate(fn, arg);
  // The key map's rows (keymap.ts) each test exercises: every one by the end.
  const covered = new Set();
  const cover = (...rows) => rows.forEach((row) => covered.add(row));

  // Every message over the viewport is in view without scrolling.
  const noteInView = async (pattern) => {
    const notes = await page.$$eval('#notes .note', (els) => els.map((e) => {
      const r = e.getBoundingClientRect();
      return { text: e.textContent, top: r.top, bottom: r.bottom, left: r.left, right: r.right, error: e.classList.contains('error') };
    }));
    const note = notes.find((n) => pattern.test(n.text));
    check(note, `a message matching ${pattern} is shown (${JSON.stringify(notes.map((n) => n.text))})`);
    check(note.top >= 0 && note.bottom <= 800 && note.left >= 0 && note.right <= 1280, `it is in view: ${JSON.stringify(note)}`);
    return note;
  };

  if (!args.quick) {
    // 1-2: a rejected setting, then valid ones: each ends in a usable page.
    log('settings: rejected, then valid');
    await page.fill('#kb', '0');
    await page.press('#kb', 'Enter');
    await waitReady(30000);
    const rejected = await noteInView(/kb/);
    check(rejected.error, 'the rejected setting is shown as an error');
    check((await page.inputValue('#kb')) === '1', `the field shows the server's kb again (${await page.inputValue('#kb')})`);
    await page.waitForTimeout(1500);
    await noteInView(/kb/); // errors stay until dismissed
    await page.fill('#kb', '2');
    await page.press('#kb', 'Enter');
    await waitReady(30000);
    check((await page.inputValue('#kb')) === '2', 'kb = 2 was applied');
    for (const mode of ['hard', 'soft']) {
      await page.selectOption('#constraints', mode);
      await waitReady(30000);
      check((await page.inputValue('#constraints')) === mode, `constraints ${mode} applied`);
    }
    // 3: Enter leaves the field; "2" is a shortcut again, not a digit of m.
    log('keyboard focus');
    await page.fill('#modes', '50');
    await page.press('#modes', 'Enter');
    await page.waitForFunction(() => document.activeElement === document.body || document.activeElement === null);
    await page.keyboard.press('2');
    check((await page.inputValue('#modes')) === '50', `m is not typed into (${await page.inputValue('#modes')})`);
    check((await page.getAttribute('[data-tool="fixed"]', 'aria-checked')) === 'true', '"2" picked the Fixed tool');
    cover('tools');
    await waitReady(120000); // Enter applied m = 50: a new basis
    check((await page.inputValue('#modes')) === '50', 'm = 50 was applied');
  }

  // Messages read, as a user would dismiss them before painting under them.
  for (const close of await page.$$('#notes .note button')) await close.click();

  // The two ends of the model along its longest axis, among the vertices facing the camera.
  const ends = await api(() => {
    const e = window.specdeformEditor;
    const p = e.restPositions();
    const n = p.length / 3;
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; ++i) {
      lo[i % 3] = Math.min(lo[i % 3], p[i]);
      hi[i % 3] = Math.max(hi[i % 3], p[i]);
    }
    const axis = [0, 1, 2].reduce((a, k) => (hi[k] - lo[k] > hi[a] - lo[a] ? k : a), 0);
    const rect = document.querySelector('#view canvas').getBoundingClientRect();
    const cam = e.cameraPosition();
    const d = (v) => Math.hypot(p[3 * v] - cam[0], p[3 * v + 1] - cam[1], p[3 * v + 2] - cam[2]);
    // Nearest to the camera among the visible extreme 3% along the axis: certainly in front.
    const pick = (sign) => {
      let best = -1;
      for (let v = 0; v < n; ++v) {
        const far = sign * (p[3 * v + axis] - (sign > 0 ? hi[axis] : lo[axis])) > -0.03 * (hi[axis] - lo[axis]);
        if (!far) continue;
        const s = e.vertexOnScreen(v);
        if (s.x < rect.left + 20 || s.x > rect.right - 20 || s.y < rect.top + 20 || s.y > rect.bottom - 40) continue;
        if (best < 0 || d(v) < d(best)) best = v;
      }
      return best;
    };
    return { handle: pick(1), fixed: pick(-1), n };
  });
  check(ends.handle >= 0 && ends.fixed >= 0, `both ends are visible (${JSON.stringify(ends)})`);
  const screen = (v) => api((v) => window.specdeformEditor.vertexOnScreen(v), v);
  const click = async (v) => {
    const s = await screen(v);
    await page.mouse.move(s.x, s.y);
    await page.mouse.down();
    await page.mouse.up();
    await waitReady(60000);
  };

  // Paint: a handle at one end, the fixed set at the other.
  log('paint');
  await page.click('[data-tool="handle"]');
  await click(ends.handle);
  await page.click('[data-tool="fixed"]');
  await page.fill('#radius', '10');
  await click(ends.fixed);
  const labels = await api(() => window.specdeformEditor.labels());
  const handles = labels.flatMap((l, v) => (l === 2 ? [v] : []));
  const fixed = labels.flatMap((l, v) => (l === 1 ? [v] : []));
  check(handles.length > 0 && fixed.length > 0, `brush selected ${handles.length} handle and ${fixed.length} fixed vertices`);
  cover('paint');

  // Drag the handle up the screen, at about 60 mouse events per second.
  log('drag');
  await page.click('[data-tool="move"]');
  const start = await screen(ends.handle);
  const counts = () => api(() => {
    const s = window.specdeformEditor.stats;
    return { drawn: s.framesDrawn, received: s.framesReceived, previews: s.previewsDrawn, latencies: s.latencies.length, receive: s.receiveLatencies.length };
  });
  const before = await counts();
  const seconds = Number(args.seconds);
  const steps = Math.max(10, Math.round(60 * seconds));
  const lift = 120;
  await page.mouse.move(start.x, start.y);
  await page.mouse.down();
  const t0 = Date.now();
  for (let i = 1; i <= steps; ++i) {
    await page.mouse.move(start.x, start.y - (lift * i) / steps);
    const wait = t0 + (1000 * seconds * i) / steps - Date.now();
    if (wait > 0) await page.waitForTimeout(wait);
  }
  const dragSeconds = (Date.now() - t0) / 1000;
  const after = await counts();
  await page.mouse.up();
  await waitReady(60000);
  // The server alone, in the same run: frames at 60 Hz, results counted, not drawn.
  const serverRate = await api(() => window.specdeformEditor.measureServer(3));
  await waitReady(60000);

  const state = await api(() => {
    const e = window.specdeformEditor;
    return { rest: e.restPositions(), now: e.positions(), transforms: e.transforms(), diagonal: e.diagonal(), stats: e.stats, preview: e.previewSize() };
  });
  const t = state.transforms[0];
  const translation = [t[3], t[7], t[11]];
  check(Math.hypot(...translation) > 0.02 * state.diagonal, `the handle moved (translation ${translation})`);
  const error = (v, target) => Math.hypot(...[0, 1, 2].map((k) => state.now[3 * v + k] - target[k])) / state.diagonal;
  const target = (v) => [0, 1, 2].map((k) => state.rest[3 * v + k] + translation[k]);
  let handleError = 0;
  for (const v of handles) handleError = Math.max(handleError, error(v, target(v)));
  let fixedError = 0;
  for (const v of fixed) fixedError = Math.max(fixedError, error(v, [0, 1, 2].map((k) => state.rest[3 * v + k])));
  check(handleError < 2e-3, `handle vertices reach their targets (max error ${handleError} of the diagonal)`);
  check(fixedError < 2e-3, `fixed vertices stay (max error ${fixedError} of the diagonal)`);
  const end = await screen(ends.handle);
  check(Math.abs(end.y - (start.y - lift)) < 0.15 * lift && Math.abs(end.x - start.x) < 0.15 * lift,
    `the handle followed the mouse on screen: from (${start.x}, ${start.y}) to (${end.x}, ${end.y}), mouse moved ${lift} px up`);
  let movedFree = 0;
  labels.forEach((l, v) => {
    if (l === 0 && error(v, [0, 1, 2].map((k) => state.rest[3 * v + k])) > 1e-3) ++movedFree;
  });
  check(movedFree > 0, 'free vertices follow the handle');

  // What was drawn is not blank: the canvas has the model's shades, not just the background.
  const drawn = await api(() => {
    const gl = document.querySelector('#view canvas');
    const c = document.createElement('canvas');
    c.width = gl.width;
    c.height = gl.height;
    const ctx = c.getContext('2d');
    ctx.drawImage(gl, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const [r0, g0, b0] = [d[0], d[1], d[2]];
    let differing = 0;
    const shades = new Set();
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - r0) + Math.abs(d[i + 1] - g0) + Math.abs(d[i + 2] - b0) > 30) ++differing;
      shades.add(d[i] >> 3);
    }
    return { fraction: differing / (d.length / 4), shades: shades.size };
  });
  check(drawn.fraction > 0.03 && drawn.shades > 8, `the canvas shows the model (${JSON.stringify(drawn)})`);
  await page.screenshot({ path: resolve(args.out, 'editor.png') });

  const latencies = state.stats.latencies.slice(before.latencies, after.latencies);
  const receive = state.stats.receiveLatencies.slice(before.receive, after.receive);
  const drawnRate = (after.drawn - before.drawn) / dragSeconds;
  const result = {
    mesh: args.mesh ? basename(args.mesh) : 'demo (bumpy bar)',
    vertices: ends.n,
    handle_vertices: handles.length,
    fixed_vertices: fixed.length,
    drag_seconds: dragSeconds,
    mouse_events: steps,
    updates_per_second: drawnRate,
    previews_per_second: (after.previews - before.previews) / dragSeconds,
    preview_vertices: state.preview,
    server_results_per_second: serverRate,
    drawn_over_server: drawnRate / serverRate,
    response_ms_median: percentile(latencies, 0.5),
    response_ms_p90: percentile(latencies, 0.9),
    results_per_second_during_drag: (after.received - before.received) / dragSeconds,
    result_ms_median: percentile(receive, 0.5),
    handle_error: handleError,
    fixed_error: fixedError,
  };
  writeFileSync(resolve(args.out, 'editor.json'), JSON.stringify(result, null, 1) + '\n');
  if (ends.n < 50000) {
    check(state.preview === 0 && result.previews_per_second === 0,
      `a mesh of ${ends.n} vertices (under 50,000) is dragged whole, its look kept (preview ${state.preview})`);
  }
  console.log(JSON.stringify(result));
  if (args['min-ratio']) {
    check(result.drawn_over_server >= Number(args['min-ratio']),
      `drawn updates per second ${drawnRate.toFixed(1)} >= ${args['min-ratio']} x the server's ${serverRate.toFixed(1)}`);
  }

  if (!args.quick) {
    // Export: the downloaded OBJ holds what is shown, in the file's numbering: a vertex the
    // reader dropped (used by no face) is written where the file had it.
    log('export');
    await page.selectOption('#export-format', 'obj');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-mesh')]);
    const exported = readFileSync(await download.path(), 'utf8').split('\n').filter((l) => l.startsWith('v '))
      .map((l) => l.split(/\s+/).slice(1, 4).map(Number));
    const original = args.mesh
      ? readFileSync(args.mesh, 'utf8').split('\n').filter((l) => l.startsWith('v ')).map((l) => l.trim().split(/\s+/).slice(1, 4).map(Number))
      : null;
    const key = (p) => p.map((x) => Math.fround(x)).join(',');
    if (original) {
      check(exported.length === original.length, `the export has the file's ${original.length} vertices (${exported.length})`);
      const fileIndex = new Map(original.map((p, i) => [key(p), i]));
      const used = new Set();
      let exportError = 0;
      for (let v = 0; v < ends.n; ++v) {
        const i = fileIndex.get(key([0, 1, 2].map((k) => state.rest[3 * v + k])));
        check(i !== undefined, `mesh vertex ${v} is a vertex of the file`);
        used.add(i);
        exportError = Math.max(exportError, ...[0, 1, 2].map((k) => Math.abs(exported[i][k] - state.now[3 * v + k])));
      }
      check(exportError < 1e-5 * state.diagonal, `the export matches the view (${exportError})`);
      original.forEach((p, i) => {
        if (!used.has(i)) check(p.every((x, k) => Math.abs(x - exported[i][k]) < 1e-6 * state.diagonal), `unused file vertex ${i} is kept`);
      });
    } else {
      check(exported.length === ends.n, `the export has ${exported.length} of ${ends.n} vertices`);
      let exportError = 0;
      exported.forEach((p, v) => (exportError = Math.max(exportError, ...p.map((x, k) => Math.abs(x - state.now[3 * v + k])))));
      check(exportError < 1e-5 * state.diagonal, `the export matches the view (${exportError})`);
    }

    // Undo puts the handle back (the rest shape), redo moves it again.
    log('undo, redo, settings');
    const restError = async () => {
      await waitReady(60000);
      return api(() => {
        const e = window.specdeformEditor;
        const [p, r] = [e.positions(), e.restPositions()];
        let m = 0;
        for (let i = 0; i < p.length; ++i) m = Math.max(m, Math.abs(p[i] - r[i]));
        return m / e.diagonal();
      });
    };
    await page.evaluate(() => document.activeElement?.blur());
    await page.keyboard.press('Control+z');
    check((await restError()) < 1e-5, 'undo returns to the rest shape');
    await page.keyboard.press('Control+Shift+z');
    check((await restError()) > 0.02, 'redo deforms it again');
    cover('undo');

    // A detail method from the panel: the server rebuilds and the frame comes back solved with it.
    await page.selectOption('#detail', 'displacement');
    await waitReady(60000);
    check((await page.inputValue('#detail')) === 'displacement', 'the detail method was applied');
    check((await restError()) > 0.02, 'the deformation survives a settings change');

    // 6: a reload gets the whole edit back from the server.
    log('reload');
    const snapshot = () => api(() => {
      const e = window.specdeformEditor;
      return { labels: e.labels(), transforms: e.transforms(), detail: document.querySelector('#detail').value,
        undo: !document.querySelector('#undo').disabled };
    });
    const edited = await snapshot();
    await page.reload();
    await waitReady();
    const reloaded = await snapshot();
    check(JSON.stringify(reloaded.labels) === JSON.stringify(edited.labels), 'the reload restores the selection');
    check(JSON.stringify(reloaded.transforms) === JSON.stringify(edited.transforms), 'the reload restores the transforms');
    check(reloaded.detail === 'displacement' && reloaded.undo, 'the reload restores the settings and undo');
    check((await restError()) > 0.02, 'the reload restores the deformation');

    // 6: the server restarts; the page reconnects by itself and restores its edit there.
    log('server restart');
    // A move under way (G) when the server goes: cancelled at once, nothing of it left on screen,
    // said on reconnection.
    const middle = await page.$eval('#view canvas', (c) => { const r = c.getBoundingClientRect(); return { x: r.left + r.width / 2, y: r.top + r.height / 2 }; });
    const beforeMove = await snapshot();
    await page.evaluate(() => document.activeElement?.blur());
    await page.mouse.move(middle.x, middle.y);
    await page.keyboard.press('g');
    await page.mouse.move(middle.x + 60, middle.y + 20, { steps: 4 });
    editor.server.kill();
    await page.waitForSelector('#banner:not([hidden])', { timeout: 10000 });
    check(await page.isHidden('#preview-label'), 'no "preview; detail on release" left once the server is gone');
    check(await page.isHidden('#header'), 'no move header left once the server is gone');
    check(JSON.stringify((await snapshot()).transforms) === JSON.stringify(beforeMove.transforms), 'the move under way was cancelled');
    const banner = await page.$eval('#banner', (b) => { const r = b.getBoundingClientRect(); return { text: b.textContent, top: r.top }; });
    check(/Disconnected/.test(banner.text) && banner.top >= 0, `a banner says the page is disconnected (${banner.text})`);
    check(await page.$eval('#export-mesh', (b) => b.disabled), 'Export is disabled while disconnected');
    check(await page.$eval('#gizmo-rotate', (b) => b.disabled), 'the transform tools are disabled while disconnected');
    await page.keyboard.press('g'); // a key while disconnected: says why it does nothing
    editor = startEditor(args.binary, meshArgs, port);
    await editor.url;
    await page.waitForSelector('#banner', { state: 'hidden', timeout: 60000 });
    await waitReady();
    const stale = await page.$$eval('#notes .note', (ns) => ns.map((n) => n.textContent).filter((t) => /disconnected/.test(t)));
    check(stale.length === 0, `reconnected, the messages raised while disconnected are gone (${stale})`);
    await page.waitForFunction(() => window.specdeformEditor.settled() && document.querySelector('#detail').value === 'displacement',
      null, { timeout: 120000 });
    const restored = await snapshot();
    check(JSON.stringify(restored.labels) === JSON.stringify(edited.labels), 'the restarted server got the selection back');
    check(JSON.stringify(restored.transforms) === JSON.stringify(edited.transforms), 'and the transforms');
    // The restored transforms' frame follows the restored selection: on a loaded machine it can
    // come after the page has settled, so wait for it (up to 30 s) rather than look once.
    let restoredError = await restError();
    for (const end = Date.now() + 30000; restoredError <= 0.02 && Date.now() < end;) {
      await page.waitForTimeout(250);
      restoredError = await restError();
    }
    check(restoredError > 0.02, `and the deformation (${restoredError} of the diagonal from the rest shape)`);
    const notes = await api(() => window.specdeformEditor.notes().map((n) => n.text));
    check(notes.some((n) => /restarted/.test(n)), `the page says the server restarted (${JSON.stringify(notes)})`);
    check(notes.some((n) => /the move \(G\) was cancelled when the connection was lost/.test(n)), 'the page says the move under way was lost');

    await transformsAndSelection();

    // Another mesh through the file picker: the edit is discarded only once confirmed.
    log('open another mesh');
    const sphere = resolve(args.out, 'sphere.off');
    execFileSync(args.binary, ['generate', 'icosphere', '--subdivisions', '2', '-o', sphere]);
    await page.setInputFiles('#open-mesh', sphere);
    await page.waitForSelector('#confirm[open]');
    await page.click('#confirm-no');
    check(!(await page.textContent('#mesh-name')).startsWith('sphere.off'), 'keeping the edit keeps the mesh');
    await page.setInputFiles('#open-mesh', sphere);
    await page.click('#confirm-yes');
    await page.waitForFunction(() => document.querySelector('#mesh-name').textContent.startsWith('sphere.off: 162 vertices'),
      null, { timeout: 60000 });
    const shown = await page.$$eval('#notes .note', (els) => els.map((e) => e.textContent));
    check(!shown.some((t) => /sending/.test(t)), `the "sending" note is gone once the mesh is open (${JSON.stringify(shown)})`);

    await paintedWhileComputing();
    await texturedFiles();
  }

  // A stroke painted while a mesh's basis is computed, then the page reloaded (still computing):
  // the stroke is back, and the server has it once the mesh is ready; likewise in a second window.
  async function paintedWhileComputing() {
    log('painted while the basis computes, reloaded');
    const plane = resolve(args.out, 'plane.obj');
    execFileSync(args.binary, ['generate', 'bumpy-plane', '--resolution', '400', '-o', plane]);
    await page.setInputFiles('#open-mesh', plane);
    if (await page.$('#confirm[open]')) await page.click('#confirm-yes');
    // The mesh is shown (its name only once it is ready).
    const loading = () => window.specdeformEditor.phase === 'loading' && window.specdeformEditor.paintable &&
      window.specdeformEditor.vertices() === 401 * 401;
    await page.waitForFunction(loading, null, { timeout: 60000 });
    await page.click('[data-tool="handle"]');
    const middle = await page.$eval('#view canvas', (c) => { const r = c.getBoundingClientRect(); return { x: r.left + r.width / 2, y: r.top + r.height / 2 }; });
    await page.mouse.move(middle.x, middle.y);
    await page.mouse.down();
    await page.mouse.move(middle.x + 30, middle.y, { steps: 3 });
    await page.mouse.up();
    // The stroke's brush queries answer after the release: its labels are read once it ended.
    await page.waitForFunction(() => window.specdeformEditor.counts().handles > 0 &&
      !window.specdeformEditor.unsettled().waits.includes('a stroke'), null, { timeout: 30000 });
    const painted = await api(() => ({ labels: window.specdeformEditor.labels(), phase: window.specdeformEditor.phase }));
    const handles = painted.labels.filter((l) => l === 2).length;
    log(`${handles} handle vertices painted, phase ${painted.phase}`);
    check(painted.phase === 'loading', `the stroke was painted while the basis computed (${painted.phase})`);
    // A second window takes the session over; then the first, reloaded, takes it back.
    const [second] = await Promise.all([page.waitForEvent('popup'), page.evaluate((u) => window.open(u), page.url())]);
    // The stroke comes back from the page's own record while the basis computes, from the server
    // once it is ready (the window before sent it and dropped the record).
    const keeps = async (p, name) => {
      await p.waitForFunction((n) => window.specdeformEditor?.vertices() === n, painted.labels.length, { timeout: 60000 });
      await p.waitForFunction((want) => {
        const labels = window.specdeformEditor.labels();
        return labels.length === want.length && labels.every((l, i) => l === want[i]);
      }, painted.labels, { timeout: 30000, polling: 200 }).catch(() => {});
      const back = await p.evaluate(() => window.specdeformEditor.labels());
      const tally = (labels) => JSON.stringify(labels.reduce((t, l) => ({ ...t, [l]: (t[l] ?? 0) + 1 }), {}));
      check(JSON.stringify(back) === JSON.stringify(painted.labels),
        `${name} shows the stroke painted while the basis computed (labels ${tally(back)}, painted ${tally(painted.labels)})`);
    };
    await keeps(second, 'a second window');
    await second.close();
    await page.reload();
    await keeps(page, 'the first, reloaded,');
    await waitReady(120000);
    await page.waitForFunction((h) => window.specdeformEditor.serverCounts()?.handles === h, handles, { timeout: 60000 });
  }

  // A textured .glb: drawn with its image, a painted handle visible over it; exported as
  // opened with nothing moved (a handle painted, not dragged), the same bytes. An OBJ chosen
  // with its MTL and image: textured as well.
  async function texturedFiles() {
    log('textured glTF and OBJ');
    const glb = resolve(args.out, 'cube.glb');
    writeTexturedGlb(glb);
    const open = async (files, name) => {
      await page.setInputFiles('#open-mesh', files);
      if (await page.$('#confirm[open]')) await page.click('#confirm-yes');
      await page.waitForFunction((n) => document.querySelector('#mesh-name').textContent.startsWith(n),
        name, { timeout: 60000 });
      await page.waitForFunction(() => window.specdeformEditor.look().textures > 0, null, { timeout: 10000 });
      await waitReady(30000);
      const look = await api(() => window.specdeformEditor.look());
      check(look.present && look.drawn && look.textures === 1, `${name}: its look is drawn with its image (${JSON.stringify(look)})`);
    };
    await open(glb, 'cube.glb: 8 vertices');
    await labelOverTexture();
    await page.screenshot({ path: resolve(args.out, 'textured.png') });
    await page.selectOption('#export-format', '');
    check(!(await page.isVisible('#export-rig')), 'a glTF without morph targets or skins shows no "rig follows"');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-mesh')]);
    check(download.suggestedFilename() === 'cube-deformed.glb', `exported as a .glb (${download.suggestedFilename()})`);
    check(readFileSync(await download.path()).equals(readFileSync(glb)), 'the exported .glb, nothing moved, is the opened one');
    // Move shows the gizmo at the painted handle; another mesh (a plane, nothing painted on it)
    // opened, nothing of the cube's stays: no gizmo.
    await page.evaluate(() => document.activeElement?.blur());
    await page.keyboard.press('4');
    check((await api(() => window.specdeformEditor.gizmoOnScreen())) !== null, 'Move shows the gizmo at the handle');
    const plane = resolve(args.out, 'small-plane.obj');
    execFileSync(args.binary, ['generate', 'bumpy-plane', '--resolution', '24', '-o', plane]);
    await page.setInputFiles('#open-mesh', plane);
    if (await page.$('#confirm[open]')) await page.click('#confirm-yes');
    await page.waitForFunction(() => document.querySelector('#mesh-name').textContent.startsWith('small-plane.obj'), null, { timeout: 60000 });
    await waitReady(30000);
    check((await api(() => window.specdeformEditor.gizmoOnScreen())) === null, 'another mesh opened: the old one\'s gizmo is gone');
    await page.keyboard.press('1');
    await open(writeTexturedObj(args.out), 'cube.obj: 8 vertices');
  }

  // A handle painted on the textured cube's corner nearest the camera is drawn in the handle's
  // orange over the image (the checker is red, white and blue): read from a screenshot near it.
  async function labelOverTexture() {
    const { corner, centre } = await api(() => {
      const e = window.specdeformEditor, p = e.restPositions(), c = e.cameraPosition();
      let corner = 0, centre = { x: 0, y: 0 };
      for (let v = 0; v < p.length / 3; ++v) {
        const d = (w) => Math.hypot(p[3 * w] - c[0], p[3 * w + 1] - c[1], p[3 * w + 2] - c[2]);
        if (d(v) < d(corner)) corner = v;
        const s = e.vertexOnScreen(v);
        centre = { x: centre.x + s.x / 8, y: centre.y + s.y / 8 };
      }
      return { corner, centre };
    });
    await page.click('[data-tool="handle"]');
    const s = await api((v) => window.specdeformEditor.vertexOnScreen(v), corner);
    await page.mouse.click(s.x, s.y);
    await waitReady(30000);
    await page.waitForTimeout(500); // drawn
    const at = { x: Math.round(s.x + 0.15 * (centre.x - s.x)), y: Math.round(s.y + 0.15 * (centre.y - s.y)) };
    const shot = await page.screenshot({ clip: { ...at, width: 12, height: 1 } });
    const pixels = await api(async (png) => {
      const image = new Image();
      image.src = `data:image/png;base64,${png}`;
      await image.decode();
      const canvas = new OffscreenCanvas(image.width, 1), context = canvas.getContext('2d');
      context.drawImage(image, 0, 0);
      const d = Array.from(context.getImageData(0, 0, image.width, 1).data);
      return Array.from({ length: image.width }, (_, i) => d.slice(4 * i, 4 * i + 3));
    }, shot.toString('base64'));
    const [r, g, b] = pixels[0];
    check(r > 1.3 * g && g > 2 * b, `the painted handle shows over the texture (rgb ${r} ${g} ${b} at ${at.x}, ${at.y})`);
    // Striped, so that it shows on a print of its own colour too: light and dark along a row.
    const light = pixels.filter(([pr, pg, pb]) => pr > 1.3 * pg && pr > 2 * pb).map(([pr]) => pr);
    check(light.length >= 6 && Math.max(...light) > 1.2 * Math.min(...light),
      `the handle over the texture is striped (${JSON.stringify(pixels)})`);
  }

  // Typed modal transforms (exact, about the handle's centroid, the result following), cancel,
  // the readouts, the views, and selection by topology. Ends with the handle as the drag left it.
  async function transformsAndSelection() {
    log('modal transforms');
    const canvas = await page.$eval('#view canvas', (c) => { const r = c.getBoundingClientRect(); return { x: r.left + r.width / 2, y: r.top + r.height / 2 }; });
    await page.mouse.move(canvas.x, canvas.y);
    await page.evaluate(() => document.activeElement?.blur());
    const keys = async (...sequence) => {
      for (const k of sequence) await page.keyboard.press(k);
    };
    const transform = () => api(() => window.specdeformEditor.transforms()[0]);
    const result = async () => {
      await waitReady(60000);
      return api(() => {
        const e = window.specdeformEditor;
        return { rest: e.restPositions(), now: e.positions(), labels: e.labels(), t: e.transforms()[0], diagonal: e.diagonal(),
          measures: e.measures() };
      });
    };
    // The handle's vertices reach the transform's targets, as near as soft constraints bring them
    // (m = 50: a move of a fifth of the diagonal within 1e-2 of it, a scale of 1.5 within 2e-2;
    // hard constraints need more modes than constrained vertices).
    const followed = (r) => {
      let worst = 0;
      r.labels.forEach((l, v) => {
        if (l !== 2) return;
        const p = [0, 1, 2].map((k) => r.rest[3 * v + k]);
        const want = [0, 1, 2].map((i) => r.t[4 * i] * p[0] + r.t[4 * i + 1] * p[1] + r.t[4 * i + 2] * p[2] + r.t[4 * i + 3]);
        worst = Math.max(worst, Math.hypot(...want.map((w, k) => w - r.now[3 * v + k])) / r.diagonal);
      });
      return worst;
    };
    const reset = async () => {
      await page.click('#reset');
      await waitReady(60000);
    };
    // Messages over the viewport take clicks: dismissed before clicking the model under them.
    const dismiss = async () => {
      for (const close of await page.$$('#notes .note button')) await close.click().catch(() => {});
    };
    const undoTwice = async () => {
      for (let i = 0; i < 2; ++i) {
        await keys('Control+z');
        await waitReady(60000); // a busy page ignores the next
      }
    };
    const centroid = (r) => {
      const c = [0, 0, 0];
      let n = 0;
      r.labels.forEach((l, v) => l === 2 && (++n, [0, 1, 2].forEach((k) => (c[k] += r.rest[3 * v + k]))));
      return c.map((x) => x / n);
    };
    await reset();
    const view = () => api(() => [window.specdeformEditor.cameraPosition(), window.specdeformEditor.cameraTarget()]);
    const before = JSON.stringify(await view());
    await page.keyboard.press('4');
    check(JSON.stringify(await view()) === before, 'switching to Move leaves the view as it was');
    await page.keyboard.press('NumpadDecimal'); // asked: the handle framed
    // The gizmo is at the pivot, in view and clear of the messages over the viewport.
    const gizmo = await api(() => window.specdeformEditor.gizmoOnScreen());
    const clear = await page.evaluate(() => {
      const c = document.querySelector('#view canvas').getBoundingClientRect();
      return { left: c.left, right: c.right, top: document.querySelector('#overlay').getBoundingClientRect().bottom, bottom: c.bottom };
    });
    check(gizmo && gizmo.x > clear.left && gizmo.x < clear.right && gizmo.y > clear.top && gizmo.y < clear.bottom,
      `the gizmo is in view, below the messages (${JSON.stringify(gizmo)} in ${JSON.stringify(clear)})`);
    const step = Number((0.2 * state.diagonal).toPrecision(1));
    // Keys act on the view after a panel checkbox was clicked (ticked and unticked here).
    await page.click('#x-mirror');
    await page.click('#x-mirror');
    check(await page.evaluate(() => !document.activeElement || document.activeElement === document.body),
      `a used checkbox keeps no keyboard focus (${await page.evaluate(() => document.activeElement?.id)})`);
    await keys('g', 'x', ...String(step));
    check(/Move D: .* \[.*\|\] along global X/.test(await page.textContent('#header')), `the header reads the move (${await page.textContent('#header')})`);
    await keys('Enter');
    let r = await result();
    check(JSON.stringify(r.t) === JSON.stringify([1, 0, 0, step, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]), `G X ${step} is exactly that translation (${r.t})`);
    check(followed(r) < 1e-2, `the handle followed G X (${followed(r)})`);
    check(await page.$eval('#header', (h) => h.hidden), 'the header goes once confirmed');

    const moved = r.t;
    await keys('g', 'y', '5');
    check((await transform())[7] === 5, 'G Y 5 moves while typed');
    await keys('Escape');
    check(JSON.stringify(await transform()) === JSON.stringify(moved), 'Esc cancels the move');
    cover('modal', 'cancel');
    await keys('r', 'x', '4', '5');
    await page.mouse.click(canvas.x, canvas.y, { button: 'right' });
    check(JSON.stringify(await transform()) === JSON.stringify(moved), 'a right-click cancels the turn');
    await waitReady(60000);

    await reset();
    await keys('r', 'z', '9', '0', 'Enter');
    r = await result();
    const c = centroid(r);
    const t = r.t;
    check(t[0] === 0 && t[1] === -1 && t[4] === 1 && t[5] === 0 && t[10] === 1, `R Z 90 is exactly a quarter turn about z (${t})`);
    const image = [0, 1, 2].map((i) => t[4 * i] * c[0] + t[4 * i + 1] * c[1] + t[4 * i + 2] * c[2] + t[4 * i + 3]);
    check(Math.hypot(...image.map((x, k) => x - c[k])) < 1e-9 * r.diagonal, `about the handle's centroid (${c} goes to ${image})`);
    // The turn is about the handle's own centre: its centroid stays, within what the soft
    // constraints give for a patch turned on its side (1% of the diagonal on the bar, 2% on the
    // armadillo; about the gizmo's old centre, beside the handle, it moved by a third).
    const shown = [0, 1, 2].map((k) => {
      let sum = 0, n = 0;
      r.labels.forEach((l, v) => l === 2 && (++n, (sum += r.now[3 * v + k])));
      return sum / n;
    });
    const stays = Math.hypot(...shown.map((x, k) => x - c[k])) / r.diagonal;
    const extent = (p) => Math.max(...[0, 1, 2].map((k) => {
      let lo = Infinity, hi = -Infinity;
      for (let i = k; i < p.length; i += 3) [lo, hi] = [Math.min(lo, p[i]), Math.max(hi, p[i])];
      return hi - lo;
    }));
    const length = extent(r.now) / extent(r.rest);
    log('R Z 90: handle error', followed(r), 'centroid moved', stays, 'length ratio', length, JSON.stringify(r.measures));
    check(stays < 5e-2, `the handle's centroid stays where it was (${stays} of the diagonal)`);
    check(r.measures && Math.abs(r.measures.area) < 0.1, `the area changes by less than 10% (${JSON.stringify(r.measures)})`);
    // The panel shows the measures at its next render after the state has them (once it read
    // dashes under CI's load): waited for, not read at once.
    const readsArea = () => {
      const text = document.getElementById('measures').textContent;
      return /area change[+-]\d/.test(text) && /largest edge stretch/.test(text);
    };
    const readable = await page.waitForFunction(readsArea, null, { timeout: 5000 }).then(() => true, () => false);
    check(readable, `the panel reads the result's area (${await page.textContent('#measures')})`);

    await reset();
    await keys('s', 'x', '1', '.', '5', 'Enter');
    r = await result();
    check(r.t[0] === 1.5 && r.t[5] === 1 && r.t[10] === 1 && Math.abs(r.t[3] + 0.5 * centroid(r)[0]) < 1e-12 * r.diagonal,
      `S X 1.5 scales x by 1.5 about the centroid (${r.t})`);
    check(followed(r) < 2e-2, `the handle followed S X 1.5 (${followed(r)})`);

    // The 3D cursor as the pivot: Shift + right-click on the handle's end, then R Z 90 turns
    // about that point.
    await reset();
    await dismiss();
    const at = await screen(ends.handle);
    await page.keyboard.down('Shift');
    await page.mouse.click(at.x, at.y, { button: 'right' });
    await page.keyboard.up('Shift');
    const cursor = await api(() => window.specdeformEditor.cursor());
    check(cursor !== null, 'Shift + right-click placed the 3D cursor');
    cover('cursor');
    await page.selectOption('#pivot', 'cursor');
    await keys('r', 'z', '9', '0', 'Enter');
    r = await result();
    const fixedPoint = [0, 1, 2].map((i) => r.t[4 * i] * cursor[0] + r.t[4 * i + 1] * cursor[1] + r.t[4 * i + 2] * cursor[2] + r.t[4 * i + 3]);
    check(r.t[1] === -1 && Math.hypot(...fixedPoint.map((x, k) => x - cursor[k])) < 1e-9 * r.diagonal,
      `R Z 90 turns about the 3D cursor (${cursor} goes to ${fixedPoint})`);
    await reset();

    // Individual pivots: a second group at the other end; R Z 90 turns each about its centroid.
    await page.selectOption('#pivot', 'individual');
    await keys('Shift+N', 'Home'); // the first view again (numpad . framed the handle)
    await dismiss();
    await click(ends.fixed);
    await keys('4', 'r', 'z', '9', '0', 'Enter');
    r = await result();
    const both = await api(() => window.specdeformEditor.transforms());
    for (const [g, t] of both.entries()) {
      const c = [0, 1, 2].map((k) => {
        let sum = 0, n = 0;
        r.labels.forEach((l, v) => l === 2 + g && (++n, (sum += r.rest[3 * v + k])));
        return sum / n;
      });
      const image = [0, 1, 2].map((i) => t[4 * i] * c[0] + t[4 * i + 1] * c[1] + t[4 * i + 2] * c[2] + t[4 * i + 3]);
      check(t[1] === -1 && Math.hypot(...image.map((x, k) => x - c[k])) < 1e-9 * r.diagonal, `group ${g + 1} turned about its own centroid`);
    }
    check(both.length === 2, `two groups turned (${both.length})`);
    await undoTwice();
    await page.selectOption('#pivot', 'median'); // a menu used keeps no keyboard either
    await keys('1');

    log('region of influence');
    await reset();
    const detail = await page.inputValue('#detail');
    await page.selectOption('#detail', 'transfer'); // anchors the held vertices exactly
    await waitReady(60000);
    await page.fill('#influence', '30');
    await page.press('#influence', 'Enter');
    await waitReady(60000);
    await page.keyboard.press('4');
    await keys('g', 'z', ...String(step), 'Enter');
    r = await result();
    check(followed(r) < 1e-2, `the handle followed G Z with a region of influence (${followed(r)})`);
    {
      // Beyond the radius in space is beyond it along the surface: those free vertices stay.
      const radius = 0.3 * r.diagonal;
      const handle = [];
      r.labels.forEach((l, v) => l >= 2 && handle.push(v));
      let held = 0, worst = 0, fixed = 0;
      const moved = (v) => Math.hypot(...[0, 1, 2].map((k) => r.now[3 * v + k] - r.rest[3 * v + k]));
      r.labels.forEach((l, v) => {
        if (l === 1) fixed = Math.max(fixed, moved(v));
        if (l !== 0) return;
        const near = handle.some((h) => Math.hypot(...[0, 1, 2].map((k) => r.rest[3 * v + k] - r.rest[3 * h + k])) <= radius);
        if (near) return;
        ++held;
        worst = Math.max(worst, moved(v));
      });
      log(`held ${held}: ${worst / r.diagonal}, fixed ${fixed / r.diagonal} of the diagonal`);
      check(held > 100 && worst <= fixed + 1e-5 * r.diagonal,
        `the surface beyond the radius stays as the fixed vertices do (${held} vertices, ${worst / r.diagonal} of the diagonal; fixed ${fixed / r.diagonal})`);
    }
    // The wheel during a move widens the region instead of zooming.
    await keys('g', 'z');
    await page.mouse.move(canvas.x, canvas.y);
    await page.mouse.wheel(0, -100);
    await waitReady(60000);
    check(Number(await page.inputValue('#influence')) > 30, `the wheel widened the region (${await page.inputValue('#influence')}%)`);
    cover('wheel');
    await keys('Escape');
    await page.fill('#influence', '0');
    await page.press('#influence', 'Enter');
    await waitReady(60000);
    await page.selectOption('#detail', detail);
    await waitReady(60000);
    await reset();

    log('views');
    const looking = () => api(() => {
      const [p, q] = [window.specdeformEditor.cameraPosition(), window.specdeformEditor.cameraTarget()];
      const d = p.map((x, k) => x - q[k]);
      return d.map((x) => x / Math.hypot(...d));
    });
    await keys('Numpad7');
    check((await looking())[1] > 0.999, 'numpad 7 looks from the top');
    await keys('Control+Numpad1');
    check((await looking())[2] < -0.999, 'Ctrl + numpad 1 looks from the back');
    await keys('Numpad1');
    check((await looking())[2] > 0.999, 'numpad 1 looks from the front');
    cover('views');

    log('select linked, invert, grow, shrink');
    const count = async (label) => (await api(() => window.specdeformEditor.labels())).filter((l) => l === label).length;
    const handles0 = await count(2);
    await keys('1');
    await keys('Control+Equal');
    await waitReady(60000);
    const grown = await count(2);
    check(grown > handles0, `grow adds a ring (${handles0} to ${grown})`);
    await keys('Control+Minus');
    await waitReady(60000);
    check((await count(2)) < grown, 'shrink takes one off');
    await undoTwice();
    check((await count(2)) === handles0, 'undo returns to the painted handle');
    cover('grow');
    await keys('2');
    await keys('Home'); // the whole model, from the front: the middle of the view is on it
    await page.mouse.move(canvas.x, canvas.y);
    await keys('l');
    await waitReady(60000);
    const linked = await count(1);
    check(linked > fixed.length, `L selects the piece under the pointer (${linked} fixed vertices)`);
    cover('linked');
    await keys('Control+i');
    await waitReady(60000);
    check((await count(1)) === 0 || (await count(1)) < linked, 'invert swaps fixed and free');
    await undoTwice();
    check((await count(1)) === fixed.length, 'undo puts the fixed region back');
    cover('invert');
    await page.click('#select-linked'); // the button: the next click picks the piece
    await page.mouse.click(canvas.x, canvas.y);
    await waitReady(60000);
    check((await count(1)) === linked, `Linked, then a click, selects the same piece (${await count(1)})`);
    await keys('Control+z');
    await waitReady(60000);
    await reset();

    log('select all and none, Tab');
    await keys('2'); // Fixed: A gives every vertex its label, Alt+A clears it, each one undo step
    const fixedBefore = await count(1);
    await keys('a');
    await waitReady(60000);
    check((await count(0)) === 0 && (await count(1)) > fixedBefore, `A: no vertex left free (${await count(1)} fixed)`);
    await keys('Alt+a');
    await waitReady(60000);
    check((await count(1)) === 0, `Alt+A: the fixed label cleared (${await count(1)})`);
    await undoTwice();
    check((await count(1)) === fixedBefore, `undone twice, the fixed part is back (${await count(1)} of ${fixedBefore})`);
    cover('all');
    await keys('Tab');
    check((await api(() => window.specdeformEditor.tool())) === 'move', 'Tab: from painting to Move');
    await keys('Tab');
    check((await api(() => window.specdeformEditor.tool())) === 'fixed', 'Tab again: back to the tool that paints');
    cover('tab');

    log('box and lasso select');
    const boxSelect = async (lasso = false) => {
      if (lasso) {
        // Ctrl + right-drag around a diamond: the lasso.
        await page.keyboard.down('Control');
        await page.mouse.move(canvas.x, canvas.y - 60);
        await page.mouse.down({ button: 'right' });
        for (const [dx, dy] of [[60, 0], [0, 60], [-60, 0], [0, -55]]) await page.mouse.move(canvas.x + dx, canvas.y + dy, { steps: 3 });
        await page.mouse.up({ button: 'right' });
        await page.keyboard.up('Control');
      } else {
        await keys('b');
        await page.mouse.move(canvas.x - 60, canvas.y - 40);
        await page.mouse.down();
        await page.mouse.move(canvas.x + 60, canvas.y + 40, { steps: 4 });
        await page.mouse.up();
      }
      await waitReady(60000);
      const n = await count(1);
      await keys('Control+z');
      await waitReady(60000);
      return n - fixed.length;
    };
    const visible = await boxSelect();
    await page.check('#xray');
    const through = await boxSelect();
    await page.uncheck('#xray');
    const lassoed = await boxSelect(true);
    log(`box: ${visible} visible, ${through} with X-ray; lasso: ${lassoed}`);
    check(lassoed > 0 && lassoed < visible, `the lasso (a diamond inside the box) selects fewer than the box (${lassoed})`);
    check(visible > 0 && through > 1.5 * visible, `a box selects the visible vertices (${visible}), with X-ray those behind too (${through})`);
    cover('box');

    log('X mirror');
    await page.click('#clear');
    await page.check('#x-mirror');
    await keys('1');
    await dismiss();
    await click(ends.handle);
    r = await result();
    const side = (label) => r.labels.flatMap((l, v) => (l === label ? [v] : []));
    const [left, right] = [side(2), side(3)];
    const xs = r.rest.filter((_, i) => i % 3 === 0);
    const plane = (Math.min(...xs) + Math.max(...xs)) / 2;
    const key = (v, flip) => [flip ? 2 * plane - r.rest[3 * v] : r.rest[3 * v], r.rest[3 * v + 1], r.rest[3 * v + 2]].map((x) => Math.round(x / (1e-3 * r.diagonal))).join();
    const images = new Set(right.map((v) => key(v, false)));
    // The demo is symmetric: every vertex's image (scans are only nearly so, or not at all).
    log(`mirror: ${left.length} vertices painted, ${right.length} on the other side`);
    if (!args.mesh) {
      check(left.length > 0 && right.length === left.length && left.every((v) => images.has(key(v, true))),
        `mirror painting paints the other side of the middle x plane (${left.length} and ${right.length} vertices)`);
    }
    await keys('g', 'x', ...String(step), 'Enter');
    r = await result();
    const other = await api(() => window.specdeformEditor.transforms()[1]);
    check(other.every((x, i) => Math.abs(x - [1, 0, 0, -step, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1][i]) < 1e-12 * r.diagonal),
      `the mirrored group moves by the mirrored G X ${step} (${other})`);
    // A box on one side, with X mirror: its vertices and their counterparts.
    await page.click('#clear');
    await waitReady(60000);
    // Around a vertex in view a tenth of the diagonal on the low side of the plane.
    const spot = await api((x) => {
      const e = window.specdeformEditor;
      const p = e.restPositions();
      const rect = document.querySelector('#view canvas').getBoundingClientRect();
      for (let v = 0; v < p.length / 3; ++v) {
        const s = p[3 * v] < x && e.vertexOnScreen(v);
        if (s && s.x > rect.left + 60 && s.x < rect.right - 60 && s.y > rect.top + 150 && s.y < rect.bottom - 80) return s;
      }
      return null;
    }, plane - 0.1 * r.diagonal);
    check(spot !== null, 'a vertex on one side is in view');
    await keys('2', 'b');
    await page.mouse.move(spot.x - 30, spot.y - 30);
    await page.mouse.down();
    await page.mouse.move(spot.x + 30, spot.y + 30, { steps: 4 });
    await page.mouse.up();
    await waitReady(60000);
    r = await result();
    const boxed = side(1);
    const fixedKeys = new Set(boxed.map((v) => key(v, false)));
    const [west, east] = [boxed.filter((v) => r.rest[3 * v] < plane).length, boxed.filter((v) => r.rest[3 * v] > plane).length];
    const unpaired = (await api(() => window.specdeformEditor.notes())).some((n) => /no counterpart/.test(n.text));
    log(`box with X mirror: ${west} and ${east} vertices on either side${unpaired ? ', some unpaired (said)' : ''}`);
    check(west > 0 && (east > 0 || unpaired), `a box on one side with X mirror selects the other side (${west}, ${east})`);
    if (!args.mesh) {
      check(west === east && boxed.every((v) => fixedKeys.has(key(v, true))), 'the two sides are each other\'s mirror images');
    }
    await page.uncheck('#x-mirror');

    log('navigation');
    // A drag with a button (and a key held): how far the camera moved, its target moved (a
    // pan), and its distance to the target changed (a zoom), over the diagonal.
    const camera = () => api(() => [window.specdeformEditor.cameraPosition(), window.specdeformEditor.cameraTarget()]);
    const apart = (a, b) => Math.hypot(...a.map((x, i) => x - b[i]));
    const drag = async (button, key) => {
      const [p, t] = await camera();
      if (key) await page.keyboard.down(key);
      await page.mouse.move(canvas.x, canvas.y);
      await page.mouse.down({ button });
      await page.mouse.move(canvas.x + 80, canvas.y + 30, { steps: 5 });
      await page.mouse.up({ button });
      if (key) await page.keyboard.up(key);
      const [q, u] = await camera();
      return { moved: apart(p, q) / r.diagonal, panned: apart(t, u) / r.diagonal, zoomed: Math.abs(apart(q, u) - apart(p, t)) / r.diagonal };
    };
    const orbits = (m) => m.moved > 1e-3 && m.panned < 1e-9 && m.zoomed < 1e-9;
    let m = await drag('middle');
    check(orbits(m), `as Blender, middle-drag orbits (${JSON.stringify(m)})`);
    m = await drag('middle', 'Shift');
    check(m.panned > 1e-3, `Shift + middle-drag pans (${JSON.stringify(m)})`);
    m = await drag('middle', 'Control');
    check(m.zoomed > 1e-3 && m.panned < 1e-9, `Ctrl + middle-drag zooms (${JSON.stringify(m)})`);
    m = await drag('right');
    check(m.moved === 0, `the right button leaves the view (${JSON.stringify(m)})`);
    await page.check('#emulate3');
    m = await drag('left', 'Alt');
    check(orbits(m), `with Alt emulating the middle button, Alt + left-drag orbits (${JSON.stringify(m)})`);
    await page.uncheck('#emulate3');
    await page.selectOption('#navigation', 'right');
    m = await drag('right');
    check(orbits(m), `the other scheme: right-drag orbits (${JSON.stringify(m)})`);
    m = await drag('middle');
    check(m.panned > 1e-3, `the other scheme: middle-drag pans (${JSON.stringify(m)})`);
    check(JSON.parse(await page.evaluate(() => localStorage.getItem('specdeform.navigation'))).scheme === 'right',
      'the scheme is kept in the browser');
    await page.selectOption('#navigation', 'blender');
    cover('orbit');
    await moreKeys();
  }

  // N, Shift+N, H and Alt+H, the numpad's turns, framing, the key map's table (against
  // docs/editor.md's), a missed press said at the pointer; then every row of the table covered.
  async function moreKeys() {
    const canvas = await page.$eval('#view canvas', (c) => { const r = c.getBoundingClientRect(); return { x: r.left + r.width / 2, y: r.top + r.height / 2 }; });
    const keys = async (...sequence) => {
      for (const k of sequence) await page.keyboard.press(k);
    };
    const camera = () => api(() => [window.specdeformEditor.cameraPosition(), window.specdeformEditor.cameraTarget()]);
    const sub = (a, b) => a.map((x, i) => x - b[i]);
    const unit = (a) => a.map((x) => x / Math.hypot(...a));
    const dot = (a, b) => a.reduce((t, x, i) => t + x * b[i], 0);
    const diagonal = await api(() => window.specdeformEditor.diagonal());
    // The centre of the box around the vertices `want` picks, where they are drawn.
    const centre = (want) => api((w) => {
      const p = window.specdeformEditor.positions(), l = window.specdeformEditor.labels();
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      l.forEach((label, v) => {
        if (w !== null && label !== w) return;
        for (let k = 0; k < 3; ++k) [lo[k], hi[k]] = [Math.min(lo[k], p[3 * v + k]), Math.max(hi[k], p[3 * v + k])];
      });
      return lo.map((x, k) => (x + hi[k]) / 2);
    }, want);

    log('keys: frame, numpad turns');
    await keys('1', 'Home');
    let [p, t] = await camera();
    check(Math.hypot(...sub(t, await centre(null))) < 1e-6 * diagonal, 'Home frames the whole mesh');
    await page.click('#clear');
    await waitReady(60000);
    await keys('1');
    await page.mouse.click(canvas.x, canvas.y); // a handle in the active group
    await waitReady(60000);
    await keys('f');
    [p, t] = await camera();
    const active = 2 + (await api(() => window.specdeformEditor.activeGroup()));
    check(Math.hypot(...sub(t, await centre(active))) < 1e-6 * diagonal, `F frames the active group (${t})`);
    cover('frame');
    await keys('Home', 'Numpad1');
    for (const [key, degrees] of [['Numpad6', 15], ['Numpad4', 15], ['Numpad8', 15], ['Numpad2', 15], ['Numpad9', 180]]) {
      const [p0, t0] = await camera();
      await keys(key);
      const [p1, t1] = await camera();
      const turned = Math.acos(Math.min(1, Math.max(-1, dot(unit(sub(p0, t0)), unit(sub(p1, t1)))))) * 180 / Math.PI;
      const [moved, distance] = [Math.hypot(...sub(t0, t1)), Math.hypot(...sub(p1, t1)) / Math.hypot(...sub(p0, t0)) - 1];
      check(Math.abs(turned - degrees) < 1e-6 && moved < 1e-9 * diagonal && Math.abs(distance) < 1e-9,
        `${key} orbits by ${degrees} degrees about the target (${turned}; target moved ${moved}, distance changed by ${distance})`);
    }
    // Numpad 5: orthographic and back; the model under the middle of the view is picked through
    // either, at the same place (the frame's height kept at the orbit's centre).
    const middle = () => api((c) => window.specdeformEditor.onModel(c.x, c.y), canvas);
    const picked = await middle();
    await keys('Numpad5');
    check((await api(() => window.specdeformEditor.projection())) === 'orthographic', 'numpad 5 switches to an orthographic view');
    check((await middle()) === picked, 'the middle of the view picks as before in the orthographic view');
    await keys('Numpad5');
    check((await api(() => window.specdeformEditor.projection())) === 'perspective', 'numpad 5 switches back');
    cover('views', 'turn');

    log('keys: N, Shift+N');
    const width = () => page.$eval('#view canvas', (c) => c.getBoundingClientRect().width);
    const w0 = await width();
    await keys('n');
    await page.waitForFunction((w) => document.querySelector('#view canvas').getBoundingClientRect().width > w, w0);
    check(await page.$eval('#panel', (e) => e.hidden), `N hides the panel; the view takes its width (${w0} to ${await width()})`);
    await keys('n');
    await page.waitForFunction((w) => document.querySelector('#view canvas').getBoundingClientRect().width === w, w0);
    check(!(await page.$eval('#panel', (e) => e.hidden)), 'N again shows it');
    const groups = await api(() => window.specdeformEditor.transforms().length);
    await keys('Shift+N');
    check((await api(() => window.specdeformEditor.transforms().length)) === groups + 1, 'Shift+N adds a handle group');
    cover('panel', 'new-group');

    log('keys: H, Alt+H');
    await keys('2', 'Home', 'Numpad1');
    const all = await api(() => window.specdeformEditor.drawnTriangles());
    // Around the point of the model nearest the middle of the view (a bent bar can leave the
    // middle empty).
    const on = await api((c) => {
      const points = [];
      for (let dx = -320; dx <= 320; dx += 20) for (let dy = -240; dy <= 240; dy += 20) points.push({ x: c.x + dx, y: c.y + dy });
      points.sort((a, b) => Math.hypot(a.x - c.x, a.y - c.y) - Math.hypot(b.x - c.x, b.y - c.y));
      return points.find((p) => window.specdeformEditor.onModel(p.x, p.y));
    }, canvas);
    check(on, `the model is in view (${JSON.stringify(await api(() => {
      const e = window.specdeformEditor;
      const p = e.positions();
      const lo = [0, 1, 2].map((k) => Math.min(...p.filter((_, i) => i % 3 === k)));
      const hi = [0, 1, 2].map((k) => Math.max(...p.filter((_, i) => i % 3 === k)));
      return { lo, hi, camera: e.cameraPosition(), target: e.cameraTarget(), drawn: e.drawnTriangles(), hidden: e.hidden().length,
        centre: e.vertexOnScreen(0) };
    }))})`);
    const rectangle = async (key) => {
      await keys(key);
      await page.mouse.move(on.x - 60, on.y - 40);
      await page.mouse.down();
      await page.mouse.move(on.x + 60, on.y + 40, { steps: 4 });
      await page.mouse.up();
    };
    await rectangle('h');
    const hidden = await api(() => window.specdeformEditor.hidden());
    const shown = await api(() => window.specdeformEditor.drawnTriangles());
    check(hidden.length > 0 && shown < all, `H and a rectangle hide its visible vertices and their triangles (${hidden.length} vertices, ${all - shown} triangles)`);
    const before = await api(() => window.specdeformEditor.labels());
    await rectangle('b'); // the same rectangle selects what was behind
    await waitReady(60000);
    const after = await api(() => window.specdeformEditor.labels());
    const behind = after.filter((l, v) => l !== before[v]).length;
    check(behind > 0 && hidden.every((v) => after[v] === before[v]),
      `a box over the hidden part selects what lies behind it (${behind} vertices), none of the hidden ones`);
    await keys('Control+z');
    await waitReady(60000);
    await keys('Alt+h');
    check((await api(() => window.specdeformEditor.hidden())).length === 0 && (await api(() => window.specdeformEditor.drawnTriangles())) === all,
      'Alt+H shows every triangle again');
    // Shift+H hides the unlabelled vertices (Blender's hide unselected); Alt+H shows them again.
    const labelled = await api(() => window.specdeformEditor.labels());
    const free = labelled.filter((l) => l === 0).length;
    await keys('Shift+h');
    const unselected = await api(() => window.specdeformEditor.hidden());
    check(free > 0 && free < labelled.length && unselected.length === free && unselected.every((v) => labelled[v] === 0),
      `Shift+H hides the ${free} unlabelled vertices, no labelled one (${unselected.length} hidden)`);
    await keys('Alt+h');
    // An armed H ends with the next key (here Tab), says so, and the next drag does not hide.
    await keys('h');
    check(!(await page.isHidden('#header')), 'H arms the box hide (its header shown)');
    await keys('Tab', 'Tab');
    check(await page.isHidden('#header'), 'another key disarms H (its header gone)');
    check((await page.textContent('#notes')).includes('hide disarmed by'), 'the disarming is said');
    await page.mouse.move(on.x - 60, on.y - 40);
    await page.mouse.down();
    await page.mouse.move(on.x + 60, on.y + 40, { steps: 4 });
    await page.mouse.up();
    await waitReady(60000);
    check((await api(() => window.specdeformEditor.hidden())).length === 0, 'the drag after a disarmed H hides nothing');
    await keys('Control+z');
    await waitReady(60000);
    // A menu closed (Esc) or just focused takes no key: numpad keys turn the view, letters do
    // not step its value by type-ahead.
    const viewNow = () => api(() => JSON.stringify([window.specdeformEditor.cameraPosition(), window.specdeformEditor.cameraTarget()]));
    for (const menu of ['#navigation', '#energy', '#pivot', '#export-format', '#detail']) {
      const value = await page.inputValue(menu);
      const seen = await viewNow();
      // Each key with the menu focused: R (type-ahead would pick "right ..."; here it starts a
      // rotation, which Esc cancels), Down (would step it), Esc (leaves it), Numpad 6 (turns).
      for (const k of ['r', 'ArrowDown', 'Escape', 'Numpad6']) {
        await page.focus(menu);
        await keys(k);
        if (k === 'r') await keys('Escape');
      }
      check((await page.inputValue(menu)) === value, `${menu} keeps ${value} after keys aimed at the view (${await page.inputValue(menu)})`);
      check((await viewNow()) !== seen, `Numpad6 turned the view with ${menu} focused`);
      check(await page.evaluate(() => !document.activeElement || document.activeElement === document.body), `${menu} handed the keyboard back`);
      await keys('Numpad4');
    }
    cover('hide');

    log('keys: a missed press said at the pointer');
    // A point of the view beside the model, clear of the messages and the help line.
    const miss = await api((c) => [[-300, 250], [300, 250], [-350, 0], [350, 0], [-300, -200], [300, -200]]
      .map(([dx, dy]) => ({ x: c.x + dx, y: c.y + dy })).find((p) => !window.specdeformEditor.onModel(p.x, p.y)), canvas);
    check(miss, 'a point of the view misses the model');
    await page.mouse.click(miss.x, miss.y);
    const tip = await page.$eval('#pointer-note', (e) => ({ hidden: e.hidden, text: e.textContent, ...e.getBoundingClientRect().toJSON() }));
    check(!tip.hidden && /missed the model/.test(tip.text) && Math.hypot(tip.x - miss.x, tip.y - miss.y) < 40,
      `a press beside the model says so at the pointer (${JSON.stringify(tip)})`);

    log('keys: the table');
    await keys('?');
    const rows = await page.$$eval('#keymap tr', (trs) => trs.map((tr) => [tr.dataset.key, ...[...tr.cells].map((c) => c.textContent)]));
    check(await page.$eval('#keymap', (e) => !e.hidden && e.getBoundingClientRect().height > 100), '? shows the key map');
    await keys('Escape');
    check(await page.$eval('#keymap', (e) => e.hidden), 'Esc closes it');
    cover('help');
    const table = readFileSync(resolve(here, '../../docs/editor.md'), 'utf8').split('## Key map')[1].split('| key | does |\n|---|---|\n')[1];
    const docs = table.slice(0, table.indexOf('\n\n')).split('\n').map((line) => line.split(' | ').map((c) => c.replace(/^\| |\s*\|$/g, '')));
    check(JSON.stringify(docs) === JSON.stringify(rows.map((r) => r.slice(1))),
      `docs/editor.md's key map is the page's (${JSON.stringify(docs.find((d, i) => JSON.stringify(d) !== JSON.stringify(rows[i]?.slice(1))))})`);
    const missing = rows.map((r) => r[0]).filter((id) => !covered.has(id));
    check(missing.length === 0, `every row of the key map is tested (not: ${missing.join(', ')})`);
  }
  check(pageErrors.length === 0, `no page errors: ${pageErrors.join('; ')}`);
} catch (e) {
  // What the page showed when it failed.
  for (const page of browser.contexts().flatMap((c) => c.pages())) {
    await page.screenshot({ path: resolve(args.out, 'failure.png') }).catch(() => {});
    const notes = await page.evaluate(() => window.specdeformEditor?.notes()).catch(() => null);
    log('page notes:', JSON.stringify(notes));
    log('page waits for:', JSON.stringify(await page.evaluate(() => window.specdeformEditor?.unsettled()).catch(() => null)));
  }
  throw e;
} finally {
  await browser.close();
  editor.server.kill();
}
