//! The controllers' action servers on either transport, and the way their goals reach the
//! session, built once: a transport makes one server per controller and action
//! ([`ActionWire`], its wire trait), and [`intake`] turns them into a topic family that runs
//! them at every control update ([`ActionFamily`]) and the input that hands what they accept
//! to the session ([`GoalCommands`], polled with the transport's other input). What a goal
//! means is `action_goals.rs`'s.

use std::sync::mpsc::{Receiver, Sender};

use rover_core::{Action, InputSource};

use super::events::{ControlUpdate, TopicFamily};

/// One controller's action server on a transport: at every control update it takes the goals
/// and cancels that came, follows the controller's run and publishes what it owes; accepted
/// goals (and cancels' stops) go to the session through `to_session`.
pub(crate) trait ActionWire: Send {
    /// One control update.
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>);
}

/// A transport's action servers, run at every control update.
pub(crate) struct ActionFamily {
    servers: Vec<Box<dyn ActionWire>>,
    to_session: Sender<Action>,
}

impl TopicFamily for ActionFamily {
    fn control(&mut self, update: &ControlUpdate) {
        for server in &mut self.servers {
            server.update(update, &self.to_session);
        }
    }
}

/// What a transport's action servers accepted, as the session takes it.
#[derive(Debug)]
pub(crate) struct GoalCommands(Receiver<Action>);

impl InputSource for GoalCommands {
    fn poll(&mut self) -> Option<Action> {
        self.0.try_recv().ok()
    }
}

/// The family that runs `servers` and the input their accepted goals come out of.
pub(crate) fn intake(servers: Vec<Box<dyn ActionWire>>) -> (ActionFamily, GoalCommands) {
    let (to_session, from_servers) = std::sync::mpsc::channel();
    (
        ActionFamily {
            servers,
            to_session,
        },
        GoalCommands(from_servers),
    )
}
