#!/usr/bin/env bash
# Builds (installing what is missing) and runs every test, the browser editor's end-to-end test
# in Debian's Chromium included. Usage: scripts/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
if ! dpkg-query -W -f='${Status}' chromium 2>/dev/null | grep -q "install ok installed"; then
  sudo_cmd=""
  [ "$(id -u)" != 0 ] && sudo_cmd="sudo"
  echo "installing: chromium (for the editor's end-to-end test)"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq chromium >/dev/null
fi
scripts/setup.sh build
ctest --test-dir build --output-on-failure -j "$(nproc)"
