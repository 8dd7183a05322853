// End-to-end test of opening a mesh in the browser editor, as a new user would (issue 34), in
// Debian's Chromium at 1280 x 800, with a fresh basis cache:
//  - the mesh is drawn before its basis is ready, and a handle and a fixed part are painted
//    while the basis computes (when it still computes: a fast machine may finish first); the
//    server takes the selection painted meanwhile once the basis is ready;
//  - every loading stage has its label, which moves at least once a second (a stage without a
//    fraction counts its seconds), and none reads "100%" while something else runs;
//  - the first drag as soon as the basis is ready: its detailed result drawn, and the CPU time
//    the server, Chromium and the harness used up to then (the two cores' floor);
//  - the basis is saved in the background after "ready", and the page says so;
//  - pointer moves coalesce: a burst of moves within one frame is acted on once;
//  - a 5-point stroke: how long it takes to play and to be applied after the release;
//  - the Log and the help line do not overlap; keys are inert while disconnected.
//
//   node e2e/loading.e2e.mjs --mesh FILE [--out DIR] [--modes M]
//
// Prints one JSON line of timings (from the page's start: navigation) and writes loading.json to
// --out. Timings are reported, not checked, but for the longest task holding the page.
import { mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { parseArgs } from 'node:util';
import { check, launchChromium, log, startEditor } from './harness.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const { values: args } = parseArgs({
  options: {
    mesh: { type: 'string' },
    modes: { type: 'string' },
    out: { type: 'string', default: 'e2e-output' },
    binary: { type: 'string', default: resolve(here, '../../build/bin/specdeform') },
    chromium: { type: 'string', default: process.env.CHROMIUM ?? '/usr/bin/chromium' },
  },
});

// What the page's state says is polled this often (ms), not once per drawn frame (Playwright's
// default): a draw of a million triangles without a GPU takes most of a second.
const kPollMs = 50;
// The longest a loading label may stand still (s): once a second, and a long task of the page.
const kStillLabelS = 2.5;
// The longest the page's thread may be held from the mesh's first part to the first drag (s):
// 0.06-0.14 s at 692k on two shared cores; the mesh's adoption in one task took 1.8-2 s.
const kLongestTaskS = 0.5;

// CPU seconds used so far by the server, by Chromium's processes and by this script (Linux's
// /proc, 100 ticks a second): the work the two cores were given.
function cpuSeconds(serverPid) {
  const ticks = (pid) => {
    try {
      const stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
      const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' '); // from the 3rd field
      return (Number(fields[11]) + Number(fields[12])) / 100; // utime + stime
    } catch {
      return 0; // gone meanwhile
    }
  };
  // Chromium's processes by --type: gpu-process (SwiftShader's drawing), renderer (the page and
  // its workers), browser (none), utility and zygotes.
  const chromium = {};
  for (const pid of readdirSync('/proc').filter((p) => /^\d+$/.test(p))) {
    let args = '';
    try { args = readFileSync(`/proc/${pid}/cmdline`, 'utf8'); } catch { continue; }
    if (!/^\S*chrom/.test(args)) continue;
    const type = /--type=([\w-]+)/.exec(args)?.[1] ?? 'browser';
    chromium[type] = (chromium[type] ?? 0) + ticks(pid);
  }
  const own = process.cpuUsage();
  return { server: ticks(serverPid), ...chromium, harness: (own.user + own.system) / 1e6 };
}

