#!/usr/bin/env bash
# Regenerate results/<device-slug>/sph.md: SPH steps per second and per-pass ms for every
# neighbour strategy over N = 8K..1M, and the 32K dam-break stability run (10 000 steps).
# Usage: scripts/bench_sph.sh [--device N|NAME] [--frames N] [--particles N] [--skip-stability]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
skip=0
pass=()
for a in "$@"; do
  case "$a" in
    --skip-stability) skip=1 ;;
    *) pass+=("$a") ;;
  esac
done
source scripts/bench_common.sh
bench_setup "${pass[@]}"
md=$dir/sph.md
sweep=("$bin" bench sph --out out/bench/sph "${dev[@]}" "${args[@]}")
stab=("$bin" bench stability --out out/bench/stability "${dev[@]}")
"${sweep[@]}" > /dev/null
[ "$skip" = 1 ] || "${stab[@]}" > /dev/null
cp out/bench/sph/sweep.csv "$dir/sph.csv"
cp out/bench/sph/sweep.png "$dir/sph.png"
[ "$skip" = 1 ] || cp out/bench/stability/stability.json "$dir/stability.json"
{
  echo "# SPH on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_sph.sh ${*}\`, which runs:"
  echo
  echo "    fluidform ${sweep[*]:1}"
  [ "$skip" = 1 ] || echo "    fluidform ${stab[*]:1}"
  echo
  echo "## Steps: the dam break scaled to N, one step per repetition"
  echo
  cat out/bench/sph/sweep.md
  echo
  echo "![SPH step cost per particle against N](sph.png)"
  echo
  echo "## Stability: the 32K dam break for 10 000 steps"
  echo
  if [ "$skip" = 1 ]; then
    echo "Not run (--skip-stability)."
  else
    cat out/bench/stability/sweep.md
    echo
    echo "Checkpoints (every 1000 steps) are in stability.json."
  fi
} > "$md"
echo "wrote $md"
