//! Errors of the simulation core.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in an input file a problem was found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, when known.
    pub line: Option<u32>,
}

impl Location {
    /// A location in `path` at `line` (1-based), if known.
    pub fn new(path: &Path, line: Option<u32>) -> Self {
        Self {
            path: path.to_path_buf(),
            line,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}", self.path.display(), line),
            None => write!(f, "{}", self.path.display()),
        }
    }
}

/// Everything that can go wrong while loading or running a simulation.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// An input file (URDF, world) is malformed or inconsistent.
    #[error("{location}: {message}")]
    Invalid {
        /// File and line.
        location: Location,
        /// What was wrong and what was expected.
        message: String,
    },
    /// The robot and world cannot be simulated together (e.g. no drive plugin).
    #[error("{0}")]
    Setup(String),
    /// A trajectory controller refused a trajectory.
    #[error("controller \"{controller}\": {error}")]
    Trajectory {
        /// The controller.
        controller: String,
        /// Why (in the message, so not a source as well).
        error: crate::physics::TrajectoryError,
    },
    /// A velocity command was rejected (NaN or infinite components).
    #[error(
        "rejected cmd_vel (linear {linear_mps} m/s, angular {angular_radps} rad/s): components must be finite; keeping the last valid command"
    )]
    NonFiniteCommand {
        /// The rejected linear.x.
        linear_mps: f64,
        /// The rejected angular.z.
        angular_radps: f64,
    },
}

impl SimError {
    /// Shorthand for [`SimError::Invalid`].
    pub fn invalid(path: &Path, line: Option<u32>, message: impl Into<String>) -> Self {
        Self::Invalid {
            location: Location::new(path, line),
            message: message.into(),
        }
    }
}

/// Result alias for the simulation core.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// The message of a caught panic (`catch_unwind`'s payload), for errors that report it.
pub(crate) fn panic_message(payload: &(dyn std::any::Any + Send)) -> &str {
    payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied())
        .unwrap_or("a panic without a message")
}

/// `"a", "b", "c"` (or `(none)`) for messages that list what there is.
pub(crate) fn quoted_list<'a>(items: impl Iterator<Item = &'a String>) -> String {
    let list: Vec<String> = items.map(|n| format!("\"{n}\"")).collect();
    if list.is_empty() {
        "(none)".to_owned()
    } else {
        list.join(", ")
    }
}
