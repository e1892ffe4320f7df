//! The IMUs' readings (sensor_msgs/Imu) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::sensors::ImuReading;

use crate::bridge::RosPlan;
use crate::bridge::diagonal;
use crate::bridge::imu::ImuWire;

/// One publisher and message per IMU, in the plan's order.
pub(super) struct Imu {
    topics: Vec<(Publisher<msgs::Imu>, msgs::Imu)>,
}

impl Imu {
    /// Advertises each IMU's topic.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let topics = plan
            .imus
            .iter()
            .map(|(topic, frame)| {
                let mut msg = msgs::Imu::default();
                msg.header.frame_id = frame.clone();
                Ok((node.advertise(topic, 100, false)?, msg))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl ImuWire for Imu {
    fn imu(&mut self, r: &ImuReading) {
        let Some((publisher, msg)) = self.topics.get_mut(r.sensor) else {
            return;
        };
        msg.header.seq = r.seq as u32;
        msg.header.stamp_s = r.stamp_s;
        let [x, y, z, w] = r.orientation_xyzw;
        msg.orientation = msgs::Quaternion { x, y, z, w };
        msg.angular_velocity = r.angular_velocity_radps.into();
        msg.linear_acceleration = r.linear_acceleration_mps2.into();
        let c = diagonal([r.covariance_diagonal; 3]);
        msg.orientation_covariance = c;
        msg.angular_velocity_covariance = c;
        msg.linear_acceleration_covariance = c;
        publisher.publish(msg);
    }
}
