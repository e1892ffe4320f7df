//! Physics: the rapier scene built from the model (`build.rs`), stepped at a fixed rate
//! (`simulation.rs`), the wheels driven by gazebo_ros_diff_drive's controller
//! (`diff_drive.rs`). Joint controllers go beside the diff drive.

pub(crate) mod actuators;
pub(crate) mod build;
pub(crate) mod diff_drive;
pub(crate) mod joints;
pub(crate) mod simulation;

pub use actuators::{
    HOLD_BANDWIDTH_HZ, HOLD_FRICTION_ERROR, HOLD_INTEGRAL_S, JointCommand, JointState,
};
pub use diff_drive::{
    DiffDriveController, EncoderOdometry, ODOM_POSE_COVARIANCE_DIAGONAL, Odometry, Twist,
    WheelSpeeds, wrap_angle,
};
pub use simulation::{ControlSample, SimOptions, Simulation};
