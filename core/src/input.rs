//! What drives the loop from outside: an [`Action`] (a script step, a key, a gamepad command,
//! ROS `/cmd_vel`), and [`InputSource`], polled for actions before every physics step.

use rover_sim::physics::{JointCommand, JointTrajectory, Twist};

use crate::teleop::KeyAction;

/// One user input. `Clone`, not `Copy`, so that an input kind may carry data (say, a list of
/// joint targets).
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Publish a velocity command.
    CmdVel(Twist),
    /// Press a teleop key.
    Key(KeyAction),
    /// Flip between manual and follow mode.
    ToggleFollow,
    /// Switch the arm's look on or off (the camera's chain turns to the class's box).
    ToggleLook,
    /// Switch the arm's reach on or off (the tool goes to a pre-grasp point short of the
    /// class's object; the camera looks at it when its chain is not the arm's).
    ToggleReach,
    /// Switch the arm's pick and place on or off (the gripper picks the class's object up and
    /// puts it on the place).
    TogglePick,
    /// Set the arm's task (off, look, reach, pick): what ROS's `/rover/arm/task` asks for.
    Arm(crate::arm::ArmMode),
    /// Move the robot's joints (the arm); the base's mode does not change.
    Joint(JointAction),
}

/// An input for the robot's joints: from a script, the driver's station, or a controller's
/// topic over ROS.
#[derive(Debug, Clone, PartialEq)]
pub enum JointAction {
    /// Command one actuated joint by name.
    Command {
        /// Joint name.
        joint: String,
        /// What it should do.
        command: JointCommand,
    },
    /// A single-joint controller's command (what its `command` topic carries).
    Controller {
        /// Controller name.
        name: String,
        /// Position, velocity or effort, per the controller's type.
        value: f64,
    },
    /// A trajectory for a joint trajectory controller.
    Trajectory {
        /// Controller name.
        controller: String,
        /// The trajectory.
        trajectory: Box<JointTrajectory>,
    },
    /// A gripper controller's command (control_msgs/GripperCommand).
    Gripper {
        /// Controller name.
        controller: String,
        /// The finger joint's position (m or rad).
        position: f64,
        /// The most effort the fingers may use (N or N m); 0 or less: the joints' limit.
        max_effort: f64,
    },
    /// Go to a named pose of the controllers file.
    Pose(String),
    /// The arm's end effector (`--ee-link`) to a point in the arm base's frame (m, REP-103),
    /// by IK; with `relative`, moved by that much from where the joints' targets put it
    /// (Cartesian jogging: quick steps add up).
    Tool {
        /// The point, or the step (m).
        position_m: [f64; 3],
        /// A step from the current target rather than a point.
        relative: bool,
    },
}

/// Input from outside the loop that drives it like manual input: the ROS bridge's `/cmd_vel`.
/// Polled before every physics step; it must not block.
pub trait InputSource {
    /// The next input waiting, if any.
    fn poll(&mut self) -> Option<Action>;
}

/// No outside input.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoInput;

impl InputSource for NoInput {
    fn poll(&mut self) -> Option<Action> {
        None
    }
}
