//! The diff drive's odometry (nav_msgs/Odometry on `odometryTopic`) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs::{self, Quaternion, Vector3};
use rover_ros1::{Node, Publisher};
use rover_sim::physics::ODOM_POSE_COVARIANCE_DIAGONAL;

use super::convert::{header, seq_of};
use crate::bridge::odom::{OdomSample, OdomWire};
use crate::bridge::{RosPlan, diagonal};

/// The odometry topic's publisher.
pub(super) struct Odom {
    publisher: Publisher<msgs::Odometry>,
    msg: msgs::Odometry,
}

impl Odom {
    /// Advertises the plan's odometry topic.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let cov = diagonal(ODOM_POSE_COVARIANCE_DIAGONAL);
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

impl OdomWire for Odom {
    fn odom(&mut self, odom: &OdomSample) {
        let msg = &mut self.msg;
        msg.header.seq = seq_of(&self.publisher);
        msg.header.stamp_s = odom.stamp_s;
        let [x, y, z] = odom.position;
        let [qx, qy, qz, qw] = odom.orientation;
        msg.position = Vector3 { x, y, z };
        msg.orientation = Quaternion {
            x: qx,
            y: qy,
            z: qz,
            w: qw,
        };
        msg.linear.x = odom.linear_mps;
        msg.angular.z = odom.angular_radps;
        self.publisher.publish(msg);
    }
}
