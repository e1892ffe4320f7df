//! Keyboard teleop for the window, as a pure state machine (tested without a window):
//! teleop_twist_keyboard's layout with hold-to-drive (or latched, like the terminal tool),
//! arrows, optional W/A/S/D, and the station's own keys.

use std::collections::BTreeSet;

use rover_core::{Action, KeyAction, Mode, TELEOP_KEYS, key_action};

/// Keyboard settings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct KeyOptions {
    /// Keep driving after a key is released, as teleop_twist_keyboard does in a terminal.
    pub latched: bool,
    /// W/A/S/D drive too (teleop's w/x/e/c speed keys are then off; q/z still scale).
    pub wasd: bool,
}

/// What a key asks the station to do.
#[derive(Debug, Clone, PartialEq)]
pub enum KeyCommand {
    /// An input for the session (drive, speed, stop, follow).
    Input(Action),
    /// Pause or resume.
    TogglePause,
    /// One control update while paused.
    StepOnce,
    /// Pick the arm's Nth actuated joint (0-based; keys 1-9).
    SelectJoint(usize),
    /// Pick the end effector's next axis, x, y or z of the arm's base, for Cartesian jogging
    /// (`0`).
    SelectToolAxis,
    /// Jog the picked joint one step down (-1, `[`) or up (+1, `]`).
    Jog(i8),
    /// Go to the controllers file's "home" pose (`h`).
    Home,
}

/// Turns key presses and releases into commands. Key names are winit's logical keys: the
/// character in lower case, `space`, `ArrowUp`/`ArrowDown`/`ArrowLeft`/`ArrowRight`.
#[derive(Debug, Clone, Default)]
pub struct KeyTeleop {
    options: KeyOptions,
    /// Driving keys held down (after arrow/WASD mapping).
    held: BTreeSet<&'static str>,
    /// The driving key whose motion is in effect.
    last_move: Option<&'static str>,
}

/// The teleop key a key name stands for (arrows and, with `wasd`, W/A/S/D map to i , j l).
/// `None` for keys the station ignores.
fn teleop_name(name: &str, wasd: bool) -> Option<&'static str> {
    Some(match (wasd, name) {
        (_, "ArrowUp") | (true, "w") => "i",
        (_, "ArrowDown") | (true, "s") => ",",
        (_, "ArrowLeft") | (true, "a") => "j",
        (_, "ArrowRight") | (true, "d") => "l",
        (true, "x" | "e" | "c") => return None,
        // Shifted teleop keys (< for , and > for .) arrive as other characters.
        (_, "<") => ",",
        (_, ">") => ".",
        (_, "space" | " ") => "space",
        // The station's own keys: follow, pause, single step.
        (_, "f") => "f",
        (_, "p") => "p",
        (_, "n") => "n",
        // The arm's: pick a joint, jog it, home; reach (grab), pick and place (retrieve)
        // and look (view) on / off.
        (_, "g") => "g",
        (_, "r") => "r",
        (_, "v") => "v",
        (_, "[") => "[",
        (_, "]") => "]",
        (_, "h") => "h",
        (_, digit @ ("0" | "1" | "2" | "3" | "4" | "5" | "6" | "7" | "8" | "9")) => {
            ["0", "1", "2", "3", "4", "5", "6", "7", "8", "9"]
                .into_iter()
                .find(|d| *d == digit)?
        }
        (_, other) => TELEOP_KEYS.split(' ').find(|k| *k == other)?,
    })
}

fn is_move(name: &str) -> bool {
    matches!(key_action(name), Some(KeyAction::Move { .. }))
}

impl KeyTeleop {
    /// A keyboard with these settings.
    pub fn new(options: KeyOptions) -> Self {
        Self {
            options,
            ..Self::default()
        }
    }

