#!/usr/bin/env bash
# Regenerate results/<device-slug>/render.md: the thesis's rendering setup (2048 particles
# in a resting blob, 512x512, Wyvill, T = 0.9, R = 0.04, I = 2) for none, A-buffer and
# S-buffer (built by raster and by compute, unsorted and sorted) and tiles, with Phong and
# with glass at recursion depth 3; then Phong with --march lipschitz; then the march's own
# costs (bench march: counters, lanes and lanes per ray switched alone, Phong on the
# S-buffer, and glass at depth 3 on the sorted S-buffer). Each row has its floor.
# Usage: scripts/bench_render.sh [--device N|NAME] [--frames N] [--particles N]
#        [--width W] [--height H] (the last three shrink the setup, e.g. for a quick check)
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
bench_setup "$@"
n=2048 w=512 h=512
rest=()
set -- "${args[@]}"
while [ $# -gt 0 ]; do
  case "$1" in
    --particles) n=$2; shift 2 ;;
    --width) w=$2; shift 2 ;;
    --height) h=$2; shift 2 ;;
    *) rest+=("$1"); shift ;;
  esac
done
args=("${rest[@]}")
setup=(--particles "$n" --width "$w" --height "$h" --density wyvill --threshold 0.9 --radius 0.04 --refine 2)
phong=("$bin" bench render --out out/bench/render-phong "${setup[@]}" --material phong "${dev[@]}" "${args[@]}")
glass=("$bin" bench render --out out/bench/render-glass "${setup[@]}" --material glass --depth 3 "${dev[@]}" "${args[@]}")
lip=("$bin" bench render --out out/bench/render-lipschitz "${setup[@]}" --material phong --march lipschitz "${dev[@]}" "${args[@]}")
march=("$bin" bench march --out out/bench/march "${setup[@]}" --material phong --list sbuffer "${dev[@]}" "${args[@]}")
march_glass=("$bin" bench march --out out/bench/march-glass "${setup[@]}" --material glass --depth 3 --list sbuffer "${dev[@]}" "${args[@]}")
"${phong[@]}" > /dev/null
"${glass[@]}" > /dev/null
"${lip[@]}" > /dev/null
"${march[@]}" > /dev/null
"${march_glass[@]}" > /dev/null
cp out/bench/march/sweep.csv "$dir/render-march.csv"
cp out/bench/march-glass/sweep.csv "$dir/render-march-glass.csv"
cp out/bench/render-phong/sweep.csv "$dir/render-phong.csv"
cp out/bench/render-glass/sweep.csv "$dir/render-glass.csv"
cp out/bench/render-phong/sweep.png "$dir/render-phong.png"
cp out/bench/render-glass/sweep.png "$dir/render-glass.png"
cp out/bench/render-lipschitz/sweep.csv "$dir/render-lipschitz.csv"
md=$dir/render.md
{
  echo "# Metaball rendering on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_render.sh ${*}\`, which runs:"
  echo
  echo "    fluidform ${phong[*]:1}"
  echo "    fluidform ${glass[*]:1}"
  echo "    fluidform ${lip[*]:1}"
  echo "    fluidform ${march[*]:1}"
  echo "    fluidform ${march_glass[*]:1}"
  echo
  echo "The thesis (GTX 1080 Ti, 2048 particles shaped like a character, 512x512): Phong"
  echo "none 11 / A-buffer 87 / S-buffer 98 fps, 8.7 / 5.8 MB; transparent at depth 3:"
  echo "none 2-3 / A 37-39 / S 52-57 fps. Here a resting blob of the same count and spacing."
  echo
  echo "## Phong"
  echo
  cat out/bench/render-phong/sweep.md
  echo
  echo "![Phong frame time per list](render-phong.png)"
  echo
  echo "## Glass, recursion depth 3"
  echo
  cat out/bench/render-glass/sweep.md
  echo
  echo "![Glass frame time per list](render-glass.png)"
  echo
  echo "## Phong, --march lipschitz"
  echo
  echo "Primary rays skip the samples the field's Lipschitz bound proves outside (the same"
  echo "hits); compare steps/px and render/march with the Phong table above."
  echo
  cat out/bench/render-lipschitz/sweep.md
  echo
  echo "## The march's own costs (Phong, S-buffer)"
  echo
  echo "Each suspect switched alone against the default (counters summed per workgroup into"
  echo "64 slots, 8 x 8 blocks, one invocation a ray): counters summed per workgroup, no"
  echo "counters, rows of 64 lanes, and 8, 16 or 32 lanes a ray (where the subgroup holds"
  echo "them). serial max: the most field evaluations one invocation made in series."
  echo
  cat out/bench/march/sweep.md
  echo
  echo "## The march's own costs (glass at depth 3, sorted S-buffer)"
  echo
  echo "The thesis's slowest rows: a pixel's ray tree, up to 15 rays, walked by one"
  echo "invocation, or by 8, 16 or 32 lanes a ray."
  echo
  cat out/bench/march-glass/sweep.md
} > "$md"
echo "wrote $md"
