//! `/tf` and the latched `/tf_static` (tf2_msgs/TFMessage) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs::{self, Quaternion, TransformStamped, Vector3};
use rover_ros1::{Node, Publisher};

use crate::bridge::events::Transform;
use crate::bridge::tf::TfWire;

/// `/tf` and `/tf_static`'s publishers.
pub(super) struct Tf {
    tf: Publisher<msgs::TfMessage>,
    tf_static: Publisher<msgs::TfMessage>,
    msg: msgs::TfMessage,
}

impl Tf {
    /// Advertises `/tf` and `/tf_static`.
    pub fn advertise(node: &Node) -> Result<Self> {
        Ok(Self {
            tf: node.advertise("/tf", 100, false)?,
            tf_static: node.advertise("/tf_static", 10, true)?,
            msg: msgs::TfMessage::default(),
        })
    }
}

/// `t` stamped `stamp_s`, into `out` (its strings keep their capacity).
fn fill(out: &mut TransformStamped, t: &Transform, stamp_s: f64) {
    out.header.stamp_s = stamp_s;
    out.header.frame_id.clone_from(&t.parent);
    out.child_frame_id.clone_from(&t.child);
    let [x, y, z] = t.translation;
    out.translation = Vector3 { x, y, z };
    let [x, y, z, w] = t.rotation;
    out.rotation = Quaternion { x, y, z, w };
}

/// `transforms` as a message, reusing `msg`.
fn message<'a>(
    msg: &'a mut msgs::TfMessage,
    transforms: &[Transform],
    stamp_s: f64,
) -> &'a msgs::TfMessage {
    msg.transforms
        .resize_with(transforms.len(), TransformStamped::default);
    for (out, t) in msg.transforms.iter_mut().zip(transforms) {
        fill(out, t, stamp_s);
    }
    msg
}

impl TfWire for Tf {
    fn tf_static(&mut self, transforms: &[Transform]) {
        let mut msg = msgs::TfMessage::default();
        self.tf_static.publish(message(&mut msg, transforms, 0.0));
    }

    fn tf(&mut self, stamp_s: f64, transforms: &[Transform]) {
        let msg = message(&mut self.msg, transforms, stamp_s);
        self.tf.publish(msg);
    }
}
