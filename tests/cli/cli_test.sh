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
grep -q '"base_miss"' "$tmp/out" || { echo "FAIL: deform --json lacks base_miss"; fails=$((fails + 1)); }
awk 'NR==1{print "# sel"} NR>1{}' /dev/null >"$tmp/p.sel"
for i in $(seq 0 288); do if [ "$i" -lt 17 ]; then echo 0; elif [ "$i" -gt 271 ]; then echo 2; else echo 1; fi; done >>"$tmp/p.sel"
printf '# lift\n1 0 0 0\n0 1 0 0\n0 0 1 0.2\n0 0 0 1\n' >"$tmp/p.def"
expect 0 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" --def "$tmp/p.def" -m 30 -o "$tmp/d.obj"
expect 0 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" --def "$tmp/p.def" --solver spatial --detail none -o "$tmp/s.obj"
expect 2 "$bin" deform "$tmp/p.off" -o "$tmp/x.off"
# An output that could not be written is refused before the solve, naming the folder.
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" -o "$tmp/no such folder/d.off"
grep -qF 'no such folder does not exist' "$tmp/err" || { echo "FAIL: missing folder: $(cat "$tmp/err")"; fails=$((fails + 1)); }
expect 1 "$bin" smooth "$tmp/p.off" -o "$tmp/d.xyz"
expect 1 "$bin" subdivide "$tmp/p.off" -o "$tmp"
# The default m on a mesh of fewer vertices: lowered, with a note.
printf 'OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n' >"$tmp/box.off"
printf '{"handles": [{"vertices": [6], "transform": {"translate": [0, 0, 0.2]}}], "fixed": [0]}' >"$tmp/box.json"
expect 0 "$bin" deform "$tmp/box.off" --scene "$tmp/box.json" -o "$tmp/box-d.off"
grep -qF 'note: m = 7: the mesh has only 8 vertices' "$tmp/err" || { echo "FAIL: small mesh: $(cat "$tmp/err")"; fails=$((fails + 1)); }
expect 2 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" -o "$tmp/x.off"
expect 2 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" --detail sideways -o "$tmp/x.off"
head -5 "$tmp/p.sel" >"$tmp/short.sel"
expect 1 "$bin" deform "$tmp/p.off" --sel "$tmp/short.sel" --def "$tmp/p.def" -o "$tmp/x.off"
printf '{"handles": [{"vertices": [9999]}]}' >"$tmp/bad.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/bad.json" -o "$tmp/x.off"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" --constraints hard -m 3 -o "$tmp/x.off"
check_error() {  # check_error FRAGMENT: the last command's stderr contains it
  grep -qF -- "$1" "$tmp/err" || { echo "FAIL: expected '$1' in: $(cat "$tmp/err")"; fails=$((fails + 1)); }
}
# Bad numbers and names (issue 26): each a clear error and no output, or valid JSON.
no_output() {  # no_output FILE: the last command wrote no FILE
  [ -e "$1" ] && { echo "FAIL: $1 written despite an error"; fails=$((fails + 1)); rm -f "$1"; }
}
printf '# far\n1 0 0 1e300\n0 1 0 0\n0 0 1 0\n0 0 0 1\n' >"$tmp/far.def"
expect 1 "$bin" deform "$tmp/p.off" --sel "$tmp/p.sel" --def "$tmp/far.def" -m 30 -o "$tmp/x.off"
check_error "more than 1000000 times the size of the constrained region"
no_output "$tmp/x.off"
printf '{"handles": [{"vertices": [288], "transform": {"translate": [0, 0, 0.2]}}], "fixed": [0], "fixed": [1]}' >"$tmp/twice.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/twice.json" -m 30 -o "$tmp/x.off"
check_error 'the key "fixed" appears twice in one object'
no_output "$tmp/x.off"
printf '{"handles": [{"vertices": [288], "transform": {"scale": -1}}], "fixed": [0, 1, 2, 16]}' >"$tmp/mirror.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/mirror.json" -m 30 -o "$tmp/x.off"
check_error "mirrors the handle (negative determinant)"
no_output "$tmp/x.off"
odd=$(printf '%s/d\377\376.off' "$tmp")
expect 0 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" -m 30 -o "$odd" --json
/usr/bin/python3 -m json.tool "$tmp/out" >/dev/null || { echo "FAIL: --json with a non-UTF-8 name is not valid JSON"; fails=$((fails + 1)); }
faces=$(sed -n 2p "$tmp/p.off" | awk '{print $2}')
awk -v f="$faces" 'NR==2{$2=f+1} {print} END{}' "$tmp/p.off" >"$tmp/dup.off"
tail -1 "$tmp/p.off" >>"$tmp/dup.off"
expect 0 "$bin" info "$tmp/dup.off" --json
grep -q '"duplicate_faces":1' "$tmp/out" || { echo "FAIL: info does not report the duplicated face: $(cat "$tmp/out")"; fails=$((fails + 1)); }
# deform drops the duplicate with a note: the same vertices as without it.
expect 0 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" -m 30 -o "$tmp/plain.off"
expect 0 "$bin" deform "$tmp/dup.off" --scene "$tmp/scene.json" -m 30 -o "$tmp/dup_out.off"
grep -q "faces on the same three vertices as an earlier face were dropped" "$tmp/err" || { echo "FAIL: no note of the dropped duplicate: $(cat "$tmp/err")"; fails=$((fails + 1)); }
vertices=$(sed -n 2p "$tmp/p.off" | awk '{print $1}')
cmp -s <(head -n $((vertices + 2)) "$tmp/plain.off" | tail -n "$vertices") <(head -n $((vertices + 2)) "$tmp/dup_out.off" | tail -n "$vertices") || { echo "FAIL: a duplicated face changed the result"; fails=$((fails + 1)); }
# A region of influence: the far end stays exactly; a radius that is not positive is refused.
expect 0 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" -m 30 --influence 0.2 -o "$tmp/near.off"
expect 2 "$bin" deform "$tmp/p.off" --scene "$tmp/scene.json" -m 30 --influence -1 -o "$tmp/x.off"
# A scene that names its mesh, read without MESH.
printf '{"mesh": "p.off", "handles": [{"vertices": [288], "transform": {"translate": [0, 0, 0.2]}}], "fixed": [0, 1]}' >"$tmp/named.json"
expect 0 "$bin" deform --scene "$tmp/named.json" -m 30 -o "$tmp/named.off"
# Scene fields of the wrong type: exit 1, one line naming the field (not an abort).
printf '{"handles": [{"vertices": [288], "transform": {"rotate": {"axis": 5, "degrees": 10}}}]}' >"$tmp/axis.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/axis.json" -o "$tmp/x.off"
check_error "axis.json handle 0 transform rotate axis: expected an array of 3 numbers, got a number"
printf '{"handles": [{"vertices": [288], "transform": {"rotate": 5}}]}' >"$tmp/rotate.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/rotate.json" -o "$tmp/x.off"
check_error "handle 0 transform rotate: expected an object, got a number"
printf '{"handles": [{"vertices": [288]}], "settings": {"modes": "all"}}' >"$tmp/modes.json"
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/modes.json" -o "$tmp/x.off"
check_error "settings modes: expected an integer, got a string"
# --json: a failure is one JSON object on stdout too, with the exit code.
expect 1 "$bin" deform "$tmp/p.off" --scene "$tmp/axis.json" -o "$tmp/x.off" --json
grep -q '^{"error":".*rotate axis: expected an array of 3 numbers, got a number","exit_code":1}$' "$tmp/out" ||
  { echo "FAIL: deform --json error: $(cat "$tmp/out")"; fails=$((fails + 1)); }
