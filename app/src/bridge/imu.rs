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

/// The covariance of sensor_msgs/Imu with `diagonal` on its diagonal, as gazebo_ros fills it.
pub(crate) fn covariance(diagonal: f64) -> [f64; 9] {
    let mut c = [0.0; 9];
    c[0] = diagonal;
    c[4] = diagonal;
    c[8] = diagonal;
    c
}
