//! rover-sim: the simulation core of rover.
//!
//! Loads a robot from URDF ([`RobotModel`], honouring the `<gazebo>` diff_drive and camera
//! extensions) and a world from TOML ([`World`]), steps rapier3d physics at a fixed rate and drives
//! the wheels like gazebo_ros_diff_drive ([`Simulation`]). Free of UI and viewer code, so it runs
//! headless in tests.
//!
//! Frames follow REP-103: x forward, y left, z up.

pub mod camera;
pub mod diff_drive;
pub mod error;
pub mod gazebo;
pub mod geometry;
pub mod mesh;
pub mod render;
pub mod robot;
pub mod sensor;
pub mod simulation;
pub mod tomlfile;
pub mod world;

pub use camera::CameraInfo;
pub use diff_drive::{DiffDriveController, Odometry, Twist, WheelSpeeds};
pub use error::{Location, Result, SimError};
pub use gazebo::{CameraConfig, DiffDriveConfig, OdometrySource};
pub use geometry::{Pose, Rgba, Shape};
pub use render::{CameraRenderer, RenderError};
pub use robot::RobotModel;
pub use sensor::{CameraFrame, CameraSensor};
pub use simulation::{ControlSample, SimOptions, Simulation};
pub use world::World;
