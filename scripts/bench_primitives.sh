#!/usr/bin/env bash
# Regenerate results/<device-slug>/primitives.md (and the sweeps' CSV) on the picked device.
# Usage: scripts/bench_primitives.sh [--device N|NAME] [--frames N]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${FLUIDFORM_BIN:-}
if [ -z "$bin" ]; then
  cargo build --release --quiet
  bin=target/release/fluidform
fi
dev=()
args=(--frames 20 --warmup 3)
while [ $# -gt 0 ]; do
  case "$1" in
    --device) dev=(--device "$2"); shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
slug=$("$bin" devices --slug "${dev[@]}")
dir=results/$slug
mkdir -p "$dir"
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
done
for what in scan sort neighbors; do
  { echo; echo "## $what"; echo; cat "out/bench/$what/sweep.md"; } >> "$md.tmp"
done
mv "$md.tmp" "$md"
echo "wrote $md"
