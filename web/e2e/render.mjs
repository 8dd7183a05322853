// Renders meshes to PNG with the editor in headless Chromium (for docs/results.md).
//
//   node e2e/render.mjs JOBS.json
//
// JOBS.json: [{"mesh": "a.obj", "png": "a.png", "view": [x, y, z], "zoom": 1.3,
// "target": [x, y, z]}, ...]: each mesh is opened in the editor (`specdeform edit`) through its
// file input, looked at from the direction `view` (towards `target`, by default the mesh's
// centre), and the view is saved without the side panel. The editor keeps its camera for a mesh
// of the same triangles: such jobs share the first one's view, except close-ups (with a target),
// which start from the whole mesh framed.
import { readFileSync } from 'node:fs';
import { basename, dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchChromium, startEditor } from './harness.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const jobs = JSON.parse(readFileSync(process.argv[2], 'utf8'));
const binary = process.env.SPECDEFORM ?? resolve(here, '../../build/bin/specdeform');
// Starts on the built-in model, so that every job is an upload the page waits for.
const { server, url } = startEditor(binary, ['-m', '5']);
const browser = await launchChromium();
try {
  const page = await browser.newPage({ viewport: { width: 900, height: 900 } });
  await page.goto(await url);
  await page.addStyleTag({ content: '#panel, #overlay, #help, #log-box, #banner { display: none !important; }' });
  await page.waitForFunction(() => window.specdeformEditor?.ready, null, { timeout: 300000 });
  for (const job of jobs) {
    const name = basename(job.mesh);
    await page.setInputFiles('#open-mesh', job.mesh);
    // The mesh is open when its name shows; an error message instead ends the run.
    const outcome = await page.waitForFunction(
      (n) => {
        const e = window.specdeformEditor;
        const error = e.notes().find((note) => note.level === 'error');
        if (error) return { error: error.text };
        const shown = document.querySelector('#mesh-name').textContent.startsWith(`${n}:`);
        return e.ready && e.settled() && shown ? { ok: true } : null;
      },
      name,
      { timeout: 300000 },
    );
    const { error } = await outcome.jsonValue();
    if (error) throw new Error(`${job.mesh}: ${error}`);
    // A close-up (a target) starts from the whole mesh framed (Home), not from the last view.
    if (job.target) await page.keyboard.press('Home');
    await page.evaluate(([v, z, t]) => window.specdeformEditor.setView(v, z, t ?? undefined),
      [job.view ?? [0.25, 0.35, 1], job.zoom ?? 1, job.target ?? null]);
    await page.waitForTimeout(300);
    await page.locator('#view').screenshot({ path: job.png });
    console.log(`rendered ${job.png}`);
  }
} finally {
  await browser.close();
  server.kill();
}
