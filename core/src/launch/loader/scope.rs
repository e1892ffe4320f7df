//! `Scope`: the substitution args' (`$(arg)`, `$(find)`, `$(anon)`, `$(dirname)`) view of the
//! scope a tag is read in.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use rover_sim::description::ResourcePaths;

use crate::launch::eval::EvalHost;
use crate::launch::model::{PROVIDED_PACKAGES, absolute, provided_placeholder};

/// Resolves substitutions against one scope.
pub(super) struct Scope<'a> {
    pub(super) args: &'a BTreeMap<String, String>,
    pub(super) file: &'a Path,
    pub(super) anon: &'a mut HashMap<String, String>,
    pub(super) resources: &'a ResourcePaths,
}

impl EvalHost for Scope<'_> {
    fn arg(&mut self, name: &str) -> Result<String, String> {
        self.args.get(name).cloned().ok_or_else(|| {
            format!("arg \"{name}\" is not defined (declare it with <arg name=\"{name}\" default=\"...\"/> or pass {name}:=VALUE)")
        })
    }

    fn find(&mut self, package: &str) -> Result<String, String> {
        match self.resources.find_package(package, self.file) {
            Ok(dir) => Ok(absolute(&dir).to_string_lossy().into_owned()),
            Err(_) if PROVIDED_PACKAGES.contains(&package) => Ok(provided_placeholder(package)),
            Err(e) => Err(format!(
                "$(find {package}): {e} (add its folder to ROS_PACKAGE_PATH or pass --package-path {package}=DIR)"
            )),
        }
    }

    fn anon(&mut self, id: &str) -> String {
        if let Some(name) = self.anon.get(id) {
            return name.clone();
        }
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().replace(['-', '.'], "_"))
            .unwrap_or_else(|_| "localhost".to_owned());
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let name = format!(
            "{id}_{host}_{}_{}",
            std::process::id(),
            u64::from(nanos).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 1
        );
        self.anon.insert(id.to_owned(), name.clone());
        name
    }

    fn dirname(&mut self) -> Result<String, String> {
        Ok(absolute(self.file)
            .parent()
            .map(|p| p.to_string_lossy().into_owned())
            .unwrap_or_default())
    }
}
