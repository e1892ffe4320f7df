//! The IMUs' readings: sensor_msgs/Imu on each IMU's topic, in its `frameName`, at its rate.

use rover_sim::sensors::ImuReading;

use super::events::TopicFamily;

/// The IMU topics on one transport, one per IMU in the plan's order.
pub(crate) trait ImuWire: Send {
    /// Publishes `reading` on its IMU's topic.
    fn imu(&mut self, reading: &ImuReading);
}

/// The IMU family.
pub(crate) struct Imu {
    wire: Box<dyn ImuWire>,
}

impl Imu {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn ImuWire>) -> Self {
        Self { wire }
    }
}

impl TopicFamily for Imu {
    fn imu(&mut self, reading: &ImuReading) {
        self.wire.imu(reading);
    }
}
