//! `/clock` (rosgraph_msgs/Clock): sim time, every control update.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use super::events::{ControlUpdate, TopicFamily};
use super::plan::RosPlan;

/// Publishes `/clock`.
pub(super) struct Clock {
    publisher: Publisher<msgs::Clock>,
    msg: msgs::Clock,
}

impl Clock {
    /// Advertises `/clock`.
    pub fn advertise(node: &Node, _plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise("/clock", 10, false)?,
            msg: msgs::Clock::default(),
        })
    }
}

impl TopicFamily for Clock {
    fn control(&mut self, update: &ControlUpdate) {
        self.msg.clock_s = update.sample.sim_time_s;
        self.publisher.publish(&self.msg);
    }
}
