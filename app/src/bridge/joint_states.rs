//! `/joint_states` (sensor_msgs/JointState): every moving joint of the plan, in its order, with
//! its position, velocity and effort, every control update (or at a joint_state_controller's
//! `publish_rate`).

use rover_sim::sensors::Schedule;

use super::events::{ControlUpdate, TopicFamily};
use super::plan::RosPlan;

/// The joints' state at a control update, in the plan's order, as sensor_msgs/JointState's
/// arrays.
#[derive(Debug, Default)]
pub(crate) struct JointArrays {
    /// Positions (rad or m; a wheel's angle).
    pub position: Vec<f64>,
    /// Velocities (rad/s or m/s).
    pub velocity: Vec<f64>,
    /// Efforts (N m or N).
    pub effort: Vec<f64>,
}

/// `/joint_states` on one transport; its names are the plan's joints'.
pub(crate) trait JointStatesWire: Send {
    /// Publishes the joints at sim time `stamp_s`.
    fn joint_states(&mut self, stamp_s: f64, joints: &JointArrays);
}

/// The joint states family.
pub(crate) struct JointStates {
    wire: Box<dyn JointStatesWire>,
    /// Whether the robot has moving joints.
    any: bool,
    /// When messages go out (every control update, or a joint_state_controller's rate).
    rate: Schedule,
    /// The arrays, reused.
    arrays: JointArrays,
}

impl JointStates {
    /// The family on `wire`, at the plan's rate.
    pub fn new(wire: Box<dyn JointStatesWire>, plan: &RosPlan) -> Self {
        Self {
            wire,
            any: !plan.joints.is_empty(),
            rate: Schedule::new(plan.joint_states_hz.unwrap_or(0.0)),
            arrays: JointArrays::default(),
        }
    }
}

impl TopicFamily for JointStates {
    fn control(&mut self, update: &ControlUpdate) {
        let now_s = update.sample.sim_time_s;
        if !self.any || !self.rate.take(now_s) {
            return;
        }
        let a = &mut self.arrays;
        a.position.clear();
        a.position.extend(update.joints.iter().map(|j| j.position));
        a.velocity.clear();
        a.velocity
            .extend(update.joints.iter().map(|j| j.velocity_radps));
        a.effort.clear();
        a.effort.extend(update.joints.iter().map(|j| j.effort));
        self.wire.joint_states(now_s, a);
    }
}
