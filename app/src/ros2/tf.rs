//! `/tf` and `/tf_static` (tf2_msgs/msg/TFMessage; `/tf_static` transient local, keep last 1,
//! as tf2's static broadcaster) on ROS 2.

use anyhow::Result;

use super::sinks::{Out, Sinks, latched_qos};
use crate::bridge::events::Transform;
use crate::bridge::tf::TfWire;
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// `/tf` and `/tf_static`.
pub(super) struct Tf {
    tf: Out<msgs::TfMessage>,
    tf_static: Out<msgs::TfMessage>,
    msg: msgs::TfMessage,
}

impl Tf {
    /// Creates `/tf` and `/tf_static` on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>) -> Result<Self> {
        Ok(Self {
            tf: sinks.out("/tf", &default_qos())?,
            tf_static: sinks.out("/tf_static", &latched_qos())?,
            msg: msgs::TfMessage::default(),
        })
    }
}

/// `transforms` stamped `stamp` into `msg` (its strings keep their capacity).
fn fill(msg: &mut msgs::TfMessage, transforms: &[Transform], stamp: Time) {
    msg.transforms
        .resize_with(transforms.len(), msgs::TransformStamped::default);
    for (out, t) in msg.transforms.iter_mut().zip(transforms) {
        out.header.stamp = stamp;
        out.header.frame_id.clone_from(&t.parent);
        out.child_frame_id.clone_from(&t.child);
        let [x, y, z] = t.translation;
        out.transform.translation = msgs::Vector3 { x, y, z };
        let [x, y, z, w] = t.rotation;
        out.transform.rotation = msgs::Quaternion { x, y, z, w };
    }
}

impl TfWire for Tf {
    fn tf_static(&mut self, transforms: &[Transform]) {
        let mut msg = msgs::TfMessage::default();
        fill(&mut msg, transforms, Time::default());
        self.tf_static.put(Time::default(), &msg);
    }

    fn tf(&mut self, stamp_s: f64, transforms: &[Transform]) {
        let stamp = Time::from_secs(stamp_s);
        fill(&mut self.msg, transforms, stamp);
        self.tf.put(stamp, &self.msg);
    }
}
