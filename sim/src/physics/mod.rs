//! Physics: the rapier scene built from the model (`build.rs`), stepped at a fixed rate
//! (`simulation.rs`), the wheels driven by gazebo_ros_diff_drive's controller
//! (`diff_drive.rs`); the robot's joints (`joints.rs`), their actuators (`actuators.rs`) and
//! the ros_control controllers that command them (`controllers.rs`) and the trajectories
//! their trajectory controllers take (`trajectory.rs`: the one check of a trajectory).

pub(crate) mod actuators;
pub(crate) mod build;
pub(crate) mod contact_springs;
pub(crate) mod contacts;
pub(crate) mod controllers;
pub(crate) mod diff_drive;
pub(crate) mod grasp;
pub(crate) mod grip_friction;
pub(crate) mod hull;
pub(crate) mod joints;
pub(crate) mod placement;
pub(crate) mod simulation;
pub(crate) mod states;
pub(crate) mod trajectory;

pub use actuators::{
    HOLD_BANDWIDTH_HZ, HOLD_FRICTION_ERROR, HOLD_INTEGRAL_S, JointCommand, JointState,
};
pub use contacts::LinkContact;
pub use controllers::{ControllerCommandState, GripperState, TrajectoryOutcome, TrajectoryState};
pub use diff_drive::{
    DiffDriveController, EncoderOdometry, ODOM_POSE_COVARIANCE_DIAGONAL, Odometry, Twist,
    WheelSpeeds, wrap_angle,
};
pub use grasp::Grasped;
pub use placement::PersonLook;
pub use simulation::{ControlSample, SimOptions, Simulation};
pub use states::ModelState;
pub use trajectory::{JointTrajectory, TrajectoryError, TrajectoryPoint};
