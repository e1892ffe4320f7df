//! Errors of the ROS 1 client.

/// What went wrong talking to the ROS master or a peer.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A socket error (refused, reset, timed out).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// A peer said something this client does not understand.
    #[error("ROS protocol: {0}")]
    Protocol(String),
    /// A master or slave API call answered with an error code.
    #[error("{method}: {status}")]
    Api {
        /// The XML-RPC method.
        method: String,
        /// The status text the peer gave.
        status: String,
    },
    /// A bad setting (master URI, node name).
    #[error("{0}")]
    Config(String),
    /// A message type this client has no definition for.
    #[error("unknown ROS message type {0}")]
    UnknownType(String),
}

impl Error {
    pub(crate) fn protocol(text: impl Into<String>) -> Self {
        Error::Protocol(text.into())
    }
}

/// Result with [`Error`].
pub type Result<T> = std::result::Result<T, Error>;
