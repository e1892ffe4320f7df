//! Errors of a run's loop.

use std::path::{Path, PathBuf};

use rover_perception::PerceptionError;
use rover_sim::{SimError, render::RenderError};

/// Everything that can stop a run from starting or going on.
#[derive(Debug, thiserror::Error)]
pub enum CoreError {
    /// The world, robot, script or physics (with file and line where known).
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The detector.
    #[error(transparent)]
    Perception(#[from] PerceptionError),
    /// The camera could not start (no graphics adapter, bad camera) or render.
    #[error("camera: {0}")]
    Camera(#[source] RenderError),
    /// A file the run writes (trace, frames) could not be created or written.
    #[error("cannot write {}: {cause}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The underlying error (in the message, so not repeated as a source).
        cause: std::io::Error,
    },
    /// An option is out of range (what was found and what is expected).
    #[error("{0}")]
    Option(String),
}

impl CoreError {
    /// A write error on `path`.
    pub fn write(path: &Path, source: std::io::Error) -> Self {
        Self::Write {
            path: path.to_path_buf(),
            cause: source,
        }
    }
}

/// Result alias for the core.
pub type Result<T, E = CoreError> = std::result::Result<T, E>;
