//! The default model: YOLOv12n (80 COCO classes) from the crates.io package `easy-yolo` 0.1.3,
//! pinned with its SHA-256 in `assets/registry.tsv`, fetched with cargo (never built: it would
//! pull `ort`, which downloads binaries) and unpacked into rover's cache by `rover-assets`. The
//! weights are AGPL-3.0 (Ultralytics); they are never part of rover.

use std::path::PathBuf;

use crate::error::{PerceptionError, Result};

/// The crates.io package that carries the default model.
const MODEL_CRATE: &str = "easy-yolo";
/// Licence of the default model's weights.
const MODEL_LICENSE: &str =
    "AGPL-3.0 (Ultralytics YOLOv12n weights, shipped in the crates.io package easy-yolo 0.1.3)";

/// Where the default model lives once fetched (`CACHE/models/yolov12n.onnx`).
pub fn default_model_path() -> PathBuf {
    let file =
        rover_assets::registry::pin("crate", MODEL_CRATE).map_or("yolov12n.onnx", |p| p.file);
    rover_assets::cache_dir().join("models").join(file)
}

/// Returns the default model's path, fetching it first if it is not cached yet (refused under
/// `ROVER_OFFLINE`, as the tests run). The first call needs crates.io (through cargo); later
/// ones work offline.
pub fn ensure_default_model() -> Result<PathBuf> {
    // Checked (its SHA-256) once per process: every detector and every `rover eval` scenario
    // asks for it.
    static CHECKED: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    if let Some(path) = CHECKED.get() {
        return Ok(path.clone());
    }
    let fetch = |e: rover_assets::AssetError| PerceptionError::Fetch(e.to_string());
    let pin = rover_assets::registry::pin("crate", MODEL_CRATE).map_err(fetch)?;
    let target = default_model_path();
    if !target.is_file() {
        tracing::info!("unpacking the default detector model (~9 MB, {MODEL_LICENSE})");
    }
    rover_assets::registry::crate_file(pin, &target).map_err(fetch)?;
    Ok(CHECKED.get_or_init(|| target).clone())
}
