//! rover-sim: the simulation core of rover.
//!
//! Loads a robot from URDF ([`RobotModel`], honouring the `<gazebo>` diff_drive and camera
//! extensions) and a world from TOML ([`World`]), steps rapier3d physics at a fixed rate and drives
//! the wheels like gazebo_ros_diff_drive ([`Simulation`]), and renders the robot's camera
//! offscreen with wgpu ([`CameraSensor`], [`CameraRenderer`]). Free of UI and viewer code, so it
//! runs headless in tests.
//!
//! Frames follow REP-103: x forward, y left, z up; camera images are in the optical frame
//! (z forward, x right, y down).
//!
//! The modules are private; this page lists the API. Viewers that draw the scene use the same
//! triangles the camera renders: [`shape_mesh`], [`object_mesh`] and [`person_parts`] give
//! [`MeshData`] in each thing's own frame.

mod camera;
mod diff_drive;
mod error;
mod gazebo;
mod geometry;
mod laser;
mod mesh;
mod noise;
mod render;
mod resource;
mod robot;
mod sdf;
mod sensor;
mod simulation;
mod tomlfile;
mod urdf;
mod world;
mod xacro;

pub use camera::{CameraInfo, link_from_optical};
pub use diff_drive::{
    DiffDriveController, EncoderOdometry, ODOM_POSE_COVARIANCE_DIAGONAL, Odometry, Twist,
    WheelSpeeds, wrap_angle,
};
pub use error::{Location, Result, SimError, panic_message};
pub use gazebo::{
    CameraConfig, DiffDriveConfig, Distortion, GaussianNoise, LaserConfig, MAX_LASER_SAMPLES,
    OdometrySource, PixelFormat,
};
pub use geometry::{Pose, Rgba, Shape, pose_from_position_yaw, pose_from_xyz_rpy, yaw_of};
pub use laser::{LaserScan, LaserSensor};
pub use mesh::{TriMesh, load_mesh};
/// nalgebra, the version rapier uses: for estimation and general matrices (one copy in the build).
pub use rapier3d::na as nalgebra;
pub use render::meshes::{
    MeshData, Part as PersonPart, Vertex as MeshVertex, object_mesh, person_parts, shape_mesh,
};
pub use render::{CameraRenderer, RenderError};
pub use resource::{NotFound, ResourcePaths};
pub use robot::{Collision, Inertial, Joint, JointKind, Link, LoadOptions, RobotModel, Visual};
pub use sdf::{Model, ModelLink};
pub use sensor::{CameraFrame, CameraSensor};
pub use simulation::{ControlSample, SimOptions, Simulation};
pub use tomlfile::{load_toml, parse_toml};
pub use world::{
    DEFAULT_STEP_HZ, DriveSpec, Ground, Object, ObjectShape, Person, Physics, RobotSpawn,
    STEP_HZ_RANGE, Walk, World, WorldFile, check_step_hz,
};
pub use xacro::{Expanded, expand_file as expand_xacro, uses_xacro};
