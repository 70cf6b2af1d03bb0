#!/usr/bin/env bash
# Regenerate results/<device-slug>/skin.md: the skinning pass, LBS and DQS, on CesiumMan
# (../shared/assets; the built-in walker where that is absent) and on a generated mesh of
# about 1M vertices (copies of the walker).
# Usage: scripts/bench_skin.sh [--device N|NAME] [--frames N]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
bench_setup "$@"
character=builtin:walker
[ -f ../shared/assets/CesiumMan.glb ] && character=../shared/assets/CesiumMan.glb
cmd=("$bin" bench skin --out out/bench/skin --character "$character" "${dev[@]}" "${args[@]}")
"${cmd[@]}" > /dev/null
cp out/bench/skin/sweep.csv "$dir/skin.csv"
md=$dir/skin.md
{
  echo "# GPU skinning on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_skin.sh ${*}\` on $(date -u +%Y-%m-%d), which runs:"
  echo
  echo "    fluidform ${cmd[*]:1}"
  echo
  echo "One dispatch per frame skins every vertex (position and normal) from the joints"
  echo "uploaded that frame; 'MB moved' counts the bytes the pass reads and writes."
  echo "Targets: DQS at most 1.5x LBS at 1M vertices on lavapipe; 1M vertices in at most"
  echo "0.1 ms on a GPU."
  echo
  cat out/bench/skin/sweep.md
  echo
  awk -F, 'NR > 1 { m[$1] = $4 } END {
    for (k in m) if (k ~ /^dqs-generated/) d = m[k]; else if (k ~ /^lbs-generated/) l = m[k];
    if (l > 0) printf "DQS / LBS at the generated mesh: %.2fx\n", d / l }' out/bench/skin/sweep.csv
} > "$md"
echo "wrote $md"
