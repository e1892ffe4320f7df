//! Who drives: the human (teleop, scripted cmd_vel) or the follower.

use rover_sim::physics::Twist;

use crate::input::Action;
use crate::teleop::{KeyAction, Teleop};

/// Control mode, as the trace's `mode` column shows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Mode {
    /// A human (keys, scripted commands) drives.
    #[default]
    Manual,
    /// The follower drives.
    Follow,
}

impl Mode {
    /// `manual` or `follow`.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Manual => "manual",
            Mode::Follow => "follow",
        }
    }
}

/// Routes inputs to cmd_vel according to the mode.
#[derive(Debug, Clone, Default)]
pub struct Pilot {
    mode: Mode,
    teleop: Teleop,
}

impl Pilot {
    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The teleop state (speed and turn limits).
    pub fn teleop(&self) -> &Teleop {
        &self.teleop
    }

    /// Applies an input; returns the cmd_vel to publish, if it changes.
    ///
    /// Any manual input while following takes control back at once (safety first). Entering
    /// follow mode publishes a stop; the follower then commands the robot from detections, and
    /// with no detector available it holds still.
    pub fn apply(&mut self, action: &Action) -> Option<Twist> {
        match action {
            Action::CmdVel(twist) => {
                self.mode = Mode::Manual;
                Some(*twist)
            }
            Action::Key(key) => {
                self.mode = Mode::Manual;
                Some(self.teleop.press(*key))
            }
            Action::ToggleFollow => {
                self.mode = match self.mode {
                    Mode::Manual => Mode::Follow,
                    Mode::Follow => Mode::Manual,
                };
                // Either way the robot stops: the teleop direction is cleared so that leaving
                // follow mode does not resume an old key press.
                self.teleop.press(KeyAction::Stop);
                Some(Twist::ZERO)
            }
            // The arm moves in either mode; the base is not touched.
            Action::Joint(_)
            | Action::ToggleLook
            | Action::ToggleReach
            | Action::TogglePick
            | Action::Arm(_) => None,
        }
    }
}
