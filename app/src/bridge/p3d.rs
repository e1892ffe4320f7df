//! p3d's ground truth: nav_msgs/Odometry on each `libgazebo_ros_p3d.so`'s topic, `frame_id` its
//! `frameName`, `child_frame_id` its `bodyName`, at its rate.

use rover_sim::sensors::PoseReading;

use super::events::TopicFamily;

/// The p3d topics on one transport, one per plugin in the plan's order.
pub(crate) trait P3dWire: Send {
    /// Publishes `reading` on its plugin's topic.
    fn p3d(&mut self, reading: &PoseReading);
}

/// The p3d family.
pub(crate) struct P3d {
    wire: Box<dyn P3dWire>,
}

impl P3d {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn P3dWire>) -> Self {
        Self { wire }
    }
}

impl TopicFamily for P3d {
    fn p3d(&mut self, reading: &PoseReading) {
        self.wire.p3d(reading);
    }
}
