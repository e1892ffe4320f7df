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
//! controller's topic would. [`Actionlib`] is an actionlib server's topics and bookkeeping,
//! whatever its action (gripper.rs serves GripperCommand with it); each server is an
//! [`ActionWire`], run with the others by the shared intake (app/src/bridge/action_intake.rs).

use std::sync::mpsc::Sender;

use anyhow::Result;
use rover_core::Action;
use rover_ros1::msgs::{
    FollowJointTrajectoryActionFeedback, FollowJointTrajectoryActionGoal,
    FollowJointTrajectoryActionResult, GoalId, GoalStatus, GoalStatusArray, Header,
};
use rover_ros1::{Decode, Message, Node, Publisher, Subscriber};

use super::convert::{seq_of, sim_trajectory};
use crate::bridge::RosPlan;
use crate::bridge::action_goals::{ActionGoals, FeedbackArrays, Goal, GoalState, Rejection};
use crate::bridge::action_intake::ActionWire;
use crate::bridge::events::{ControlUpdate, RunSample};

/// Seconds between status messages (actionlib's 5 Hz).
const STATUS_PERIOD_S: f64 = 0.2;
/// Seconds between feedback messages (joint_trajectory_controller's 20 Hz).
const FEEDBACK_PERIOD_S: f64 = 0.05;

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

/// A refused goal's status: REJECTED, with the reason.
pub(super) fn rejected(id: GoalId, why: &Rejection) -> GoalStatus {
    GoalStatus {
        goal_id: id,
        status: GoalStatus::REJECTED,
        text: why.why.clone(),
    }
}

/// An action's `feedback` or `result` message: it has a header to stamp.
pub(super) trait Stamped: Message + Default {
    /// Its header.
    fn header(&mut self) -> &mut Header;
}

/// [`Stamped`] for action messages whose header is their `header` field.
macro_rules! stamped {
    ($($t:ty),*) => {$(
        impl Stamped for $t {
            fn header(&mut self) -> &mut Header {
                &mut self.header
            }
        }
    )*};
}

stamped!(
    FollowJointTrajectoryActionResult,
    FollowJointTrajectoryActionFeedback,
    rover_ros1::msgs::GripperCommandActionResult,
    rover_ros1::msgs::GripperCommandActionFeedback
);

/// Publishes `msg` numbered and stamped `now_s`.
fn publish<M: Stamped>(publisher: &mut Publisher<M>, msg: &mut M, now_s: f64) {
    let seq = seq_of(publisher);
    let h = msg.header();
    h.seq = seq;
    h.stamp_s = now_s;
    publisher.publish(msg);
}

/// One actionlib server's five topics and its goal book, whatever its action: goals `G` in,
/// feedback `F` and results `R` out.
pub(super) struct Actionlib<G, F, R> {
    /// What its goals mean.
    pub goals: ActionGoals<GoalId>,
    goal_in: Subscriber<G>,
    cancel_in: Subscriber<GoalId>,
    status: Publisher<GoalStatusArray>,
    feedback: Publisher<F>,
    result: Publisher<R>,
    status_msg: GoalStatusArray,
    /// The feedback message, refilled for each publication.
    pub feedback_msg: F,
    /// The result message, refilled for each publication.
    pub result_msg: R,
    next_status_s: f64,
    next_feedback_s: f64,
    /// Goals without an id of their own get `rover-N`.
    unnamed: u64,
}

impl<G: Decode + Send + 'static, F: Stamped, R: Stamped> Actionlib<G, F, R> {
    /// Subscribes to `goals.action`'s `goal` and `cancel` and advertises its `status`,
    /// `feedback` and `result` on `node`; `kind` names the action type for the log.
    pub fn open(node: &Node, goals: ActionGoals<GoalId>, kind: &str) -> Result<Self> {
        let topic = |name: &str| format!("{}/{name}", goals.action);
        tracing::info!("ROS: action {} ({kind})", goals.action);
        Ok(Self {
            goal_in: node.subscribe(&topic("goal"), 10)?,
            cancel_in: node.subscribe(&topic("cancel"), 10)?,
            status: node.advertise(&topic("status"), 10, false)?,
            feedback: node.advertise(&topic("feedback"), 10, false)?,
            result: node.advertise(&topic("result"), 10, false)?,
            status_msg: GoalStatusArray::default(),
            feedback_msg: F::default(),
            result_msg: R::default(),
            next_status_s: 0.0,
            next_feedback_s: 0.0,
            unnamed: 0,
            goals,
        })
    }

    /// The next goal that came, with its id (`rover-N` for a goal sent without one).
    pub fn next_goal(&mut self, id_of: impl Fn(&G) -> GoalId) -> Option<(GoalId, G)> {
        let msg = self.goal_in.try_recv()?;
        let mut id = id_of(&msg);
        if id.id.is_empty() {
            self.unnamed += 1;
            id.id = format!("rover-{}", self.unnamed);
        }
        Some((id, msg))
    }

    /// The next `cancel` message's rule, as actionlib reads it: the goal with its id, and
    /// every goal stamped at or before a non-zero stamp; an empty id with a zero stamp is
    /// every goal.
    pub fn next_cancel(&mut self) -> Option<impl Fn(&Goal<GoalId>) -> bool + use<G, F, R>> {
        let cancel = self.cancel_in.try_recv()?;
        Some(move |g: &Goal<GoalId>| {
            (cancel.id.is_empty() && cancel.stamp_s == 0.0)
                || (!cancel.id.is_empty() && g.id.id == cancel.id)
                || (cancel.stamp_s != 0.0 && g.id.stamp_s <= cancel.stamp_s)
        })
    }

    /// Publishes [`Self::result_msg`].
    pub fn publish_result(&mut self, now_s: f64) {
        publish(&mut self.result, &mut self.result_msg, now_s);
    }

    /// Whether feedback is due (20 Hz).
    pub fn feedback_due(&mut self, now_s: f64) -> bool {
        let due = now_s + 1e-9 >= self.next_feedback_s;
        if due {
            self.next_feedback_s = now_s + FEEDBACK_PERIOD_S;
        }
        due
    }

    /// Publishes [`Self::feedback_msg`].
    pub fn publish_feedback(&mut self, now_s: f64) {
        publish(&mut self.feedback, &mut self.feedback_msg, now_s);
    }

    /// The `status` topic: at 5 Hz and whenever a goal's state changed.
    pub fn publish_status(&mut self, now_s: f64) {
        if self.goals.take_changed() || now_s + 1e-9 >= self.next_status_s {
            self.next_status_s = now_s + STATUS_PERIOD_S;
            let m = &mut self.status_msg;
            m.status_list.clear();
            m.status_list
                .extend(self.goals.goals.iter().map(goal_status));
            m.header.seq = seq_of(&self.status);
            m.header.stamp_s = now_s;
            self.status.publish(m);
        }
    }
}

