//! The driver's station's arm keys: pick one of the robot's actuated joints (1-9; the gamepad's
//! D-pad left and right), jog it a step at a time (`[` and `]`, held keys repeat; D-pad down
//! and up), go home (`h`; the pad's North button). Jogging moves the joint's target one step
//! from its current target, so quick repeated presses add up exactly however fast the joint
//! follows; the joint's limits and the actuator's velocity and effort limits still apply.

use rover_core::{Action, JointAction};
use rover_sim::{JointCommand, JointId, JointKind, Simulation};

/// One jog step of a revolute joint (rad).
pub(super) const JOG_RAD: f64 = 0.1;
/// One jog step of a prismatic joint (m).
pub(super) const JOG_M: f64 = 0.01;

/// Which joint the keys move.
#[derive(Debug, Clone, Default)]
pub(super) struct ArmKeys {
    joints: Vec<JointId>,
    selected: usize,
}

impl ArmKeys {
    /// The robot's actuated joints, in file order.
    pub fn new(sim: &Simulation) -> Self {
        Self {
            joints: sim.robot().actuated_joints(),
            selected: 0,
        }
    }

    /// Whether the robot has joints to jog.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Picks joint `index` (0-based) when there is one.
    pub fn select(&mut self, index: usize) {
        if index < self.joints.len() {
            self.selected = index;
        }
    }

    /// Picks the next (`step` +1) or previous (-1) joint, wrapping around.
    pub fn select_next(&mut self, step: i8) {
        let n = self.joints.len();
        if n > 0 {
            let step = if step >= 0 { 1 } else { n - 1 };
            self.selected = (self.selected + step) % n;
        }
    }

    /// The command that jogs the picked joint one step in `direction` (-1 or +1).
    pub fn jog(&self, sim: &Simulation, direction: i8) -> Option<Action> {
        let id = *self.joints.get(self.selected)?;
        let joint = sim.robot().joint(id);
        let step = match joint.kind {
            JointKind::Prismatic { .. } => JOG_M,
            _ => JOG_RAD,
        };
        let from = sim.joint_target(id)?;
        Some(Action::Joint(JointAction::Command {
            joint: joint.name.clone(),
            command: JointCommand::Position(from + f64::from(direction) * step),
        }))
    }

    /// The HUD's arm line: the picked joint, where it is, and the keys (see [`task_line`] for
    /// the line while look or reach runs).
    pub fn status(&self, sim: &Simulation) -> Option<String> {
        let id = *self.joints.get(self.selected)?;
        let joint = sim.robot().joint(id);
        let unit = match joint.kind {
            JointKind::Prismatic { .. } => "m",
            _ => "rad",
        };
        let q = sim.joint_state(id).map_or(0.0, |s| s.position);
        Some(format!(
            "arm {}/{} {} {q:+.2} {unit}  [ ] jog  1-{} pick  h home",
            self.selected + 1,
            self.joints.len(),
            joint.name.trim_end_matches("_joint"),
            self.joints.len().min(9)
        ))
    }
}

/// The HUD's arm line while look or reach runs: the task, the reach's state and how far the
/// tool is from its goal, and the key that stops it; `None` when neither runs.
pub fn task_line(status: &rover_core::ArmStatus) -> Option<String> {
    use rover_core::ArmMode;
    match status.mode {
        ArmMode::Off => None,
        ArmMode::Look => Some("arm LOOK at the class   v stops   g reach".to_owned()),
        ArmMode::Reach => {
            let to_goal = status
                .tool_to_goal_m()
                .map(|d| format!(", tool {d:.2} m from the goal"))
                .unwrap_or_default();
            Some(format!(
                "arm REACH {}{to_goal}   g stops",
                status.reach.as_str()
            ))
        }
    }
}