expect 1 "$bin" info "$tmp/missing.off" --json
grep -q '"exit_code":1' "$tmp/out" || { echo "FAIL: info --json error: $(cat "$tmp/out")"; fails=$((fails + 1)); }
expect 2 "$bin" basis "$tmp/s.off" -m zero --json
grep -q '"exit_code":2' "$tmp/out" || { echo "FAIL: basis --json error: $(cat "$tmp/out")"; fails=$((fails + 1)); }
expect 1 "$bin" info "$tmp/missing.off"
[ -s "$tmp/out" ] && { echo "FAIL: an error without --json printed on stdout"; fails=$((fails + 1)); }
# Handle groups of vertices the reader dropped (a vertex no face uses, appended as vertex 289).
awk 'NR == 2 { $1 = $1 + 1 } { print } NR == 291 { print "5 5 5" }' "$tmp/p.off" >"$tmp/unused.off"
printf '{"handles": [{"vertices": [289]}], "fixed": [0]}' >"$tmp/dropped.json"
# (after the reader's note on the vertex it dropped: two lines on stderr)
"$bin" deform "$tmp/unused.off" --scene "$tmp/dropped.json" -m 30 -o "$tmp/x.off" 2>"$tmp/err"
[ $? = 1 ] || { echo "FAIL: a handle group of dropped vertices only did not exit 1"; fails=$((fails + 1)); }
check_error "handle group 0: all 1 of its vertices (file vertex 289 first) are used by no face"
printf '{"handles": [{"vertices": [288, 289], "transform": {"translate": [0, 0, 0.2]}}], "fixed": [0]}' >"$tmp/partly.json"
expect 0 "$bin" deform "$tmp/unused.off" --scene "$tmp/partly.json" -m 30 -o "$tmp/partly.off"
check_error "partly.json: note: handle group 0: 1 of its 2 vertices are used by no face and were left out"
# Files that are not what they claim: cut inside a face, a Git LFS pointer; triangle strips.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4' >"$tmp/cut.obj"
expect 1 "$bin" info "$tmp/cut.obj"
check_error "truncated: the file ends inside face 1"
printf 'version https://git-lfs.github.com/spec/v1\noid sha256:0123\nsize 1234\n' >"$tmp/lfs.ply"
expect 1 "$bin" info "$tmp/lfs.ply"
check_error "lfs.ply: is a Git LFS pointer, not the mesh: run git lfs pull"
printf 'ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0\n9 0 2 1 3 -1 2 4 3 5\n' >"$tmp/strips.ply"
expect 0 "$bin" info "$tmp/strips.ply" --json
grep -q '"faces":4,' "$tmp/out" || { echo "FAIL: strips.ply: $(cat "$tmp/out")"; fails=$((fails + 1)); }
# info names defects: a bow tie (two triangles sharing vertex 0 only, the second turned over).
printf 'OFF\n5 2 0\n0 0 0\n1 0 0\n0 1 0\n-1 0 0\n0 -1 0\n3 0 1 2\n3 0 3 4\n' >"$tmp/bowtie.off"
expect 0 "$bin" info "$tmp/bowtie.off" --json
grep -q '"pinch_vertices":1,"first_pinch_vertex":0,' "$tmp/out" ||
  { echo "FAIL: bowtie.off: $(cat "$tmp/out")"; fails=$((fails + 1)); }
