//! hector's GPS: sensor_msgs/NavSatFix on each receiver's `topicName` and its velocity as
//! geometry_msgs/Vector3Stamped on `velocityTopicName`, both in its `frameId`, at its rate.

use rover_sim::sensors::FixReading;

use super::events::TopicFamily;

/// The GPS topics on one transport, one pair per receiver in the plan's order.
pub(crate) trait GpsWire: Send {
    /// Publishes `fix` and its velocity on its receiver's topics.
    fn gps(&mut self, fix: &FixReading);
}

/// The GPS family.
pub(crate) struct Gps {
    wire: Box<dyn GpsWire>,
}

impl Gps {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn GpsWire>) -> Self {
        Self { wire }
    }
}

impl TopicFamily for Gps {
    fn gps(&mut self, fix: &FixReading) {
        self.wire.gps(fix);
    }
}

/// NavSatFix's `position_covariance_type` for a diagonal known (hector's).
pub(crate) const COVARIANCE_TYPE_DIAGONAL_KNOWN: u8 = 2;
