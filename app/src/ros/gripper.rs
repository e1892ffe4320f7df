//! MoveIt's gripper on ROS 1: an actionlib server for each gripper controller, as
//! gripper_action_controller serves it: `/<ns>/<controller>/gripper_cmd/{goal,cancel,status,
//! feedback,result}` (control_msgs/GripperCommandAction). A goal is a finger position and the
//! most effort; it ends SUCCEEDED at its goal (`reached_goal`), ABORTED when the fingers stall
//! on something (`stalled`; SUCCEEDED with the controller's `allow_stalling`), PREEMPTED when
//! cancelled (the fingers hold where they are) or replaced. A goal with a number that is not
//! finite is REJECTED. What a goal means is the shared bridge's
//! (app/src/bridge/action_goals.rs); actionlib's topics, ids, cancel rule and status list are
//! actions.rs's [`Actionlib`].

use std::sync::mpsc::Sender;

use anyhow::Result;
use rover_core::Action;
use rover_ros1::Node;
use rover_ros1::msgs::{
    GripperCommandActionFeedback, GripperCommandActionGoal, GripperCommandActionResult,
    GripperCommandResult,
};

use super::actions::{Actionlib, goal_status, rejected};
use crate::bridge::RosPlan;
use crate::bridge::action_goals::{ActionGoals, check_gripper};
use crate::bridge::action_intake::ActionWire;
use crate::bridge::events::{ControlUpdate, GripperSample};

/// GripperCommand's result (and feedback) fields from a sample.
fn result_of(g: GripperSample) -> GripperCommandResult {
    GripperCommandResult {
        position: g.position,
        effort: g.effort,
        stalled: g.stalled,
        reached_goal: g.reached_goal,
    }
}

/// `gripper_cmd` for one gripper controller.
pub(super) struct GripperServer {
    io: Actionlib<
        GripperCommandActionGoal,
        GripperCommandActionFeedback,
        GripperCommandActionResult,
    >,
}

/// Serves `gripper_cmd` for each of the plan's gripper controllers on `node`.
pub(super) fn gripper_servers(
    node: &Node,
    plan: &RosPlan,
    robot: &rover_sim::model::RobotModel,
) -> Result<Vec<Box<dyn ActionWire>>> {
    ActionGoals::grippers(plan, robot)
        .into_iter()
        .map(|goals| {
            let server = GripperServer {
                io: Actionlib::open(node, goals, "control_msgs/GripperCommandAction")?,
            };
            Ok(Box::new(server) as Box<dyn ActionWire>)
        })
        .collect()
}

impl ActionWire for GripperServer {
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = self.io.goals.run(update);
        while let Some((id, msg)) = self.io.next_goal(|m| m.goal_id.clone()) {
            let c = msg.command;
            match check_gripper(c.position, c.max_effort) {
                Ok(()) => self.io.goals.accept_gripper(
                    id,
                    (c.position, c.max_effort),
                    (now_s, run),
                    to_session,
                ),
                Err(r) => {
                    tracing::warn!(
                        "ROS: {} rejected goal {}: {}",
                        self.io.goals.controller,
                        id.id,
                        r.why
                    );
                    let m = &mut self.io.result_msg;
                    m.status = rejected(id, &r);
                    m.result = result_of(run.gripper);
                    self.io.publish_result(now_s);
                }
            }
        }
        while let Some(named) = self.io.next_cancel() {
            self.io
                .goals
                .cancel_gripper(named, run.gripper.position, to_session);
        }
        self.io.goals.follow(run, now_s);
        let mut ended = Vec::new();
        self.io
            .goals
            .take_ended(|g| ended.push((goal_status(g), result_of(g.last_run.gripper))));
        for (status, result) in ended {
            let m = &mut self.io.result_msg;
            m.status = status;
            m.result = result;
            self.io.publish_result(now_s);
        }
        if self.io.feedback_due(now_s)
            && let Some(g) = self.io.goals.goals.iter().find(|g| !g.ended())
        {
            let m = &mut self.io.feedback_msg;
            m.status = goal_status(g);
            m.feedback = result_of(run.gripper);
            self.io.publish_feedback(now_s);
        }
        self.io.publish_status(now_s);
    }
}