/// `follow_joint_trajectory` for one trajectory controller.
pub(super) struct TrajectoryServer {
    io: Actionlib<
        FollowJointTrajectoryActionGoal,
        FollowJointTrajectoryActionFeedback,
        FollowJointTrajectoryActionResult,
    >,
    feedback_arrays: FeedbackArrays,
}

/// Serves `follow_joint_trajectory` for each of the plan's trajectory controllers on `node`.
pub(super) fn trajectory_servers(node: &Node, plan: &RosPlan) -> Result<Vec<Box<dyn ActionWire>>> {
    ActionGoals::trajectories(plan, "~/command")
        .into_iter()
        .map(|goals| {
            let server = TrajectoryServer {
                io: Actionlib::open(node, goals, "control_msgs/FollowJointTrajectoryAction")?,
                feedback_arrays: FeedbackArrays::default(),
            };
            Ok(Box::new(server) as Box<dyn ActionWire>)
        })
        .collect()
}

impl ActionWire for TrajectoryServer {
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = self.io.goals.run(update);
        while let Some((id, msg)) = self.io.next_goal(|m| m.goal_id.clone()) {
            self.take_goal(id, msg, (now_s, run), to_session);
        }
        while let Some(named) = self.io.next_cancel() {
            self.io.goals.cancel_trajectory(named, to_session);
        }
        self.io.goals.follow(run, now_s);
        let mut ended = Vec::new();
        self.io
            .goals
            .take_ended(|g| ended.push((goal_status(g), g.error_code)));
        for (status, code) in ended {
            let m = &mut self.io.result_msg;
            m.result.error_code = code;
            m.result.error_string.clone_from(&status.text);
            m.status = status;
            self.io.publish_result(now_s);
        }
        if self.io.feedback_due(now_s) {
            self.publish_feedback(update, now_s);
        }
        self.io.publish_status(now_s);
    }
}

impl TrajectoryServer {
    /// Checks a goal: a refused one gets its REJECTED result at once, an accepted one starts.
    fn take_goal(
        &mut self,
        id: GoalId,
        msg: FollowJointTrajectoryActionGoal,
        now: (f64, RunSample),
        to_session: &Sender<Action>,
    ) {
        let trajectory = sim_trajectory(msg.goal.trajectory);
        match self.io.goals.check(&trajectory, false) {
            Ok(()) => self
                .io
                .goals
                .accept_trajectory(id, trajectory, now, to_session),
            Err(r) => {
                tracing::warn!(
                    "ROS: {} rejected goal {}: {}",
                    self.io.goals.controller,
                    id.id,
                    r.why
                );
                let m = &mut self.io.result_msg;
                m.status = rejected(id, &r);
                m.result.error_code = r.code;
                m.result.error_string = r.why;
                self.io.publish_result(now.0);
            }
        }
    }

    /// The executing goal's feedback: the joints' setpoints, positions and their difference.
    fn publish_feedback(&mut self, update: &ControlUpdate, now_s: f64) {
        let arrays = &mut self.feedback_arrays;
        let Some(g) = self.io.goals.feedback(update, now_s, arrays) else {
            return;
        };
        let m = &mut self.io.feedback_msg;
        m.status = goal_status(g);
        let f = &mut m.feedback;
        f.header.stamp_s = now_s;
        f.joint_names.clone_from(&self.io.goals.joint_names);
        // Copied in place: no allocation once warm.
        f.desired.positions.clone_from(&arrays.desired);
        f.actual.positions.clone_from(&arrays.actual);
        f.actual.velocities.clone_from(&arrays.actual_velocities);
        f.error.positions.clone_from(&arrays.error);
        self.io.publish_feedback(now_s);
    }
}
