//! The optional onnxruntime runtime (`--runtime onnxruntime`): the same graph rover's surgery
//! produced for tract, run by the `libonnxruntime.so` that PyPI's `onnxruntime` package ships,
//! loaded at run time through the `ort` crate (never downloaded or linked at build time). tract
//! stays the default; this is an adapter behind the same [`crate::Detector`].

use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use ort::session::Session;
use ort::session::builder::GraphOptimizationLevel;
use ort::value::TensorRef;

use crate::error::{PerceptionError, Result};

/// Which runtime runs the network.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Runtime {
    /// tract-onnx, pure Rust, in the binary (the default).
    #[default]
    Tract,
    /// onnxruntime's shared library, found at run time ([`find_onnxruntime_library`]).
    OnnxRuntime,
}

impl Runtime {
    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Runtime::Tract => "tract",
            Runtime::OnnxRuntime => "onnxruntime",
        }
    }
}

/// An onnxruntime session on rover's graph, with its output copied into a reused buffer.
pub(crate) struct OrtSession {
    session: Session,
    shape: [usize; 4],
}

impl OrtSession {
    /// Loads `library` (once per process; see [`find_onnxruntime_library`]) and builds a session on
    /// `model_bytes` with `threads` intra-op threads.
    pub(crate) fn new(
        library: &Path,
        model_bytes: &[u8],
        input_shape: [usize; 4],
        threads: usize,
        model_path: &Path,
    ) -> Result<Self> {
        let fail = |stage: &str, e: &dyn std::fmt::Display| {
            PerceptionError::model(model_path, format!("onnxruntime: {stage}: {e}"))
        };
        let environment = environment(library).map_err(|e| fail("loading the library", &e))?;
        let session = Session::builder(&environment)
            .map_err(|e| fail("creating a session", &e))?
            .with_optimization_level(GraphOptimizationLevel::Level3)
            .map_err(|e| fail("setting the optimisation level", &e))?
            .with_intra_threads(threads)
            .map_err(|e| fail("setting the threads", &e))?
            // Spinning workers would take the core the simulation loop needs.
            .with_intra_op_spinning(false)
            .map_err(|e| fail("turning off spinning", &e))?
            .commit_from_memory(model_bytes)
            .map_err(|e| fail("loading the model", &e))?;
        tracing::info!("detector runtime: onnxruntime from {}", library.display());
        Ok(Self {
            session,
            shape: input_shape,
        })
    }

    /// Runs the network on `input` (NCHW f32 of the session's shape); the first output goes
    /// into `output` (reused) and its shape into `shape`.
    pub(crate) fn run(
        &mut self,
        input: &[f32],
        output: &mut Vec<f32>,
        shape: &mut Vec<usize>,
    ) -> Result<()> {
        let err = |e: ort::Error| PerceptionError::Inference(format!("onnxruntime: {e}"));
        let tensor = TensorRef::from_array_view((self.shape, input)).map_err(err)?;
        let outputs = self.session.run(ort::inputs![tensor]).map_err(err)?;
        if outputs.len() == 0 {
            return Err(PerceptionError::Inference(
                "onnxruntime: the model produced no output".into(),
            ));
        }
        let (out_shape, data) = outputs[0].try_extract_tensor::<f32>().map_err(err)?;
        output.clear();
        output.extend_from_slice(data);
        shape.clear();
        shape.extend(out_shape.iter().map(|&d| usize::try_from(d).unwrap_or(0)));
        Ok(())
    }
}

/// onnxruntime allows one environment per process: the first detector creates it (loading the
/// library), later ones share it.
fn environment(library: &Path) -> std::result::Result<ort::environment::Environment, String> {
    static ENVIRONMENT: Mutex<Option<ort::environment::Environment>> = Mutex::new(None);
    let mut slot = ENVIRONMENT.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(env) = slot.as_ref() {
        return Ok(env.clone());
    }
    let env = ort::init_from(library)
        .map_err(|e| e.to_string())?
        .with_name("rover")
        .build()
        .map_err(|e| e.to_string())?;
    *slot = Some(env.clone());
    Ok(env)
}

/// Where onnxruntime's library is: `ORT_DYLIB_PATH` (ort's variable) when set, else the
/// `onnxruntime/capi/libonnxruntime.so*` of a pip install in `$VIRTUAL_ENV`, the venv in rover's
/// cache (`~/.cache/rover/venv`, where `scripts/setup.sh` puts it), `~/.local` or the
/// system's Python. The error lists every place
/// searched.
pub fn find_onnxruntime_library() -> Result<PathBuf> {
    if let Some(path) = std::env::var_os("ORT_DYLIB_PATH") {
        let path = PathBuf::from(path);
        return if path.is_file() {
            Ok(path)
        } else {
            Err(PerceptionError::Runtime(format!(
                "ORT_DYLIB_PATH is {}, which is not a file",
                path.display()
            )))
        };
    }
    let mut prefixes: Vec<PathBuf> = Vec::new();
    if let Some(venv) = std::env::var_os("VIRTUAL_ENV") {
        prefixes.push(PathBuf::from(venv).join("lib"));
    }
    // The venv scripts/setup.sh makes, in the cache the default model also lives in.
    prefixes.push(rover_assets::cache_dir().join("venv/lib"));
    if let Some(home) = std::env::var_os("HOME") {
        prefixes.push(PathBuf::from(home).join(".local/lib"));
    }
    prefixes.push(PathBuf::from("/usr/local/lib"));
    prefixes.push(PathBuf::from("/usr/lib"));
    let mut searched = Vec::new();
    for prefix in &prefixes {
        let Ok(entries) = std::fs::read_dir(prefix) else {
            continue;
        };
        let mut pythons: Vec<PathBuf> = entries
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with("python3"))
            .map(|e| e.path())
            .collect();
        pythons.sort();
        for python in pythons {
            for packages in ["site-packages", "dist-packages"] {
                let capi = python.join(packages).join("onnxruntime/capi");
                if let Some(lib) = library_in(&capi) {
                    return Ok(lib);
                }
                searched.push(capi);
            }
        }
    }
    let places: Vec<String> = if searched.is_empty() {
        prefixes.iter().map(|p| p.display().to_string()).collect()
    } else {
        searched.iter().map(|p| p.display().to_string()).collect()
    };
    Err(PerceptionError::Runtime(format!(
        "onnxruntime's library (libonnxruntime.so) was not found: `pip install onnxruntime` (in a venv, in ~/.local, or rover's ~/.cache/rover/venv), or set ORT_DYLIB_PATH to the file. Searched: {}",
        places.join(", ")
    )))
}

/// `libonnxruntime.so*` in `dir` (not the providers' libraries beside it).
fn library_in(dir: &Path) -> Option<PathBuf> {
    let mut found: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .filter(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.starts_with("libonnxruntime.so")
        })
        .map(|e| e.path())
        .collect();
    found.sort();
    found.into_iter().next()
}
