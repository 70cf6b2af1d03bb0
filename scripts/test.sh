#!/usr/bin/env bash
# Set up the machine and run every test on lavapipe with the Khronos validation layer on.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cargo test --workspace --all-targets -- --test-threads=2
