//! Errors of the perception crate.

use std::path::PathBuf;

/// Everything that can go wrong loading a model or detecting.
#[derive(Debug, thiserror::Error)]
pub enum PerceptionError {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The model file is not a usable ONNX model.
    #[error("{}: {message}", path.display())]
    Model {
        /// The model file.
        path: PathBuf,
        /// What is wrong and what was expected.
        message: String,
    },
    /// The model's output does not look like any YOLO head rover knows.
    #[error("{}: output shape {shape:?} is not a known YOLO head; expected [1, 4+C, N] (YOLOv8/11/12), [1, N, 5+C] (YOLOv5) or [1, K, 6] (YOLOv10 end-to-end)", path.display())]
    UnknownHead {
        /// The model file.
        path: PathBuf,
        /// The output shape found.
        shape: Vec<usize>,
    },
    /// Class names could not be found or read.
    #[error("{0}")]
    Labels(String),
    /// The default model could not be obtained.
    #[error("cannot obtain the default model: {0}")]
    Fetch(String),
    /// An image has the wrong size or layout.
    #[error("bad image: {0}")]
    Image(String),
    /// Inference failed.
    #[error("inference failed: {0}")]
    Inference(String),
    /// The detector worker thread is gone.
    #[error("the detector thread stopped: {0}")]
    WorkerGone(String),
    /// The detector panicked (a bug in rover or tract, or a model it cannot run).
    #[error("the detector crashed: {0}")]
    Panicked(String),
    /// The optional onnxruntime runtime (`--runtime onnxruntime`) is not available.
    #[error("{0}")]
    Runtime(String),
    /// The onnxruntime reference (tests and benchmarks) could not run.
    #[error("{0}")]
    Reference(String),
}

impl PerceptionError {
    pub(crate) fn model(path: &std::path::Path, message: impl Into<String>) -> Self {
        Self::Model {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// Result alias for the perception crate.
pub type Result<T, E = PerceptionError> = std::result::Result<T, E>;
