//! What drives the loop from outside: an [`Action`] (a script step, a key, a gamepad command,
//! ROS `/cmd_vel`), and [`InputSource`], polled for actions before every physics step.

use rover_sim::Twist;

use crate::teleop::KeyAction;

/// One user input. `Clone`, not `Copy`, so that an input kind may carry data (say, a list of
/// joint targets).
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Publish a velocity command.
    CmdVel(Twist),
    /// Press a teleop key.
    Key(KeyAction),
    /// Flip between manual and follow mode.
    ToggleFollow,
}

/// Input from outside the loop that drives it like manual input: the ROS bridge's `/cmd_vel`.
/// Polled before every physics step; it must not block.
pub trait InputSource {
    /// The next input waiting, if any.
    fn poll(&mut self) -> Option<Action>;
}

/// No outside input.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoInput;

impl InputSource for NoInput {
    fn poll(&mut self) -> Option<Action> {
        None
    }
}
