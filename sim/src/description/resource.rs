//! Finding the files robot and world descriptions refer to: `package://NAME/...` and
//! `$(find NAME)` through ROS packages, `model://NAME/...` through Gazebo model folders,
//! `file://` and relative paths.
//!
//! A ROS package is a folder with a `package.xml`; its name is the `<name>` in that file, not the
//! folder's name. Packages are looked up, in order: in the explicit `--package-path NAME=DIR`
//! entries, upward from the file being loaded (each ancestor folder that is a package, and the
//! packages beside it; then an ancestor folder called NAME holding a package.xml, as in a ROS 2
//! install's `share/NAME`), and in the folders of `ROS_PACKAGE_PATH` (searched a few levels
//! deep).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How deep below a `ROS_PACKAGE_PATH` or `GAZEBO_MODEL_PATH` entry packages and models are
/// looked for.
const SEARCH_DEPTH: usize = 4;

/// A URI or package that could not be found, with every place that was searched.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what} not found; searched: {}{hint}", searched_list(.searched))]
pub struct NotFound {
    /// What was looked for (`package "foo"`, `package://foo/bar.stl`).
    pub what: String,
    /// Folders and files searched, in order.
    pub searched: Vec<PathBuf>,
    /// What to do about it (starting with "; "), or empty.
    pub hint: String,
}

