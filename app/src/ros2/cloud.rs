//! The point clouds (sensor_msgs/msg/PointCloud2) on ROS 2, best effort as rclcpp's
//! SensorDataQoS.

use anyhow::Result;
use rover_sim::sensors::PointCloud;

use super::sinks::{Out, Sinks, sensor_qos};
use crate::bridge::RosPlan;
use crate::bridge::cloud::{CloudWire, point_fields, topics};
use rover_ros2::msgs::{self, Header, Lent, Time};

/// One topic per cloud topic, in the plan's order.
pub(super) struct Clouds {
    topics: Vec<Out<msgs::PointCloud2>>,
}

impl Clouds {
    /// Creates each cloud topic on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let topics = topics(plan)
            .map(|topic| sinks.out(topic, &sensor_qos()))
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl CloudWire for Clouds {
    fn cloud(&mut self, topic: usize, cloud: &mut PointCloud) {
        let Some(out) = self.topics.get_mut(topic) else {
            return;
        };
        // The points are lent to the message and come back once it is written.
        let data = Lent::new(std::mem::take(&mut cloud.data));
        let msg = msgs::PointCloud2 {
            header: Header {
                stamp: Time::from_secs(cloud.stamp_s),
                frame_id: std::mem::take(&mut cloud.frame_id),
            },
            height: cloud.height,
            width: cloud.width,
            fields: point_fields(cloud.layout),
            is_bigendian: false,
            point_step: cloud.point_step_bytes(),
            row_step: cloud.row_step_bytes(),
            data: data.clone(),
            is_dense: cloud.is_dense,
        };
        out.put(msg.header.stamp, &msg);
        let msgs::PointCloud2 { header, .. } = msg;
        cloud.frame_id = header.frame_id;
        // A buffer still held elsewhere is let go; the pool makes a new one.
        cloud.data = data.take_back().unwrap_or_default();
    }
}
