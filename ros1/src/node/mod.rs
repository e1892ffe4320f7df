//! A ROS 1 node: registers with the master, serves the slave API, accepts TCPROS subscribers
//! and connects to publishers. Everything runs on its own threads; publishing never blocks the
//! caller (each subscriber has a bounded queue, and a slow one loses messages, not the
//! publisher's time). When the master goes away the node says so once, keeps its peer
//! connections, and registers everything again when a master answers (also a new one: the
//! master's PID is watched).
//!
//! The files: `state` (the [`Node`] handle and what its threads share), `options`
//! ([`NodeOptions`], [`global_name`]), `lifecycle` (`Node`'s methods and its `Drop`), `slave`
//! (the accept loops and the slave API), `publisher` ([`Publisher`] and the subscribers it
//! serves), `subscriber` ([`Subscriber`] and the publishers it reads) and `master`
//! (registration and the master watch). This file only re-exports them.

mod lifecycle;
mod master;
mod options;
mod publisher;
mod slave;
mod state;
mod subscriber;
#[cfg(test)]
mod tests;

pub use options::{NodeOptions, global_name};
pub use publisher::Publisher;
pub use state::Node;
pub use subscriber::Subscriber;
