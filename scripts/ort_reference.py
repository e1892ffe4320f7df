#!/usr/bin/env python3
"""Runs an ONNX model with onnxruntime on a raw float32 input: rover's reference runtime.

usage: ort_reference.py MODEL.onnx INPUT.f32 N,C,H,W OUTPUT.f32 [--threads T] [--runs R] [--profile 1]

Writes the first output as raw little-endian float32 and prints one JSON line:
{"shape": [...], "median_ms": ..., "runs": R, "threads": T, "onnxruntime": "x.y.z"}
With --profile 1 it adds "ops": {op_type: ms per run}, from onnxruntime's own profiler.
"""
import json
import os
import sys
import time

try:
    import numpy as np
    import onnxruntime as ort
except ImportError as e:  # pragma: no cover - environment problem, not a test result
    sys.exit(f"ort_reference.py needs numpy and onnxruntime: pip install onnxruntime ({e})")


def main(argv):
    args = []
    skip = False
    for a in argv:
        if skip:
            skip = False
        elif a.startswith("--"):
            skip = True
        else:
            args.append(a)
    opts = {argv[i]: argv[i + 1] for i in range(len(argv) - 1) if argv[i].startswith("--")}
    if len(args) != 4:
        sys.exit(__doc__)
    model, input_path, shape, output_path = args
    threads = int(opts.get("--threads", 1))
    runs = int(opts.get("--runs", 1))
    shape = [int(v) for v in shape.split(",")]
    x = np.fromfile(input_path, dtype="<f4").reshape(shape)
    so = ort.SessionOptions()
    so.intra_op_num_threads = threads
    so.inter_op_num_threads = 1
    profile = opts.get("--profile") == "1"
    if profile:
        so.enable_profiling = True
        so.profile_file_prefix = os.path.join(os.path.dirname(os.path.abspath(output_path)), "ort_profile")
    session = ort.InferenceSession(model, so, providers=["CPUExecutionProvider"])
    name = session.get_inputs()[0].name
    times = []
    out = None
    for _ in range(max(runs, 1)):
        start = time.perf_counter()
        out = session.run(None, {name: x})[0]
        times.append((time.perf_counter() - start) * 1000.0)
    out.astype("<f4").tofile(output_path)
    times.sort()
    report = {
        "shape": list(out.shape),
        "median_ms": times[len(times) // 2],
        "runs": len(times),
        "threads": threads,
        "onnxruntime": ort.__version__,
    }
    if profile:
        with open(session.end_profiling()) as f:
            events = json.load(f)
        ops = {}
        for e in events:
            if e.get("cat") == "Node" and e.get("name", "").endswith("_kernel_time"):
                op = e.get("args", {}).get("op_name", "?")
                ops[op] = ops.get(op, 0.0) + e.get("dur", 0) / 1000.0
        report["ops"] = {k: v / len(times) for k, v in ops.items()}
    print(json.dumps(report))


if __name__ == "__main__":
    main(sys.argv[1:])
