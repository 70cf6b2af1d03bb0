# Sourced by the bench_*.sh scripts, which then call `bench_setup ARGS...`: picks the binary
# (FLUIDFORM_BIN, else a release build), splits --device from the bench switches, and names
# the results folder. Sets: bin, dev (array), args (array), slug, dir (FLUIDFORM_RESULTS,
# else results/<slug>). A function, not sourced arguments: `source FILE` with none hands
# FILE the caller's own arguments, which a script that filters its switches must not pass.
bench_setup() {
  bin=${FLUIDFORM_BIN:-}
  if [ -z "$bin" ]; then
    cargo build --release --quiet
    bin=target/release/fluidform
  fi
  dev=()
  args=()
  while [ $# -gt 0 ]; do
    case "$1" in
      --device) dev=(--device "$2"); shift 2 ;;
      *) args+=("$1"); shift ;;
    esac
  done
  # Defaults unless given: 20 timed repetitions after 3 warm-up.
  [[ " ${args[*]} " == *" --frames "* ]] || args+=(--frames 20)
  [[ " ${args[*]} " == *" --warmup "* ]] || args+=(--warmup 3)
  slug=$("$bin" devices --slug "${dev[@]}")
  dir=${FLUIDFORM_RESULTS:-results/$slug}
  mkdir -p "$dir"
}
