#!/usr/bin/env bash
# Reproduce every table and figure of the papers on one device: thesis tables 2-8, seed
# 002's figure 9, the adaptive-pressure fill test and the scaling sweep, written to
# results/<device-slug>/ (<name>.csv, .md, .png, image sheets, findings.md).
# Usage: scripts/reproduce.sh [--device N|NAME] [--quick]
# FLUIDFORM_BIN selects a prebuilt binary (e.g. one carried to a GPU machine).
# The full run takes about an hour on lavapipe (2 cores); --quick about a minute.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${FLUIDFORM_BIN:-}
if [ -z "$bin" ]; then
  cargo build --release --quiet
  bin=target/release/fluidform
fi
"$bin" experiment all "$@"
