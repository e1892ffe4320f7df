//! The arm's look, reach and pick out: `/rover/arm/state` (std_msgs/String, latched, on
//! every change: `off`, `look`, `reach <state>` or `pick <state>`), `/rover/arm/object` and
//! `/rover/arm/goal` (geometry_msgs/PointStamped in the robot's base frame, every control
//! update while reach or pick has them: the object point it goes for and reach's pre-grasp
//! point).
//! The task comes in on `/rover/arm/task` (input.rs).

use rover_core::{ArmMode, PickState, ReachState};

use super::events::{ArmSample, ControlUpdate, TopicFamily};

/// The arm's task and reach state.
pub(crate) const STATE_TOPIC: &str = "/rover/arm/state";
/// The object reach goes for, in the base frame.
pub(crate) const OBJECT_TOPIC: &str = "/rover/arm/object";
/// The pre-grasp point the tool is sent to, in the base frame.
pub(crate) const GOAL_TOPIC: &str = "/rover/arm/goal";

/// Which of the arm's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ArmPoint {
    /// The object point ([`OBJECT_TOPIC`]).
    Object,
    /// The pre-grasp goal ([`GOAL_TOPIC`]).
    Goal,
}

/// The arm's topics on one transport; the points are in the plan's base frame.
pub(crate) trait ArmWire: Send {
    /// Publishes the state text.
    fn state(&mut self, stamp_s: f64, text: &str);
    /// Publishes a point (m, base frame).
    fn point(&mut self, which: ArmPoint, stamp_s: f64, point_m: [f64; 3]);
}

/// The arm family.
pub(crate) struct Arm {
    wire: Box<dyn ArmWire>,
    text: String,
    last: Option<(ArmMode, ReachState, PickState)>,
}

impl Arm {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn ArmWire>) -> Self {
        Self {
            wire,
            text: String::new(),
            last: None,
        }
    }
}

impl TopicFamily for Arm {
    fn control(&mut self, update: &ControlUpdate) {
        let ArmSample {
            mode,
            reach,
            pick,
            object_base_m,
            goal_base_m,
        } = update.arm;
        let t = update.sample.sim_time_s;
        if self.last != Some((mode, reach, pick)) {
            self.last = Some((mode, reach, pick));
            self.text.clear();
            self.text.push_str(mode.as_str());
            let state = match mode {
                ArmMode::Reach => Some(reach.as_str()),
                ArmMode::Pick => Some(pick.as_str()),
                ArmMode::Off | ArmMode::Look => None,
            };
            if let Some(state) = state {
                self.text.push(' ');
                self.text.push_str(state);
            }
            self.wire.state(t, &self.text);
        }
        if matches!(mode, ArmMode::Reach | ArmMode::Pick) {
            for (which, p) in [
                (ArmPoint::Object, object_base_m),
                (ArmPoint::Goal, goal_base_m),
            ] {
                if let Some(p) = p {
                    self.wire.point(which, t, p);
                }
            }
        }
    }
}
