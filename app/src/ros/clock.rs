//! `/clock` (rosgraph_msgs/Clock) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use crate::bridge::clock::ClockWire;

/// `/clock`'s publisher.
pub(super) struct Clock {
    publisher: Publisher<msgs::Clock>,
    msg: msgs::Clock,
}

impl Clock {
    /// Advertises `/clock`.
    pub fn advertise(node: &Node) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise("/clock", 10, false)?,
            msg: msgs::Clock::default(),
        })
    }
}

impl ClockWire for Clock {
    fn clock(&mut self, sim_time_s: f64) {
        self.msg.clock_s = sim_time_s;
        self.publisher.publish(&self.msg);
    }
}
