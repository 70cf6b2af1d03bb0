#!/usr/bin/env bash
# Set up the machine and run every test on lavapipe with the Khronos validation layer on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# One build on a fresh machine: incremental state would only double the disk it takes.
CARGO_INCREMENTAL=0 cargo test --workspace --all-targets -- --test-threads=2
