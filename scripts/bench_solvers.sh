#!/usr/bin/env bash
# Regenerate results/<device-slug>/solvers.md: the dam break per pressure solver (wcsph,
# pcisph, dfsph, pbf) at 16K, 64K and 256K, each at its own stable step and at matched
# accuracy (mean density error <= 1% and <= 0.1%), with a plot of density error against
# cost; then the 32K dam break for 10 simulated seconds per solver (stability).
# Usage: scripts/bench_solvers.sh [--device N|NAME] [--frames N] [--warmup N]
#        [--particles N] [--seconds S] [--stability-particles N] [--skip-stability]
# --frames/--warmup: frames of 20 ms timed / played first (default 10 after 5: the timed
# window is 0.1 s..0.3 s of the dam break); --seconds: the stability run's length;
# --stability-particles: its N (default the scene's 32K); --skip-stability: rows only.
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine); SKIP_ROWS=1
# rewrites the md from out/bench/solvers without running the rows again.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=10
stab_n=()
skip=0
pass=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --stability-particles) stab_n=(--particles "$2"); shift 2 ;;
    --skip-stability) skip=1; shift ;;
    *) pass+=("$1"); shift ;;
  esac
done
# bench_common.sh's defaults (20 after 3) are repetitions; here frames are scene time.
[[ " ${pass[*]-} " == *" --frames "* ]] || pass+=(--frames 10)
[[ " ${pass[*]-} " == *" --warmup "* ]] || pass+=(--warmup 5)
source scripts/bench_common.sh
bench_setup "${pass[@]}"
md=$dir/solvers.md
rows=("$bin" bench solvers --out out/bench/solvers "${dev[@]}" "${args[@]}")
if [ -z "${SKIP_ROWS:-}" ]; then
  "${rows[@]}" > /dev/null
fi
cp out/bench/solvers/sweep.csv "$dir/solvers.csv"
cp out/bench/solvers/solvers.png "$dir/solvers.png"
stab_rows=()
solvers=(wcsph pcisph dfsph pbf)
[ "$skip" = 1 ] && solvers=()
for s in "${solvers[@]}"; do
  out=out/bench/stability-$s
  cmd=("$bin" bench stability --solver "$s" --seconds "$seconds" "${stab_n[@]}" --out "$out" "${dev[@]}")
  if "${cmd[@]}" > /dev/null 2> "$out.log"; then
    status=ok
  else
    status="FAILED: $(tail -1 "$out.log")"
  fi
  [ -f "$out/stability.json" ] && cp "$out/stability.json" "$dir/stability-$s.json"
  stab_rows+=("$s|$status|fluidform ${cmd[*]:1}")
done
{
  echo "# Pressure solvers on $slug"
  echo
  "$bin" devices | sed 's/^/    /'
  echo
  echo "Made by \`scripts/bench_solvers.sh ${*}\` on $(date -u +%F), which runs:"
  echo
  echo "    fluidform ${rows[*]:1}"
  echo
  echo "The dam break (a 0.8 x 1.0 x 0.8 m column in a 2.4 m tank at 32K, the scene scaled to"
  echo "N) played for --warmup frames of 20 ms, then --frames frames timed. Per row: GPU ms"
  echo "per step (median over the timed frames of the \`sph\` scopes / steps), simulated"
  echo "seconds per GPU second, pressure iterations per step (DFSPH: density + divergence),"
  echo "and the density error the density pass measures each step: the mean over steps of"
  echo "the mean over particles of max(rho / rho0 - 1, 0), and its largest value."
  echo
  cat out/bench/solvers/sweep.md
  echo
  echo "![mean density error against GPU seconds per simulated second](solvers.png)"
  echo
  echo "## Stability: the dam break (${stab_n[1]:-32K} particles) for $seconds simulated seconds per solver"
  echo
  echo "| solver | result | simulated s | steps | sim s per GPU s | final mean density / rho0 | NaN | outside | command |"
  echo "|---|---|---|---|---|---|---|---|---|"
  [ "$skip" = 1 ] && echo "(not run: --skip-stability)"
  for r in "${stab_rows[@]}"; do
    IFS='|' read -r s status cmd <<< "$r"
    f=out/bench/stability-$s/stability.json
    if [ -f "$f" ]; then
      python3 - "$f" "$s" "$status" "$cmd" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); c = j["checkpoints"][-1] if j["checkpoints"] else {}
gpu = j["gpu_seconds"] or float("nan")
print(f"| {sys.argv[2]} | {sys.argv[3]} | {j['simulated_seconds']:.2f} | {j['steps']} | "
      f"{j['simulated_seconds'] / gpu:.4f} | {c.get('density_mean_over_rest', float('nan')):.4f} | "
      f"{c.get('nan', '-')} | {c.get('outside_domain', '-')} | `{sys.argv[4]}` |")
PY
    else
      echo "| $s | $status | - | - | - | - | - | - | `$cmd` |"
    fi
  done
  echo
  echo "Checkpoints (every tenth of the run) are in stability-<solver>.json."
} > "$md"
echo "wrote $md"
