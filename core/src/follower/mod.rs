//! The person follower: turns darknet_ros-style detections (and, when the robot has one, 2D laser
//! scans) into cmd_vel. docs/FOLLOWER.md describes it for users.
//!
//! - **Target**: a person of the configured class, picked as the nearest and then kept: each
//!   detection is placed in the odometry frame (range from the box height, or from where the feet
//!   meet the ground when the box is cut off at the top; the robot's pose at the image's time) and
//!   associated with the target when it falls inside a gate around the target's prediction.
//! - **Estimator**: a constant-velocity Kalman filter ([`TargetFilter`]) on the target's position
//!   and velocity, fed by the camera and by laser returns around the prediction (the laser keeps
//!   a close target whose head the low camera cannot see). Its prediction leads moving targets,
//!   centres the gate and aims the search.
//! - **States** ([`FollowState`]): TRACKING (seen lately: steer to centre it, regulate the range
//!   to the standoff, calm inside a deadband), PURSUING (lost: drive to the standoff from where
//!   the track last was, predicted with its velocity for a bounded time, and look there; a close
//!   standing target the camera cannot see whole is finished on the track), SEARCHING (nothing
//!   there on arrival: turn toward the prediction, then sweep; never drives), STALE (detector
//!   messages stopped: stop), NO DETECTOR, WAITING (nothing heard yet).
//! - **Obstacles**: with a laser, commands whose arcs come near a return are replaced by the best
//!   free arc toward the target ([`AvoidConfig::choose`]). Without a laser the follower cannot see obstacles.
//!
//! Pure library code on sim time: no threads, no clocks, no UI, no allocation per update once
//! the buffers have grown.

mod avoid;
mod config;
mod control;
mod filter;
mod measure;
mod state;
mod target;
mod track;
mod tuning;

pub use avoid::{AvoidConfig, Avoided};
pub use config::{CameraGeometry, FollowerConfig, LaserMount, range_bearing_from};
pub use filter::TargetFilter;
pub use state::Follower;
pub use target::{FollowState, FollowTarget};

#[cfg(test)]
#[allow(
    clippy::expect_used,
    reason = "tests: a failed expect is a failed test"
)]
mod tests;