expect 0 "$bin" bench --quick --json "$tmp/bench.json" --markdown "$tmp/bench.md"
grep -q '"PT1_basis"' "$tmp/bench.json" && grep -q '"spatial_prefactored_frame"' "$tmp/bench.json" ||
  { echo "FAIL: bench JSON lacks the Table 1 columns"; fails=$((fails + 1)); }
grep -q '^| bumpy-bar-6 ' "$tmp/bench.md" || { echo "FAIL: bench markdown lacks its rows"; fails=$((fails + 1)); }
expect 0 "$bin" converge "$tmp/p.off" --scene "$tmp/scene.json" -m 10 20 40 --json "$tmp/conv.json" -o "$tmp/conv"
grep -q '"displacement_vs_spatial"' "$tmp/conv.json" && [ -s "$tmp/conv/m40_deformed.off" ] ||
  { echo "FAIL: converge wrote no table or meshes"; fails=$((fails + 1)); }
expect 0 "$bin" compare "$tmp/p.off" --scene "$tmp/scene.json" -m 20 --repeat 1 --peer-iterations 50 \
  --json "$tmp/cmp.json" --markdown "$tmp/cmp.md" -o "$tmp/cmp"
[ "$(grep -c '^| ' "$tmp/cmp.md")" = 6 ] && grep -q '"base_handle_miss"' "$tmp/cmp.json" &&
  [ -s "$tmp/cmp/SR_ARAP__CGAL___converged.off" ] ||
  { echo "FAIL: compare wrote no table of five methods or no meshes"; fails=$((fails + 1)); }
expect 0 "$bin" demo -o "$tmp/demo" -m 40
[ -s "$tmp/demo/4_deformed.obj" ] || { echo "FAIL: demo wrote no deformed mesh"; fails=$((fails + 1)); }
expect 1 "$bin" edit "$tmp/missing.obj" --port 0
expect 1 "$bin" edit --assets "$tmp/nowhere" --port 0
expect 1 "$bin" edit --host not-an-address --port 0 --assets "$tmp"
expect 2 "$bin" edit --port 70000
# The program runs with glibc's huge pages for malloc (apps/huge_pages_start.h): it starts itself
# again with glibc.malloc.hugetlb=1 in GLIBC_TUNABLES, and a value the user set stays. Read from
# the running editor server's environment (where glibc cuts a list of several tunables at its
# first ':' as it parses it, so other tunables kept are not seen there).
tunables_of() {  # tunables_of [VAR=VALUE...]: the server's GLIBC_TUNABLES
  env -u GLIBC_TUNABLES "$@" "$bin" edit --port 0 --no-cache --assets "$tmp" >"$tmp/serve" 2>&1 &
  local pid=$! i
  for i in $(seq 100); do grep -q http "$tmp/serve" && break; sleep 0.1; done
  tr '\0' '\n' </proc/$pid/environ | sed -n 's/^GLIBC_TUNABLES=//p'
  kill $pid; wait $pid 2>/dev/null
}
if ldd --version 2>&1 | grep -qiE 'glibc|gnu libc'; then
  echo '<html></html>' >"$tmp/index.html"
  [ "$(tunables_of)" = glibc.malloc.hugetlb=1 ] ||
    { echo "FAIL: the program runs without huge pages: '$(tunables_of)'"; fails=$((fails + 1)); }
  [ "$(tunables_of GLIBC_TUNABLES=glibc.malloc.hugetlb=0)" = glibc.malloc.hugetlb=0 ] ||
    { echo "FAIL: the user's hugetlb=0 not kept"; fails=$((fails + 1)); }
fi
[ "$fails" = 0 ] && echo "cli tests passed"
exit "$fails"
