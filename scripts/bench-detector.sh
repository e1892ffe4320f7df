#!/usr/bin/env bash
# Detector benchmark: rover's tract-onnx detector vs onnxruntime (PyPI) on the same graph, input
# tensor and thread count. Installs onnxruntime for the current user if it is missing.
# usage: scripts/bench-detector.sh [extra `rover bench detect` options, e.g. --input-size 640x480]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if ! python3 -c "import onnxruntime, numpy" 2>/dev/null; then
  echo "bench: installing onnxruntime from PyPI"
  python3 -m pip install --quiet onnxruntime numpy
fi
for size in 512x384 640x480 640x640; do
  echo
  cargo run --release --quiet -- bench detect --input-size "$size" "$@"
done
