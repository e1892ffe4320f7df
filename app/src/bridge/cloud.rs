//! Point clouds (sensor_msgs/PointCloud2): each 3D lidar's on its `topicName`, in its
//! `frameName`, at its rate (x y z intensity ring); a depth camera's organized cloud on
//! `/<cameraName>/<pointCloudTopicName>` in its optical frame, with every depth image (x y z
//! rgb). The points go out as the sensors lay them down, without a copy.

use rover_msgs::PointField;
use rover_sim::sensors::{CloudLayout, CloudSource, PointCloud};

use super::RosPlan;
use super::events::TopicFamily;

/// The cloud topics on one transport, one per entry of [`topics`], in that order.
pub(crate) trait CloudWire: Send {
    /// Publishes `cloud` on topic number `topic` (its data may be lent to the message and
    /// stays with the cloud).
    fn cloud(&mut self, topic: usize, cloud: &mut PointCloud);
}

/// The plan's cloud topics: each lidar's (`RobotModel::lidars` order), then the depth
/// camera's.
pub(crate) fn topics(plan: &RosPlan) -> impl Iterator<Item = &str> {
    plan.lidar_topics
        .iter()
        .map(String::as_str)
        .chain(plan.depth_cloud_topic.as_deref())
}

/// The cloud family.
pub(crate) struct Clouds {
    wire: Box<dyn CloudWire>,
    lidars: usize,
    depth: bool,
}

impl Clouds {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn CloudWire>, plan: &RosPlan) -> Self {
        Self {
            wire,
            lidars: plan.lidar_topics.len(),
            depth: plan.depth_cloud_topic.is_some(),
        }
    }
}

impl TopicFamily for Clouds {
    fn cloud(&mut self, cloud: &mut PointCloud) {
        let topic = match cloud.source {
            CloudSource::Lidar(n) if n < self.lidars => n,
            CloudSource::DepthCamera if self.depth => self.lidars,
            _ => return,
        };
        self.wire.cloud(topic, cloud);
    }
}

/// The message's field list for clouds laid out as `layout`.
pub(crate) fn point_fields(layout: CloudLayout) -> Vec<PointField> {
    layout
        .fields()
        .iter()
        .map(|f| PointField {
            name: f.name.to_owned(),
            offset: f.offset_bytes,
            datatype: f.datatype,
            count: f.count,
        })
        .collect()
}
