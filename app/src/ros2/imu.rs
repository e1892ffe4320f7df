//! The IMUs' readings (sensor_msgs/msg/Imu) on ROS 2, best effort as rclcpp's SensorDataQoS
//! (gazebo_ros's IMU plugin publishes with it).

use anyhow::Result;
use rover_sim::sensors::ImuReading;

use super::sinks::{Out, Sinks, sensor_qos};
use crate::bridge::RosPlan;
use crate::bridge::diagonal;
use crate::bridge::imu::ImuWire;
use rover_ros2::msgs::{self, Time};

/// One topic and message per IMU, in the plan's order.
pub(super) struct Imu {
    topics: Vec<(Out<msgs::Imu>, msgs::Imu)>,
}

impl Imu {
    /// Creates each IMU's topic on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let topics = plan
            .imus
            .iter()
            .map(|(topic, frame)| {
                let mut msg = msgs::Imu::default();
                msg.header.frame_id = frame.clone();
                Ok((sinks.out(topic, &sensor_qos())?, msg))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl ImuWire for Imu {
    fn imu(&mut self, r: &ImuReading) {
        let Some((out, msg)) = self.topics.get_mut(r.sensor) else {
            return;
        };
        msg.header.stamp = Time::from_secs(r.stamp_s);
        let [x, y, z, w] = r.orientation_xyzw;
        msg.orientation = msgs::Quaternion { x, y, z, w };
        msg.angular_velocity = r.angular_velocity_radps.into();
        msg.linear_acceleration = r.linear_acceleration_mps2.into();
        let c = diagonal([r.covariance_diagonal; 3]);
        msg.orientation_covariance = c;
        msg.angular_velocity_covariance = c;
        msg.linear_acceleration_covariance = c;
        out.put(msg.header.stamp, msg);
    }
}
