#!/usr/bin/env bash
# Regenerates docs/results/: the paper's Table 1, Fig. 5 and Fig. 6 measured on this machine,
# pictures of the pipeline (original, smooth base, deformed base, detailed result), all with the
# paper's linear energy; the linear energy, spectral ARAP and CGAL's SR-ARAP on scenes that turn
# (tables and pictures); the Blender add-on against Blender's Laplacian Deform; the intrinsic
# Delaunay Laplacian against the cotan one on every shared model; and the exact and the
# multilevel basis on subdivided meshes up to 2.77M vertices.
# Needs ../shared/meshes (the test meshes) and a build (scripts/setup.sh); installs
# python3-matplotlib for the plot, chromium for the pictures and blender where missing.
# Usage: scripts/reproduce.sh [OUT]     (default: docs/results; takes about 45 minutes)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs/results}
models=../shared/meshes/models
scenes=../shared/meshes/scenes
bin=build/bin/specdeform
[ -d "$models" ] || { echo "reproduce: $models not found (the shared test meshes)" >&2; exit 1; }
[ -x "$bin" ] || { echo "reproduce: $bin not found (run scripts/setup.sh)" >&2; exit 1; }
scripts/apt_install.sh python3-matplotlib chromium blender
mkdir -p "$out/pictures"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
arm=$models/armadillo.obj
hand=docs/results/scenes/armadillo-hand.json

echo "== machine"
{ lscpu | grep -E "^Model name|^CPU\(s\)"; free -g | grep Mem; git rev-parse --short HEAD; } \
  | tee "$out/machine.txt"

echo "== Table 1"
$bin bench "$models/lion.off" "$models/stanford-bunny.obj" "$arm" --energy linear \
  --json "$out/table1.json" --markdown "$out/table1.md"
$bin bench "$arm" --subdivide 1 2 --energy linear --json "$out/table1_subdivided.json" \
  --markdown "$out/table1_subdivided.md"

echo "== Fig. 5: time against m"
$bin bench "$arm" -m 50 100 200 300 500 1000 --energy linear --json "$out/fig5.json" \
  --markdown "$out/fig5.md"
/usr/bin/python3 scripts/plot_fig5.py "$out/fig5.json" "$out/fig5.svg"

echo "== Fig. 6: results against m"
$bin converge "$arm" --scene "$hand" --energy linear -m 50 100 200 300 500 900 \
  -o "$work/fig6" --json "$out/fig6.json" --markdown "$out/fig6.md"
$bin converge "$scenes/bar-bend.off" --sel "$scenes/bar-bend.sel" --def "$scenes/bar-bend.def" \
  --energy linear -m 50 100 200 300 500 900 --json "$out/fig6_bar_bend.json" \
  --markdown "$out/fig6_bar_bend.md"

echo "== the pipeline (paper Fig. 1)"
pipeline() {  # pipeline NAME MESH SCENE-ARGS...
  local name=$1 mesh=$2
  shift 2
  cp "$mesh" "$work/${name}_1_original.${mesh##*.}"
  $bin smooth "$mesh" -m 100 -o "$work/${name}_2_smooth.obj"
  $bin deform "$mesh" "$@" -m 100 --energy linear --detail none \
    -o "$work/${name}_3_deformed_base.obj"
  $bin deform "$mesh" "$@" -m 100 --energy linear --detail transfer \
    -o "$work/${name}_4_deformed.obj"
}
pipeline armadillo "$arm" --scene "$hand"
pipeline bar_bend "$scenes/bar-bend.off" --sel "$scenes/bar-bend.sel" --def "$scenes/bar-bend.def"

echo "== Rotations: linear, spectral ARAP and SR-ARAP"
for shape in bumpy-bar bumpy-tube; do
  docs/results/scenes/bumpy_bar.py $shape "$work/$shape.off" "$bin"
done
rotations() {  # rotations NAME MESH SCENE-ARGS...
  local name=$1 mesh=$2
  shift 2
  $bin compare "$mesh" "$@" --repeat 21 -o "$work/rotations_$name" \
    --json "$out/rotations_$name.json" --markdown "$out/rotations_$name.md"
}
for s in bar-twist bar-bend bumpy-plane; do
  rotations "${s//-/_}" "$scenes/$s.off" --sel "$scenes/$s.sel" --def "$scenes/$s.def"
done
for s in bumpy-bar-twist bumpy-bar-bend bumpy-tube-twist bumpy-tube-bend; do
  rotations "${s//-/_}" "$work/${s%-*}.off" --scene "docs/results/scenes/$s.json"
