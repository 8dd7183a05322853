#!/usr/bin/env bash
# Builds the libFuzzer targets with clang and runs each for SECONDS (default 60) from its seed
# corpus in fuzz/corpus/<target>. Usage: scripts/fuzz.sh [SECONDS]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ not installed, skipped"; exit 0
fi
targets="mesh_readers scene editor_messages"
CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=Release -DSPECDEFORM_BUILD_FUZZERS=ON \
  -DSPECDEFORM_BUILD_TESTS=OFF -DSPECDEFORM_BUILD_BENCHMARKS=OFF -DSPECDEFORM_BUILD_CLI=OFF \
  -DSPECDEFORM_BUILD_PYTHON=OFF >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target $(printf 'fuzz_%s ' $targets) >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for target in $targets; do
  mkdir "$work/$target"
  cp fuzz/corpus/$target/* "$work/$target/"
  build-fuzz/bin/fuzz_$target "$work/$target" -max_total_time="$seconds" -max_len=4096 \
    -rss_limit_mb=2048 -print_final_stats=1 2>&1 | grep -E "Done|ERROR|SUMMARY"
  echo "fuzz_$target: no crash in ${seconds}s"
done
