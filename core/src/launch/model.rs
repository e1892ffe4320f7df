//! What a launch file asks for, as roslaunch reads it: parameters, nodes, includes rover does
//! itself, and where each came from; roslaunch's name rules and how a node's process is made.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::shell::shell_split;
use super::value::ParamValue;

/// Packages whose nodes and launch files rover does itself: `$(find PKG)` resolves to a
/// placeholder (`<rover>/PKG`) when they are not installed, so a launch file that uses them
/// still loads.
pub const PROVIDED_PACKAGES: [&str; 8] = [
    "gazebo_ros",
    "darknet_ros",
    "xacro",
    "robot_state_publisher",
    "joint_state_publisher",
    "joint_state_publisher_gui",
    "controller_manager",
    "gazebo_plugins",
];

/// The placeholder folder `$(find PKG)` gives for a provided package that is not installed.
pub fn provided_placeholder(package: &str) -> String {
    format!("<rover>/{package}")
}

/// How [`load`] reads a launch file.
#[derive(Debug, Clone, Default)]
pub struct LaunchOptions {
    /// `name:=value` args for the top file, as on roslaunch's command line.
    pub args: Vec<(String, String)>,
    /// Where `$(find)` and packages are found.
    pub resources: rover_sim::description::ResourcePaths,
    /// rover's reading: the includes rover does itself (gazebo_ros' `empty_world.launch`,
    /// `darknet_ros.launch`) are recorded in [`Launch::provided`] and not read. Without it,
    /// they are read like any other file when installed (roslaunch's reading, for
    /// `--dump-params`), and skipped with a warning when not.
    pub rover: bool,
    /// Run `<param command=...>` commands other than xacro (on by default in `rover launch`;
    /// off where the input is not trusted, such as fuzzing).
    pub run_commands: bool,
}

/// Where something in a launch file is: file and 1-based line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The launch file.
    pub file: PathBuf,
    /// Its line.
    pub line: u32,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.file.display(), self.line)
    }
}

/// A launch file that cannot be read: where, and what was expected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}:{line}: {message}", file.display())]
pub struct LaunchError {
    /// The launch file.
    pub file: PathBuf,
    /// Its line (1-based; 0 when the file itself could not be read).
    pub line: u32,
    /// What is wrong, and what was expected.
    pub message: String,
}

impl LaunchError {
    pub(crate) fn new(file: &Path, line: u32, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            line,
            message: message.into(),
        }
    }
}

/// How a parameter's value was made.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamSource {
    /// A `value` attribute.
    Value,
    /// `textfile`: the file's text.
    TextFile(PathBuf),
    /// `binfile`: the file's bytes.
    BinFile(PathBuf),
    /// `command` running xacro: the file and its `name:=value` args (rover expands it itself).
    Xacro {
        /// The xacro file.
        file: PathBuf,
        /// Its args.
        args: BTreeMap<String, String>,
    },
    /// Another `command`: its words.
    Command(Vec<String>),
    /// `<rosparam>` YAML: its file, `None` when inline.
    Yaml(Option<PathBuf>),
}

/// One parameter roslaunch would set.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// The value.
    pub value: ParamValue,
    /// How it was made.
    pub source: ParamSource,
    /// The tag that set it.
    pub at: Location,
}

/// `<node output=...>`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Output {
    /// `log` (roslaunch's default): stdout to a log file.
    #[default]
    Log,
    /// `screen`: stdout to the terminal.
    Screen,
}

/// One `<node>` roslaunch would start.
#[derive(Debug, Clone, PartialEq)]
pub struct LaunchNode {
    /// Its package.
    pub pkg: String,
    /// Its executable's name in the package (`type`).
    pub node_type: String,
    /// Its name (without namespace).
    pub name: String,
    /// Its namespace, global, with a trailing `/`.
    pub namespace: String,
    /// Its `args`, substitutions resolved (split like a shell when started).
    pub args: String,
    /// `<remap>`s in effect, `from` -> `to`, in roslaunch's order.
    pub remaps: Vec<(String, String)>,
    /// `<env>`s in effect.
    pub env: Vec<(String, String)>,
    /// Where its stdout goes.
    pub output: Output,
    /// Start it again when it exits.
    pub respawn: bool,
    /// Seconds to wait before that.
    pub respawn_delay_s: f64,
    /// When it exits, stop everything.
    pub required: bool,
    /// `launch-prefix` (a command put before it).
    pub launch_prefix: Option<String>,
    /// `cwd` (`node` or `ROS_HOME`).
    pub cwd: Option<String>,
    /// The tag.
    pub at: Location,
}

impl LaunchNode {
    /// The node's full name (`/ns/name`), as `roslaunch --nodes` prints it.
    pub fn full_name(&self) -> String {
        ns_join(&self.namespace, &self.name)
    }

    /// `ROS_NAMESPACE` for the process: the namespace without its trailing `/`, `None` at the
    /// root.
    pub fn ros_namespace(&self) -> Option<String> {
        let ns = self.namespace.trim_end_matches('/');
        (!ns.is_empty()).then(|| ns.to_owned())
    }
}

/// An `<include>` of a launch file rover does itself (or, reading as roslaunch, one that is not
/// installed), with the args passed to it.
#[derive(Debug, Clone, PartialEq)]
pub struct ProvidedInclude {
    /// The package (`gazebo_ros`, `darknet_ros`).
    pub package: String,
    /// The file's name (`empty_world.launch`).
    pub file_name: String,
    /// The `<arg>`s passed, resolved.
    pub args: BTreeMap<String, String>,
    /// The namespace it was included in.
    pub namespace: String,
    /// The `<include>` tag.
    pub at: Location,
}

