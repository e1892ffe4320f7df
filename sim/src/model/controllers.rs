//! A ros_control controllers file as rover runs it: which controller drives which joint, with
//! what gains and tolerances, and the robot's named poses. `description::controllers` reads
//! it from YAML; `physics::controllers` runs it.

use std::path::PathBuf;

use crate::model::actuation::Pid;

/// The controllers of one robot (`--controllers FILE.yaml`, `controllers = "..."` in a world's
/// `[robot]`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ControllerConfig {
    /// The file it was read from (for messages).
    pub source: PathBuf,
    /// The controllers, in file order.
    pub controllers: Vec<ControllerSpec>,
    /// `gazebo_ros_control/pid_gains/<joint>`: gains for joints driven through a position
    /// interface (in Gazebo, without them the joint is set kinematically; rover holds it with
    /// its own gains either way).
    pub pid_gains: Vec<(String, Pid)>,
    /// `named_poses/<name>/<joint>: position` (a rover addition, like an SRDF group state):
    /// poses the driver's station and scripts can ask for by name, such as "home".
    pub named_poses: Vec<NamedPose>,
}

impl ControllerConfig {
    /// The controller named `name` (its name without the namespace).
    pub fn controller(&self, name: &str) -> Option<&ControllerSpec> {
        self.controllers.iter().find(|c| c.name == name)
    }

    /// The first gripper controller (file order): its name and settings. The grasp assist,
    /// pick and `rover bench physics --hold` use it.
    pub fn first_gripper(&self) -> Option<(&str, &GripperSpec)> {
        self.controllers.iter().find_map(|c| match &c.kind {
            ControllerKind::Gripper(g) => Some((c.name.as_str(), g)),
            _ => None,
        })
    }

    /// The pose named `name`.
    pub fn named_pose(&self, name: &str) -> Option<&NamedPose> {
        self.named_poses.iter().find(|p| p.name == name)
    }
}

/// A named set of joint positions.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedPose {
    /// The pose's name.
    pub name: String,
    /// Joint name and position (rad or m), in file order.
    pub joints: Vec<(String, f64)>,
}

/// One controller.
#[derive(Debug, Clone, PartialEq)]
pub struct ControllerSpec {
    /// Its name (the YAML key): topics live under `<namespace>/<name>/`.
    pub name: String,
    /// The YAML namespace it was written under (`arm` for `arm: {my_controller: ...}`; empty
    /// at the top level).
    pub namespace: String,
    /// Its `type`, as written (`effort_controllers/JointPositionController`).
    pub type_name: String,
    /// What it does.
    pub kind: ControllerKind,
    /// Line of its key in the file.
    pub line: u32,
    /// gz-sim's joint controller systems: the command `<topic>` (std_msgs/Float64, or
    /// trajectory_msgs/JointTrajectory for a trajectory), no state topic. `None`: ros_control's
    /// `<namespace>/<name>/command`.
    pub topic: Option<String>,
}

impl ControllerSpec {
    /// The joints it drives (none for a joint state controller).
    pub fn joints(&self) -> &[String] {
        self.kind.joints()
    }
}

/// What a controller does.
#[derive(Debug, Clone, PartialEq)]
pub enum ControllerKind {
    /// `joint_state_controller/JointStateController`: publishes `/joint_states`.
    JointState {
        /// `publish_rate` (Hz).
        publish_rate_hz: f64,
    },
    /// A single-joint controller with a `command` topic (std_msgs/Float64).
    Joint {
        /// `joint`.
        joint: String,
        /// What the command means.
        command: CommandKind,
    },
    /// `position_controllers/JointTrajectoryController` or `effort_controllers/...`: follows
    /// trajectory_msgs/JointTrajectory messages.
    Trajectory(TrajectorySpec),
    /// `position_controllers/GripperActionController` or `effort_controllers/...`: a gripper's
    /// finger joint, commanded as control_msgs/GripperCommand (a position and the most effort);
    /// the joints that `<mimic>` it follow.
    Gripper(GripperSpec),
}

impl ControllerKind {
    /// The joints it drives (none for a joint state controller).
    pub fn joints(&self) -> &[String] {
        match self {
            Self::JointState { .. } => &[],
            Self::Joint { joint, .. } => std::slice::from_ref(joint),
            Self::Trajectory(t) => &t.joints,
            Self::Gripper(g) => std::slice::from_ref(&g.joint),
        }
    }
}

/// What a single-joint controller's command is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CommandKind {
    /// `effort_controllers/JointPositionController`: a position reached with these gains.
    PositionPid(Pid),
    /// `position_controllers/JointPositionController`: a position, reached with rover's hold
    /// (Gazebo would set it kinematically).
    Position,
    /// `velocity_controllers/JointVelocityController` (and `effort_controllers/...`): a
    /// velocity.
    Velocity,
    /// `effort_controllers/JointEffortController`: an effort, forwarded.
    Effort,
}

/// A joint trajectory controller.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectorySpec {
    /// `joints`, in order.
    pub joints: Vec<String>,
    /// `gains/<joint>` (required by the effort variant), in `joints` order; `None`: rover's
    /// hold gains.
    pub gains: Option<Vec<Pid>>,
    /// `constraints`.
    pub constraints: TrajectoryConstraints,
    /// `state_publish_rate` (Hz, default 50).
    pub state_publish_rate_hz: f64,
}

/// `constraints` of a joint trajectory controller. A tolerance of 0 is not checked, as in
/// ros_control.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryConstraints {
    /// `goal_time` (s): how long after the last point the goal tolerances may take to be met.
    pub goal_time_s: f64,
    /// `stopped_velocity_tolerance` (rad/s or m/s; default 0.01).
    pub stopped_velocity_tolerance: f64,
    /// `<joint>/trajectory`: the largest position error while the trajectory runs, in `joints`
    /// order.
    pub trajectory: Vec<f64>,
    /// `<joint>/goal`: the largest position error at the end, in `joints` order.
    pub goal: Vec<f64>,
}

/// A gripper action controller (ros_control's gripper_action_controller): one finger joint, the
/// others mimicking it.
#[derive(Debug, Clone, PartialEq)]
pub struct GripperSpec {
    /// `joint`: the finger joint commanded.
    pub joint: String,
    /// `goal_tolerance` (m or rad; default 0.01): within it the goal is reached.
    pub goal_tolerance: f64,
    /// `stalled_velocity_threshold` (m/s or rad/s; default 0.001): slower than this, the
    /// fingers are not moving.
    pub stalled_velocity_threshold: f64,
    /// `stall_timeout` (s; default 1.0): not moving this long short of the goal is a stall.
    pub stall_timeout_s: f64,
    /// `allow_stalling` (default false, as ROS 1's controller): a stall ends the goal
    /// succeeded rather than aborted (a grasp that closes on an object).
    pub allow_stalling: bool,
    /// `gains/<joint>` (the effort variant's position loop, its output capped by the goal's
    /// `max_effort`); `None`: rover's hold gains.
    pub gains: Option<Pid>,
}
