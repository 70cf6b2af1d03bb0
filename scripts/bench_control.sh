#!/usr/bin/env bash
# Regenerate results/<device-slug>/control.md and its plots:
# 1. the built-in giraffe (neck 2.5 rest spacings thick) and giraffe.obj filled from a
#    pool with --adaptive off, on and smooth: times to 80% and 90% coverage;
# 2. CesiumMan walking (tests/scenes/cesium_man_walk.toml: his own volume of water): every
#    --adaptive mode with --control-velocity 0 and 5, the inside fraction over the last cycle;
# 3. --placement rays re-placing about 3000 control particles every frame in the built-in
#    character: its share of the GPU frame.
# Usage: [PARTS="giraffe giraffe-obj cesium rays"] scripts/bench_control.sh [--device N|NAME]
# [--frames N] (the built-in giraffe's cap, default 900 frames, 9.7 s; giraffe.obj plays
# 600, CesiumMan 400, rays 60)
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
set -euo pipefail
cd "$(dirname "$0")/.."
[[ " $* " == *" --frames "* ]] || set -- "$@" --frames 900
source scripts/bench_common.sh
bench_setup "$@"
# The other parts' frame caps replace the giraffes'.
rest=()
skip=0
for a in "${args[@]}"; do
  if [ "$skip" = 1 ]; then skip=0; continue; fi
  if [ "$a" = --frames ]; then skip=1; continue; fi
  rest+=("$a")
done
assets=../shared/assets
run() { # out-name, then bench arguments
  local name=$1; shift
  "$bin" bench control --out "out/bench/$name" "${dev[@]}" "$@" > /dev/null
  cp "out/bench/$name/sweep.csv" "$dir/$name.csv"
  cp "out/bench/$name/coverage.png" "$dir/$name.png"
}
# PARTS picks what to (re)measure; the page is made from every part's CSV in the folder.
parts=" ${PARTS:-giraffe giraffe-obj cesium rays} "
[[ $parts == *" giraffe "* ]] && run control-giraffe "${args[@]}"
[[ $parts == *" giraffe-obj "* ]] && run control-giraffe-obj --scene tests/scenes/giraffe_liquid.toml --frames 600 "${rest[@]}"
[[ $parts == *" cesium "* ]] && run control-cesium --scene tests/scenes/cesium_man_walk.toml --velocities 0,5 --frames 400 "${rest[@]}"
[[ $parts == *" rays "* ]] && run control-rays --scene character --placement rays --control-spacing 0.0185 --adaptive on --frames 60 "${rest[@]}"
md=$dir/control.md
table() { # the sweep's table without the per-pass columns
  python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
keep = [k for k in rows[0] if not k.endswith("_ms") or k in ("median_ms", "sph/control_ms", "sph/control/place_ms")]
keep = [k for k in keep if k != "ns_per_element"]
print("| " + " | ".join(keep) + " |")
print("|" + "---|" * len(keep))
for r in rows:
    print("| " + " | ".join(r[k] for k in keep) + " |")
PY
}
{
  echo "# Control: filling shapes on $slug"
  echo
  "$bin" devices "${dev[@]}" | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_control.sh ${*}\` on $(date -u +%Y-%m-%d). Each row is one run"
  echo "(\`fluidform bench control\`, points view 64 x 64, GPU frame medians over every frame;"
  echo "full columns in the CSVs beside this file)."
  echo
  echo "## 1. Giraffes: adaptive control pressure"
  echo
  echo "The thesis (figures 12/13): its giraffe filled 6x faster with adaptive control"
  echo "pressure. Target: time to 90% coverage with on at most 1/3 of off. 'not in T s':"
  echo "never within the frame cap. Coverage counts control particles with fluid density"
  echo "at least 50% of rho_0; those within a kernel radius of the surface see a free"
  echo "surface's partial density, so a filled shape plateaus near 0.85: time to 80% is"
  echo "given beside. Runs differ from run to run (float atomics reorder sums and the"
  echo "flow is chaotic): compare the modes' times as ratios, not to the millisecond."
  echo
  echo "Built-in giraffe ([plot](control-giraffe.png)):"
  echo
  table "$dir/control-giraffe.csv"
  echo
  echo "giraffe.obj, 600 frames ([plot](control-giraffe-obj.png)):"
  echo
  table "$dir/control-giraffe-obj.csv"
  echo
  echo "## 2. CesiumMan walking: inside fraction over the last cycle"
  echo
  echo "Target: at least 0.85 with the best switches ([plot](control-cesium.png))."
  echo
  table "$dir/control-cesium.csv"
  echo
  echo "## 3. Rays placement every frame"
  echo
  echo "Target: at most 20% of the frame for about 3000 control particles (place share)."
  echo
  table "$dir/control-rays.csv"
} > "$md"
echo "wrote $md"
