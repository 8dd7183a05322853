// End-to-end test of the browser editor in real Chromium (Debian's chromium, driven by
// playwright-core): start `specdeform edit`, paint a handle and a fixed region with the brush,
// drag the handle with the mouse, and check what the server sent back and what was drawn; then
// export the mesh, undo and redo, change the detail method, and open another mesh.
//
//   node e2e/editor.e2e.mjs [--mesh FILE] [--seconds S] [--out DIR]
//
// Without --mesh it uses the built-in demo model. The drag lasts --seconds (default 2) at about
// 60 mouse events per second; the test prints one JSON line with the updates per second and the
// drag response (mouse event to frame drawn, median and 90th percentile), and writes
// editor.png to --out (default: e2e-output).
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseArgs } from 'node:util';
import { launchChromium, startEditor } from './harness.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const { values: args } = parseArgs({
  options: {
    mesh: { type: 'string' },
    seconds: { type: 'string', default: '2' },
    out: { type: 'string', default: 'e2e-output' },
    binary: { type: 'string', default: resolve(here, '../../build/bin/specdeform') },
    chromium: { type: 'string', default: process.env.CHROMIUM ?? '/usr/bin/chromium' },
  },
});

function check(condition, message) {
  if (!condition) throw new Error(`check failed: ${message}`);
}

const percentile = (values, p) => {
  const s = [...values].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(p * s.length))];
};

