//! roslaunch files, read as roslaunch reads them (ROS 1 Noetic's XML format).
//!
//! [`load`] walks a launch file and its includes with roslaunch's rules (`<arg>` with
//! default/value and include-scoped args, `<include>` with `ns` and `pass_all_args`,
//! `<group>` with `ns`, `if`/`unless` on every tag, `<param>` with `value`/`type`/`textfile`/
//! `binfile`/`command`, `<rosparam>` load/delete with inline YAML or a file, `<node>` with its
//! `<remap>`, `<param>`, `<rosparam>` and `<env>`, `<remap>` and `<env>` in scope) and the
//! substitution args (`$(arg)`, `$(find)`, `$(env)`, `$(optenv)`, `$(anon)`, `$(eval)`,
//! `$(dirname)`). The result, [`Launch`], is the parameters roslaunch would set and the nodes it
//! would start, with the file and line each came from. `rover launch` then does Gazebo's and
//! darknet_ros's part itself ([`RoverPart`]) and starts the other nodes.
//!
//! `$(find xacro)/xacro FILE` in a `command` runs rover's own xacro (no ROS install needed);
//! `$(find PKG)` of a package rover stands in for ([`PROVIDED_PACKAGES`]) does not fail when
//! that package is not installed.

mod eval;
mod loader;
mod model;
mod rover;
mod shell;
mod subst;
#[cfg(test)]
mod tests;
mod value;

pub use loader::{find_launch_file, load};
pub use model::{
    Launch, LaunchError, LaunchNode, LaunchOptions, Location, Output, PROVIDED_PACKAGES, Param,
    ParamSource, ProvidedInclude, canonical_name, find_node_executable, ns_join,
    provided_placeholder,
};
pub use rover::{DetectorRequest, NodeRole, RoverPart, SpawnRequest, WorldRequest, role_of};
pub use shell::shell_split;
pub use value::ParamValue;
