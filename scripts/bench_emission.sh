#!/usr/bin/env bash
# Regenerate results/<device-slug>/emission.md: seed 002's figure 9, frames per second of
# the emitting game room at 8K..64K particles, counting grid against hash + bitonic sort,
# with the per-pass split (skin, RenderToUV, emit, arrange, density, forces, integrate).
# Usage: scripts/bench_emission.sh [--device N|NAME] [--frames N] [--particles N]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine); on a GPU,
# FLUIDFORM_SWEEP="65536 131072 262144 524288 1048576" adds the sweep to 1M.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
bench_setup "$@"
md=$dir/emission.md
fig=("$bin" bench emission --out out/bench/emission "${dev[@]}" "${args[@]}")
"${fig[@]}" > /dev/null
cp out/bench/emission/sweep.csv "$dir/emission.csv"
cp out/bench/emission/sweep.png "$dir/emission.png"
sweep_md=""
if [ -n "${FLUIDFORM_SWEEP:-}" ]; then
  for n in $FLUIDFORM_SWEEP; do
    "$bin" bench emission --neighbors grid --particles "$n" --out "out/bench/emission-$n" "${dev[@]}" > /dev/null
    sweep_md+=$(tail -n +3 "out/bench/emission-$n/sweep.md" | head -1)$'\n'
  done
fi
{
  echo "# Motion-trail emission (seed 002, figure 9) on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_emission.sh ${*}\`, which runs:"
  echo
  echo "    fluidform ${fig[*]:1}"
  echo
  echo "The game room (4 x 3 m, two pillars) with a 2 x 1.5 m pool of N particles, every one an"
  echo "emitter slot alive at the start with ages spread over the 4 s life limit; births at"
  echo "N / 3 per second keep them alive while the built-in walker runs its loop. One frame is"
  echo "one step: skin, RenderToUV (512 x 512 atlas), then the SPH step with emit before arrange."
  echo "The headline is the frame scope; fps = 1000 / median frame ms."
  echo
  cat out/bench/emission/sweep.md
  echo
  echo "![frame cost per particle against N](emission.png)"
  if [ -n "$sweep_md" ]; then
    echo
    echo "## Counting grid to 1M"
    echo
    head -2 out/bench/emission/sweep.md
    printf '%s' "$sweep_md"
  fi
} > "$md"
echo "wrote $md"
