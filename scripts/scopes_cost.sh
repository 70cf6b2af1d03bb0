#!/usr/bin/env bash
# What the profiler's timestamps cost (issue 67): the default liquid character played with
# `run --scopes frame` (one timestamp pair a frame), `passes` (the frame and its phases)
# and `all` (every pass: about 1,000 timestamps a frame at 64K particles), in rounds of the
# three in turn (the order reversed every other round), each mode's GPU frame median over
# its frames after the first tenth. Writes results/<device-slug>/scopes.md.
# Usage: scripts/scopes_cost.sh [--device N|NAME] [--particles N] [--width W] [--height H]
#        [--frames N] [--rounds N]   (defaults: 65536 particles, 1280x720, 30 frames, 2 rounds)
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
given="$*"
bench_setup "$@"
n=65536 w=1280 h=720 frames=30 rounds=2
set -- "${args[@]}"
while [ $# -gt 0 ]; do
  case "$1" in
    --particles) n=$2; shift 2 ;;
    --width) w=$2; shift 2 ;;
    --height) h=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --warmup) shift 2 ;;  # bench_setup's default; a run has none
    *) echo "scopes_cost.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
logs=out/scopes
rm -rf "$logs"
modes=(frame passes all)
for r in $(seq 1 "$rounds"); do
  order=("${modes[@]}")
  [ $((r % 2)) = 0 ] && order=(all passes frame)
  for m in "${order[@]}"; do
    "$bin" run --scene character --particles "$n" --width "$w" --height "$h" --frames "$frames" \
      --save-every 0 --scopes "$m" --quiet "${dev[@]}" --out "$logs/$m-$r" > /dev/null
  done
done
md=$dir/scopes.md
python3 - "$logs" "$rounds" "$frames" > "$md" <<'PY'
import csv, statistics, sys
logs, rounds, frames = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
skip = max(1, frames // 10)
rows = {}
for m in ("frame", "passes", "all"):
    ms, scopes = [], 0
    for r in range(1, rounds + 1):
        t = list(csv.DictReader(open(f"{logs}/{m}-{r}/timings.csv")))
        ms += [float(x["ms"]) for x in t if x["pass"] == "frame" and int(x["frame"]) >= skip]
        scopes = max(scopes, sum(1 for x in t if x["frame"] == str(skip)))
    rows[m] = (statistics.median(ms), len(ms), scopes)
base = rows["frame"][0]
print("| --scopes | timed scopes a frame | frames | GPU frame median ms | x frame |")
print("|---|---|---|---|---|")
for m, (med, k, s) in rows.items():
    print(f"| {m} | {s} | {k} | {med:.3f} | {med / base:.3f} |")
PY
{
  echo
  echo "Made by \`scripts/scopes_cost.sh $given\` ($n particles, ${w}x$h, $frames frames, $rounds rounds)"
  echo "on $slug, $(date -u +%Y-%m-%dT%H:%M:%SZ). A timed scope is two timestamps."
} >> "$md"
echo "wrote $md"
