//! Input scripts for headless runs: timed steps on sim time.
//!
//! ```toml
//! steps = [
//!   { at = 0.0, cmd_vel = [0.5, 0.0] },   # linear.x m/s, angular.z rad/s
//!   { at = 2.0, key = "j" },              # a teleop_twist_keyboard key
//!   { at = 3.0, toggle = "follow" },      # flip between manual and follow mode
//!   { at = 3.0, toggle = "reach" },       # the arm's reach on or off (or "look")
//!   { at = 4.0, joint = "arm_2_joint", position = -0.8 },  # or velocity = / effort =
//!   { at = 6.0, pose = "home" },          # a named pose of the controllers file
//!   { at = 7.0, tool = [0.5, -0.2, 0.1] },  # the end effector (--ee-link) to a point, m,
//!                                         # in the arm base's frame (--arm-base), by IK
//!   { at = 8.0, controller = "gripper_controller", command = 0.02 },  # its `command` topic
//! ]
//! ```
//!
//! Joint, pose and controller names are checked against the robot when the step runs: an
//! unknown one is reported once as a warning and the step is dropped.

use std::path::Path;

use rover_sim::{
    SimError,
    physics::{ControlSample, JointCommand, Twist},
};
use serde::Deserialize;

use crate::error::Result;
use crate::input::{Action, JointAction};
use crate::observer::Observer;
use crate::session::Session;
use crate::teleop::{TELEOP_KEYS, key_action};

/// One timed step.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Sim time at which it applies (s).
    pub at_s: f64,
    /// What it does.
    pub action: Action,
}

/// A validated script, steps in time order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Script {
    /// Steps sorted by time (ties keep file order).
    pub steps: Vec<Step>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScript {
    #[serde(default)]
    steps: Vec<RawStep>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    at: f64,
    cmd_vel: Option<[f64; 2]>,
    key: Option<String>,
    toggle: Option<String>,
    joint: Option<String>,
    position: Option<f64>,
    velocity: Option<f64>,
    effort: Option<f64>,
    pose: Option<String>,
    controller: Option<String>,
    command: Option<f64>,
    tool: Option<[f64; 3]>,
}

impl RawStep {
    /// A joint, pose or controller step, if this is one; `Err` names what is wrong.
    fn joint_action(&self) -> Option<std::result::Result<JointAction, String>> {
        let values = [self.position, self.velocity, self.effort];
        let given = values.iter().filter(|v| v.is_some()).count();
        if let Some(joint) = &self.joint {
            let command = match (self.position, self.velocity, self.effort) {
                (Some(q), None, None) => JointCommand::Position(q),
                (None, Some(v), None) => JointCommand::Velocity(v),
                (None, None, Some(e)) => JointCommand::Effort(e),
                _ => {
                    return Some(Err(format!(
                        "joint \"{joint}\" needs exactly one of `position`, `velocity` or `effort`, found {given}"
                    )));
                }
            };
            if !command.is_finite() {
                return Some(Err(format!(
                    "joint \"{joint}\": the command must be a finite number"
                )));
            }
            return Some(Ok(JointAction::Command {
                joint: joint.clone(),
                command,
            }));
        }
        if given > 0 {
            return Some(Err(
                "`position`, `velocity` and `effort` go with `joint = \"<name>\"`".into(),
            ));
        }
        if let Some(pose) = &self.pose {
            return Some(Ok(JointAction::Pose(pose.clone())));
        }
        if let Some(position_m) = self.tool {
            if !position_m.iter().all(|v| v.is_finite()) {
                return Some(Err("`tool` must be three finite numbers (m)".into()));
            }
            return Some(Ok(JointAction::Tool {
                position_m,
                relative: false,
            }));
        }
        match (&self.controller, self.command) {
            (Some(name), Some(value)) if value.is_finite() => Some(Ok(JointAction::Controller {
                name: name.clone(),
                value,
            })),
            (Some(name), Some(_)) => Some(Err(format!(
                "controller \"{name}\": `command` must be a finite number"
            ))),
            (Some(name), None) => Some(Err(format!(
                "controller \"{name}\" needs `command = <number>`"
            ))),
            (None, Some(_)) => Some(Err("`command` goes with `controller = \"<name>\"`".into())),
            (None, None) => None,
        }
    }
}

