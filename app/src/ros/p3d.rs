//! p3d's ground truth (nav_msgs/Odometry) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs::{self, Quaternion};
use rover_ros1::{Node, Publisher};
use rover_sim::sensors::PoseReading;

use super::convert::header;
use crate::bridge::p3d::P3dWire;
use crate::bridge::{RosPlan, diagonal};

/// One publisher and message per p3d plugin, in the plan's order.
pub(super) struct P3d {
    topics: Vec<(Publisher<msgs::Odometry>, msgs::Odometry)>,
}

impl P3d {
    /// Advertises each plugin's topic.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let topics = plan
            .p3ds
            .iter()
            .map(|t| {
                let msg = msgs::Odometry {
                    header: header(&t.frame),
                    child_frame_id: t.child_frame.clone(),
                    position: msgs::Vector3::default(),
                    orientation: Quaternion::default(),
                    pose_covariance: [0.0; 36],
                    linear: msgs::Vector3::default(),
                    angular: msgs::Vector3::default(),
                    twist_covariance: [0.0; 36],
                };
                Ok((node.advertise(&t.topic, 50, false)?, msg))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl P3dWire for P3d {
    fn p3d(&mut self, r: &PoseReading) {
        let Some((publisher, msg)) = self.topics.get_mut(r.sensor) else {
            return;
        };
        msg.header.seq = r.seq as u32;
        msg.header.stamp_s = r.stamp_s;
        msg.position = r.position_m.into();
        let [x, y, z, w] = r.orientation_xyzw;
        msg.orientation = Quaternion { x, y, z, w };
        msg.linear = r.linear_mps.into();
        msg.angular = r.angular_radps.into();
        let c = diagonal([r.covariance_diagonal; 6]);
        msg.pose_covariance = c;
        msg.twist_covariance = c;
        publisher.publish(msg);
    }
}
