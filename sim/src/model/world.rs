//! A world: the ground, objects, people, Gazebo models, physics settings and where the robot
//! spawns. Plain data; read from TOML or SDF by `description`.

use std::path::PathBuf;

use crate::geometry::{Pose, Rgba, Shape, pose_from_position_yaw};
use crate::model::drive::DriveSpec;
use crate::model::person::Person;
use crate::model::robot::{Collision, Visual};

/// Default physics step rate (Hz); see docs/WORLDS.md for why.
pub const DEFAULT_STEP_HZ: f64 = 200.0;

/// A loaded and validated world.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// World name (defaults to the file stem).
    pub name: String,
    /// The file it came from.
    pub source: PathBuf,
    /// Free-text description.
    pub description: String,
    /// Where and which robot to spawn.
    pub robot: RobotSpawn,
    /// Physics settings.
    pub physics: Physics,
    /// The ground plane.
    pub ground: Ground,
    /// Boxes, cylinders, spheres and walls.
    pub objects: Vec<Object>,
    /// People standing in the world.
    pub people: Vec<Person>,
    /// Models of a Gazebo SDF world (empty for TOML worlds).
    pub models: Vec<Model>,
    /// The direction sunlight travels (world frame, unit): from a Gazebo world's directional
    /// light (`model://sun`'s is (-0.5, 0.1, -0.9)), else [`DEFAULT_SUN_DIRECTION`].
    pub sun_direction: [f64; 3],
    /// Where the world is on the Earth (`<spherical_coordinates>`, `[spherical_coordinates]`):
    /// what a Gazebo GPS sensor reads.
    pub spherical_coordinates: SphericalCoordinates,
}

/// The world's place on WGS-84, as SDF's `<spherical_coordinates>` gives it (surface model
/// `EARTH_WGS84`): the world's origin at `latitude_deg`, `longitude_deg` and `elevation_m`,
/// its x axis `heading_deg` from east (0: x east, y north, z up, ENU). Gazebo's defaults: all
/// zero.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SphericalCoordinates {
    /// Latitude of the world's origin (deg, north positive).
    pub latitude_deg: f64,
    /// Longitude of the world's origin (deg, east positive).
    pub longitude_deg: f64,
    /// Height of the world's origin above the ellipsoid (m).
    pub elevation_m: f64,
    /// Heading of the world frame (deg): east is `x cos h + y sin h`, north `-x sin h + y cos h`.
    pub heading_deg: f64,
}

/// rover's own sun: late morning, from behind-left of a car facing +x.
pub const DEFAULT_SUN_DIRECTION: [f64; 3] = [0.45, -0.35, -0.82];

/// Robot spawn settings (`[robot]`).
#[derive(Debug, Clone, PartialEq)]
pub struct RobotSpawn {
    /// URDF file, resolved against the world file's folder; `None` = the app's default robot.
    pub urdf: Option<PathBuf>,
    /// Spawn position on the ground (x, y in m).
    pub position_m: [f64; 2],
    /// Spawn heading (rad, counter-clockwise from +x).
    pub yaw_rad: f64,
    /// `xacro_args`: `$(arg NAME)` values when the robot is a xacro file.
    pub xacro_args: std::collections::BTreeMap<String, String>,
    /// `[robot.drive]`: how to drive a robot whose URDF names no drive plugin.
    pub drive: Option<DriveSpec>,
    /// `controllers`: a ros_control controllers YAML for the robot, resolved against the world
    /// file's folder.
    pub controllers: Option<PathBuf>,
    /// `bridge_config`: a ros_gz_bridge topic map (YAML) naming the robot's gz topics on ROS,
    /// resolved against the world file's folder.
    pub bridge_config: Option<PathBuf>,
    /// `camera`: which of the robot's cameras to render, by `<sensor name>` or cameraName
    /// (default: the first).
    pub camera: Option<String>,
    /// `srdf`: a MoveIt SRDF for the robot (resolved against the world file's folder): its
    /// planning group gives the arm's base and end effector, its `<disable_collisions>` the
    /// link pairs the planner does not check against each other.
    pub srdf: Option<PathBuf>,
    /// `arm_group`: which SRDF group is the arm (default: `arm`, else the only group).
    pub arm_group: Option<String>,
    /// `arm_base`: the link the arm's look and reach work from (default: the robot's root).
    pub arm_base: Option<String>,
    /// `ee_link`: the arm's end effector, which reaches.
    pub ee_link: Option<String>,
    /// `grasp`: how the gripper holds what it closes on.
    pub grasp: GraspMode,
    /// `place`: where pick puts what it picked: a world object (dropped on or in it) or a
    /// point (set down there).
    pub place: Option<Place>,
    /// `pick`: the world object pick takes by its known pose (as a MoveIt pick node is given a
    /// collision object), with no camera; `None`: the object of the class the detector sees.
    pub pick: Option<String>,
    /// `fetch`: where (m, x forward and y left in the arm's base frame) the object should be
    /// when the car stops to pick it; set, the pick drives the car: to within reach of what it
    /// sees, then to a world object place. `None`: the pick never moves the base.
    pub fetch: Option<[f64; 2]>,
    /// `pose`: a named pose of the controllers file (`named_poses`) the joints move to as the
    /// world starts, as a launch file's first command would (a head turned to the table).
    pub pose: Option<String>,
}