impl Script {
    /// Loads and validates a script file.
    pub fn load(path: &Path) -> Result<Self> {
        let raw: RawScript = rover_sim::description::load_toml(path)?;
        Self::from_raw(raw, path)
    }

    /// Parses script text; `path` is used in messages.
    pub fn from_str(text: &str, path: &Path) -> Result<Self> {
        let raw: RawScript = rover_sim::description::parse_toml(text, path)?;
        Self::from_raw(raw, path)
    }

    fn from_raw(raw: RawScript, path: &Path) -> Result<Self> {
        let mut steps = Vec::with_capacity(raw.steps.len());
        for (i, s) in raw.steps.into_iter().enumerate() {
            let bail = |message: String| -> Result<Self> {
                Err(SimError::invalid(path, None, format!("at `steps[{i}]`: {message}")).into())
            };
            if !(s.at.is_finite() && s.at >= 0.0) {
                return bail(format!(
                    "`at` must be a sim time in seconds >= 0, found {}",
                    s.at
                ));
            }
            let joint = s.joint_action();
            let base_given = s.cmd_vel.is_some() || s.key.is_some() || s.toggle.is_some();
            let action = match (joint, s.cmd_vel, s.key, s.toggle) {
                (Some(_), _, _, _) if base_given => {
                    return bail(
                        "expected exactly one of `cmd_vel`, `key`, `toggle`, `joint`, `pose`, `controller` or `tool` besides `at`".into(),
                    );
                }
                (Some(Ok(action)), ..) => Action::Joint(action),
                (Some(Err(message)), ..) => return bail(message),
                (None, cmd_vel, key, toggle) => match (cmd_vel, key, toggle) {
                    (Some([linear, angular]), None, None) => {
                        let twist = Twist::new(linear, angular);
                        if !twist.is_finite() {
                            return bail(format!(
                                "cmd_vel must be two finite numbers [linear.x m/s, angular.z rad/s], found [{linear}, {angular}]"
                            ));
                        }
                        Action::CmdVel(twist)
                    }
                    (None, Some(key), None) => match key_action(&key) {
                        Some(a) => Action::Key(a),
                        None => {
                            return bail(format!(
                                "key \"{key}\" is not a teleop key; expected one of: {TELEOP_KEYS}"
                            ));
                        }
                    },
                    (None, None, Some(mode)) => match mode.as_str() {
                        "follow" => Action::ToggleFollow,
                        "look" => Action::ToggleLook,
                        "reach" => Action::ToggleReach,
                        "pick" => Action::TogglePick,
                        other => {
                            return bail(format!(
                                "toggle \"{other}\" is unknown; expected \"follow\", \"look\", \"reach\" or \"pick\""
                            ));
                        }
                    },
                    _ => {
                        return bail(
                        "expected exactly one of `cmd_vel`, `key`, `toggle`, `joint`, `pose`, `controller` or `tool` besides `at`".into(),
                    );
                    }
                },
            };
            steps.push(Step { at_s: s.at, action });
        }
        steps.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
        Ok(Self { steps })
    }

    /// Time of the last step (0 for an empty script).
    pub fn end_s(&self) -> f64 {
        self.steps.last().map_or(0.0, |s| s.at_s)
    }
}

/// Plays a script into a session: every step applies at the first physics step at or after its
/// sim time. The one player for headless runs and the window.
#[derive(Debug, Clone, Default)]
pub struct ScriptPlayer {
    script: Script,
    next: usize,
}

impl ScriptPlayer {
    /// A player at the script's start.
    pub fn new(script: Script) -> Self {
        Self { script, next: 0 }
    }

    /// The script.
    pub fn script(&self) -> &Script {
        &self.script
    }

    /// True when the script switches something that acts on detections (the follower, the
    /// arm's look or reach) on or off somewhere.
    pub fn toggles_perception(&self) -> bool {
        self.script.steps.iter().any(|s| {
            matches!(
                s.action,
                Action::ToggleFollow
                    | Action::ToggleLook
                    | Action::ToggleReach
                    | Action::TogglePick
            )
        })
    }

    /// Applies the steps due at the session's sim time (half a physics step of tolerance).
    pub fn play(&mut self, session: &mut Session, observer: &mut dyn Observer) {
        let now = session.sim().sim_time_s();
        let half_step_s = session.sim().dt_s() / 2.0;
        while let Some(step) = self.script.steps.get(self.next) {
            if step.at_s > now + half_step_s {
                break;
            }
            session.input(step.action.clone(), observer);
            self.next += 1;
        }
    }

