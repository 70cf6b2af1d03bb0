#!/usr/bin/env bash
# Our DFSPH beside SPlisHSPlasH's (pysplishsplash 2.19.0, installed in a virtual
# environment at out/peer-venv) on the same dam break: the 0.8 x 1.0 x 0.8 m column in
# the 2.4 x 1.4 x 0.8 m tank at the particle spacing fluidform picks for --particles N,
# each iterating to a mean density error of --error percent with its own CFL step, one
# after the other on this machine, SPlisHSPlasH on --threads threads (default: the
# machine's cores). Appends the comparison to results/<device>/solvers.md.
# Usage: scripts/peer_splishsplash.sh [--device N|NAME] [--particles N] [--seconds S]
#        [--error PCT] [--threads T] [--wheels DIR]
# --wheels DIR installs pysplishsplash and numpy from wheels in DIR (pip download them
# where there is a network; a GPU machine has none) instead of from the index.
# FLUIDFORM_BIN selects a prebuilt binary.
set -euo pipefail
cd "$(dirname "$0")/.."
particles=65536
seconds=0.4
error=0.1
threads=$(nproc)
wheels=
pass=()
while [ $# -gt 0 ]; do
  case "$1" in
    --particles) particles=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --error) error=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --wheels) wheels=$2; shift 2 ;;
    *) pass+=("$1"); shift ;;
  esac
done
source scripts/bench_common.sh
bench_setup "${pass[@]}"
venv=out/peer-venv
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
if [ -n "$wheels" ]; then
  "$venv/bin/pip" install --quiet --no-index --find-links "$wheels" "pysplishsplash==2.19.0" "numpy<2"
else
  "$venv/bin/pip" install --quiet "pysplishsplash==2.19.0" "numpy<2"
fi
# The wheel's own libGLdispatch clashes with the system's libGLX at import (a segfault):
# the system's is loaded first.
glx=$(ldconfig -p | awk '/libGLdispatch\.so\.0 /{print $NF; exit}')
out=out/peer
mkdir -p "$out"
# Frames of the scene's own length (dt x substeps; scaling to N keeps it).
frame=$("$bin" scene show dam-break | python3 -c "
import sys, tomllib
f = tomllib.loads(sys.stdin.read())['fluid']
print(f['dt'] * f.get('substeps', 1))")
frames=$(python3 -c "print(round($seconds / $frame))")
target=$(python3 -c "print($error / 100)")

# Ours: the dam break scaled to N, DFSPH at its own step, the solves to the target.
# Points on a 64 x 64 frame: the run draws every frame, the comparison times the sph scopes.
ours=("$bin" run --scene dam-break --particles "$particles" --solver dfsph --render points
  --width 64 --height 64 --save-every 0 --frames "$frames" --fluid "density_error=$target"
  --fluid "divergence_error=$target" --out "$out/fluidform" --quiet "${dev[@]}")
start=$(date +%s.%N)
"${ours[@]}" > "$out/fluidform.log"
ours_wall=$(python3 -c "import time; print(time.time() - $start)")
# The column's lattice: n = (0.8 / s)^2 (1.0 / s) particles at spacing s.
read -r n spacing <<< "$(python3 - "$out/fluidform/summary.json" <<'PY'
import json, sys
n = json.load(open(sys.argv[1]))["stats"]["particles"]
print(n, (0.64 / n) ** (1 / 3))
PY
)"
echo "fluidform: $n particles at a spacing of $spacing m"
# SPlisHSPlasH at the same spacing (its particle diameter).
OMP_NUM_THREADS=$threads LD_PRELOAD=${glx:-} "$venv/bin/python" scripts/peer_splishsplash.py \
  "$out/splishsplash.json" "$spacing" "$seconds" "$error" > "$out/splishsplash.log" 2>&1
python3 - "$out" "$dir/solvers.md" "$ours_wall" "${ours[*]:1}" "$threads" <<'PY'
import csv, json, sys, datetime
out, md, wall, cmd, threads = sys.argv[1:6]
s = json.load(open(f"{out}/fluidform/summary.json"))
st = s["stats"]
# GPU time of the sph scopes, every frame.
gpu_ms = sum(float(r["ms"]) for r in csv.DictReader(open(f"{out}/fluidform/timings.csv"))
             if r["pass"] == "sph")
sim = st["simulated_seconds"]
de = st["density_error"]
ours = sim / (gpu_ms / 1000.0)
p = json.load(open(f"{out}/splishsplash.json"))
# SPlisHSPlasH's own totals at its exit: density and divergence iterations.
tot = {}
for line in open(f"{out}/splishsplash.log"):
    for key in ("iterations", "iterationsV"):
        if line.strip().startswith(f"Total number: DFSPH - {key}:"):
            tot[key] = int(line.split(":")[-1])
# Its totals count every step, the first included.
its = (f'{tot["iterations"] / (p["steps"] + 1):.1f} + {tot["iterationsV"] / (p["steps"] + 1):.1f}'
       if len(tot) == 2 else "")
rows = [
    ("fluidform DFSPH", st["particles"], sim, gpu_ms / 1000.0, ours, st["steps"],
     gpu_ms / max(st["steps"], 1), 1000.0 * sim / max(st["steps"], 1),
     f'{de["iterations_mean"]:.1f} + {de["divergence_iterations_mean"]:.1f}',
     100.0 * de["mean"]),
    ("SPlisHSPlasH DFSPH", p["particles"], p["simulated_s"], p["wall_s"], p["sim_s_per_wall_s"],
     p["steps"], p["ms_per_step"], p["mean_dt_ms"], its, 100.0 * p["mean_density_error"]),
]
with open(md, "a") as f:
    f.write(f"\n## DFSPH beside SPlisHSPlasH ({datetime.date.today()})\n\n")
    f.write(f"Made by `scripts/peer_splishsplash.sh`: `fluidform {cmd}` (its wall time, start-up\n")
    f.write(f"and shader compilation included: {float(wall):.1f} s), then SPlisHSPlasH 2.19.0's DFSPH\n")
    f.write(f"(pysplishsplash, {threads} threads, volume-map walls, cubic kernel, its own CFL step)\n")
    f.write("on the same tank, column and particle spacing, iterating to the same mean density\n")
    f.write("error. Ours: simulated seconds per GPU second of the `sph` scopes; SPlisHSPlasH's:\n")
    f.write("per wall second from the end of its first step (set-up and volume map left out).\n")
    f.write("Density error: the mean over steps (SPlisHSPlasH: every fifth) of the mean over\n")
    f.write("particles of max(rho / rho0 - 1, 0).\n\n")
    f.write("| solver | particles | simulated s | seconds | sim s per s | steps | ms per step | mean dt ms | iterations | mean density error % |\n")
    f.write("|---|---|---|---|---|---|---|---|---|---|\n")
    for r in rows:
        f.write(f"| {r[0]} | {r[1]} | {r[2]:.3f} | {r[3]:.2f} | {r[4]:.4f} | {r[5]} | {r[6]:.1f} | {r[7]:.2f} | {r[8]} | {r[9]:.3f} |\n")
    f.write(f"\nfluidform's DFSPH runs at {ours / p['sim_s_per_wall_s']:.2f}x SPlisHSPlasH's in simulated seconds per second.\n")
print(f"ours {ours:.4f} sim s per GPU s, SPlisHSPlasH {p['sim_s_per_wall_s']:.4f} per wall s")
PY