const cacheDir = mkdtempSync(join(tmpdir(), 'specdeform-cache-'));
const editArgs = [...(args.mesh ? [args.mesh] : []), ...(args.modes ? ['-m', args.modes] : [])];
const editor = startEditor(args.binary, editArgs, 0, cacheDir);
const url = await editor.url;
const browser = await launchChromium(args.chromium);
mkdirSync(args.out, { recursive: true });
const result = { mesh: args.mesh ? basename(args.mesh) : 'demo (bumpy bar)' };
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  // Every status the page shows, with when it was first shown (ms from navigation).
  await page.addInitScript(() => {
    window.statusLog = [];
    addEventListener('pointerup', () => (window.releasedAt = performance.now()), true);
    window.longTasks = []; // [start, duration] (ms) of tasks that held the page over 50 ms
    window.harnessTasks = []; // [start, end] (ms) of the harness's own work in the page
    new PerformanceObserver((l) => window.longTasks.push(...l.getEntries().map((e) => [e.startTime, e.duration])))
      .observe({ entryTypes: ['longtask'] });
    document.addEventListener('DOMContentLoaded', () => {
      const status = document.getElementById('status');
      new MutationObserver(() => {
        const text = status.textContent;
        if (window.statusLog.at(-1)?.text !== text) window.statusLog.push({ t: performance.now(), text });
      }).observe(status, { childList: true, characterData: true, subtree: true });
    });
  });
  // The socket's messages, [seconds from navigation, '>' sent or '<' received, type, bytes]: where
  // the time between the server's replies and the page's reactions goes.
  const messages = [];
  const opened = Date.now();
  const kindOf = (payload) => {
    if (typeof payload === 'string') return JSON.parse(payload).type ?? 'text';
    return `binary ${payload.readUInt32LE(0)}`;
  };
  page.on('websocket', (ws) => {
    const record = (dir) => ({ payload }) => messages.push(
      [+((Date.now() - opened) / 1000).toFixed(3), dir, kindOf(payload), payload.length]);
    ws.on('framesent', record('>'));
    ws.on('framereceived', record('<'));
  });
  const cpuAtOpening = cpuSeconds(editor.server.pid);
  await page.goto(url);
  const api = (fn, arg) => page.evaluate(fn, arg);
  const now = () => api(() => performance.now());
  const waitReady = (timeout = 180000) =>
    page.waitForFunction(() => window.specdeformEditor?.ready && window.specdeformEditor.settled(), null, { timeout });

  // 1. The mesh on screen before its basis.
  await page.waitForFunction(() => window.specdeformEditor?.stats.meshDrawn !== null, null, { timeout: 120000 });
  const drawn = await api(() => ({ at: window.specdeformEditor.stats.meshDrawn, phase: window.specdeformEditor.phase }));
  // The mesh's arrival: its first and last parts, drawn whole (flat), then shaded.
  const arrival = await api(() => window.specdeformEditor.stats);
  result.mesh_first_byte_s = arrival.meshStarted / 1000;
  result.mesh_received_s = arrival.meshReceived / 1000;
  result.mesh_seen_s = arrival.meshSeen / 1000; // some of its triangles drawn
  result.mesh_shown_s = arrival.meshShown / 1000;
  result.mesh_drawn_s = drawn.at / 1000;
  log(`mesh drawn at ${result.mesh_drawn_s.toFixed(2)} s, phase ${drawn.phase}`);
  // (The harness's own work in the page, here and below, is marked: its tasks are not the
  // editor's.)
  const shades = await api(() => {
    const t0 = performance.now();
    const gl = document.querySelector('#view canvas');
    const c = Object.assign(document.createElement('canvas'), { width: gl.width, height: gl.height });
    const ctx = c.getContext('2d');
    ctx.drawImage(gl, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const set = new Set();
    for (let i = 0; i < d.length; i += 4) set.add(d[i] >> 3);
    window.harnessTasks.push([t0, performance.now()]);
    return set.size;
  });
  check(shades > 8, `the mesh is drawn shaded (${shades} shades)`);

  // The two ends of the model along its longest axis, among the vertices facing the camera.
  const ends = await api(() => {
    const t0 = performance.now();
    const e = window.specdeformEditor;
    const p = e.restPositions();
    const n = p.length / 3;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; ++i) [lo[i % 3], hi[i % 3]] = [Math.min(lo[i % 3], p[i]), Math.max(hi[i % 3], p[i])];
    const axis = [0, 1, 2].reduce((a, k) => (hi[k] - lo[k] > hi[a] - lo[a] ? k : a), 0);
    const rect = document.querySelector('#view canvas').getBoundingClientRect();
    const cam = e.cameraPosition();
    const d = (v) => Math.hypot(p[3 * v] - cam[0], p[3 * v + 1] - cam[1], p[3 * v + 2] - cam[2]);
    const pick = (sign) => {
      let best = -1;
      for (let v = 0; v < n; ++v) {
        if (!(sign * (p[3 * v + axis] - (sign > 0 ? hi[axis] : lo[axis])) > -0.03 * (hi[axis] - lo[axis]))) continue;
        const s = e.vertexOnScreen(v);
        if (s.x < rect.left + 20 || s.x > rect.right - 20 || s.y < rect.top + 120 || s.y > rect.bottom - 60) continue;
        if (best < 0 || d(v) < d(best)) best = v;
      }
      return best;
    };
    const found = { handle: pick(1), fixed: pick(-1), n };
    window.harnessTasks.push([t0, performance.now()]);
    return found;
  });
  check(ends.handle >= 0 && ends.fixed >= 0, `both ends are visible (${JSON.stringify(ends)})`);
  result.vertices = ends.n;
  const screen = (v) => api((v) => window.specdeformEditor.vertexOnScreen(v), v);
  // A stroke of `points` pointer positions around vertex v, one mouse event each.
  const stroke = async (v, points = 1) => {
    const s = await screen(v);
    await page.mouse.move(s.x, s.y);
    await page.mouse.down();
    for (let i = 1; i < points; ++i) await page.mouse.move(s.x + 3 * i, s.y + 2 * (i % 2));
    await page.mouse.up();
  };
  const labelCounts = () => api(() => {
    const c = window.specdeformEditor.counts();
    return { handles: c.handles + c.pinned, fixed: c.fixed };
  });

  // 2. Painted while the basis computes.
  log('paint while the basis computes');
  await page.click('[data-tool="handle"]');
  await stroke(ends.handle);
  await page.click('[data-tool="fixed"]');
  await page.fill('#radius', '10');
  await stroke(ends.fixed);
  await page.waitForFunction(() => window.specdeformEditor.counts().fixed > 0, null, { timeout: 30000 });
  const painted = { ...(await labelCounts()), phase: await api(() => window.specdeformEditor.phase), at: await now() };
  result.painted_before_ready = painted.phase === 'loading';
  result.handle_painted_s = painted.at / 1000;
  log(`painted ${painted.handles} handle and ${painted.fixed} fixed vertices at ${(painted.at / 1000).toFixed(2)} s, phase ${painted.phase}`);
  check(painted.handles > 0 && painted.fixed > 0, `a handle and a fixed part were painted (${JSON.stringify(painted)})`);
  // The counts show what was painted within a second, the basis computing or not.
  const counted = await page.waitForFunction(() => {
    const c = window.specdeformEditor.counts();
    return document.getElementById('counts').textContent.includes(`fixed: ${c.fixed.toLocaleString()}`);
  }, null, { timeout: 1000, polling: kPollMs }).then(() => true, () => false);
  check(counted, `the panel counts the painted vertices as soon as they are painted ("${await page.textContent('#counts')}", phase ${painted.phase})`);
  // The first drag waits only for the basis and the selection (not the transfer's details).
  // (When the basis is ready before the fixed part is painted, the two strokes reach the server
  // one after the other: wait for both.)
  await page.waitForFunction((p) => {
    const e = window.specdeformEditor;
    const c = e.serverCounts();
    return e.ready && c?.handles === p.handles && c?.fixed === p.fixed;
  }, painted, { timeout: 300000, polling: kPollMs }).catch(() => {});
  result.selection_applied_s = (await now()) / 1000;
  result.ready_s = (await api(() => window.statusLog.find((s) => /: ready/.test(s.text))?.t ?? performance.now())) / 1000;
  const applied = await api(() => window.specdeformEditor.serverCounts());
  check(applied.handles === painted.handles && applied.fixed === painted.fixed,
    `the server took the selection painted while loading (${JSON.stringify(applied)} of ${JSON.stringify(painted)})`);

  // 3. Every stage labelled; none sits at 100%.
  const statuses = await api(() => window.statusLog);
  const loading = statuses.filter((s) => s.t <= result.ready_s * 1000 + 1);
  let longest = { seconds: 0, text: '' };
  loading.forEach((s, i) => {
    const next = loading[i + 1]?.t ?? result.ready_s * 1000;
    if (next - s.t > 1000 * longest.seconds) longest = { seconds: (next - s.t) / 1000, text: s.text };
  });
  result.stages = [...new Set(loading.map((s) => s.text.replace(/\d+%/, '').replace(/ · .*/, '')))];
  result.stage_starts_s = Object.fromEntries(result.stages.map((stage) =>
    [stage, loading.find((s) => s.text.startsWith(stage.trim()))?.t / 1000]));
  result.longest_status = longest;
  log('stages:', JSON.stringify(result.stages), 'longest:', JSON.stringify(longest));
  check(!loading.some((s, i) => /100%/.test(s.text) && (loading[i + 1]?.t ?? 0) - s.t > 1000),
    'no status reads 100% for over a second');
  // Each label moves at least once a second (a stage without a fraction counts its seconds); a
  // task holding the page (the mesh's adoption, over a second at 692k) may hold one back.
  check(longest.seconds < kStillLabelS, `no label stands still for ${kStillLabelS} s (${JSON.stringify(longest)})`);

  // 4. The first drag: the handle up the screen in 12 steps; its detailed result drawn.
  log('drag');
  await page.click('[data-tool="move"]');
  const start = await screen(ends.handle);
  const drawnBefore = await api(() => window.specdeformEditor.stats.framesDrawn);
  const td = Date.now();
  result.drag_started_s = (await now()) / 1000;
  await page.mouse.move(start.x, start.y);
  await page.mouse.down();
  for (let i = 1; i <= 12; ++i) await page.mouse.move(start.x, start.y - 10 * i);
  await page.mouse.up();
  const up = Date.now();
  // When the page took the release (a busy page answers the harness later): the release's
  // frame may be drawn before an evaluation's answer comes back.
  const upOnPage = await api(() => window.releasedAt);
  // The whole mesh drawn at the release's pose: its details as displacements while the
  // transfer's factorisation runs, then (settled) with the transfer.
  await page.waitForFunction((t) => window.specdeformEditor.stats.detailedDrawn > t, upOnPage,
    { timeout: 120000 }).catch(() => {});
  result.first_drag_whole_mesh_drawn_s = (await api(() => window.specdeformEditor.stats.detailedDrawn)) / 1000;
  // The work done by then: were the two cores ever idle?
  const cpu = cpuSeconds(editor.server.pid);
  result.cpu_to_first_drag_s = Object.fromEntries(Object.keys(cpu).map((k) => [k, +(cpu[k] - (cpuAtOpening[k] ?? 0)).toFixed(1)]));
  result.cpu_to_first_drag_s.server_before_opening = +cpuAtOpening.server.toFixed(1);
  result.draws_to_first_drag = await api(() => window.specdeformEditor.draws());
  result.full_draws_to_first_drag = await api(() => window.specdeformEditor.fullDraws());
  result.draws_skipped_to_first_drag = await api(() => window.specdeformEditor.drawsSkipped());
  await waitReady(120000);
  result.drag_12_steps_play_s = (up - td) / 1000;
  result.drag_detailed_after_release_s = (Date.now() - up) / 1000;
  result.first_drag_drawn_s = (await now()) / 1000;
  // Where the page's main thread was held (tasks over 50 ms), up to the drag's detail.
  const { longTasks, harnessTasks } = await api(() => ({ longTasks: window.longTasks, harnessTasks: window.harnessTasks }));
  const harness = ([t, d]) => harnessTasks.some(([b, e]) => b >= t && e <= t + d);
  result.harness_tasks_s = longTasks.filter(harness).map(([t, d]) => [+(t / 1000).toFixed(2), +(d / 1000).toFixed(2)]);
  result.long_tasks_s = longTasks.sort((a, b) => b[1] - a[1]).slice(0, 8)
    .map(([t, d]) => [+(t / 1000).toFixed(2), +(d / 1000).toFixed(2)]);
  // From the mesh's first part to the first drag (its press), a task that took the first part
  // included: the page answers throughout.
  result.longest_task_to_drag_s = +(Math.max(0, ...longTasks
    .filter(([t, d]) => t + d > arrival.meshStarted && t < result.drag_started_s * 1000 && !harness([t, d]))
    .map(([, d]) => d)) / 1000).toFixed(3);
  check(result.longest_task_to_drag_s < kLongestTaskS,
    `no task holds the page ${kLongestTaskS} s from the mesh's first part to the first drag (${result.longest_task_to_drag_s} s)`);
  result.messages_s = messages.filter(([t]) => t <= result.first_drag_drawn_s + 0.5);
  const moved = await api(() => window.specdeformEditor.transforms()[0]);
  check(Math.hypot(moved[3], moved[7], moved[11]) > 0, 'the drag moved the handle');
  check((await api(() => window.specdeformEditor.stats.framesDrawn)) > drawnBefore, 'the drag was drawn');
  await page.screenshot({ path: resolve(args.out, 'loading.png') });

  // 5. The basis saved in the background, and said so.
  await page.waitForFunction(() => window.specdeformEditor.notes().some((n) => /saved the basis for next time|basis was not saved/.test(n.text)), null, { timeout: 120000 });
  const saved = await api(() => ({ notes: window.specdeformEditor.notes().map((n) => n.text), log: window.statusLog.map((s) => s.text) }));
  // The status says "saving" unless the transfer's factoring, whose status comes first, outlasts
  // the save (a 43k basis saves in a fraction of a second): reported, the note checked.
  result.saving_status_shown = saved.log.some((t) => /saving the basis for next time/.test(t));
  check(saved.notes.some((t) => /saved the basis for next time/.test(t)), `the basis was saved (${JSON.stringify(saved.notes)})`);
  result.saved = saved.notes.find((t) => /saved the basis/.test(t));

  // 6. Pointer moves coalesce: 40 moves within one task are acted on once or twice.
  const coalesced = await api(() => new Promise((done) => {
    const s = window.specdeformEditor.stats;
    const [moves, acted] = [s.pointerMoves, s.pointerActed];
    const canvas = document.querySelector('#view canvas');
    for (let i = 0; i < 40; ++i) {
      canvas.dispatchEvent(new PointerEvent('pointermove', { clientX: 400 + i, clientY: 400, bubbles: true }));
    }
    requestAnimationFrame(() => requestAnimationFrame(() => done({ moves: s.pointerMoves - moves, acted: s.pointerActed - acted })));
  }));
  check(coalesced.moves === 40 && coalesced.acted <= 2, `40 pointer moves in one frame acted on at most twice (${JSON.stringify(coalesced)})`);

  // 7. A 5-point stroke: applied (the server's answer) after the release.
  for (const close of await page.$$('#notes .note button')) await close.click().catch(() => {});
  await page.click('[data-tool="handle"]');
  await page.fill('#radius', '4');
  const before = await labelCounts();
  const t5 = Date.now();
  await stroke(ends.handle, 5);
  const released = Date.now();
  // Applied: the server's answer counts what the page painted.
  await page.waitForFunction(() => {
    const e = window.specdeformEditor;
    const c = e.counts();
    return e.serverCounts()?.handles === c.handles + c.pinned;
  }, null, { timeout: 60000, polling: kPollMs });
  result.stroke_5_points_play_s = (released - t5) / 1000;
  result.stroke_applied_after_release_s = (Date.now() - released) / 1000;
  await waitReady(120000);
  const after = await labelCounts();
  check(after.handles >= before.handles, 'the stroke painted');

  // 8. The Log, opened, clear of the help line.
  await page.click('#log-box summary');
  const boxes = await api(() => ['log-box', 'help', 'hint'].map((id) => {
    const r = document.getElementById(id).getBoundingClientRect();
    return { id, left: r.left, right: r.right, top: r.top, bottom: r.bottom };
  }));
  const overlap = (a, b) => a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom;
  check(!overlap(boxes[0], boxes[1]) && !overlap(boxes[0], boxes[2]), `the Log covers neither the help nor the hint (${JSON.stringify(boxes)})`);
  await page.click('#log-box summary');

  // 9. Disconnected: keys do nothing.
  editor.server.kill();
  await page.waitForFunction(() => window.specdeformEditor.phase === 'disconnected', null, { timeout: 20000 });
  await page.keyboard.press('2');
  check((await page.getAttribute('[data-tool="fixed"]', 'aria-checked')) !== 'true', '"2" does not pick a tool while disconnected');
  await page.keyboard.press('g');
  check(await page.$eval('#header', (h) => h.hidden), 'G does not start a move while disconnected');
  check(pageErrors.length === 0, `no page errors: ${pageErrors.join('; ')}`);
} catch (e) {
  for (const page of browser.contexts().flatMap((c) => c.pages())) {
    await page.screenshot({ path: resolve(args.out, 'failure.png') }).catch(() => {});
    log('page notes:', JSON.stringify(await page.evaluate(() => window.specdeformEditor?.notes()).catch(() => null)));
    log('statuses:', JSON.stringify(await page.evaluate(() => window.statusLog).catch(() => null)));
  }
  throw e;
} finally {
  await browser.close();
  editor.server.kill();
  rmSync(cacheDir, { recursive: true, force: true });
}
writeFileSync(resolve(args.out, 'loading.json'), JSON.stringify(result, null, 1) + '\n');
console.log(JSON.stringify(result));