    /// Plays the due steps, then advances the session one physics step. Returns the control
    /// sample when the diff drive's control loop ran.
    pub fn step(
        &mut self,
        session: &mut Session,
        observer: &mut dyn Observer,
    ) -> Result<Option<ControlSample>> {
        self.play(session, observer);
        session.step(observer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::teleop::KeyAction;

    fn parse(text: &str) -> crate::Result<Script> {
        Script::from_str(text, Path::new("s.toml"))
    }

    #[test]
    fn parses_and_sorts_steps() -> crate::Result<()> {
        let s = parse(
            "steps = [ { at = 2.0, key = \"j\" }, { at = 0.0, cmd_vel = [0.5, 0.0] }, { at = 3.0, toggle = \"follow\" } ]",
        )?;
        assert_eq!(s.steps.len(), 3);
        assert_eq!(s.steps[0].action, Action::CmdVel(Twist::new(0.5, 0.0)));
        assert_eq!(s.steps[2].action, Action::ToggleFollow);
        assert_eq!(s.end_s(), 3.0);
        // The [[steps]] table form is the same thing.
        let t = parse("[[steps]]\nat = 1.0\nkey = \"k\"\n")?;
        assert_eq!(t.steps[0].action, Action::Key(KeyAction::Stop));
        Ok(())
    }

    #[test]
    fn rejects_unknown_kinds_and_bad_values() {
        let err = |text: &str| parse(text).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err("steps = [ { at = 1.0, jump = true } ]").contains("unknown field `jump`"));
        assert!(err("steps = [ { at = 1.0 } ]").contains("exactly one of"));
        assert!(err("steps = [ { at = 1.0, key = \"y\" } ]").contains("not a teleop key"));
        assert!(err("steps = [ { at = -1.0, key = \"k\" } ]").contains(">= 0"));
        assert!(err("steps = [ { at = 1.0, cmd_vel = [nan, 0.0] } ]").contains("finite"));
        assert!(
            err("steps = [ { at = 1.0, toggle = \"dance\" } ]")
                .contains("expected \"follow\", \"look\", \"reach\" or \"pick\"")
        );
        let both = err("steps = [ { at = 1.0, joint = \"a\", position = 1.0, velocity = 2.0 } ]");
        assert!(both.contains("exactly one of `position`"), "{both}");
        let nan = err("steps = [ { at = 1.0, joint = \"a\", position = nan } ]");
        assert!(nan.contains("finite"), "{nan}");
        let stray = err("steps = [ { at = 1.0, position = 1.0 } ]");
        assert!(stray.contains("go with `joint"), "{stray}");
        let mixed = err("steps = [ { at = 1.0, key = \"k\", pose = \"home\" } ]");
        assert!(mixed.contains("exactly one of"), "{mixed}");
    }

    #[test]
    fn parses_joint_pose_and_controller_steps() -> crate::Result<()> {
        let s = parse(
            "steps = [ { at = 1.0, joint = \"arm_2_joint\", position = -0.8 }, { at = 2.0, pose = \"home\" }, { at = 3.0, controller = \"grip\", command = 0.02 } ]",
        )?;
        assert_eq!(
            s.steps[0].action,
            Action::Joint(JointAction::Command {
                joint: "arm_2_joint".into(),
                command: JointCommand::Position(-0.8)
            })
        );
        assert_eq!(
            s.steps[1].action,
            Action::Joint(JointAction::Pose("home".into()))
        );
        assert_eq!(
            s.steps[2].action,
            Action::Joint(JointAction::Controller {
                name: "grip".into(),
                value: 0.02
            })
        );
        let tool = parse("steps = [ { at = 1.0, tool = [0.5, -0.2, 0.1] } ]")?;
        assert_eq!(
            tool.steps[0].action,
            Action::Joint(JointAction::Tool {
                position_m: [0.5, -0.2, 0.1],
                relative: false
            })
        );
        let bad = parse("steps = [ { at = 1.0, tool = [0.5, nan, 0.1] } ]")
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(bad.contains("three finite numbers"), "{bad}");
        Ok(())
    }
}
