#!/usr/bin/env bash
# Regenerate results/<device-slug>/particles.md: seed 003's particle systems, update, sort
# and draw ms of a full pool of sprites at 64K, 256K and 1M, per integrator and sort, and
# the same pool drawn as points (no sort: the closed form against Euler and Verlet).
# Usage: scripts/bench_particles.sh [--device N|NAME] [--frames N] [--particles N]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
bench_setup "$@"
md=$dir/particles.md
sprites=("$bin" bench particles --out out/bench/particles "${dev[@]}" "${args[@]}")
points=("$bin" bench particles --draw points --out out/bench/particles-points "${dev[@]}" "${args[@]}")
"${sprites[@]}" > /dev/null
"${points[@]}" > /dev/null
cp out/bench/particles/sweep.csv "$dir/particles.csv"
cp out/bench/particles/sweep.png "$dir/particles.png"
cp out/bench/particles-points/sweep.csv "$dir/particles-points.csv"
{
  echo "# Particle systems (seed 003) on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_particles.sh ${*}\`, which runs:"
  echo
  echo "    fluidform ${sprites[*]:1}"
  echo "    fluidform ${points[*]:1}"
  echo
  echo "A pool of N particles, all alive (born at t = 0 from a 0.8 m sphere, lives of 2 +- 1 s,"
  echo "so none dies while measured; births at N / 2 per second keep it full), gravity and"
  echo "one bouncing plane (the closed form has no plane: gravity alone), drawn at 512 x 512."
  echo "One frame = emit + update (Euler, Verlet; none for the closed form) + sort by view"
  echo "depth + draw. The headline is the whole GPU frame; pass columns are its scopes."
  echo
  echo "## Sprites (alpha-blended, sorted back to front)"
  echo
  cat out/bench/particles/sweep.md
  echo
  echo "![frame cost per particle against N](particles.png)"
  echo
  echo "## Points (opaque, depth-tested, unsorted)"
  echo
  cat out/bench/particles-points/sweep.md
} > "$md"
echo "wrote $md"
