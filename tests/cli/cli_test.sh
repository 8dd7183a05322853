#!/usr/bin/env bash
# Exit codes and one-line errors of the specdeform program: 0 ok, 1 bad input, 2 bad arguments.
set -u
bin=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
expect() {  # expect CODE COMMAND...
  local code=$1
  shift
  "$@" >"$tmp/out" 2>"$tmp/err"
  local got=$?
  if [ "$got" != "$code" ]; then
    echo "FAIL: '$*' exited $got, expected $code"; cat "$tmp/err"; fails=$((fails + 1))
  elif [ "$code" != 0 ] && [ "$(wc -l <"$tmp/err")" != 1 ]; then
    echo "FAIL: '$*' printed more than one error line"; cat "$tmp/err"; fails=$((fails + 1))
  fi
}
expect 0 "$bin" generate icosphere --subdivisions 3 -o "$tmp/s.off"
expect 0 "$bin" info "$tmp/s.off" --json
expect 0 "$bin" basis "$tmp/s.off" -m 9 -o "$tmp/s.sdbasis" --json
grep -q '"eigenvalues"' "$tmp/out" || { echo "FAIL: basis --json lacks eigenvalues"; fails=$((fails + 1)); }
expect 0 "$bin" smooth "$tmp/s.off" -m 9 --basis "$tmp/s.sdbasis" -o "$tmp/smooth.ply"
expect 0 "$bin" subdivide "$tmp/s.off" -o "$tmp/fine.obj"
expect 2 "$bin"
expect 2 "$bin" basis
expect 2 "$bin" basis "$tmp/s.off" -m zero
expect 2 "$bin" generate cube -o "$tmp/c.off"
expect 1 "$bin" info "$tmp/missing.off"
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n' >"$tmp/trunc.off"
expect 1 "$bin" info "$tmp/trunc.off"
expect 1 "$bin" basis "$tmp/s.off" -m 100000
expect 1 "$bin" smooth "$tmp/fine.obj" -m 9 --basis "$tmp/s.sdbasis" -o "$tmp/x.obj"
[ -e "$tmp/x.obj" ] && { echo "FAIL: output written despite an error"; fails=$((fails + 1)); }
[ "$fails" = 0 ] && echo "cli tests passed"
exit "$fails"
