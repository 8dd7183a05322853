// What the editor's browser scripts share: starting `specdeform edit` and headless Chromium.
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

// Starts `BINARY edit --port PORT --no-cache ARGS...` (PORT 0: any free one; `cacheDir`: that
// basis cache instead of none); `url` resolves to the address it prints, once it serves the page.
export function startEditor(binary, editArgs = [], port = 0, cacheDir = null) {
  const cache = cacheDir ? ['--cache-dir', cacheDir] : ['--no-cache'];
  const server = spawn(binary, ['edit', '--port', String(port), ...cache, ...editArgs], {
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  const url = new Promise((resolveUrl, reject) => {
    server.stdout.on('data', (d) => {
      const m = /http:\/\/\S+/.exec(String(d));
      if (m) resolveUrl(m[0]);
    });
    server.on('exit', (code) => reject(new Error(`specdeform edit exited with ${code}`)));
  });
  return { server, url };
}

// Debian's Chromium (or `executablePath`), drawing WebGL with SwiftShader where there is no GPU.
export function launchChromium(executablePath = process.env.CHROMIUM ?? '/usr/bin/chromium') {
  return chromium.launch({
    executablePath,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--no-sandbox'],
  });
}

// One line of the test's progress on stderr.
export const log = (...a) => console.error('e2e:', ...a);

// Throws, naming what failed, unless `condition` holds.
export function check(condition, message) {
  if (!condition) throw new Error(`check failed: ${message}`);
}
