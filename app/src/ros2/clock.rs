//! `/clock` (rosgraph_msgs/msg/Clock) on ROS 2.

use anyhow::Result;

use super::sinks::{Out, Sinks};
use crate::bridge::clock::ClockWire;
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// `/clock`'s topic.
pub(super) struct Clock {
    out: Out<msgs::Clock>,
}

impl Clock {
    /// Creates `/clock` on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>) -> Result<Self> {
        Ok(Self {
            out: sinks.out("/clock", &default_qos())?,
        })
    }
}

impl ClockWire for Clock {
    fn clock(&mut self, sim_time_s: f64) {
        let stamp = Time::from_secs(sim_time_s);
        self.out.put(stamp, &msgs::Clock { clock: stamp });
    }
}
