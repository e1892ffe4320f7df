//! The walk over a launch file's tags, with roslaunch's scoping: namespaces, args per file,
//! private (`~`) params collected for the nodes that follow, remaps and env inherited by
//! children, includes with their own args.
//!
//! Here the entry points; `state.rs` the shared types (`Loader`, `Ctx`, `FileReader`), and one
//! `impl Loader` per tag family: `attributes.rs`, `structure.rs`, `params.rs`, `nodes.rs`.

mod attributes;
mod files;
mod nodes;
mod params;
mod scope;
mod state;
mod structure;

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use crate::launch::model::{Launch, LaunchError, LaunchOptions, Location, files_named};
use state::{Ctx, Loader};

/// Reads the launch file `path` (and its includes) with `options`.
pub fn load(path: &Path, options: &LaunchOptions) -> Result<Launch, LaunchError> {
    let mut loader = Loader {
        options,
        out: Launch::default(),
        anon: HashMap::new(),
        stack: Vec::new(),
    };
    let mut top_args = BTreeMap::new();
    for (name, value) in &options.args {
        top_args.insert(name.clone(), value.clone());
    }
    let ctx = Ctx {
        ns: "/".to_owned(),
        file: path.to_path_buf(),
        args: top_args,
        arg_names: Vec::new(),
        include_args: None,
        private: Vec::new(),
        remaps: Vec::new(),
        env: Vec::new(),
        pass_all_args: false,
    };
    loader.file(
        path,
        ctx,
        Location {
            file: path.to_path_buf(),
            line: 0,
        },
    )?;
    Ok(loader.out)
}

/// The launch file `name` in package folder `package_dir` (searched a few folders deep, as
/// `roslaunch PKG FILE` finds it).
pub fn find_launch_file(package_dir: &Path, name: &str) -> Result<PathBuf, String> {
    let mut found = files_named(vec![(package_dir.to_path_buf(), 0)], name);
    found.sort();
    match found.len() {
        0 => Err(format!(
            "no file named \"{name}\" in package folder {}",
            package_dir.display()
        )),
        1 => Ok(found.remove(0)),
        _ => Err(format!(
            "more than one \"{name}\" in {}: {}; give the path instead",
            package_dir.display(),
            found
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}