fn searched_list(searched: &[PathBuf]) -> String {
    if searched.is_empty() {
        return "(nowhere: no package path given)".to_owned();
    }
    searched
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Where ROS packages and Gazebo models are found.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ResourcePaths {
    /// Explicit package folders by package name (`--package-path NAME=DIR`).
    pub packages: BTreeMap<String, PathBuf>,
    /// Folders searched for packages (`ROS_PACKAGE_PATH`).
    pub package_search: Vec<PathBuf>,
    /// Folders holding Gazebo models (`--model-path`, `GZ_SIM_RESOURCE_PATH`,
    /// `IGN_GAZEBO_RESOURCE_PATH`, `GAZEBO_MODEL_PATH`).
    pub model_search: Vec<PathBuf>,
}

impl ResourcePaths {
    /// Paths from the environment: `ROS_PACKAGE_PATH`; `GZ_SIM_RESOURCE_PATH`,
    /// `IGN_GAZEBO_RESOURCE_PATH` and `GAZEBO_MODEL_PATH` for models.
    pub fn from_env() -> Self {
        let split = |var: &str| -> Vec<PathBuf> {
            std::env::var_os(var)
                .map(|v| {
                    std::env::split_paths(&v)
                        .filter(|p| !p.as_os_str().is_empty())
                        .collect()
                })
                .unwrap_or_default()
        };
        // Modern Gazebo's resource paths first, then Gazebo classic's.
        let mut model_search = split("GZ_SIM_RESOURCE_PATH");
        model_search.extend(split("IGN_GAZEBO_RESOURCE_PATH"));
        model_search.extend(split("GAZEBO_MODEL_PATH"));
        Self {
            packages: BTreeMap::new(),
            package_search: split("ROS_PACKAGE_PATH"),
            model_search,
        }
    }

    /// Adds an explicit package folder.
    pub fn with_package(mut self, name: impl Into<String>, dir: impl Into<PathBuf>) -> Self {
        self.packages.insert(name.into(), dir.into());
        self
    }

    /// Adds a Gazebo model folder, searched before the others.
    pub fn with_model_path(mut self, dir: impl Into<PathBuf>) -> Self {
        self.model_search.insert(0, dir.into());
        self
    }

    /// The folder of ROS package `name`, looked up from a file in `near`.
    pub fn find_package(&self, name: &str, near: &Path) -> Result<PathBuf, NotFound> {
        let mut searched = Vec::new();
        if let Some(dir) = self.packages.get(name) {
            return Ok(dir.clone());
        }
        let near = absolute(near);
        for dir in near.ancestors() {
            if package_name(dir).as_deref() == Some(name) {
                return Ok(dir.to_path_buf());
            }
            searched.push(dir.to_path_buf());
            // Packages beside this folder (a workspace's src/ holding several packages).
            if let Ok(entries) = std::fs::read_dir(dir) {
                let mut children: Vec<PathBuf> = entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.is_dir())
                    .collect();
                children.sort();
                if let Some(found) = children
                    .into_iter()
                    .find(|c| package_name(c).as_deref() == Some(name))
                {
                    return Ok(found);
                }
            }
        }
        // A ROS 2 install's share/NAME folder is found by its name even when its package.xml
        // says otherwise (example-robot-data's says example_robot_descriptions).
        if let Some(dir) = near
            .ancestors()
            .find(|d| d.file_name().is_some_and(|n| n == name) && d.join("package.xml").is_file())
        {
            return Ok(dir.to_path_buf());
        }
        for root in &self.package_search {
            searched.push(root.clone());
            // A package by its package.xml's name, or a share/NAME folder by its own (as
            // above): a pip-installed example-robot-data's `cmeel.prefix/share` on the path
            // finds `example-robot-data`.
            if let Some(found) = find_below(root, SEARCH_DEPTH, &|dir| {
                package_name(dir).as_deref() == Some(name)
                    || (dir.file_name().is_some_and(|n| n == name)
                        && dir.join("package.xml").is_file())
            }) {
                return Ok(found);
            }
        }
        let hint = if self.package_search.is_empty() {
            format!(
                "; ROS_PACKAGE_PATH is not set: set it to a folder the package is in (a pip install's site-packages/cmeel.prefix/share, a catkin workspace's src), or pass --package-path {name}=DIR"
            )
        } else {
            String::new()
        };
        Err(NotFound {
            what: format!("ROS package \"{name}\""),
            searched,
            hint,
        })
    }

    /// The folder of Gazebo model `name` (`model://NAME`): a folder called NAME with a
    /// `model.config` or `model.sdf` in a model path.
    pub fn find_model(&self, name: &str) -> Result<PathBuf, NotFound> {
        let mut searched = Vec::new();
        for root in &self.model_search {
            let candidate = root.join(name);
            if candidate.join("model.config").is_file() || candidate.join("model.sdf").is_file() {
                return Ok(candidate);
            }
            searched.push(root.clone());
        }
        let hint = if self.model_search.is_empty() {
            "; no model path is set: set GZ_SIM_RESOURCE_PATH (or GAZEBO_MODEL_PATH) to the folder holding the model, or pass --model-path DIR".to_owned()
        } else {
            String::new()
        };
        Err(NotFound {
            what: format!("Gazebo model \"{name}\" (model://{name})"),
            searched,
            hint,
        })
    }

    /// Resolves a URI naming a folder or a file (as SDF material scripts' `<uri>` do) to the
    /// folder: `model://MODEL/rel`, `file://` or a plain path relative to `base_dir`; `None`
    /// when there is no such folder.
    pub fn resolve_dir(&self, uri: &str, base_dir: &Path) -> Option<PathBuf> {
        let path = if let Some(rest) = uri.strip_prefix("model://") {
            let (model, rel) = rest.split_once('/').unwrap_or((rest, ""));
            self.find_model(model).ok()?.join(rel)
        } else {
            let p = Path::new(uri.strip_prefix("file://").unwrap_or(uri));
            if p.is_absolute() {
                p.to_path_buf()
            } else {
                base_dir.join(p)
            }
        };
        if path.is_dir() {
            Some(path)
        } else if path.is_file() {
            path.parent().map(Path::to_path_buf)
        } else {
            None
        }
    }

    /// Resolves a file URI as URDF and SDF use them: `package://PKG/rel`, `model://MODEL/rel`,
    /// `file:///abs`, `file://rel` or a plain path (relative to `base_dir`).
    pub fn resolve(&self, uri: &str, base_dir: &Path) -> Result<PathBuf, NotFound> {
        let (root, rel) = if let Some(rest) = uri.strip_prefix("package://") {
            let (package, rel) = rest.split_once('/').unwrap_or((rest, ""));
            let dir = self.find_package(package, base_dir).map_err(|mut e| {
                e.what = format!("{uri}: {}", e.what);
                e
            })?;
            (dir, rel)
        } else if let Some(rest) = uri.strip_prefix("model://") {
            let (model, rel) = rest.split_once('/').unwrap_or((rest, ""));
            let dir = self.find_model(model).map_err(|mut e| {
                e.what = format!("{uri}: {}", e.what);
                e
            })?;
            (dir, rel)
        } else {
            let plain = uri.strip_prefix("file://").unwrap_or(uri);
            let p = Path::new(plain);
            let p = if p.is_absolute() {
                p.to_path_buf()
            } else {
                base_dir.join(p)
            };
            return if p.is_file() {
                Ok(p)
            } else {
                Err(NotFound {
                    what: format!("file {uri}"),
                    searched: vec![p],
                    hint: String::new(),
                })
            };
        };
        let p = root.join(rel);
        if p.is_file() {
            Ok(p)
        } else {
            Err(NotFound {
                what: format!("file {uri}"),
                searched: vec![p],
                hint: String::new(),
            })
        }
    }
}

