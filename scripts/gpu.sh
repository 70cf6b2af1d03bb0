#!/usr/bin/env bash
# One command for a lent GPU: every GPU table, inside a time budget. In order, each part
# with its share of the budget (time a part leaves unused goes to the next):
#   devices; the bench scripts (primitives, sph, render, solvers) 26%; every experiment in
#   full, in one process, 46%; the default liquid character at 1280x720 and 64K particles
#   8%; the 1M DFSPH dam break for 3 simulated seconds, rendering off 10% (--quick: 62%,
#   18%, 8%, 6%); then the steps that were cut run again with what is left, if that is at
#   least twice their first share; 3% for the pages. nvidia-smi logs the device's clocks,
#   power and throttle reasons all along (read-only); each page gets its steps' ranges.
# A step that would overrun its share is cut (killed at it) or skipped, with a line saying so.
# Writes <out> (default results/<device-slug>/, with --quick out/gpu-quick/<slug>/): every table, findings.md, character.md,
# dambreak.md and gpu.md (what each step took); then devices.md beside it (every device
# side by side). Logs go to out/gpu/ (FLUIDFORM_LOGS).
# Usage: scripts/gpu.sh [--device D] [--budget-s S] [--quick] [--out DIR] [--validation]
#   --quick: tiny sizes, three experiments and a 150 s budget, to check the script on
#   lavapipe (a test runs it). Needs only a binary: FLUIDFORM_BIN, else
#   target/release/fluidform, else .gpu/fluidform; and the Vulkan loader. No build, no network.
#   --validation: the Khronos layer on for every command that takes it (the test's run).
set -uo pipefail
cd "$(dirname "$0")/.."

dev=() budget= quick=0 out= val=()
while [ $# -gt 0 ]; do
  case "$1" in
    --device) dev=(--device "$2"); shift 2 ;;
    --validation) val=(--validation); shift ;;
    --budget-s) budget=$2; shift 2 ;;
    --quick) quick=1; shift ;;
    --out) out=$2; shift 2 ;;
    *) echo "gpu.sh: unknown argument '$1' (see the header of scripts/gpu.sh)" >&2; exit 2 ;;
  esac
done
[ -n "$budget" ] || budget=$([ $quick = 1 ] && echo 150 || echo 420)
if ! [[ "$budget" =~ ^[0-9]+$ ]] || [ "$budget" -lt 10 ]; then
  echo "gpu.sh: --budget-s must be a whole number of seconds, at least 10 (got '$budget')" >&2
  exit 2
fi
bin=${FLUIDFORM_BIN:-}
for b in target/release/fluidform .gpu/fluidform; do
  [ -n "$bin" ] || { [ -x "$b" ] && bin=$b; }
done
if [ -z "$bin" ] || [ ! -x "$bin" ]; then
  echo "gpu.sh: no fluidform binary: set FLUIDFORM_BIN or build with cargo build --release" >&2
  exit 2
