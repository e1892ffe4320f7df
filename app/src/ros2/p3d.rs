//! p3d's ground truth (nav_msgs/msg/Odometry) on ROS 2, reliable as gazebo_ros publishes it.

use anyhow::Result;
use rover_sim::sensors::PoseReading;

use super::sinks::{Out, Sinks, header};
use crate::bridge::p3d::P3dWire;
use crate::bridge::{RosPlan, diagonal};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Covariance, Time};

/// One topic and message per p3d plugin, in the plan's order.
pub(super) struct P3d {
    topics: Vec<(Out<msgs::Odometry>, msgs::Odometry)>,
}

impl P3d {
    /// Creates each plugin's topic on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let topics = plan
            .p3ds
            .iter()
            .map(|t| {
                let msg = msgs::Odometry {
                    header: header(&t.frame),
                    child_frame_id: t.child_frame.clone(),
                    ..msgs::Odometry::default()
                };
                Ok((sinks.out(&t.topic, &default_qos())?, msg))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl P3dWire for P3d {
    fn p3d(&mut self, r: &PoseReading) {
        let Some((out, msg)) = self.topics.get_mut(r.sensor) else {
            return;
        };
        msg.header.stamp = Time::from_secs(r.stamp_s);
        msg.pose.pose.position = r.position_m.into();
        let [x, y, z, w] = r.orientation_xyzw;
        msg.pose.pose.orientation = msgs::Quaternion { x, y, z, w };
        msg.twist.twist.linear = r.linear_mps.into();
        msg.twist.twist.angular = r.angular_radps.into();
        let c = diagonal([r.covariance_diagonal; 6]);
        msg.pose.covariance = Covariance(c);
        msg.twist.covariance = Covariance(c);
        out.put(msg.header.stamp, msg);
    }
}
