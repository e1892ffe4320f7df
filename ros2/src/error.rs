//! The crate's error: a DDS entity that could not be created, or a sample that could not be
//! written, with what rover was doing.

/// What went wrong on the DDS side of a ROS 2 node.
#[derive(Debug, thiserror::Error)]
#[error("{what}")]
pub struct Error {
    /// What rover was doing ("creating the DDS topic for /odom").
    pub what: String,
    /// RustDDS's own error.
    #[source]
    pub source: Box<dyn std::error::Error + Send + Sync>,
}

/// The crate's results.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Names what was being done when a RustDDS call failed.
pub(crate) trait Context<T> {
    /// The error, if any, as an [`Error`] saying `what` (computed only on failure).
    fn with_context(self, what: impl FnOnce() -> String) -> Result<T>;
    /// The error, if any, as an [`Error`] saying `what`.
    fn context(self, what: &str) -> Result<T>;
}

impl<T, E: std::error::Error + Send + Sync + 'static> Context<T> for std::result::Result<T, E> {
    fn with_context(self, what: impl FnOnce() -> String) -> Result<T> {
        self.map_err(|e| Error {
            what: what(),
            source: Box::new(e),
        })
    }

    fn context(self, what: &str) -> Result<T> {
        self.with_context(|| what.to_owned())
    }
}
