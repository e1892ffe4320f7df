//! `/clock` (rosgraph_msgs/Clock): sim time, every control update.

use super::events::{ControlUpdate, TopicFamily};

/// `/clock` on one transport.
pub(crate) trait ClockWire: Send {
    /// Publishes sim time `sim_time_s`.
    fn clock(&mut self, sim_time_s: f64);
}

/// The clock family.
pub(crate) struct Clock {
    wire: Box<dyn ClockWire>,
}

impl Clock {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn ClockWire>) -> Self {
        Self { wire }
    }
}

impl TopicFamily for Clock {
    fn control(&mut self, update: &ControlUpdate) {
        self.wire.clock(update.sample.sim_time_s);
    }
}