/// Where pick puts what it picked (`[robot] place`, `--place`).
#[derive(Debug, Clone, PartialEq)]
pub enum Place {
    /// A world object by name (`place = "bin"`): the object is let go a little above its top
    /// (a bin's floor, a tray).
    Object(String),
    /// A point in the world frame (`place = [x, y, z]`, m): the object's bottom centre is set
    /// down there.
    Point([f64; 3]),
}

/// How a gripper holds what it closes on (`[robot] grasp`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GraspMode {
    /// By friction: the fingers squeeze with their capped motor force (the default: nothing
    /// but physics; slip is measured, not hidden).
    #[default]
    Friction,
    /// gazebo_grasp_fix's rule: an object two fingers push on from opposing sides for about a
    /// second is fixed to the palm until the fingers open.
    Assist,
}

/// Physics settings (`[physics]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Physics {
    /// Fixed step rate (Hz).
    pub step_hz: f64,
    /// Gravity (m/s^2, world frame).
    pub gravity_mps2: [f64; 3],
    /// Solver iterations per step.
    pub solver_iterations: usize,
    /// How the robot's moving joints are solved (`joints = "multibody"` or `"impulse"`).
    pub joints: JointSolver,
    /// How stiff contacts between moving bodies are: the natural frequency of rapier's soft
    /// contact constraint (Hz; default [`DEFAULT_CONTACT_HZ`], rapier's). A spring whose
    /// stiffness is the bodies' effective mass times (2 pi contact_hz)^2: at 30 Hz, 5 N squeezes
    /// a 50 g ball ~5 mm between two fingers; a grasping world may want it stiffer.
    pub contact_hz: f64,
}

/// Rapier's natural frequency for contacts between moving bodies (Hz).
pub const DEFAULT_CONTACT_HZ: f64 = 30.0;

/// How a robot's moving joints are solved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointSolver {
    /// Reduced coordinates: rapier's multibody joints.
    Multibody,
    /// Constraints between pairs of bodies: rapier's impulse joints (the default).
    #[default]
    Impulse,
}

/// The ground (`[ground]`): a flat square centred on the origin, top at z = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Ground {
    /// Side lengths along x and y (m).
    pub size_m: [f64; 2],
    /// Friction coefficient.
    pub friction: f32,
    /// Main colour.
    pub color: Rgba,
    /// Second colour of the checker texture.
    pub checker_color: Rgba,
    /// Checker square size (m).
    pub checker_size_m: f64,
}

/// A static or dynamic object.
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    /// Name (unique within the world).
    pub name: String,
    /// Shape, centred on `position_m` (world TOML makes boxes, cylinders along z and
    /// spheres).
    pub shape: Shape,
    /// Centre position (m, world frame).
    pub position_m: [f64; 3],
    /// Heading about +z (rad).
    pub yaw_rad: f64,
    /// Colour.
    pub color: Rgba,
    /// Mass (kg); `None` for a static object.
    pub mass_kg: Option<f64>,
    /// Friction coefficient.
    pub friction: f32,
    /// The COCO class it is (`class = "..."`); `None`: unlabelled.
    pub class: Option<String>,
}

/// Physics step rates rover accepts (Hz), from world files and `--physics-hz` alike.
pub const STEP_HZ_RANGE: std::ops::RangeInclusive<f64> = 50.0..=10_000.0;

/// Checks a physics step rate against [`STEP_HZ_RANGE`]; the error says what was expected.
pub fn check_step_hz(step_hz: f64) -> std::result::Result<(), String> {
    if step_hz.is_finite() && STEP_HZ_RANGE.contains(&step_hz) {
        Ok(())
    } else {
        Err(format!(
            "expected a physics step rate of {}..={} Hz (default {DEFAULT_STEP_HZ}), found {step_hz}",
            STEP_HZ_RANGE.start(),
            STEP_HZ_RANGE.end()
        ))
    }
}

impl Object {
    /// Where the object's centre is, turned by its yaw.
    pub fn world_from_object(&self) -> Pose {
        pose_from_position_yaw(self.position_m, self.yaw_rad)
    }
}

/// A model of an SDF world: rigid links with their shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// Model name (`<model name>` or the `<include><name>`).
    pub name: String,
    /// `<static>`: fixed in the world whatever its links' masses.
    pub is_static: bool,
    /// Where the model's frame is (world frame).
    pub world_from_model: Pose,
    /// Links, each a rigid body.
    pub links: Vec<ModelLink>,
    /// The COCO class it is: from [`MODEL_CLASSES`](crate::model::classes::MODEL_CLASSES) by
    /// its `model://` name (or its own name); `None`: unlabelled.
    pub class: Option<String>,
    /// Only the part of the model at least this high in its own frame is labelled (m), as
    /// COCO boxes a stop sign's face and not its pole ([`MODEL_LABEL_PARTS`](crate::model::classes::MODEL_LABEL_PARTS));
    /// `None`: all of it.
    pub label_above_m: Option<f32>,
}

/// One link of a [`Model`].
#[derive(Debug, Clone, PartialEq)]
pub struct ModelLink {
    /// Link name.
    pub name: String,
    /// Where the link starts (world frame).
    pub world_from_link: Pose,
    /// `<inertial><mass>` (kg); `None` when the link gives none.
    pub mass_kg: Option<f64>,
    /// Visual shapes in the link frame.
    pub visuals: Vec<Visual>,
    /// Collision shapes in the link frame.
    pub collisions: Vec<Collision>,
}

impl ModelLink {
    /// Whether physics moves this link (its model is not static and it has a mass).
    pub fn is_dynamic(&self, model: &Model) -> bool {
        !model.is_static && self.mass_kg.is_some_and(|m| m > 0.0)
    }
}
