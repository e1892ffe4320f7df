//! MoveIt's way in on ROS 1: an actionlib server for each joint trajectory controller, as
//! gazebo_ros_control with joint_trajectory_controller serves it:
//! `/<ns>/<controller>/follow_joint_trajectory/{goal,cancel,status,feedback,result}`
//! (control_msgs/FollowJointTrajectoryAction). What a goal means (which are refused and with
//! which code, how its run ends, preemption, cancels that stop the joints) is the shared
//! bridge's (app/src/bridge/action_goals.rs); here is actionlib's wire:
//! - a refused goal gets a REJECTED result with its code (INVALID_JOINTS, INVALID_GOAL);
//! - an accepted one is ACTIVE, then SUCCEEDED, ABORTED (with the tolerance violated) or
//!   PREEMPTED (cancelled, or replaced by a newer goal or a topic command), with its result;
//! - `cancel` as actionlib reads it: an id, or every goal stamped up to a time (an empty id
//!   and zero stamp: every goal);
//! - `status` at 5 Hz of sim time (actionlib's `status_frequency`) and on every change;
//!   feedback at 20 Hz while a goal runs.
//!
//! A topic family on the publishing thread: requests are read at every control update and
//! accepted trajectories go to the session through the input, as a command on the
//! controller's topic would.

use std::sync::mpsc::Sender;

use anyhow::Result;
use rover_core::Action;
use rover_ros1::msgs::{
    FollowJointTrajectoryActionFeedback, FollowJointTrajectoryActionGoal,
    FollowJointTrajectoryActionResult, GoalId, GoalStatus, GoalStatusArray,
};
use rover_ros1::{Node, Publisher, Subscriber};

use super::convert::{header, seq_of, sim_trajectory};
use crate::bridge::RosPlan;
use crate::bridge::action_goals::{ActionGoals, FeedbackArrays, Goal, GoalState};
use crate::bridge::events::{ControlUpdate, RunSample, TopicFamily};

/// Seconds between status messages (actionlib's 5 Hz).
const STATUS_PERIOD_S: f64 = 0.2;
/// Seconds between feedback messages (joint_trajectory_controller's 20 Hz).
pub(super) const FEEDBACK_PERIOD_S: f64 = 0.05;

/// A goal's actionlib status.
fn status_of(state: GoalState) -> u8 {
    match state {
        GoalState::Executing => GoalStatus::ACTIVE,
        GoalState::Succeeded => GoalStatus::SUCCEEDED,
        GoalState::Aborted => GoalStatus::ABORTED,
        GoalState::Canceled => GoalStatus::PREEMPTED,
    }
}

/// A goal's entry in the status list.
pub(super) fn goal_status(g: &Goal<GoalId>) -> GoalStatus {
    GoalStatus {
        goal_id: g.id.clone(),
        status: status_of(g.state),
        text: g.error_string.clone(),
    }
}

/// One controller's action server.
struct ActionServer {
    goals: ActionGoals<GoalId>,
    goal_in: Subscriber<FollowJointTrajectoryActionGoal>,
    cancel_in: Subscriber<GoalId>,
    status: Publisher<GoalStatusArray>,
    feedback: Publisher<FollowJointTrajectoryActionFeedback>,
    result: Publisher<FollowJointTrajectoryActionResult>,
    status_msg: GoalStatusArray,
    feedback_msg: FollowJointTrajectoryActionFeedback,
    result_msg: FollowJointTrajectoryActionResult,
    feedback_arrays: FeedbackArrays,
    next_status_s: f64,
    next_feedback_s: f64,
    /// Goals without an id of their own get `rover-N`.
    unnamed: u64,
}

/// The action servers of every joint trajectory controller, and the way to the session.
pub(super) struct TrajectoryActions {
    servers: Vec<ActionServer>,
    to_session: Sender<Action>,
}