    /// A key went down (`pressed`) or up. `mode` is the pilot's mode now: releasing the
    /// driving key stops the car only in manual mode (the follower keeps its command).
    pub fn key(&mut self, name: &str, pressed: bool, mode: Mode) -> Option<KeyCommand> {
        let name = teleop_name(name, self.options.wasd)?;
        if !pressed {
            self.held.remove(name);
            if self.options.latched || !is_move(name) || self.last_move != Some(name) {
                return None;
            }
            // Hold-to-drive: releasing the key that drives falls back to another driving key
            // still held, else stops.
            return match self.held.iter().copied().find(|k| is_move(k)) {
                Some(other) => {
                    self.last_move = Some(other);
                    key_action(other).map(|a| KeyCommand::Input(Action::Key(a)))
                }
                None => {
                    self.last_move = None;
                    (mode == Mode::Manual)
                        .then_some(KeyCommand::Input(Action::Key(KeyAction::Stop)))
                }
            };
        }
        match name {
            "f" => Some(KeyCommand::Input(Action::ToggleFollow)),
            "g" => Some(KeyCommand::Input(Action::ToggleReach)),
            "r" => Some(KeyCommand::Input(Action::TogglePick)),
            "v" => Some(KeyCommand::Input(Action::ToggleLook)),
            "p" => Some(KeyCommand::TogglePause),
            "n" => Some(KeyCommand::StepOnce),
            "[" => Some(KeyCommand::Jog(-1)),
            "]" => Some(KeyCommand::Jog(1)),
            "h" => Some(KeyCommand::Home),
            "0" => Some(KeyCommand::SelectToolAxis),
            digit if digit.len() == 1 && digit.as_bytes()[0].is_ascii_digit() => Some(
                KeyCommand::SelectJoint(usize::from(digit.as_bytes()[0] - b'1')),
            ),
            other => {
                let action = key_action(other)?;
                if is_move(other) {
                    self.held.insert(other);
                    self.last_move = Some(other);
                }
                Some(KeyCommand::Input(Action::Key(action)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mv(x: f64, th: f64) -> Option<KeyCommand> {
        Some(KeyCommand::Input(Action::Key(KeyAction::Move { x, th })))
    }
    const STOP: Option<KeyCommand> = Some(KeyCommand::Input(Action::Key(KeyAction::Stop)));
    const MANUAL: Mode = Mode::Manual;

    #[test]
    fn digits_pick_a_joint_brackets_jog_it_and_h_goes_home() {
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("1", true, MANUAL), Some(KeyCommand::SelectJoint(0)));
        assert_eq!(k.key("5", true, MANUAL), Some(KeyCommand::SelectJoint(4)));
        assert_eq!(k.key("]", true, MANUAL), Some(KeyCommand::Jog(1)));
        assert_eq!(k.key("[", true, MANUAL), Some(KeyCommand::Jog(-1)));
        assert_eq!(k.key("h", true, MANUAL), Some(KeyCommand::Home));
        assert_eq!(k.key("0", true, MANUAL), Some(KeyCommand::SelectToolAxis));
        // Releases do nothing.
        assert_eq!(k.key("]", false, MANUAL), None);
    }

    #[test]
    fn hold_to_drive_stops_on_release() {
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("i", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("i", false, MANUAL), STOP);
    }

    #[test]
    fn releasing_one_of_two_driving_keys_falls_back_to_the_other() {
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("i", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("j", true, MANUAL), mv(0.0, 1.0));
        // j drives; releasing it goes back to i, still held.
        assert_eq!(k.key("j", false, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("i", false, MANUAL), STOP);
        // Releasing a key that is no longer in effect changes nothing.
        assert_eq!(k.key("u", true, MANUAL), mv(1.0, 1.0));
        assert_eq!(k.key("o", true, MANUAL), mv(1.0, -1.0));
        assert_eq!(k.key("u", false, MANUAL), None);
        assert_eq!(k.key("o", false, MANUAL), STOP);
    }

    #[test]
    fn speed_keys_do_not_drive_or_stop() {
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("i", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(
            k.key("q", true, MANUAL),
            Some(KeyCommand::Input(Action::Key(KeyAction::Scale {
                speed: 1.1,
                turn: 1.1
            })))
        );
        assert_eq!(k.key("q", false, MANUAL), None);
        assert_eq!(k.key("i", false, MANUAL), STOP);
    }

    #[test]
    fn latched_keeps_driving_like_the_terminal_teleop() {
        let mut k = KeyTeleop::new(KeyOptions {
            latched: true,
            wasd: false,
        });
        assert_eq!(k.key("i", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("i", false, MANUAL), None);
        assert_eq!(k.key("k", true, MANUAL), STOP);
        assert_eq!(k.key("space", true, MANUAL), STOP);
    }

    #[test]
    fn arrows_always_and_wasd_when_asked() {
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("ArrowUp", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("ArrowUp", false, MANUAL), STOP);
        assert_eq!(k.key("ArrowLeft", true, MANUAL), mv(0.0, 1.0));
        // Without --wasd, w is teleop's "linear speed x1.1".
        assert_eq!(
            k.key("w", true, MANUAL),
            Some(KeyCommand::Input(Action::Key(KeyAction::Scale {
                speed: 1.1,
                turn: 1.0
            })))
        );
        let mut k = KeyTeleop::new(KeyOptions {
            latched: false,
            wasd: true,
        });
        assert_eq!(k.key("w", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("s", true, MANUAL), mv(-1.0, 0.0));
        assert_eq!(k.key("a", true, MANUAL), mv(0.0, 1.0));
        assert_eq!(k.key("d", true, MANUAL), mv(0.0, -1.0));
        // The speed keys that W/A/S/D shadow are off; q/z still scale.
        assert_eq!(k.key("x", true, MANUAL), None);
        assert_eq!(k.key("e", true, MANUAL), None);
        assert!(k.key("z", true, MANUAL).is_some());
    }

    #[test]
    fn shifted_keys_station_keys_and_follow_mode() {
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("<", true, MANUAL), mv(-1.0, 0.0));
        assert_eq!(k.key(">", true, MANUAL), mv(-1.0, 1.0));
        assert_eq!(
            k.key("f", true, MANUAL),
            Some(KeyCommand::Input(Action::ToggleFollow))
        );
        assert_eq!(
            k.key("g", true, MANUAL),
            Some(KeyCommand::Input(Action::ToggleReach))
        );
        assert_eq!(
            k.key("v", true, MANUAL),
            Some(KeyCommand::Input(Action::ToggleLook))
        );
        assert_eq!(
            k.key("r", true, MANUAL),
            Some(KeyCommand::Input(Action::TogglePick))
        );
        assert_eq!(k.key("0", true, MANUAL), Some(KeyCommand::SelectToolAxis));
        assert_eq!(k.key("3", true, MANUAL), Some(KeyCommand::SelectJoint(2)));
        assert_eq!(k.key("p", true, MANUAL), Some(KeyCommand::TogglePause));
        assert_eq!(k.key("n", true, MANUAL), Some(KeyCommand::StepOnce));
        assert_eq!(k.key("y", true, MANUAL), None);
        // Releasing the last driving key while following leaves the follower's command alone.
        let mut k = KeyTeleop::new(KeyOptions::default());
        assert_eq!(k.key("i", true, MANUAL), mv(1.0, 0.0));
        assert_eq!(k.key("i", false, Mode::Follow), None);
    }
}
