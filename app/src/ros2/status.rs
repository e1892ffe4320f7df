//! `/rover/status` (std_msgs/msg/String) on ROS 2.

use anyhow::Result;

use super::sinks::{Out, Sinks};
use crate::bridge::status::{STATUS_TOPIC, StatusWire};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// `/rover/status`.
pub(super) struct Status {
    out: Out<msgs::Text>,
    msg: msgs::Text,
}

impl Status {
    /// Creates `/rover/status` on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>) -> Result<Self> {
        Ok(Self {
            out: sinks.out(STATUS_TOPIC, &default_qos())?,
            msg: msgs::Text::default(),
        })
    }
}

impl StatusWire for Status {
    fn status(&mut self, stamp_s: f64, text: &str) {
        self.msg.data.clear();
        self.msg.data.push_str(text);
        self.out.put(Time::from_secs(stamp_s), &self.msg);
    }
}