impl TrajectoryActions {
    /// Serves `follow_joint_trajectory` for each of the plan's trajectory controllers on
    /// `node`; accepted trajectories go to the session through `to_session`.
    pub fn serve(node: &Node, plan: &RosPlan, to_session: Sender<Action>) -> Result<Self> {
        let mut servers = Vec::new();
        for goals in ActionGoals::trajectories(plan, "~/command") {
            let topic = |name: &str| format!("{}/{name}", goals.action);
            tracing::info!(
                "ROS: action {} (control_msgs/FollowJointTrajectoryAction)",
                goals.action
            );
            servers.push(ActionServer {
                goal_in: node.subscribe(&topic("goal"), 10)?,
                cancel_in: node.subscribe(&topic("cancel"), 10)?,
                status: node.advertise(&topic("status"), 10, false)?,
                feedback: node.advertise(&topic("feedback"), 10, false)?,
                result: node.advertise(&topic("result"), 10, false)?,
                status_msg: GoalStatusArray::default(),
                feedback_msg: FollowJointTrajectoryActionFeedback::default(),
                result_msg: FollowJointTrajectoryActionResult::default(),
                feedback_arrays: FeedbackArrays::default(),
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

impl TopicFamily for TrajectoryActions {
    fn control(&mut self, update: &ControlUpdate) {
        for server in &mut self.servers {
            server.update(update, &self.to_session);
        }
    }
}

impl ActionServer {
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = self.goals.run(update);
        while let Some(msg) = self.goal_in.try_recv() {
            self.take_goal(msg, now_s, run, to_session);
        }
        while let Some(cancel) = self.cancel_in.try_recv() {
            self.goals.cancel_trajectory(named_by(&cancel), to_session);
        }
        self.goals.follow(run, now_s);
        let (result, msg) = (&mut self.result, &mut self.result_msg);
        self.goals.take_ended(|g| {
            msg.status = goal_status(g);
            msg.result.error_code = g.error_code;
            msg.result.error_string.clone_from(&g.error_string);
            publish_result(result, msg, now_s);
        });
        if now_s + 1e-9 >= self.next_feedback_s {
            self.next_feedback_s = now_s + FEEDBACK_PERIOD_S;
            self.publish_feedback(update, now_s);
        }
        publish_status(
            &mut self.goals,
            (&mut self.status, &mut self.status_msg),
            &mut self.next_status_s,
            now_s,
        );
    }

    /// Checks a goal: a refused one gets its REJECTED result at once, an accepted one starts.
    fn take_goal(
        &mut self,
        msg: FollowJointTrajectoryActionGoal,
        now_s: f64,
        run: RunSample,
        to_session: &Sender<Action>,
    ) {
        let id = own_id(msg.goal_id, &mut self.unnamed);
        let trajectory = sim_trajectory(msg.goal.trajectory);
        match self.goals.check(&trajectory, false) {
            Ok(()) => self
                .goals
                .accept_trajectory(id, trajectory, (now_s, run), to_session),
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
                    text: r.why.clone(),
                };
                m.result.error_code = r.code;
                m.result.error_string = r.why;
                publish_result(&mut self.result, m, now_s);
            }
        }
    }

    /// The executing goal's feedback: the joints' setpoints, positions and their difference.
    fn publish_feedback(&mut self, update: &ControlUpdate, now_s: f64) {
        let arrays = &mut self.feedback_arrays;
        let Some(g) = self.goals.feedback(update, now_s, arrays) else {
            return;
        };
        let m = &mut self.feedback_msg;
        m.status = goal_status(g);
        let f = &mut m.feedback;
        f.header.stamp_s = now_s;
        f.joint_names.clone_from(&self.goals.joint_names);
        // Copied in place: no allocation once warm.
        f.desired.positions.clone_from(&arrays.desired);
        f.actual.positions.clone_from(&arrays.actual);
        f.actual.velocities.clone_from(&arrays.actual_velocities);
        f.error.positions.clone_from(&arrays.error);
        m.header.seq = seq_of(&self.feedback);
        m.header.stamp_s = now_s;
        self.feedback.publish(m);
    }
}

/// Publishes a result, stamped `now_s`.
fn publish_result(
    publisher: &mut Publisher<FollowJointTrajectoryActionResult>,
    msg: &mut FollowJointTrajectoryActionResult,
    now_s: f64,
) {
    msg.header = header("");
    msg.header.seq = seq_of(publisher);
    msg.header.stamp_s = now_s;
    publisher.publish(msg);
}

/// Which goals a `cancel` message names, by actionlib's rule: the goal with its id, and every
/// goal stamped at or before a non-zero stamp; an empty id with a zero stamp is every goal.
pub(super) fn named_by(cancel: &GoalId) -> impl Fn(&Goal<GoalId>) -> bool + '_ {
    move |g| {
        (cancel.id.is_empty() && cancel.stamp_s == 0.0)
            || (!cancel.id.is_empty() && g.id.id == cancel.id)
            || (cancel.stamp_s != 0.0 && g.id.stamp_s <= cancel.stamp_s)
    }
}

/// A goal's id, `rover-N` for a goal sent without one.
pub(super) fn own_id(mut id: GoalId, unnamed: &mut u64) -> GoalId {
    if id.id.is_empty() {
        *unnamed += 1;
        id.id = format!("rover-{unnamed}");
    }
    id
}

/// The `status` topic: at 5 Hz and whenever a goal's state changed.
pub(super) fn publish_status(
    goals: &mut ActionGoals<GoalId>,
    (publisher, msg): (&mut Publisher<GoalStatusArray>, &mut GoalStatusArray),
    next_s: &mut f64,
    now_s: f64,
) {
    if goals.take_changed() || now_s + 1e-9 >= *next_s {
        *next_s = now_s + STATUS_PERIOD_S;
        msg.status_list.clear();
        msg.status_list.extend(goals.goals.iter().map(goal_status));
        msg.header.seq = seq_of(publisher);
        msg.header.stamp_s = now_s;
        publisher.publish(msg);
    }
}
