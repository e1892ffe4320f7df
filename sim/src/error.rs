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

/// Parses XML (URDF, xacro, SDF; DTDs allowed), reporting malformed input with its line.
pub(crate) fn parse_xml<'a>(text: &'a str, path: &Path) -> Result<roxmltree::Document<'a>> {
    roxmltree::Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .map_err(|e| {
        let pos = e.pos();
        SimError::invalid(
            path,
            Some(pos.row),
            format!("malformed XML (column {}): {e}", pos.col),
        )
    })
}

/// Result alias for the simulation core.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// Largest text file rover reads (robot descriptions, xacro includes, worlds, scripts).
pub const MAX_TEXT_FILE_BYTES: u64 = 64 << 20;

/// Reads a regular file of at most `max_bytes`. A device, FIFO or folder (`/dev/zero` named as
/// an include or mesh would otherwise be read forever) and a larger file are errors naming it.
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let io = |source| SimError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(SimError::invalid(
            path,
            None,
            "not a regular file: expected a file to read",
        ));
    }
    if meta.len() > max_bytes {
        return Err(SimError::invalid(
            path,
            None,
            format!("file is {} bytes; expected at most {max_bytes}", meta.len()),
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > max_bytes {
        return Err(SimError::invalid(
            path,
            None,
            format!("file grew past {max_bytes} bytes while being read"),
        ));
    }
    Ok(bytes)
}

/// Reads a UTF-8 text file of at most [`MAX_TEXT_FILE_BYTES`] (see [`read_bounded`]).
pub fn read_text(path: &Path) -> Result<String> {
    String::from_utf8(read_bounded(path, MAX_TEXT_FILE_BYTES)?).map_err(|e| SimError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        ),
    })
}

/// The message of a caught panic (`catch_unwind`'s payload), for errors that report it.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> &str {
    payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied())
        .unwrap_or("a panic without a message")
}