/// Everything a launch file asks for, as roslaunch reads it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Launch {
    /// Parameters by global name (mappings unrolled, as roslaunch sets them).
    pub params: BTreeMap<String, Param>,
    /// Nodes, in the order they are declared.
    pub nodes: Vec<LaunchNode>,
    /// Namespaces cleared before setting (`clear_params`).
    pub clear_params: Vec<String>,
    /// Parameters deleted first (`<rosparam command="delete">`).
    pub deletes: Vec<String>,
    /// Every launch file read, in order.
    pub files: Vec<PathBuf>,
    /// Includes not read: those rover does itself.
    pub provided: Vec<ProvidedInclude>,
    /// What roslaunch would warn about (unknown attributes and tags, skipped tags).
    pub warnings: Vec<String>,
}

impl Launch {
    /// The parameters as `roslaunch --dump-params` prints them: `name: value` lines, one per
    /// parameter, in name order (values in YAML's flow style).
    pub fn dump_params(&self) -> String {
        let mut out = String::new();
        for (name, param) in &self.params {
            out.push_str(name);
            out.push_str(": ");
            out.push_str(&param.value.to_yaml());
            out.push('\n');
        }
        out
    }
}

/// roslaunch's `ns_join`: `name` inside namespace `ns` (global and private names stay).
pub fn ns_join(ns: &str, name: &str) -> String {
    if name.starts_with('/') || name.starts_with('~') {
        return name.to_owned();
    }
    if ns == "~" {
        return format!("~{name}");
    }
    if ns.is_empty() {
        return name.to_owned();
    }
    if ns.ends_with('/') {
        format!("{ns}{name}")
    } else {
        format!("{ns}/{name}")
    }
}

/// A ROS name without repeated or trailing slashes.
pub fn canonical_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        if c == '/' && out.ends_with('/') {
            continue;
        }
        out.push(c);
    }
    if out.len() > 1 && out.ends_with('/') {
        out.pop();
    }
    out
}

/// The executable of node type `node_type` in the package folder `package_dir`: a file of that
/// name, executable, searched a few folders deep (as roslaunch finds a package's scripts), then
/// in `/usr/lib/PKG` and `/usr/libexec/PKG` (where Debian installs ROS nodes).
pub fn find_node_executable(
    package: &str,
    package_dir: Option<&Path>,
    node_type: &str,
) -> Result<PathBuf, String> {
    use std::os::unix::fs::PermissionsExt;
    let mut roots: Vec<(PathBuf, usize)> = package_dir
        .map(|d| vec![(absolute(d), 0)])
        .unwrap_or_default();
    for prefix in ["/usr/lib", "/usr/libexec"] {
        let d = Path::new(prefix).join(package);
        if d.is_dir() {
            roots.push((d, SEARCH_DEPTH - 1));
        }
    }
    let mut found = files_named(roots, node_type);
    found.sort();
    let executable =
        |p: &PathBuf| std::fs::metadata(p).is_ok_and(|m| m.permissions().mode() & 0o111 != 0);
    if let Some(exe) = found.iter().find(|p| executable(p)) {
        return Ok(exe.clone());
    }
    match found.first() {
        Some(p) => Err(format!(
            "{} is not executable (chmod +x {})",
            p.display(),
            p.display()
        )),
        None => Err(format!(
            "cannot find node type \"{node_type}\" in package \"{package}\"{}",
            package_dir
                .map(|d| format!(" ({})", d.display()))
                .unwrap_or_else(|| " (the package was not found)".to_owned())
        )),
    }
}

/// How many folders deep a package is searched for a launch file or a node's executable.
const SEARCH_DEPTH: usize = 6;

/// Files called `name` under `roots` (each with the depth it starts at; hidden folders skipped,
/// at most [`SEARCH_DEPTH`] deep), as roslaunch finds a package's launch files and scripts.
pub(crate) fn files_named(mut dirs: Vec<(PathBuf, usize)>, name: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    while let Some((dir, depth)) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            let file_name = entry.file_name();
            let file_name = file_name.to_string_lossy();
            if path.is_dir() && !file_name.starts_with('.') && depth < SEARCH_DEPTH {
                dirs.push((path, depth + 1));
            } else if path.is_file() && file_name == name {
                found.push(path);
            }
        }
    }
    found
}

impl LaunchNode {
    /// The process's command line as roslaunch builds it: `launch-prefix`, the executable,
    /// `args` split like a shell, the remaps (`from:=to`) and `__name:=NAME`.
    pub fn command_line(&self, executable: &Path) -> Result<Vec<String>, String> {
        let mut words = match &self.launch_prefix {
            Some(prefix) => shell_split(prefix)?,
            None => Vec::new(),
        };
        words.push(executable.to_string_lossy().into_owned());
        words.extend(shell_split(&self.args)?);
        for (from, to) in &self.remaps {
            words.push(format!("{from}:={to}"));
        }
        words.push(format!("__name:={}", self.name));
        Ok(words)
    }

    /// The environment roslaunch sets for it besides the inherited one: `ROS_MASTER_URI`,
    /// `ROS_NAMESPACE` (when not at the root) and its `<env>`s.
    pub fn environment(&self, master_uri: &str) -> Vec<(String, String)> {
        let mut env = vec![("ROS_MASTER_URI".to_owned(), master_uri.to_owned())];
        if let Some(ns) = self.ros_namespace() {
            env.push(("ROS_NAMESPACE".to_owned(), ns));
        }
        env.extend(self.env.iter().cloned());
        env
    }
}

/// `path` absolute, with `.` and `..` folded (Python's `os.path.abspath`, as rospack gives a
/// package's folder).
pub(crate) fn absolute(path: &Path) -> PathBuf {
    use std::path::Component;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}