const { server, url } = startEditor(args.binary, args.mesh ? [args.mesh] : []);
const browser = await launchChromium(args.chromium);
try {
  const page = await browser.newPage({ viewport: { width: 1200, height: 760 } });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(await url);
  await page.waitForFunction(() => window.specdeformEditor?.ready, null, { timeout: 120000 });
  const editor = 'window.specdeformEditor';

  // The two ends of the model along its longest axis, among the vertices facing the camera.
  const ends = await page.evaluate(() => {
    const e = window.specdeformEditor;
    const p = e.restPositions();
    const n = p.length / 3;
    const lo = [0, 1, 2].map((k) => Math.min(...p.filter((_, i) => i % 3 === k)));
    const hi = [0, 1, 2].map((k) => Math.max(...p.filter((_, i) => i % 3 === k)));
    const axis = [0, 1, 2].reduce((a, k) => (hi[k] - lo[k] > hi[a] - lo[a] ? k : a), 0);
    const rect = document.querySelector('#view canvas').getBoundingClientRect();
    const visible = [];
    for (let v = 0; v < n; ++v) {
      const s = e.vertexOnScreen(v);
      if (s.x > rect.left + 20 && s.x < rect.right - 20 && s.y > rect.top + 20 && s.y < rect.bottom - 20) {
        visible.push(v);
      }
    }
    // Nearest to the camera among the extreme 3% along the axis: certainly in front.
    const pick = (sign) => {
      const c = visible.filter((v) => sign * (p[3 * v + axis] - (sign > 0 ? hi[axis] : lo[axis])) > -0.03 * (hi[axis] - lo[axis]));
      const cam = window.specdeformEditor.cameraPosition();
      const d = (v) => Math.hypot(p[3 * v] - cam[0], p[3 * v + 1] - cam[1], p[3 * v + 2] - cam[2]);
      return c.reduce((a, v) => (d(v) < d(a) ? v : a), c[0]);
    };
    return { handle: pick(1), fixed: pick(-1), n };
  });
  const screen = (v) => page.evaluate(([e, v]) => eval(e).vertexOnScreen(v), [editor, v]);
  const click = async (v) => {
    const s = await screen(v);
    await page.mouse.move(s.x, s.y);
    await page.mouse.down();
    await page.mouse.up();
  };

  // Paint: a handle at one end, the fixed set at the other.
  await page.click('[data-tool="handle"]');
  await click(ends.handle);
  await page.click('[data-tool="fixed"]');
  await page.fill('#radius', '10');
  await click(ends.fixed);
  const labels = await page.evaluate(() => window.specdeformEditor.labels());
  const handles = labels.flatMap((l, v) => (l === 2 ? [v] : []));
  const fixed = labels.flatMap((l, v) => (l === 1 ? [v] : []));
  check(handles.length > 0 && fixed.length > 0, `brush selected ${handles.length} handle and ${fixed.length} fixed vertices`);

  // Drag the handle up the screen, at about 60 mouse events per second.
  await page.click('[data-tool="move"]');
  const start = await screen(ends.handle);
  const counts = () => page.evaluate(() => {
    const s = window.specdeformEditor.stats;
    return { drawn: s.framesDrawn, received: s.framesReceived, latencies: s.latencies.length, receive: s.receiveLatencies.length };
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
  await page.mouse.up();
  const after = await counts();
  // Let the last frame arrive and be drawn.
  await page.waitForFunction(() => window.specdeformEditor.settled(), null, { timeout: 30000 });

  const state = await page.evaluate(() => {
    const e = window.specdeformEditor;
    return { rest: e.restPositions(), now: e.positions(), transforms: e.transforms(), diagonal: e.diagonal(), stats: e.stats };
  });
  const t = state.transforms[0];
  const translation = [t[3], t[7], t[11]];
  check(Math.hypot(...translation) > 0.02 * state.diagonal, `the handle moved (translation ${translation})`);
  const error = (v, target) => Math.hypot(...[0, 1, 2].map((k) => state.now[3 * v + k] - target[k])) / state.diagonal;
  const target = (v) => [0, 1, 2].map((k) => state.rest[3 * v + k] + translation[k]);
  const handleError = Math.max(...handles.map((v) => error(v, target(v))));
  const fixedError = Math.max(...fixed.map((v) => error(v, [0, 1, 2].map((k) => state.rest[3 * v + k]))));
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
  const drawn = await page.evaluate(() => {
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
  mkdirSync(args.out, { recursive: true });
  await page.screenshot({ path: resolve(args.out, 'editor.png') });

  // Export: the downloaded OBJ holds what is shown.
  await page.selectOption('#export-format', 'obj');
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-mesh')]);
  const exported = readFileSync(await download.path(), 'utf8').split('\n').filter((l) => l.startsWith('v '));
  check(exported.length === ends.n, `the export has ${exported.length} of ${ends.n} vertices`);
  const exportError = Math.max(...exported.map((l, v) =>
    Math.max(...l.split(/\s+/).slice(1, 4).map((x, k) => Math.abs(Number(x) - state.now[3 * v + k])))));
  check(exportError < 1e-5 * state.diagonal, `the export matches the view (${exportError})`);

  // Undo puts the handle back (the rest shape), redo moves it again.
  const restError = async () => {
    await page.waitForFunction(() => window.specdeformEditor.settled(), null, { timeout: 30000 });
    return page.evaluate(() => {
      const e = window.specdeformEditor;
      const [p, r] = [e.positions(), e.restPositions()];
      return Math.max(...p.map((x, i) => Math.abs(x - r[i]))) / e.diagonal();
    });
  };
  await page.evaluate(() => document.activeElement?.blur()); // shortcuts skip focused inputs
  await page.keyboard.press('Control+z');
  check((await restError()) < 1e-5, 'undo returns to the rest shape');
  await page.keyboard.press('Control+Shift+z');
  check((await restError()) > 0.02, 'redo deforms it again');

  // A detail method from the panel: the server rebuilds and the frame comes back solved with it.
  await page.selectOption('#detail', 'displacement');
  await page.waitForFunction(() => document.querySelector('#detail').value === 'displacement' &&
    window.specdeformEditor.ready, null, { timeout: 60000 });
  check((await restError()) > 0.02, 'the deformation survives a settings change');

  // Another mesh through the file picker.
  const sphere = resolve(args.out, 'sphere.off');
  execFileSync(args.binary, ['generate', 'icosphere', '--subdivisions', '2', '-o', sphere]);
  await page.setInputFiles('#open-mesh', sphere);
  await page.waitForFunction(() => document.querySelector('#mesh-name').textContent.startsWith('sphere.off: 162 vertices'),
    null, { timeout: 60000 });
  check(pageErrors.length === 0, `no page errors: ${pageErrors.join('; ')}`);

  const latencies = state.stats.latencies.slice(before.latencies, after.latencies);
  const receive = state.stats.receiveLatencies.slice(before.receive, after.receive);
  const result = {
    mesh: args.mesh ?? 'demo (bumpy bar)',
    vertices: ends.n,
    handle_vertices: handles.length,
    fixed_vertices: fixed.length,
    drag_seconds: dragSeconds,
    mouse_events: steps,
    updates_per_second: (after.drawn - before.drawn) / dragSeconds,
    response_ms_median: percentile(latencies, 0.5),
    response_ms_p90: percentile(latencies, 0.9),
    results_per_second: (after.received - before.received) / dragSeconds,
    result_ms_median: percentile(receive, 0.5),
    handle_error: handleError,
    fixed_error: fixedError,
  };
  writeFileSync(resolve(args.out, 'editor.json'), JSON.stringify(result, null, 1) + '\n');
  console.log(JSON.stringify(result));
} finally {
  await browser.close();
  server.kill();
}
