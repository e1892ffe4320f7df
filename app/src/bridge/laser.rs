//! The first laser's scans (sensor_msgs/LaserScan on its `topicName`, in its `frameName`), at
//! its update rate.

use rover_sim::sensors::LaserScan;

use super::events::TopicFamily;

/// The scan topic on one transport (publishing nothing when the robot has no laser).
pub(crate) trait ScanWire: Send {
    /// Publishes `scan`. Its ranges' buffer may be lent to the message; it stays with the scan.
    fn scan(&mut self, scan: &mut LaserScan);
}

/// The laser family.
pub(crate) struct Laser {
    wire: Box<dyn ScanWire>,
}

impl Laser {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn ScanWire>) -> Self {
        Self { wire }
    }
}

impl TopicFamily for Laser {
    fn scan(&mut self, scan: &mut LaserScan) {
        self.wire.scan(scan);
    }
}
