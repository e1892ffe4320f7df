//! Input scripts for headless runs: timed steps on sim time.
//!
//! ```toml
//! steps = [
//!   { at = 0.0, cmd_vel = [0.5, 0.0] },   # linear.x m/s, angular.z rad/s
//!   { at = 2.0, key = "j" },              # a teleop_twist_keyboard key
//!   { at = 3.0, toggle = "follow" },      # flip between manual and follow mode
//! ]
//! ```

use std::path::Path;

use anyhow::{Result, bail};
use serde::Deserialize;

use crate::teleop::{KeyAction, TELEOP_KEYS, key_action};
use rover_sim::Twist;

/// What a step does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Action {
    /// Publish a velocity command.
    CmdVel(Twist),
    /// Press a teleop key.
    Key(KeyAction),
    /// Flip between manual and follow mode.
    ToggleFollow,
}

/// One timed step.
#[derive(Debug, Clone, Copy, PartialEq)]
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
}

impl Script {
    /// Loads and validates a script file.
    pub fn load(path: &Path) -> Result<Self> {
        let raw: RawScript = rover_sim::tomlfile::load_toml(path)?;
        Self::from_raw(raw, path)
    }

    /// Parses script text; `path` is used in messages.
    pub fn from_str(text: &str, path: &Path) -> Result<Self> {
        let raw: RawScript = rover_sim::tomlfile::parse_toml(text, path)?;
        Self::from_raw(raw, path)
    }

    fn from_raw(raw: RawScript, path: &Path) -> Result<Self> {
        let mut steps = Vec::with_capacity(raw.steps.len());
        for (i, s) in raw.steps.into_iter().enumerate() {
            let here = format!("{}: at `steps[{i}]`", path.display());
            if !(s.at.is_finite() && s.at >= 0.0) {
                bail!(
                    "{here}: `at` must be a sim time in seconds >= 0, found {}",
                    s.at
                );
            }
            let action = match (s.cmd_vel, s.key, s.toggle) {
                (Some([linear, angular]), None, None) => {
                    let twist = Twist::new(linear, angular);
                    if !twist.is_finite() {
                        bail!(
                            "{here}: cmd_vel must be two finite numbers [linear.x m/s, angular.z rad/s], found [{linear}, {angular}]"
                        );
                    }
                    Action::CmdVel(twist)
                }
                (None, Some(key), None) => match key_action(&key) {
                    Some(a) => Action::Key(a),
                    None => bail!(
                        "{here}: key \"{key}\" is not a teleop key; expected one of: {TELEOP_KEYS}"
                    ),
                },
                (None, None, Some(mode)) => match mode.as_str() {
                    "follow" => Action::ToggleFollow,
                    other => bail!("{here}: toggle \"{other}\" is unknown; expected \"follow\""),
                },
                _ => bail!(
                    "{here}: expected exactly one of `cmd_vel`, `key` or `toggle` besides `at`"
                ),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Script> {
        Script::from_str(text, Path::new("s.toml"))
    }

    #[test]
    fn parses_and_sorts_steps() -> Result<()> {
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
            err("steps = [ { at = 1.0, toggle = \"dance\" } ]").contains("expected \"follow\"")
        );
    }
}
