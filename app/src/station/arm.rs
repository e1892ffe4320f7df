//! The driver's station's arm keys: pick one of the robot's actuated joints (1-9; the gamepad's
//! D-pad left and right), or with an end effector (`--ee-link`) one of its axes, x, y or z of
//! the arm's base (`0`, again for the next), jog it a step at a time (`[` and `]`, held keys
//! repeat; D-pad down and up: 0.1 rad, 1 cm, or 1 cm of the tool by IK), go home (`h`; the
//! pad's North button). Jogging moves the joint's target one step
//! from its current target, so quick repeated presses add up exactly however fast the joint
//! follows; the joint's limits and the actuator's velocity and effort limits still apply.

use rover_core::{Action, JointAction};
use rover_sim::{
    model::{JointId, JointKind},
    physics::{JointCommand, Simulation},
};

/// One jog step of a revolute joint (rad).
pub(super) const JOG_RAD: f64 = 0.1;
/// One jog step of a prismatic joint (m).
pub(super) const JOG_M: f64 = 0.01;

/// One Cartesian jog step of the end effector (m).
pub(super) const JOG_TOOL_M: f64 = 0.01;

/// Which joint (or tool axis) the keys move.
#[derive(Debug, Clone, Default)]
pub(super) struct ArmKeys {
    joints: Vec<JointId>,
    selected: usize,
    /// The end effector's axis picked (0 x, 1 y, 2 z), instead of a joint.
    tool_axis: Option<usize>,
}

impl ArmKeys {
    /// The robot's actuated joints, in file order.
    pub fn new(sim: &Simulation) -> Self {
        Self {
            joints: sim.robot().actuated_joints(),
            selected: 0,
            tool_axis: None,
        }
    }

    /// Picks the end effector's next axis (x, then y, then z, then x again).
    pub fn select_tool_axis(&mut self) {
        self.tool_axis = Some(self.tool_axis.map_or(0, |a| (a + 1) % 3));
    }

    /// Whether the robot has joints to jog.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Picks joint `index` (0-based) when there is one.
    pub fn select(&mut self, index: usize) {
        if index < self.joints.len() {
            self.selected = index;
            self.tool_axis = None;
        }
    }

    /// Picks the next (`step` +1) or previous (-1) joint, wrapping around.
    pub fn select_next(&mut self, step: i8) {
        let n = self.joints.len();
        if n > 0 {
            let step = if step >= 0 { 1 } else { n - 1 };
            self.selected = (self.selected + step) % n;
            self.tool_axis = None;
        }
    }

    /// The command that jogs the picked joint one step in `direction` (-1 or +1).
    pub fn jog(&self, sim: &Simulation, direction: i8) -> Option<Action> {
        if let Some(axis) = self.tool_axis {
            let mut step = [0.0; 3];
            step[axis] = f64::from(direction) * JOG_TOOL_M;
            return Some(Action::Joint(JointAction::Tool {
                position_m: step,
                relative: true,
            }));
        }
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
        if let Some(axis) = self.tool_axis {
            return Some(format!(
                "arm tool {}  [ ] jog {:.0} cm  0 next axis  1-{} pick a joint",
                ["x", "y", "z"][axis],
                JOG_TOOL_M * 100.0,
                self.joints.len().min(9)
            ));
        }
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
/// tool is from its goal, whether the robot hides the object, and the key that stops it;
/// `None` when neither runs.
pub fn task_line(status: &rover_core::ArmStatus) -> Option<String> {
    use rover_core::ArmMode;
    let hidden = if status.hidden {
        " (hidden by the robot)"
    } else {
        ""
    };
    match status.mode {
        ArmMode::Off => None,
        ArmMode::Look => Some("arm LOOK at the class   v stops   g reach".to_owned()),
        ArmMode::Reach => {
            let to_goal = status
                .tool_to_goal_m()
                .map(|d| format!(", tool {d:.2} m from the goal"))
                .unwrap_or_default();
            Some(format!(
                "arm REACH {}{hidden}{to_goal}   g stops",
                status.reach.as_str()
            ))
        }
        ArmMode::Pick => Some(format!(
            "arm PICK {}{hidden}   r stops",
            status.pick.as_str()
        )),
    }
}
