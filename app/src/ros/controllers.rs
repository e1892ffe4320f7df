//! The controllers' `command` topics in: std_msgs/Float64 for single-joint controllers,
//! trajectory_msgs/JointTrajectory for joint trajectory controllers, as rover input
//! ([`JointAction`]). A command the simulation refuses (an unknown joint, a value that is not
//! finite) is dropped with a warning by the session.

use anyhow::Result;
use rover_core::{Action, InputSource, JointAction};
use rover_ros1::msgs;
use rover_ros1::{Node, Subscriber};

use super::convert::sim_trajectory;
use crate::bridge::RosPlan;
use crate::bridge::input::poll_in_turn;

#[derive(Debug)]
enum Topic {
    Value(Subscriber<msgs::Float64>),
    Trajectory(Subscriber<msgs::JointTrajectory>),
}

/// The subscriptions to every controller's `command` topic.
#[derive(Debug)]
pub(super) struct ControllerCommands {
    topics: Vec<(String, Topic)>,
    /// Where the next poll starts, so that every topic gets its turn.
    next: usize,
}

impl ControllerCommands {
    /// Subscribes to the plan's controller topics.
    pub fn subscribe(node: &Node, plan: &RosPlan) -> Result<Self> {
        let mut topics = Vec::with_capacity(plan.controllers.len());
        for c in &plan.controllers {
            let topic = if c.trajectory {
                Topic::Trajectory(node.subscribe(&c.command_topic, 10)?)
            } else {
                Topic::Value(node.subscribe(&c.command_topic, 10)?)
            };
            topics.push((c.name.clone(), topic));
        }
        Ok(Self { topics, next: 0 })
    }
}

/// A trajectory message as `controller`'s action.
fn trajectory_action(controller: &str, msg: msgs::JointTrajectory) -> JointAction {
    JointAction::Trajectory {
        controller: controller.to_owned(),
        trajectory: Box::new(sim_trajectory(msg)),
    }
}

impl InputSource for ControllerCommands {
    fn poll(&mut self) -> Option<Action> {
        poll_in_turn(
            &mut self.topics,
            &mut self.next,
            |(name, topic)| match topic {
                Topic::Value(sub) => sub.try_recv().map(|m| JointAction::Controller {
                    name: name.clone(),
                    value: m.data,
                }),
                Topic::Trajectory(sub) => sub.try_recv().map(|m| trajectory_action(name, m)),
            },
        )
    }
}
