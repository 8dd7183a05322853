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
# --laplacian: the cache records it, and a cache of the other Laplacian is refused.
expect 0 "$bin" smooth "$tmp/s.off" -m 9 --laplacian intrinsic-delaunay --basis "$tmp/id.sdbasis" -o "$tmp/smooth-id.ply"
expect 1 "$bin" smooth "$tmp/s.off" -m 9 --basis "$tmp/id.sdbasis" -o "$tmp/x.ply"
grep -qF 'computed with the intrinsic-delaunay Laplacian' "$tmp/err" || { echo "FAIL: cache of the other Laplacian: $(cat "$tmp/err")"; fails=$((fails + 1)); }
expect 2 "$bin" basis "$tmp/s.off" -m 9 --laplacian delaunay
# deform: a JSON scene, the Botsch-Sorkine files, errors
"$bin" generate bumpy-plane --resolution 16 -o "$tmp/p.off" >/dev/null
printf '{"handles": [{"vertices": [288], "transform": {"translate": [0, 0, 0.2]}}], "fixed": [0, 1, 2, 16]}' >"$tmp/scene.json"
expect 0 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" -m 30 -o "$tmp/d.off" --json --repeat 3
grep -q '"constraint_error"' "$tmp/out" || { echo "FAIL: deform --json lacks constraint_error"; fails=$((fails + 1)); }
awk 'NR==1{print "# sel"} NR>1{}' /dev/null >"$tmp/p.sel"
for i in $(seq 0 288); do if [ "$i" -lt 17 ]; then echo 0; elif [ "$i" -gt 271 ]; then echo 2; else echo 1; fi; done >>"$tmp/p.sel"
printf '# lift\n1 0 0 0\n0 1 0 0\n0 0 1 0.2\n0 0 0 1\n' >"$tmp/p.def"
expect 0 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" --def "$tmp/p.def" -m 30 -o "$tmp/d.obj"
expect 0 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" --def "$tmp/p.def" --solver spatial --detail none -o "$tmp/s.obj"
expect 2 "$bin" deform "$tmp/p.off" -o "$tmp/x.off"
expect 2 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" -o "$tmp/x.off"
expect 2 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" --detail sideways -o "$tmp/x.off"
head -5 "$tmp/p.sel" >"$tmp/short.sel"
expect 1 "$bin" deform "$tmp/p.off" --sel "$tmp/short.sel" --def "$tmp/p.def" -o "$tmp/x.off"
printf '{"handles": [{"vertices": [9999]}]}' >"$tmp/bad.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/bad.json" -o "$tmp/x.off"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" --constraints hard -m 3 -o "$tmp/x.off"
expect 0 "$bin" bench --quick --json "$tmp/bench.json" --markdown "$tmp/bench.md"
grep -q '"PT1_basis"' "$tmp/bench.json" && grep -q '"spatial_prefactored_frame"' "$tmp/bench.json" ||
  { echo "FAIL: bench JSON lacks the Table 1 columns"; fails=$((fails + 1)); }
grep -q '^| bumpy-bar-6 ' "$tmp/bench.md" || { echo "FAIL: bench markdown lacks its rows"; fails=$((fails + 1)); }
expect 0 "$bin" converge "$tmp/p.off" --scene "$tmp/scene.json" -m 10 20 40 --json "$tmp/conv.json" -o "$tmp/conv"
grep -q '"displacement_vs_spatial"' "$tmp/conv.json" && [ -s "$tmp/conv/m40_deformed.obj" ] ||
  { echo "FAIL: converge wrote no table or meshes"; fails=$((fails + 1)); }
expect 0 "$bin" demo -o "$tmp/demo" -m 40
[ -s "$tmp/demo/4_deformed.obj" ] || { echo "FAIL: demo wrote no deformed mesh"; fails=$((fails + 1)); }
expect 1 "$bin" edit "$tmp/missing.obj" --port 0
expect 1 "$bin" edit --assets "$tmp/nowhere" --port 0
expect 1 "$bin" edit --host not-an-address --port 0 --assets "$tmp"
expect 2 "$bin" edit --port 70000
[ "$fails" = 0 ] && echo "cli tests passed"
exit "$fails"
