//! rover's cache folder, and whether fetching into it is allowed.

use std::path::PathBuf;

/// rover's cache folder: `$ROVER_CACHE_DIR`, else `$XDG_CACHE_HOME/rover`, else
/// `~/.cache/rover` (the system's temporary folder when there is no home).
pub fn cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("ROVER_CACHE_DIR") {
        return PathBuf::from(dir);
    }
    std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir)
        .join("rover")
}

/// Whether fetching is refused: `ROVER_OFFLINE` set to anything but empty or `0`. `./test` sets
/// it once set-up has fetched everything, so no test downloads: a test that finds the cache
/// without what it needs fails (or skips) naming it, instead of fetching.
pub fn offline() -> bool {
    std::env::var_os("ROVER_OFFLINE").is_some_and(|v| !v.is_empty() && v != "0")
}