done
rotations armadillo_hand "$arm" --scene "$hand"
scripts/rotations_table.py "$out/rotations.md" \
  "bar-twist (135 degrees)=$out/rotations_bar_twist.json" \
  "bar-bend (90 degrees)=$out/rotations_bar_bend.json" \
  "bumpy-plane (lifted)=$out/rotations_bumpy_plane.json" \
  "bumpy bar, twist 150 degrees=$out/rotations_bumpy_bar_twist.json" \
  "bumpy bar, bend 100 degrees=$out/rotations_bumpy_bar_bend.json" \
  "bumpy tube, twist 150 degrees=$out/rotations_bumpy_tube_twist.json" \
  "bumpy tube, bend 100 degrees=$out/rotations_bumpy_tube_bend.json" \
  "armadillo hand=$out/rotations_armadillo_hand.json"

echo "== Blender: the add-on against Laplacian Deform (same process, medians of 21 updates)"
SPECDEFORM_BLENDER_DIR=build/blender SPECDEFORM_SHARED_DIR=../shared PYTHONDONTWRITEBYTECODE=1 \
  blender -b --factory-startup --python-exit-code 1 \
  --python benchmarks/blender_vs_laplacian_deform.py -- --updates 21 --reference "$work" \
  --markdown "$out/blender_vs_laplacian_deform.md" --json "$out/blender_vs_laplacian_deform.json"

echo "== A robust Laplacian: each Laplacian's eigenvalues against a finer remeshing"
for mass in lumped consistent; do
  build/bin/laplacian_agreement --mass $mass --json "$out/laplacian_$mass.json" \
    --markdown "$out/laplacian_$mass.md"
done

echo "== The basis against scipy's eigsh (same run, medians of 5)"
PYTHONPATH=build/python /usr/bin/python3 benchmarks/basis_vs_scipy.py "$arm" -k 100 --repeat 5 \
  --json "$out/basis_vs_scipy.json"

echo "== Large meshes: the exact and the multilevel basis (about 15 minutes, 10 GB at 2.77M)"
for level in 1 2 3; do $bin subdivide "$arm" -l $level -o "$work/armadillo-l$level.obj"; done
for level in 1 2; do
  $bin subdivide "$models/stanford-bunny.obj" -l $level -o "$work/bunny-l$level.obj"
done
ear=docs/results/scenes/bunny-ear.json
/usr/bin/python3 scripts/scaling.py "$out/scaling" "$arm=$hand" "$work/armadillo-l1.obj=$hand" \
  "$work/armadillo-l2.obj=$hand" "$work/bunny-l1.obj=$ear" "$work/bunny-l2.obj=$ear" \
  "$work/armadillo-l3.obj=$hand" --lanczos-below 200000

echo "== Assemblies: folds at a turning handle, and a free piece that follows"
build/bin/handle_folds >"$out/handle_folds.md"
PYTHONPATH=build/python /usr/bin/python3 scripts/assembly_pictures.py "$work/assembly" "$out/pictures"
node web/e2e/render.mjs "$work/assembly/jobs.json"
PYTHONPATH=build/python /usr/bin/python3 scripts/handle_border_pictures.py "$models/camelhead.off" \
  "$work/handle_border" "$out/pictures"
node web/e2e/render.mjs "$work/handle_border/jobs.json"

echo "== pictures"
jobs="["
for f in "$work"/armadillo_* "$work"/fig6/m*_deformed.obj; do
  base=$(basename "$f"); base=${base%.*}
  case $base in *smooth_deformed) continue ;; esac
  [ "$base" = "${base#m}" ] || base=armadillo_fig6_$base
  jobs+="{\"mesh\": \"$f\", \"png\": \"$out/pictures/$base.png\", \"view\": [0, 0.15, 1]},"
done
for f in "$work"/bar_bend_*; do
  base=$(basename "$f"); base=${base%.*}
  jobs+="{\"mesh\": \"$f\", \"png\": \"$out/pictures/$base.png\", \"view\": [0.2, 0.5, 1]},"
done
# The editor keeps its camera for another pose of the same mesh: each scene's three pictures share
# the view fitted to its first, and consecutive scenes are on different meshes.
for name in bumpy_bar_bend bar_bend bumpy_tube_bend bumpy_bar_twist bar_twist bumpy_tube_twist \
  bumpy_plane armadillo_hand; do
  case $name in
    armadillo*) view="[0, 0.15, 1]" ;;
    *plane) view="[0.2, -1, 0.45]" ;;
    *) view="[0.2, 0.5, 1]" ;;
  esac
  for m in linear:linear__spectral arap:ARAP__spectral sr_arap:SR_ARAP__CGAL___converged; do
    mesh=$work/rotations_$name/${m#*:}.obj png=$out/pictures/rotations_${name}_${m%%:*}.png
    jobs+="{\"mesh\": \"$mesh\", \"png\": \"$png\", \"view\": $view},"
  done
done
echo "${jobs%,}]" >"$work/jobs.json"
node web/e2e/render.mjs "$work/jobs.json"
echo "reproduce: wrote $out"
