//! The diff drive's odometry (nav_msgs/Odometry on `odometryTopic`), every control update, with
//! gazebo_ros_diff_drive's covariance.

use anyhow::Result;
use rover_ros1::msgs::{self, Quaternion, Vector3};
use rover_ros1::{Node, Publisher};
use rover_sim::{ControlSample, ODOM_POSE_COVARIANCE_DIAGONAL};

use super::convert::{header, seq_of};
use super::events::{ControlUpdate, TopicFamily};
use super::plan::RosPlan;

/// Publishes the odometry topic.
pub(super) struct Odom {
    publisher: Publisher<msgs::Odometry>,
    msg: msgs::Odometry,
}

/// A 6x6 row-major covariance with `diagonal` on its diagonal.
fn covariance(diagonal: [f64; 6]) -> [f64; 36] {
    let mut c = [0.0; 36];
    for (i, d) in diagonal.iter().enumerate() {
        c[i * 7] = *d;
    }
    c
}

impl Odom {
    /// Advertises the plan's odometry topic.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let cov = covariance(ODOM_POSE_COVARIANCE_DIAGONAL);
        Ok(Self {
            publisher: node.advertise(&plan.odom_topic, 50, false)?,
            msg: msgs::Odometry {
                header: header(&plan.odom_frame),
                child_frame_id: plan.base_frame.clone(),
                position: Vector3::default(),
                orientation: Quaternion::default(),
                pose_covariance: cov,
                linear: Vector3::default(),
                angular: Vector3::default(),
                twist_covariance: cov,
            },
        })
    }
}

/// The base's pose in the odometry frame as /odom and /tf's odom -> base carry it, on either
/// transport: position (x, y, z in m) and orientation (a unit quaternion x, y, z, w). With
/// `odometrySource` world that is the base's full pose, height and tilt included, as
/// gazebo_ros_diff_drive publishes the model's world pose; with encoder it is planar.
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

/// [`odom_pose`] as ROS 1's message types (the odometry's pose and /tf's odom -> base).
pub(super) fn odom_pose_msg(sample: &ControlSample) -> (Vector3, Quaternion) {
    let ([x, y, z], [qx, qy, qz, qw]) = odom_pose(sample);
    let rotation = Quaternion {
        x: qx,
        y: qy,
        z: qz,
        w: qw,
    };
    (Vector3 { x, y, z }, rotation)
}

impl TopicFamily for Odom {
    fn control(&mut self, update: &ControlUpdate) {
        let o = update.sample.odometry;
        let msg = &mut self.msg;
        msg.header.seq = seq_of(&self.publisher);
        msg.header.stamp_s = update.sample.sim_time_s;
        (msg.position, msg.orientation) = odom_pose_msg(&update.sample);
        msg.linear.x = o.linear_mps;
        msg.angular.z = o.angular_radps;
        self.publisher.publish(msg);
    }
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
