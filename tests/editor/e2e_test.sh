#!/usr/bin/env bash
# Runs the browser editor's end-to-end test (web/e2e/editor.e2e.mjs) in Debian's Chromium.
# Usage: e2e_test.sh SPECDEFORM_BINARY WEB_DIR OUTPUT_DIR. Exit 77 (skipped) without Chromium,
# Node.js >= 20 or the editor's npm packages.
set -u
bin=$1 web=$2 out=$3
chromium=${CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then echo "SKIP: no $chromium (apt-get install chromium)"; exit 77; fi
if ! node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 20 ? 0 : 1)'; then
  echo "SKIP: Node.js >= 20 needed by playwright-core"; exit 77
fi
if [ ! -d "$web/node_modules/playwright-core" ]; then
  echo "SKIP: run scripts/setup.sh first (web/node_modules)"; exit 77
fi
exec node "$web/e2e/editor.e2e.mjs" --binary "$bin" --chromium "$chromium" --out "$out"
