#!/usr/bin/env bash
# Set up the machine and play the built-in default scene (frames land in out/run).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo run --release -- run "$@"
