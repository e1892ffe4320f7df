//! Where rover finds its bundled worlds and robots.

use std::path::{Path, PathBuf};

/// The repository root this binary was built from (for running from anywhere with `cargo run`).
fn build_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// Finds a bundled file: relative to the current directory first, then to the source tree.
pub fn bundled_path(relative: &str) -> PathBuf {
    let here = PathBuf::from(relative);
    if here.exists() {
        return here;
    }
    let built = build_root().join(relative);
    if built.exists() { built } else { here }
}

/// The default world, `worlds/playground.toml`.
pub(crate) fn default_world() -> PathBuf {
    bundled_path("worlds/playground.toml")
}

/// The default robot, `assets/robots/my_robot.urdf`.
pub fn default_robot_path() -> PathBuf {
    bundled_path("assets/robots/my_robot.urdf")
}
