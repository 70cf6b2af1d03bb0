#!/usr/bin/env bash
# Liquid characters nobody tuned for: for each FILE[:HEIGHT[:FRAMES[:UP]]] given (a closed,
# skinned .glb/.gltf or a closed .obj; height in metres, default 1.7; frames default 180,
# so that the metrics' window, the second half, comes after the fill (about 0.5 s);
# UP the file's up axis, y by default, z for a Z-up OBJ), write a scene that names only
# the file, its height (and up axis), [pool] and [control] (the domain,
# camera, spacing and pool are fitted: README "Your own character"), run it with the
# points view and print one markdown row of its fidelity metrics (mean and minimum over
# the second half of the run). Scenes and outputs go to out/characters/<name>/. With
# --look, each runs with its scene's own look (water: metaballs, tinted) at 240 x 240,
# saving every 30th frame, instead of the points view.
# Usage: scripts/characters.sh [--device N|NAME] [--look] FILE[:HEIGHT[:FRAMES[:UP]]] ...
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${FLUIDFORM_BIN:-}
if [ -z "$bin" ]; then
  cargo build --release --quiet
  bin=target/release/fluidform
fi
dev=()
files=()
view=(--render points --save-every 0)
while [ $# -gt 0 ]; do
  case "$1" in
    --device) dev=(--device "$2"); shift 2 ;;
    --look) view=(--width 240 --height 240 --save-every 30); shift ;;
    *) files+=("$1"); shift ;;
  esac
done
[ ${#files[@]} -gt 0 ] || { echo "usage: scripts/characters.sh [--device D] [--look] FILE[:HEIGHT[:FRAMES[:UP]]] ..." >&2; exit 2; }
echo "| character | height m | frames | particles | spacing m | fill | (min) | iou | (min) | spray | surface p95 | density in shape | speed excess m/s | time to 90% s | control share | wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for spec in "${files[@]}"; do
  IFS=':' read -r file height frames up <<< "$spec"
  height=${height:-1.7}
  frames=${frames:-180}
  up=${up:-y}
  name=$(basename "$file" | sed 's/\.[^.]*$//')
  out=out/characters/$name
  mkdir -p "$out"
  cat > "$out/scene.toml" <<EOF
name = "$name"
frames = $frames
[character]
file = "$(realpath "$file")"
height = $height
up = "$up"
[pool]
[control]
EOF
  start=$(date +%s)
  if ! "$bin" run --scene "$out/scene.toml" "${view[@]}" --out "$out" "${dev[@]}" > "$out/log" 2>&1; then
    echo "| $name | $height | $frames | FAILED: $(tail -1 "$out/log" | tr '|' '/') |"
    continue
  fi
  wall=$(( $(date +%s) - start ))
  python3 - "$out/summary.json" "$out/log" "$name" "$height" "$frames" "$wall" <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))
log = open(sys.argv[2]).read()
t = s["stats"]["control"]["targets"][0]
w = t["fidelity"]
g = lambda k, f="mean": (w.get(k) or {}).get(f, float("nan"))
p = s["pass_ms"]
share = p.get("sph/control", {"median": 0.0})["median"] / p["sph"]["median"]
n = re.search(r"pool [^,]*, (\d+) particles", log)
sp = re.search(r"spacing ([0-9.]+) m", log)
t90 = t["time_to_90"]
print(f"| {sys.argv[3]} | {sys.argv[4]} | {sys.argv[5]} | {n.group(1) if n else ''} | {sp.group(1) if sp else ''} | "
      f"{g('fill'):.3f} | {g('fill','min'):.3f} | {g('iou'):.3f} | {g('iou','min'):.3f} | {g('spray'):.4f} | "
      f"{g('surface_p95'):.2f} | {g('density_in_shape'):.3f} | {g('speed_excess'):.2f} | "
      f"{'' if t90 is None else f'{t90:.2f}'} | {share:.2f} | {sys.argv[6]} |")
PY
done
