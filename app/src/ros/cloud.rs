//! The point clouds (sensor_msgs/PointCloud2) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::sensors::PointCloud;

use crate::bridge::RosPlan;
use crate::bridge::cloud::{CloudWire, point_fields, topics};

/// One publisher and message per cloud topic, in the plan's order.
pub(super) struct Clouds {
    topics: Vec<(Publisher<msgs::PointCloud2>, msgs::PointCloud2)>,
}

impl Clouds {
    /// Advertises each cloud topic.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let topics = topics(plan)
            .map(|topic| {
                Ok((
                    node.advertise(topic, 2, false)?,
                    msgs::PointCloud2::default(),
                ))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl CloudWire for Clouds {
    fn cloud(&mut self, topic: usize, cloud: &mut PointCloud) {
        let Some((publisher, msg)) = self.topics.get_mut(topic) else {
            return;
        };
        msg.header.seq = cloud.seq as u32;
        msg.header.stamp_s = cloud.stamp_s;
        if msg.header.frame_id != cloud.frame_id {
            msg.header.frame_id.clone_from(&cloud.frame_id);
        }
        if msg.fields.is_empty() {
            msg.fields = point_fields(cloud.layout);
        }
        msg.height = cloud.height;
        msg.width = cloud.width;
        msg.is_bigendian = false;
        msg.point_step = cloud.point_step_bytes();
        msg.row_step = cloud.row_step_bytes();
        msg.is_dense = cloud.is_dense;
        // Published from the cloud's buffer, which stays with it.
        std::mem::swap(&mut msg.data, &mut cloud.data);
        publisher.publish(msg);
        std::mem::swap(&mut msg.data, &mut cloud.data);
    }
}
