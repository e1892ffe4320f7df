//! The diff drive's odometry (nav_msgs/msg/Odometry) on ROS 2.

use anyhow::Result;
use rover_sim::physics::ODOM_POSE_COVARIANCE_DIAGONAL;

use super::sinks::{Out, Sinks, header};
use crate::bridge::odom::{OdomSample, OdomWire};
use crate::bridge::{RosPlan, diagonal};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Covariance, Time};

/// The odometry topic.
pub(super) struct Odom {
    out: Out<msgs::Odometry>,
    msg: msgs::Odometry,
}

impl Odom {
    /// Creates the plan's odometry topic on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let cov = diagonal(ODOM_POSE_COVARIANCE_DIAGONAL);
        let mut msg = msgs::Odometry {
            header: header(&plan.odom_frame),
            child_frame_id: plan.base_frame.clone(),
            ..msgs::Odometry::default()
        };
        msg.pose.covariance = Covariance(cov);
        msg.twist.covariance = Covariance(cov);
        Ok(Self {
            out: sinks.out(&plan.odom_topic, &default_qos())?,
            msg,
        })
    }
}

impl OdomWire for Odom {
    fn odom(&mut self, odom: &OdomSample) {
        let msg = &mut self.msg;
        msg.header.stamp = Time::from_secs(odom.stamp_s);
        let [x, y, z] = odom.position;
        msg.pose.pose.position = msgs::Vector3 { x, y, z };
        let [x, y, z, w] = odom.orientation;
        msg.pose.pose.orientation = msgs::Quaternion { x, y, z, w };
        msg.twist.twist.linear.x = odom.linear_mps;
        msg.twist.twist.angular.z = odom.angular_radps;
        self.out.put(msg.header.stamp, msg);
    }
}
