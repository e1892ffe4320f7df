//! Gamepad teleop (gilrs): left stick drives, right stick turns, a deadman button must be held to
//! move, a button toggles follow; hot-plug; a pad unplugged while driving stops the car.

use rover_sim::physics::Twist;

/// Stick values below this are treated as zero.
pub const DEADZONE: f32 = 0.12;

/// What the pads ask for this poll.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PadCommand {
    /// Drive with this command (deadman held).
    Drive(Twist),
    /// Stop (deadman released, or the pad that drove was unplugged).
    Stop,
    /// Toggle follow mode.
    ToggleFollow,
    /// Pick the arm's next (+1) or previous (-1) joint (D-pad right / left).
    NextJoint(i8),
    /// Jog the picked joint up (+1) or down (-1) one step (D-pad up / down).
    Jog(i8),
    /// Go to the "home" pose (Y / North).
    Home,
}

/// The arm's buttons: the D-pad picks and jogs a joint, North goes home.
pub fn arm_button(button: gilrs::Button) -> Option<PadCommand> {
    match button {
        gilrs::Button::DPadRight => Some(PadCommand::NextJoint(1)),
        gilrs::Button::DPadLeft => Some(PadCommand::NextJoint(-1)),
        gilrs::Button::DPadUp => Some(PadCommand::Jog(1)),
        gilrs::Button::DPadDown => Some(PadCommand::Jog(-1)),
        gilrs::Button::North => Some(PadCommand::Home),
        _ => None,
    }
}

/// The state the pad logic needs from one pad, for testing without hardware.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PadState {
    /// Deadman button (left bumper) held.
    pub deadman: bool,
    /// Left stick up (+1) / down (-1).
    pub left_y: f32,
    /// Right stick right (+1) / left (-1).
    pub right_x: f32,
}

/// Pad logic: turns pad states and events into commands.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PadTeleop {
    driving: bool,
}

impl PadTeleop {
    /// The command for the current state, given teleop's speed and turn limits. Returns `None`
    /// when the pad is idle and was idle (so the keyboard keeps control).
    pub fn update(
        &mut self,
        state: PadState,
        speed_mps: f64,
        turn_radps: f64,
    ) -> Option<PadCommand> {
        let dz = |v: f32| {
            if v.abs() < DEADZONE {
                0.0
            } else {
                f64::from(v)
            }
        };
        if state.deadman {
            self.driving = true;
            Some(PadCommand::Drive(Twist::new(
                dz(state.left_y) * speed_mps,
                -dz(state.right_x) * turn_radps,
            )))
        } else if std::mem::take(&mut self.driving) {
            Some(PadCommand::Stop)
        } else {
            None
        }
    }

    /// The pad that was driving went away: stop.
    pub fn disconnected(&mut self) -> Option<PadCommand> {
        std::mem::take(&mut self.driving).then_some(PadCommand::Stop)
    }
}

/// All connected gamepads (gilrs).
pub struct Gamepads {
    gilrs: gilrs::Gilrs,
    logic: PadTeleop,
    active: Option<gilrs::GamepadId>,
}

impl std::fmt::Debug for Gamepads {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gamepads")
            .field("active", &self.active)
            .finish()
    }
}

impl Gamepads {
    /// Starts gamepad input (no pads attached is fine).
    pub fn new() -> Result<Self, String> {
        let gilrs = gilrs::Gilrs::new().map_err(|e| e.to_string())?;
        for (_, pad) in gilrs.gamepads() {
            tracing::info!("gamepad: {}", pad.name());
        }
        Ok(Self {
            gilrs,
            logic: PadTeleop::default(),
            active: None,
        })
    }

    /// Reads pending events; returns what the pads ask for.
    pub fn poll(&mut self, speed_mps: f64, turn_radps: f64) -> Option<PadCommand> {
        let mut toggle = false;
        let mut stop = None;
        let mut arm = None;
        while let Some(gilrs::Event { id, event, .. }) = self.gilrs.next_event() {
            match event {
                gilrs::EventType::Connected => {
                    tracing::info!("gamepad connected: {}", self.gilrs.gamepad(id).name());
                }
                gilrs::EventType::Disconnected => {
                    tracing::warn!("gamepad disconnected");
                    if self.active == Some(id) {
                        self.active = None;
                        stop = self.logic.disconnected();
                    }
                }
                gilrs::EventType::ButtonPressed(gilrs::Button::South, _) => toggle = true,
                gilrs::EventType::ButtonPressed(button, _) if arm_button(button).is_some() => {
                    arm = arm.or(arm_button(button));
                }
                gilrs::EventType::ButtonPressed(gilrs::Button::LeftTrigger, _) => {
                    self.active = Some(id);
                }
                _ => {}
            }
        }
        if toggle {
            return Some(PadCommand::ToggleFollow);
        }
        if stop.is_some() {
            return stop;
        }
        if arm.is_some() {
            return arm;
        }
        let state = self.active.map_or(PadState::default(), |id| {
            let pad = self.gilrs.gamepad(id);
            PadState {
                deadman: pad.is_pressed(gilrs::Button::LeftTrigger),
                left_y: pad.value(gilrs::Axis::LeftStickY),
                right_x: pad.value(gilrs::Axis::RightStickX),
            }
        });
        self.logic.update(state, speed_mps, turn_radps)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_d_pad_picks_and_jogs_a_joint_and_north_goes_home() {
        assert_eq!(
            arm_button(gilrs::Button::DPadRight),
            Some(PadCommand::NextJoint(1))
        );
        assert_eq!(
            arm_button(gilrs::Button::DPadLeft),
            Some(PadCommand::NextJoint(-1))
        );
        assert_eq!(arm_button(gilrs::Button::DPadUp), Some(PadCommand::Jog(1)));
        assert_eq!(
            arm_button(gilrs::Button::DPadDown),
            Some(PadCommand::Jog(-1))
        );
        assert_eq!(arm_button(gilrs::Button::North), Some(PadCommand::Home));
        assert_eq!(arm_button(gilrs::Button::South), None);
    }

    #[test]
    fn deadman_gates_driving_and_release_or_unplug_stops() {
        let mut pad = PadTeleop::default();
        let idle = PadState {
            left_y: 1.0,
            ..PadState::default()
        };
        assert_eq!(pad.update(idle, 0.5, 1.0), None, "no deadman, no motion");
        let held = PadState {
            deadman: true,
            left_y: 1.0,
            right_x: -0.5,
        };
        assert_eq!(
            pad.update(held, 0.5, 1.0),
            Some(PadCommand::Drive(Twist::new(0.5, 0.5)))
        );
        let small = PadState {
            deadman: true,
            left_y: 0.05,
            right_x: 0.0,
        };
        assert_eq!(
            pad.update(small, 0.5, 1.0),
            Some(PadCommand::Drive(Twist::ZERO))
        );
        assert_eq!(pad.update(idle, 0.5, 1.0), Some(PadCommand::Stop));
        assert_eq!(pad.update(idle, 0.5, 1.0), None);
        pad.update(held, 0.5, 1.0);
        assert_eq!(pad.disconnected(), Some(PadCommand::Stop));
        assert_eq!(pad.disconnected(), None);
    }
}
