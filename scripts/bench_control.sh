#!/usr/bin/env bash
# Regenerate results/<device-slug>/control.md: the built-in giraffe (neck 2.5 rest spacings
# thick) filled from a pool with --adaptive off, on and smooth; time to 90% coverage.
# Usage: scripts/bench_control.sh [--device N|NAME] [--frames N] (default 900 frames, 9.7 s)
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
# The frame cap: 900 unless given (bench_common would default to 20).
[[ " $* " == *" --frames "* ]] || set -- "$@" --frames 900
source scripts/bench_common.sh "$@"
cmd=("$bin" bench control --out out/bench/control "${dev[@]}" "${args[@]}")
"${cmd[@]}" > /dev/null
cp out/bench/control/sweep.csv "$dir/control.csv"
md=$dir/control.md
{
  echo "# Control: filling the giraffe on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_control.sh ${*}\` on $(date -u +%Y-%m-%d), which runs:"
  echo
  echo "    fluidform ${cmd[*]:1}"
  echo
  echo "The thesis (figures 12/13): its giraffe filled 6x faster with adaptive control"
  echo "pressure (180 s against 30 s). Target here: time to 90% coverage with on at most"
  echo "1/3 of off. 'not in T s' means coverage never reached 90% within the frame cap."
  echo
  cat out/bench/control/sweep.md
} > "$md"
echo "wrote $md"
