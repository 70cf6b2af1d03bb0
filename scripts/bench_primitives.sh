#!/usr/bin/env bash
# Regenerate results/<device-slug>/primitives.md (and the sweeps' CSV) on the picked device.
# Usage: scripts/bench_primitives.sh [--device N|NAME] [--frames N]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
bench_setup "$@"
md=$dir/primitives.md
{
  echo "# GPU primitives on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_primitives.sh ${*}\`, which runs:"
  echo
} > "$md.tmp"
for what in scan sort neighbors; do
  cmd=("$bin" bench "$what" --out "out/bench/$what" "${dev[@]}" "${args[@]}")
  echo "    fluidform ${cmd[*]:1}" >> "$md.tmp"
  "${cmd[@]}" > /dev/null
  cp "out/bench/$what/sweep.csv" "$dir/$what.csv"
  cp "out/bench/$what/sweep.png" "$dir/$what.png"
done
for what in scan sort neighbors; do
  { echo; echo "## $what"; echo; cat "out/bench/$what/sweep.md"; echo; echo "![$what cost per element against N]($what.png)"; } >> "$md.tmp"
done
mv "$md.tmp" "$md"
echo "wrote $md"
