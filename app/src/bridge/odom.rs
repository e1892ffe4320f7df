//! The diff drive's odometry (nav_msgs/Odometry on `odometryTopic`, with
//! gazebo_ros_diff_drive's covariance), every control update, or at gz-sim DiffDrive's
//! `odom_publish_frequency`.

use rover_sim::physics::ControlSample;
use rover_sim::sensors::Schedule;

use super::events::{ControlUpdate, TopicFamily};
use super::plan::RosPlan;

/// The base in the odometry frame at a control update, as /odom carries it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct OdomSample {
    /// Sim time (s).
    pub stamp_s: f64,
    /// Position (m).
    pub position: [f64; 3],
    /// Orientation (unit quaternion x, y, z, w).
    pub orientation: [f64; 4],
    /// Forward speed in the base frame (m/s).
    pub linear_mps: f64,
    /// Turn rate (rad/s).
    pub angular_radps: f64,
}

/// The odometry topic on one transport.
pub(crate) trait OdomWire: Send {
    /// Publishes `odom`.
    fn odom(&mut self, odom: &OdomSample);
}

/// The odometry family.
pub(crate) struct Odom {
    wire: Box<dyn OdomWire>,
    rate: Schedule,
}

impl Odom {
    /// The family on `wire`, at the plan's odometry rate.
    pub fn new(wire: Box<dyn OdomWire>, plan: &RosPlan) -> Self {
        Self {
            wire,
            rate: Schedule::new(plan.odom_rate_hz),
        }
    }
}

impl TopicFamily for Odom {
    fn control(&mut self, update: &ControlUpdate) {
        if !self.rate.take(update.sample.sim_time_s) {
            return;
        }
        let (position, orientation) = odom_pose(&update.sample);
        let o = update.sample.odometry;
        self.wire.odom(&OdomSample {
            stamp_s: update.sample.sim_time_s,
            position,
            orientation,
            linear_mps: o.linear_mps,
            angular_radps: o.angular_radps,
        });
    }
}

/// The base's pose in the odometry frame as /odom and /tf's odom -> base carry it: position
/// (x, y, z in m) and orientation (a unit quaternion x, y, z, w). With `odometrySource` world
/// that is the base's full pose, height and tilt included, as gazebo_ros_diff_drive publishes
/// the model's world pose; with encoder it is planar.
pub(crate) fn odom_pose(sample: &ControlSample) -> ([f64; 3], [f64; 4]) {
    let o = sample.odometry;
    let [z, roll, pitch] = sample.odometry_z_roll_pitch;
    // Roll, then pitch, then yaw (REP-103's fixed-axis x-y-z), as tf's setRPY builds it.
    let (sr, cr) = (roll / 2.0).sin_cos();
    let (sp, cp) = (pitch / 2.0).sin_cos();
    let (sy, cy) = (o.yaw_rad / 2.0).sin_cos();
    let quaternion = [
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    ];
    ([o.x_m, o.y_m, z], quaternion)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_odometry_orientation_is_roll_then_pitch_then_yaw() {
        let mut sample = ControlSample {
            sim_time_s: 0.0,
            ground_truth: Default::default(),
            odometry: Default::default(),
            odometry_z_roll_pitch: [0.05, 0.1, -0.2],
            cmd: Default::default(),
            wheel_targets_radps: [0.0; 2],
            wheel_measured_radps: [0.0; 2],
        };
        sample.odometry.x_m = 1.0;
        sample.odometry.yaw_rad = 2.5;
        let (position, [x, y, z, w]) = odom_pose(&sample);
        assert_eq!(position, [1.0, 0.0, 0.05]);
        let expected = glam::DQuat::from_euler(glam::EulerRot::ZYX, 2.5, -0.2, 0.1);
        let got = glam::DQuat::from_xyzw(x, y, z, w);
        assert!(got.angle_between(expected) < 1e-12, "{got} vs {expected}");
        // Planar odometry (encoder, or level ground) is a rotation about z alone.
        sample.odometry_z_roll_pitch = [0.0; 3];
        let (_, q) = odom_pose(&sample);
        let (s, c) = (1.25_f64).sin_cos();
        assert_eq!(q, [0.0, 0.0, s, c]);
    }
}
