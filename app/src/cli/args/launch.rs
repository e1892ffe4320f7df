//! `rover launch`'s and `rover xacro`'s options ([`LaunchArgs`], [`XacroArgs`]).

use std::path::PathBuf;

use clap::Args;

use super::parsers::parse_package_path;
use super::run::RunArgs;

/// `rover launch` arguments: the launch file, roslaunch's query options, and rover's run
/// options (--headless, --duration, --trace, --record-mcap, ...).
#[derive(Debug, Args)]
pub(crate) struct LaunchArgs {
    /// `PKG FILE.launch` (FILE found in ROS package PKG, as `roslaunch PKG FILE` finds it) or
    /// `PATH.launch`, then `name:=value` args for the file
    #[arg(required = true, num_args = 1.., value_name = "PKG FILE | PATH")]
    pub(crate) launch: Vec<String>,

    /// Print the parameters the launch sets (YAML, as `roslaunch --dump-params`) and exit
    #[arg(long)]
    pub(crate) dump_params: bool,

    /// Print the nodes' names (as `roslaunch --nodes`) and exit
    #[arg(long)]
    pub(crate) nodes: bool,

    /// Print the command line NODE would be started with, environment first (as
    /// `roslaunch --args NODE`), and exit
    #[arg(long = "args", value_name = "NODE")]
    pub(crate) node_args: Option<String>,

    /// Print the launch files read (as `roslaunch --files`) and exit
    #[arg(long)]
    pub(crate) files: bool,

    #[command(flatten)]
    pub(crate) run: RunArgs,
}

/// `rover xacro` arguments.
#[derive(Debug, Args)]
pub(crate) struct XacroArgs {
    /// The xacro file
    pub(crate) file: PathBuf,

    /// `name:=value` args (`$(arg name)`)
    #[arg(value_name = "ARG")]
    pub(crate) args: Vec<String>,

    /// Where ROS package NAME is, for $(find NAME) (repeatable)
    #[arg(long = "package-path", value_name = "NAME=DIR", value_parser = parse_package_path)]
    pub(crate) package_paths: Vec<(String, PathBuf)>,
}
