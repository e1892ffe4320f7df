//! onnxruntime as the reference runtime (Python, `scripts/ort_reference.py`): the detector tests
//! and `rover bench detect` run it on exactly the graph and input tensor rover uses. A tool for
//! tests and benchmarks; the detector never needs Python.

use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{PerceptionError, Result};

/// The onnxruntime script, written next to its input for each call (so it is found however
/// rover is run).
const SCRIPT: &str = include_str!("../../scripts/ort_reference.py");

/// What onnxruntime produced.
#[derive(Debug, Clone)]
pub struct OrtRun {
    /// The first output, raw.
    pub output: Vec<f32>,
    /// Its shape.
    pub shape: Vec<usize>,
    /// Median latency over the runs (ms).
    pub median_ms: f64,
    /// onnxruntime's version.
    pub version: String,
    /// Milliseconds per run by ONNX op type, from onnxruntime's profiler (empty unless asked).
    pub ops: Vec<(String, f64)>,
}

/// Runs `model` on `input` (`shape`, f32) with onnxruntime, `threads` intra-op threads,
/// `runs` times. Needs `python3` with `onnxruntime` and `numpy`.
pub fn onnxruntime_reference(
    model: &Path,
    input: &[f32],
    shape: &[usize],
    threads: usize,
    runs: usize,
) -> Result<OrtRun> {
    static CALLS: AtomicU64 = AtomicU64::new(0);
    let dir = std::env::temp_dir().join(format!(
        "rover-ort-{}-{}",
        std::process::id(),
        CALLS.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).map_err(|e| PerceptionError::io(&dir, e))?;
    let result = run_in(&dir, model, input, shape, threads, runs, false);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// [`onnxruntime_reference`] on one thread with its profiler on: [`OrtRun::ops`] says where the time goes.
pub fn onnxruntime_reference_profiled(
    model: &Path,
    input: &[f32],
    shape: &[usize],
    runs: usize,
) -> Result<OrtRun> {
    let dir = std::env::temp_dir().join(format!("rover-ort-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| PerceptionError::io(&dir, e))?;
    let result = run_in(&dir, model, input, shape, 1, runs, true);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn run_in(
    dir: &Path,
    model: &Path,
    input: &[f32],
    shape: &[usize],
    threads: usize,
    runs: usize,
    profile: bool,
) -> Result<OrtRun> {
    let input_path = dir.join("input.f32");
    let output_path = dir.join("output.f32");
    let bytes: Vec<u8> = input.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(&input_path, bytes).map_err(|e| PerceptionError::io(&input_path, e))?;
    let script = dir.join("ort_reference.py");
    std::fs::write(&script, SCRIPT).map_err(|e| PerceptionError::io(&script, e))?;
    let shape_arg = shape
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(",");
    let out = Command::new("python3")
        .arg(&script)
        .arg(model)
        .arg(&input_path)
        .arg(shape_arg)
        .arg(&output_path)
        .args([
            "--threads",
            &threads.to_string(),
            "--runs",
            &runs.max(1).to_string(),
            "--profile",
            if profile { "1" } else { "0" },
        ])
        .output()
        .map_err(|e| PerceptionError::Reference(format!("cannot run python3: {e}")))?;
    if !out.status.success() {
        return Err(PerceptionError::Reference(format!(
            "onnxruntime reference failed (pip install onnxruntime numpy): {}",
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).map_err(|e| {
        PerceptionError::Reference(format!(
            "unexpected output from the onnxruntime script: {e}"
        ))
    })?;
    let shape = report["shape"]
        .as_array()
        .map(|dims| {
            dims.iter()
                .filter_map(|d| d.as_u64().map(|d| d as usize))
                .collect()
        })
        .unwrap_or_default();
    let raw = std::fs::read(&output_path).map_err(|e| PerceptionError::io(&output_path, e))?;
    Ok(OrtRun {
        output: raw
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        shape,
        median_ms: report["median_ms"].as_f64().unwrap_or(f64::NAN),
        version: report["onnxruntime"].as_str().unwrap_or("?").to_owned(),
        ops: report["ops"]
            .as_object()
            .map(|ops| {
                ops.iter()
                    .filter_map(|(k, v)| v.as_f64().map(|ms| (k.clone(), ms)))
                    .collect()
            })
            .unwrap_or_default(),
    })
}