fi
case "$bin" in /*) ;; *) bin=$PWD/$bin ;; esac
export FLUIDFORM_BIN=$bin
# CesiumMan's scene names ../shared/assets; a device machine gets them carried in .gpu/assets.
if [ ! -e ../shared/assets ] && [ -d .gpu/assets ]; then
  mkdir -p ../shared && ln -s "$PWD/.gpu/assets" ../shared/assets
fi

slug=$("$bin" devices --slug "${dev[@]}") || { echo "gpu.sh: no usable Vulkan device" >&2; exit 1; }
# A quick run never lands on a device's committed results.
[ -n "$out" ] || out=$([ $quick = 1 ] && echo out/gpu-quick || echo results)/$slug
logs=${FLUIDFORM_LOGS:-out/gpu}
mkdir -p "$out" "$logs"
export FLUIDFORM_RESULTS=$out
t0=$(date +%s)
rows=() cut_names=() cut_shares=() cut_cmds=() spans=()

now() { echo $(( $(date +%s) - t0 )); }
say() { echo "[gpu.sh $(now)/$budget s] $*" >&2; }
# The second by which the budget's first FRACTION (in percent) is spent.
until_pct() { echo $(( budget * $1 / 100 )); }
# Where each step's share ends (percent of the budget). A GPU spends its time in the
# experiments; lavapipe's quick run in the bench scripts' compiles and slow frames.
if [ $quick = 1 ]; then
  ends=(5 12 35 62 80 88 94)
else
  ends=(5 12 16 26 72 80 90)
fi

# step NAME UNTIL CMD...: run CMD until second UNTIL of the budget, logged to out/gpu/NAME.log.
step() {
  local name=$1 until=$2; shift 2
  local left=$(( until - $(now) )) start rc status note
  if [ "$left" -lt 3 ]; then
    [[ $name == *" again" ]] && return
    say "$name: skipped, its share is spent ($left s left)"
    rows+=("$name|$left|0|skipped|its share was spent before it started")
    return
  fi
  say "$name: up to $left s"
  start=$(now)
  local e0 e1
  e0=$(date +%s.%N)
  timeout --kill-after=5 "$left" "$@" > "$logs/$name.log" 2>&1
  rc=$?
  e1=$(date +%s.%N)
  spans+=("$name|$e0|$e1")
  case $rc in
    0) status=ran; note= ;;
    124 | 137)
      status=cut
      note="overran its share of $left s and was stopped"
      cut_names+=("$name") cut_shares+=("$left") cut_cmds+=("$(printf '%q ' "$@")")
      ;;
    *) status=failed; note=$(grep -v '^\s*$' "$logs/$name.log" | tail -1 | tr '|' '/') ;;
  esac
  rows+=("$name|$left|$(( $(now) - start ))|$status|$note")
  say "$name: $status after $(( $(now) - start )) s${note:+ ($note)}"
}

# 1. The device, and its state while the steps run: clocks, power and throttle reasons
# every 200 ms, read-only (nothing here changes a clock).
"$bin" devices > "$out/devices.txt" 2>&1
say "device $slug; writing $out"
state=$out/device-state.csv smi=
if command -v nvidia-smi > /dev/null 2>&1; then
  reasons=clocks_throttle_reasons.active
  nvidia-smi --help-query-gpu 2> /dev/null | grep -q clocks_event_reasons.active &&
    reasons=clocks_event_reasons.active
  q=timestamp,clocks.sm,clocks.mem,power.draw,temperature.gpu,$reasons,pstate
  nvidia-smi --query-gpu=$q --format=csv,nounits -lms 200 > "$state" 2> "$logs/nvidia-smi.log" &
  smi=$!
  trap '[ -n "$smi" ] && kill "$smi" 2> /dev/null' EXIT
  nvidia-smi --query-gpu=name,driver_version,clocks.max.sm,clocks.max.mem,power.limit \
    --format=csv > "$out/device-limits.csv" 2>> "$logs/nvidia-smi.log"
else
  say "nvidia-smi not found: the device's clocks, power and throttle reasons are not recorded; going on"
  state=
  rm -f "$out/device-state.csv" "$out/device-limits.csv"
fi

# 2. The bench scripts, repetitions sized to the budget.
if [ $quick = 1 ]; then
  reps=(--frames 2 --warmup 1)
  small=(--particles 8192)
  render=(--particles 256 --width 64 --height 64)
  scopes=(--particles 2048 --width 64 --height 64 --frames 4 --rounds 1)
  solvers=(--particles 1024 --frames 1 --warmup 1 --skip-stability)
  sph=(--skip-stability)
else
  reps=(--frames $([ "$budget" -ge 900 ] && echo 20 || echo 10) --warmup 2)
  small=() render=() sph=()
  scopes=(--frames 30 --rounds 1)
  solvers=(--seconds $([ "$budget" -ge 900 ] && echo 10 || echo 3))
fi
step bench-primitives "$(until_pct "${ends[0]}")" bash scripts/bench_primitives.sh "${dev[@]}" "${val[@]}" "${reps[@]}" "${small[@]}"
step bench-sph "$(until_pct "${ends[1]}")" bash scripts/bench_sph.sh "${dev[@]}" "${val[@]}" "${reps[@]}" "${small[@]}" "${sph[@]}"
step bench-render "$(until_pct "${ends[2]}")" bash scripts/bench_render.sh "${dev[@]}" "${val[@]}" "${reps[@]}" "${render[@]}"
# What the profiler's ~1,000 timestamps a character frame cost (--scopes frame|passes|all).
step scopes "$(until_pct "${ends[2]}")" bash scripts/scopes_cost.sh "${dev[@]}" "${scopes[@]}"
step bench-solvers "$(until_pct "${ends[3]}")" bash scripts/bench_solvers.sh "${dev[@]}" "${val[@]}" "${solvers[@]}"
# SPlisHSPlasH 2.19's DFSPH on this machine's cores beside ours, on the same dam break at
# 0.1% (issue 59), from carried wheels: the device machine reaches no package index.
if [ $quick = 0 ] && ls out/wheels/pysplishsplash-2.19.0-*.whl > /dev/null 2>&1; then
  step peer "$(until_pct $(( ends[3] + (ends[4] - ends[3]) / 4 )))" bash scripts/peer_splishsplash.sh "${dev[@]}" --wheels out/wheels
else
  say "SPlisHSPlasH peer skipped: no pysplishsplash-2.19.0 wheel in out/wheels (pip download it and numpy's where there is a network, and carry out/wheels)"
fi

# 3. The experiments in one process, sharing pipelines, SPIR-V and the thesis scene; each
#    notes its span (FLUIDFORM_SPANS) for its row in gpu.md and the device state on its page.
mapfile -t names < <("$bin" experiment list)
[ $quick = 1 ] && names=(table8 fig9 scaling)
qx=()
[ $quick = 1 ] && qx=(--quick)
exp_spans=$logs/experiment-spans.txt
: > "$exp_spans"
export FLUIDFORM_SPANS=$exp_spans
from=$(now)
step experiments "$(until_pct "${ends[4]}")" "$bin" experiment "$(IFS=,; echo "${names[*]}")" --out "$out" --quiet "${dev[@]}" "${qx[@]}" "${val[@]}"
# One row per experiment: its own time, or why it has none.
missing=()
for n in "${names[@]}"; do
  line=$(grep "^experiment-$n|" "$exp_spans" | tail -1)
  if [ -n "$line" ]; then
    IFS='|' read -r _ a b <<< "$line"
    rows+=("experiment-$n|-|$(python3 -c "print(round($b - $a))")|ran|")
  else
    missing+=("$n")
    rows+=("experiment-$n|-|0|cut|the experiments step ended before it finished")
  fi
done
# A cut experiments step runs again with the experiments it did not finish.
if [ ${#missing[@]} -gt 0 ] && [ ${#cut_names[@]} -gt 0 ] && [ "${cut_names[-1]}" = experiments ]; then
  cut_cmds[-1]=$(printf '%q ' "$bin" experiment "$(IFS=,; echo "${missing[*]}")" --out "$out" --quiet "${dev[@]}" "${qx[@]}" "${val[@]}")
fi
[ $quick = 1 ] && rows+=("other experiments|-|0|skipped|--quick runs ${names[*]} only (tests/experiment.rs runs every experiment quick)")

# 4. The default liquid character at 1280x720 and 64K particles.
if [ $quick = 1 ]; then
  ch=(--width 160 --height 90 --particles 4096 --frames 6 --save-every 3)
else
  ch=(--width 1280 --height 720 --particles 65536 --save-every 199)  # its first and last frames
fi
cmd=("$bin" run --scene character "${ch[@]}" --out "$logs/character" --quiet "${dev[@]}" "${val[@]}")
rm -rf "$logs/character"
step character "$(until_pct "${ends[5]}")" "${cmd[@]}"
char_cmd="fluidform ${cmd[*]:1}"

# 5. The 1M DFSPH dam break for 3 simulated seconds (rendering off).
if [ $quick = 1 ]; then
  db=(--particles 8192 --seconds 0.05)
else
  db=(--particles 1000000 --seconds 3)
fi
cmd=("$bin" bench stability --solver dfsph "${db[@]}" --out "$logs/dambreak" "${dev[@]}" "${val[@]}")
rm -rf "$logs/dambreak"
step dambreak "$(until_pct "${ends[6]}")" "${cmd[@]}"
db_cmd="fluidform ${cmd[*]:1}"

# 6. The cut steps again, in order, where what is left is at least twice their first share.
for i in "${!cut_names[@]}"; do
  left=$(( $(until_pct 97) - $(now) ))
  if [ "$left" -ge $(( 2 * cut_shares[i] )) ]; then
    eval "step \"\${cut_names[i]} again\" $(until_pct 97) ${cut_cmds[i]}"
  else
    say "${cut_names[i]}: not run again ($left s left, its first share was ${cut_shares[i]} s)"
  fi
done

# 7. The pages of the character and the dam break.
if [ -f "$logs/character/summary.json" ]; then
  cp "$logs/character/summary.json" "$out/character.json"
  last=$(ls "$logs"/character/frame_*.png 2> /dev/null | tail -1)
  [ -n "$last" ] && cp "$last" "$out/character.png"
  python3 scripts/gpu_report.py character "$out/character.json" "$char_cmd" > "$out/character.md"
fi
if [ -f "$logs/dambreak/stability.json" ]; then
  cp "$logs/dambreak/stability.json" "$out/dambreak.json"
  python3 scripts/gpu_report.py dambreak "$out/dambreak.json" "$db_cmd" > "$out/dambreak.md"
fi

# 8. The device's state during each step, on its pages and in gpu.md.
[ -n "$smi" ] && kill "$smi" 2> /dev/null && wait "$smi" 2> /dev/null
smi=
{ printf '%s\n' "${spans[@]}"; cat "$exp_spans"; } > "$logs/spans.txt"
python3 scripts/gpu_report.py state "${state:-none}" "$logs/spans.txt" "$out" > "$logs/state.md" 2> "$logs/state.log" ||
  echo "(the device-state report failed: $(tail -1 "$logs/state.log"))" > "$logs/state.md"

# 9. Every device side by side, and what each step took. (A cut script can leave a .tmp.)
rm -f "$out"/*.tmp
"$bin" compare --results "$(dirname "$out")" > /dev/null 2> "$logs/compare.log" ||
  rows+=("compare|-|0|failed|$(tail -1 "$logs/compare.log")")
{
  echo "# scripts/gpu.sh on $slug"
  echo
  echo "Made by \`scripts/gpu.sh$([ $quick = 1 ] && echo ' --quick') --budget-s $budget\` on $(date -u +%Y-%m-%dT%H:%M:%SZ), $(now) s in all,"
  echo "with $("$bin" --version) (commit, compiler)."
  echo "Each step's share ends at a fixed second of the budget; one that would overrun it is"
  echo "stopped there (cut) or not started (skipped). Logs were in $logs/."
  echo
  sed 's/^/    /' "$out/devices.txt"
  echo
  echo "| step | share s | took s | status | note |"
  echo "|---|---|---|---|---|"
  for r in "${rows[@]}"; do echo "| ${r//|/ | } |"; done
  echo
  cat "$logs/state.md"
  echo
  echo "Pages: [findings](findings.md), [character](character.md), [dam break](dambreak.md),"
  echo "[every device side by side](../devices.md)."
} > "$out/gpu.md"
say "done: $out/gpu.md"
