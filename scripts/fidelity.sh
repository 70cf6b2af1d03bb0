#!/usr/bin/env bash
# Regenerate results/<device-slug>/control-fidelity.md (+ .csv): the liquid-character fidelity
# metrics (README "Fidelity metrics") per control-switch combination on the built-in
# walker standing in his own pool (tests/scenes/walker_pool.toml, 2 s: metrics over the
# second 1 s walk cycle), and the thesis's control against the fidelity preset on
# CesiumMan (tests/scenes/cesium_man_pool.toml, 4 s: his second 2 s cycle; only the file,
# animation, height and a pool; needs ../shared/assets). Points view (the
# metrics do not depend on the picture). Usage: scripts/fidelity.sh [--device N|NAME]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/bench_common.sh
bench_setup "$@"
md=$dir/control-fidelity.md
csv=$dir/control-fidelity.csv
walker=tests/scenes/walker_pool.toml
cesium=tests/scenes/cesium_man_pool.toml
runs=(
  "walker|thesis|--control-preset thesis"
  "walker|fidelity (default)|"
  "walker|fidelity with attraction 0|--control-attraction 0"
  "walker|fidelity with attraction 60|--control-attraction 60"
  "walker|fidelity with velocity 0|--control-velocity 0"
  "walker|fidelity with damping 0|--control-damping 0"
  "walker|fidelity without eq. 7|--control-pressure 0"
  "walker|fidelity without eq. 7 or velocity, damping 11|--control-pressure 0 --control-velocity 0 --control-damping 11"
  "walker|fidelity with frictionless walls|--fluid friction=0"
  "walker|fidelity with motion frames|--control-motion frames"
  "walker|fidelity with adaptive smooth|--adaptive smooth"
  "walker|fidelity refreshed every step|--control-every 1"
  "walker|fidelity refreshed every 8 steps|--control-every 8"
  "cesium|thesis|--control-preset thesis"
  "cesium|fidelity (default)|"
  "cesium|fidelity with frictionless walls|--fluid friction=0"
)
echo "scene,combination,fill_mean,fill_min,iou_mean,iou_min,spray_mean,surface_p95_mean,density_in_shape_mean,speed_excess_mean,time_to_90_s,control_share,sph_ms_per_frame,switches" > "$csv"
mkdir -p out/fidelity
k=0
for r in "${runs[@]}"; do
  IFS='|' read -r scene name sw <<< "$r"
  file=$walker
  [ "$scene" = cesium ] && file=$cesium
  out=out/fidelity/$k
  k=$((k + 1))
  # shellcheck disable=SC2086
  if ! "$bin" run --scene "$file" --render points --quiet --out "$out" "${dev[@]}" $sw > "$out.log" 2>&1; then
    # (The unstable run's message, its commas made semicolons, fills the first column.)
    echo "$scene,$name,FAILED: $(tail -1 "$out.log" | tr ',' ';'),,,,,,,,,,,$sw" >> "$csv"
    continue
  fi
  python3 - "$out/summary.json" "$scene" "$name" "$sw" >> "$csv" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t = s["stats"]["control"]["targets"][0]
w = t["fidelity"]
g = lambda k, f="mean": (w.get(k) or {}).get(f, float("nan"))
p = s["pass_ms"]
sph = p["sph"]["median"]
ctl = p.get("sph/control", {"median": 0.0})["median"]
t90 = t["time_to_90"]
print(f"{sys.argv[2]},{sys.argv[3]},{g('fill'):.3f},{g('fill','min'):.3f},{g('iou'):.3f},"
      f"{g('iou','min'):.3f},{g('spray'):.4f},{g('surface_p95'):.2f},{g('density_in_shape'):.3f},"
      f"{g('speed_excess'):.2f},{'' if t90 is None else f'{t90:.2f}'},{ctl / sph:.2f},{sph:.1f},{sys.argv[4]}")
PY
done
{
  echo "# Liquid-character fidelity on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/fidelity.sh ${*}\` on $(date -u +%F). Each row is one \`fluidform run"
  echo "--scene FILE --render points SWITCHES\`; metrics as the README defines them, mean (and"
  echo "minimum) over the second half of the run (the walker: its second 1 s walk cycle;"
  echo "CesiumMan: the second half of his first 2 s cycle). control share: the"
  echo "\`sph/control\` scopes over the \`sph\` scope (GPU medians per frame). Targets (issue 29):"
  echo "fill >= 0.9, iou >= 0.7, spray <= 0.02, density in shape 0.9-1.1, speed excess <= 1 m/s,"
  echo "time to 90% <= 1.5 s, control share <= 0.30."
  echo
  echo "| scene | combination | fill | (min) | iou | (min) | spray | surface p95 (spacings) | density in shape | speed excess m/s | time to 90% s | control share | sph ms/frame | switches |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  tail -n +2 "$csv" | sed 's/,/ | /g; s/^/| /; s/$/ |/'
} > "$md"
echo "wrote $md"
