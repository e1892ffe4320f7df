#!/usr/bin/env bash
# The long fuzz run: ROVER_FUZZ_INPUTS inputs (default 1,000,000) over every parser, 2 s hang
# limit, 3 GiB memory cap. Figures go to target/fuzz-report.txt; a failing input is saved in
# $TMPDIR/rover-fuzz-failures/. Options through the environment:
#   ROVER_FUZZ_INPUTS=N  ROVER_FUZZ_SEED=S  ROVER_FUZZ_TARGETS=urdf,xacro  ROVER_FUZZ_ONNX=N
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/rover/target}"
cargo test --workspace --test fuzz long_fuzz_run -- --ignored --nocapture
cat target/fuzz-report.txt
