//! rover, the application: adapters at the edge of the loop in `rover-core`.
//!
//! * [`cli`] — the command line (`rover`, `rover --headless`, `rover bench`, `rover detect`).
//! * [`viewer`] — the Rerun recorder: viewer modes, the static scene, per-tick logging, images,
//!   the blueprint.
//! * [`station`] — the driver's station: the window, its HUD, keyboard and gamepad teleop.
//! * [`ros`] — the ROS 1 bridge (`--ros`): `/cmd_vel` in; odometry, TF, camera and darknet_ros
//!   topics out, on [`rover_ros1`].
//! * [`ros2`] — the ROS 2 bridge (`--ros2`): the same names over DDS, on RustDDS.
//!
//! The binary `rover` is a thin `main` over [`cli::main`], so tests drive exactly what users
//! run.

mod bridge;
pub mod cli;
pub mod palette;
pub mod ros;
pub mod ros2;
pub mod station;
pub mod viewer;