fn absolute(p: &Path) -> PathBuf {
    std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf())
}

/// The `<name>` in `dir/package.xml`, if `dir` is a ROS package.
fn package_name(dir: &Path) -> Option<String> {
    let text = std::fs::read_to_string(dir.join("package.xml")).ok()?;
    let doc = roxmltree::Document::parse(&text).ok()?;
    let name = doc
        .root_element()
        .children()
        .find(|n| n.has_tag_name("name"))?
        .text()?
        .trim()
        .to_owned();
    (!name.is_empty()).then_some(name)
}

/// Breadth-first search below `root` (at most `depth` levels) for a folder `accept`s, not
/// descending into packages.
fn find_below(root: &Path, depth: usize, accept: &dyn Fn(&Path) -> bool) -> Option<PathBuf> {
    let mut level = vec![root.to_path_buf()];
    for _ in 0..=depth {
        let mut next = Vec::new();
        for dir in level {
            if accept(&dir) {
                return Some(dir);
            }
            if dir.join("package.xml").is_file() {
                continue;
            }
            if let Ok(entries) = std::fs::read_dir(&dir) {
                let mut children: Vec<PathBuf> = entries
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| p.is_dir())
                    .collect();
                children.sort();
                next.extend(children);
            }
        }
        if next.is_empty() {
            break;
        }
        level = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn package(dir: &Path, name: &str) -> std::io::Result<()> {
        std::fs::create_dir_all(dir)?;
        std::fs::write(
            dir.join("package.xml"),
            format!("<package format=\"2\"><name>{name}</name></package>"),
        )
    }

    #[test]
    fn packages_are_named_by_package_xml_not_folder() -> Result<(), Box<dyn std::error::Error>> {
        let tmp = tempfile::tempdir()?;
        let ws = tmp.path().join("src");
        package(&ws.join("desc-folder"), "my-robot_description")?;
        package(&ws.join("other"), "other_pkg")?;
        std::fs::create_dir_all(ws.join("desc-folder/meshes"))?;
        std::fs::write(ws.join("desc-folder/meshes/a.stl"), "solid a\nendsolid a\n")?;
        std::fs::create_dir_all(ws.join("desc-folder/urdf"))?;
        let near = ws.join("desc-folder/urdf");
        let paths = ResourcePaths::default();
        assert_eq!(
            paths.find_package("my-robot_description", &near)?,
            absolute(&ws.join("desc-folder"))
        );
        assert_eq!(
            paths.find_package("other_pkg", &near)?,
            absolute(&ws.join("other"))
        );
        assert_eq!(
            paths.resolve("package://my-robot_description/meshes/a.stl", &near)?,
            absolute(&ws.join("desc-folder/meshes/a.stl"))
        );
        let err = paths
            .find_package("nope", &near)
            .err()
            .ok_or("found a package that does not exist")?;
        assert!(err.to_string().contains("ROS package \"nope\" not found"));
        assert!(
            err.to_string()
                .contains("ROS_PACKAGE_PATH is not set: set it to a folder the package is in"),
            "{err}"
        );
        assert!(err.searched.contains(&absolute(&near)));

        let via_env = ResourcePaths {
            package_search: vec![tmp.path().to_path_buf()],
            ..Default::default()
        };
        assert_eq!(
            via_env.find_package("other_pkg", Path::new("/"))?,
            ws.join("other")
        );
        // A pip-installed share/NAME folder whose package.xml names it otherwise
        // (example-robot-data's says example_robot_descriptions), found through the path.
        let share = tmp.path().join("site/cmeel.prefix/share");
        package(
            &share.join("example-robot-data"),
            "example_robot_descriptions",
        )?;
        let pip = ResourcePaths {
            package_search: vec![share.clone()],
            ..Default::default()
        };
        assert_eq!(
            pip.find_package("example-robot-data", Path::new("/"))?,
            share.join("example-robot-data")
        );
        let explicit = ResourcePaths::default().with_package("x", "/somewhere");
        assert_eq!(
            explicit.find_package("x", &near)?,
            PathBuf::from("/somewhere")
        );
        let missing = paths
            .resolve("package://my-robot_description/meshes/b.stl", &near)
            .err()
            .ok_or("resolved a missing file")?;
        assert!(missing.to_string().contains("b.stl"), "{missing}");
        Ok(())
    }
}
