//! MoveIt's gripper on ROS 1: an actionlib server for each gripper controller, as
//! gripper_action_controller serves it: `/<ns>/<controller>/gripper_cmd/{goal,cancel,status,
//! feedback,result}` (control_msgs/GripperCommandAction). A goal is a finger position and the
//! most effort; it ends SUCCEEDED at its goal (`reached_goal`), ABORTED when the fingers stall
//! on something (`stalled`; SUCCEEDED with the controller's `allow_stalling`), PREEMPTED when
//! cancelled (the fingers hold where they are) or replaced. A goal with a number that is not
//! finite is REJECTED. What a goal means is the shared bridge's
//! (app/src/bridge/action_goals.rs); the cancel rule, ids and status list are actions.rs's.

use std::sync::mpsc::Sender;

use anyhow::Result;
use rover_core::Action;
use rover_ros1::msgs::{
    GoalId, GoalStatus, GoalStatusArray, GripperCommandActionFeedback, GripperCommandActionGoal,
    GripperCommandActionResult, GripperCommandResult,
};
use rover_ros1::{Node, Publisher, Subscriber};

use super::actions::{FEEDBACK_PERIOD_S, goal_status, named_by, own_id, publish_status};
use super::convert::seq_of;
use crate::bridge::RosPlan;
use crate::bridge::action_goals::ActionGoals;
use crate::bridge::events::{ControlUpdate, GripperSample, TopicFamily};

/// GripperCommand's result (and feedback) fields from a sample.
fn result_of(g: GripperSample) -> GripperCommandResult {
    GripperCommandResult {
        position: g.position,
        effort: g.effort,
        stalled: g.stalled,
        reached_goal: g.reached_goal,
    }
}

/// One gripper controller's action server.
struct GripperServer {
    goals: ActionGoals<GoalId>,
    goal_in: Subscriber<GripperCommandActionGoal>,
    cancel_in: Subscriber<GoalId>,
    status: Publisher<GoalStatusArray>,
    feedback: Publisher<GripperCommandActionFeedback>,
    result: Publisher<GripperCommandActionResult>,
    status_msg: GoalStatusArray,
    feedback_msg: GripperCommandActionFeedback,
    result_msg: GripperCommandActionResult,
    next_status_s: f64,
    next_feedback_s: f64,
    unnamed: u64,
}

/// The action servers of every gripper controller, and the way to the session.
pub(super) struct GripperActions {
    servers: Vec<GripperServer>,
    to_session: Sender<Action>,
}

impl GripperActions {
    /// Serves `gripper_cmd` for each of the plan's gripper controllers on `node`; accepted
    /// commands go to the session through `to_session`.
    pub fn serve(
        node: &Node,
        plan: &RosPlan,
        robot: &rover_sim::RobotModel,
        to_session: Sender<Action>,
    ) -> Result<Self> {
        let mut servers = Vec::new();
        for goals in ActionGoals::grippers(plan, robot) {
            let topic = |name: &str| format!("{}/{name}", goals.action);
            tracing::info!(
                "ROS: action {} (control_msgs/GripperCommandAction)",
                goals.action
            );
            servers.push(GripperServer {
                goal_in: node.subscribe(&topic("goal"), 10)?,
                cancel_in: node.subscribe(&topic("cancel"), 10)?,
                status: node.advertise(&topic("status"), 10, false)?,
                feedback: node.advertise(&topic("feedback"), 10, false)?,
                result: node.advertise(&topic("result"), 10, false)?,
                status_msg: GoalStatusArray::default(),
                feedback_msg: GripperCommandActionFeedback::default(),
                result_msg: GripperCommandActionResult::default(),
                next_status_s: 0.0,
                next_feedback_s: 0.0,
                unnamed: 0,
                goals,
            });
        }
        Ok(Self {
            servers,
            to_session,
        })
    }
}

impl TopicFamily for GripperActions {
    fn control(&mut self, update: &ControlUpdate) {
        for server in &mut self.servers {
            server.update(update, &self.to_session);
        }
    }
}

impl GripperServer {
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = self.goals.run(update);
        while let Some(msg) = self.goal_in.try_recv() {
            let id = own_id(msg.goal_id, &mut self.unnamed);
            let c = msg.command;
            match ActionGoals::<GoalId>::check_gripper(c.position, c.max_effort) {
                Ok(()) => self.goals.accept_gripper(
                    id,
                    (c.position, c.max_effort),
                    (now_s, run),
                    to_session,
                ),
                Err(r) => {
                    tracing::warn!(
                        "ROS: {} rejected goal {}: {}",
                        self.goals.controller,
                        id.id,
                        r.why
                    );
                    let m = &mut self.result_msg;
                    m.status = GoalStatus {
                        goal_id: id,
                        status: GoalStatus::REJECTED,
                        text: r.why,
                    };
                    m.result = result_of(run.gripper);
                    publish(&mut self.result, m, now_s);
                }
            }
        }
        while let Some(cancel) = self.cancel_in.try_recv() {
            self.goals
                .cancel_gripper(named_by(&cancel), run.gripper.position, to_session);
        }
        self.goals.follow(run, now_s);
        let (result, msg) = (&mut self.result, &mut self.result_msg);
        self.goals.take_ended(|g| {
            msg.status = goal_status(g);
            msg.result = result_of(g.last_run.gripper);
            publish(result, msg, now_s);
        });
        if now_s + 1e-9 >= self.next_feedback_s {
            self.next_feedback_s = now_s + FEEDBACK_PERIOD_S;
            if let Some(g) = self.goals.goals.iter().find(|g| !g.ended()) {
                let m = &mut self.feedback_msg;
                m.status = goal_status(g);
                m.feedback = result_of(run.gripper);
                publish(&mut self.feedback, m, now_s);
            }
        }
        publish_status(
            &mut self.goals,
            (&mut self.status, &mut self.status_msg),
            &mut self.next_status_s,
            now_s,
        );
    }
}

/// The messages a gripper server publishes: stamped and numbered.
trait Stamped: rover_ros1::Message {
    fn header(&mut self) -> &mut rover_ros1::msgs::Header;
}

impl Stamped for GripperCommandActionResult {
    fn header(&mut self) -> &mut rover_ros1::msgs::Header {
        &mut self.header
    }
}

impl Stamped for GripperCommandActionFeedback {
    fn header(&mut self) -> &mut rover_ros1::msgs::Header {
        &mut self.header
    }
}

/// Publishes `msg` stamped `now_s`.
fn publish<M: Stamped>(publisher: &mut Publisher<M>, msg: &mut M, now_s: f64) {
    let seq = seq_of(publisher);
    let h = msg.header();
    h.seq = seq;
    h.stamp_s = now_s;
    publisher.publish(msg);
}
