#!/usr/bin/env bash
# Builds (installing what is missing) and runs every test, the browser editor's end-to-end test
# in Debian's Chromium included. Usage: scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/apt_install.sh chromium  # for the editor's end-to-end test
scripts/setup.sh build
echo "test: installed and built in ${SECONDS} s"
ctest --test-dir build --output-on-failure -j "$(nproc)"
