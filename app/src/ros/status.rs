//! `/rover/status` (std_msgs/String) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use crate::bridge::status::{STATUS_TOPIC, StatusWire};

/// `/rover/status`'s publisher.
pub(super) struct Status {
    publisher: Publisher<msgs::Text>,
    msg: msgs::Text,
}

impl Status {
    /// Advertises `/rover/status`.
    pub fn advertise(node: &Node) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise(STATUS_TOPIC, 10, false)?,
            msg: msgs::Text::default(),
        })
    }
}

impl StatusWire for Status {
    fn status(&mut self, _stamp_s: f64, text: &str) {
        self.msg.data.clear();
        self.msg.data.push_str(text);
        self.publisher.publish(&self.msg);
    }
}
