//! `/rover/status` (std_msgs/String, once a second of sim time): one line a person can read
//! with `rostopic echo` or `ros2 topic echo` to see the run is alive and what the base and the
//! arm are doing: `sim 12.0 s, odom 1.23 -0.40 m 12.3 deg, cmd 0.30 m/s 0.00 rad/s, arm off`.

use std::fmt::Write;

use super::events::{ControlUpdate, TopicFamily};

/// The topic.
pub(crate) const STATUS_TOPIC: &str = "/rover/status";

/// Seconds of sim time between messages.
const PERIOD_S: f64 = 1.0;

/// `/rover/status` on one transport.
pub(crate) trait StatusWire: Send {
    /// Publishes the line.
    fn status(&mut self, stamp_s: f64, text: &str);
}

/// The status family.
pub(crate) struct Status {
    wire: Box<dyn StatusWire>,
    /// Sim time of the next message.
    next_s: f64,
    /// The line, reused.
    text: String,
}

impl Status {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn StatusWire>) -> Self {
        Self {
            wire,
            next_s: 0.0,
            text: String::new(),
        }
    }
}

impl TopicFamily for Status {
    fn control(&mut self, update: &ControlUpdate) {
        let s = &update.sample;
        if s.sim_time_s + 1e-9 < self.next_s {
            return;
        }
        self.next_s = s.sim_time_s + PERIOD_S;
        self.text.clear();
        let _ = write!(
            self.text,
            "sim {:.1} s, odom {:.2} {:.2} m {:.1} deg, cmd {:.2} m/s {:.2} rad/s, arm {}",
            s.sim_time_s,
            s.odometry.x_m,
            s.odometry.y_m,
            s.odometry.yaw_rad.to_degrees(),
            s.cmd.linear_mps,
            s.cmd.angular_radps,
            update.arm.mode.as_str(),
        );
        self.wire.status(s.sim_time_s, &self.text);
    }
}
