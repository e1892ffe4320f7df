//! `follow_joint_trajectory` for each joint trajectory controller, as ros2_control's
//! joint_trajectory_controller serves it (`/<controller>/follow_joint_trajectory`,
//! control_msgs/action/FollowJointTrajectory): the send_goal, cancel_goal and get_result
//! services and the feedback and status topics, as rcl maps an action onto them
//! (`rq/<action>/_action/send_goalRequest`, `rt/<action>/_action/feedback`, ...).
//!
//! A topic family on the publishing thread: at every control update it takes the requests
//! that came and answers them. What a goal means (which are refused, how its run ends,
//! preemption, cancels) is the shared bridge's (app/src/bridge/action_goals.rs); here is
//! ROS 2's wire: a refused goal is not accepted (its reason in rover's log), an ended one is
//! SUCCEEDED, ABORTED or CANCELED in the status list and get_result's reply. Feedback at
//! 20 Hz (joint_trajectory_controller's `action_monitor_rate`).

use std::sync::mpsc::Sender;

use anyhow::{Context, Result};
use rover_core::Action;
use rover_sim::{JointTrajectory, TrajectoryPoint};
use rustdds::no_key::DataWriter;
use rustdds::{CDRSerializerAdapter, DomainParticipant, GUID, QosPolicies, RTPSEntity, TopicKind};
use serde::Serialize;

use super::action_msgs::{
    CANCEL_ERROR_GOAL_TERMINATED, CANCEL_ERROR_NONE, CANCEL_ERROR_UNKNOWN_GOAL_ID, CancelGoal,
    FEEDBACK_TYPE, FeedbackMessage, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    GetResult, GoalInfo, GoalStatus, GoalStatusArray, STATUS_ABORTED, STATUS_CANCELED,
    STATUS_EXECUTING, STATUS_SUCCEEDED, STATUS_TYPE, SendGoal, Uuid,
};
use super::dds::{default_qos, latched_qos};
use super::discovery::RosDistro;
use super::msgs::{Duration, Time};
use super::services::{RequestHeader, Server};
use crate::bridge::RosPlan;
use crate::bridge::action_goals::{ActionGoals, FeedbackArrays, Goal, GoalState, code};
use crate::bridge::events::{ControlUpdate, TopicFamily};

/// Seconds between feedback messages (20 Hz).
const FEEDBACK_PERIOD_S: f64 = 0.05;

/// A writer of `M` on the DDS topic `name` (already mapped: `rt/...`).
fn writer<M: Serialize>(
    participant: &DomainParticipant,
    publisher: &rustdds::Publisher,
    name: &str,
    type_name: &str,
    qos: QosPolicies,
) -> Result<DataWriter<M, CDRSerializerAdapter<M>>> {
    let topic = participant
        .create_topic(
            name.to_owned(),
            type_name.to_owned(),
            &qos,
            TopicKind::NoKey,
        )
        .with_context(|| format!("creating the DDS topic {name}"))?;
    publisher
        .create_datawriter_no_key(&topic, Some(qos))
        .with_context(|| format!("creating the writer of {name}"))
}

/// A goal's status as action_msgs numbers it.
fn status_of(state: GoalState) -> i8 {
    match state {
        GoalState::Executing => STATUS_EXECUTING,
        GoalState::Succeeded => STATUS_SUCCEEDED,
        GoalState::Aborted => STATUS_ABORTED,
        GoalState::Canceled => STATUS_CANCELED,
    }
}

/// A goal's id and acceptance time.
fn goal_info(g: &Goal<Uuid>) -> GoalInfo {
    GoalInfo {
        goal_id: g.id,
        stamp: Time::from_secs(g.accepted_s),
    }
}

/// A goal's result.
fn result(g: &Goal<Uuid>) -> FollowJointTrajectoryResult {
    FollowJointTrajectoryResult {
        error_code: g.error_code,
        error_string: g.error_string.clone(),
    }
}

/// One controller's action server.
struct ActionServer {
    goals: ActionGoals<Uuid>,
    send_goal: Server<SendGoal>,
    cancel_goal: Server<CancelGoal>,
    get_result: Server<GetResult>,
    feedback: DataWriter<FeedbackMessage, CDRSerializerAdapter<FeedbackMessage>>,
    status: DataWriter<GoalStatusArray, CDRSerializerAdapter<GoalStatusArray>>,
    /// get_result requests waiting for their goal to end.
    waiting: Vec<(RequestHeader, Uuid)>,
    next_feedback_s: f64,
    feedback_arrays: FeedbackArrays,
    feedback_msg: FeedbackMessage,
}

/// The action servers of every joint trajectory controller, and the way to the session.
pub(super) struct TrajectoryActions {
    servers: Vec<ActionServer>,
    to_session: Sender<Action>,
}

impl TrajectoryActions {
    /// Serves `follow_joint_trajectory` for each of the plan's trajectory controllers;
    /// accepted trajectories go to the session through `to_session`.
    pub fn serve(
        participant: &DomainParticipant,
        subscriber: &rustdds::Subscriber,
        publisher: &rustdds::Publisher,
        plan: &RosPlan,
        distro: RosDistro,
        to_session: Sender<Action>,
    ) -> Result<Self> {
        let mut servers = Vec::new();
        for goals in ActionGoals::trajectories(plan, "~/joint_trajectory") {
            let internal = format!("{}/_action/", goals.action);
            let dds = format!("rt{internal}");
            tracing::info!(
                "ROS 2: action {} (control_msgs/action/FollowJointTrajectory)",
                goals.action
            );
            servers.push(ActionServer {
                send_goal: Server::new(
                    participant,
                    subscriber,
                    publisher,
                    &format!("{internal}send_goal"),
                )?,
                cancel_goal: Server::new(
                    participant,
                    subscriber,
                    publisher,
                    &format!("{internal}cancel_goal"),
                )?,
                get_result: Server::new(
                    participant,
                    subscriber,
                    publisher,
                    &format!("{internal}get_result"),
                )?,
                feedback: writer(
                    participant,
                    publisher,
                    &format!("{dds}feedback"),
                    FEEDBACK_TYPE,
                    default_qos(),
                )?,
                status: writer(
                    participant,
                    publisher,
                    &format!("{dds}status"),
                    STATUS_TYPE,
                    latched_qos(),
                )?,
                goals,
                waiting: Vec::new(),
                next_feedback_s: 0.0,
                feedback_arrays: FeedbackArrays::default(),
                feedback_msg: FeedbackMessage {
                    with_index: distro >= RosDistro::Lyrical,
                    ..FeedbackMessage::default()
                },
            });
        }
        Ok(Self {
            servers,
            to_session,
        })
    }

    /// The servers' readers and writers, for `ros_discovery_info`.
    pub fn gids(&self) -> (Vec<GUID>, Vec<GUID>) {
        let mut readers = Vec::new();
        let mut writers = Vec::new();
        for s in &self.servers {
            for (r, w) in [
                s.send_goal.gids(),
                s.cancel_goal.gids(),
                s.get_result.gids(),
            ] {
                readers.push(r);
                writers.push(w);
            }
            writers.push(s.feedback.guid());
            writers.push(s.status.guid());
        }
        (readers, writers)
    }
}

impl TopicFamily for TrajectoryActions {
    fn control(&mut self, update: &ControlUpdate) {
        for server in &mut self.servers {
            server.update(update, &self.to_session);
        }
    }
}

/// A goal as the simulation takes it.
fn trajectory_of(goal: &FollowJointTrajectoryGoal) -> JointTrajectory {
    let secs = |d: Duration| f64::from(d.sec) + f64::from(d.nanosec) * 1e-9;
    let t = &goal.trajectory;
    let stamp = t.header.stamp;
    JointTrajectory {
        start_s: f64::from(stamp.sec) + f64::from(stamp.nanosec) * 1e-9,
        joint_names: t.joint_names.clone(),
        points: t
            .points
            .iter()
            .map(|p| TrajectoryPoint {
                positions: p.positions.clone(),
                velocities: p.velocities.clone(),
                accelerations: p.accelerations.clone(),
                time_from_start_s: secs(p.time_from_start),
            })
            .collect(),
    }
}

impl ActionServer {
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = self.goals.run(update);
        while let Some((header, (goal_id, goal))) = self.send_goal.next_request() {
            let trajectory = trajectory_of(&goal);
            let multi_dof = !goal.multi_dof_trajectory.points.is_empty();
            let accepted = match self.goals.check(&trajectory, multi_dof) {
                Ok(()) => {
                    self.goals
                        .accept_trajectory(goal_id, trajectory, (now_s, run), to_session);
                    true
                }
                Err(r) => {
                    tracing::warn!(
                        "ROS 2: {} rejected a goal: {}",
                        self.goals.controller,
                        r.why
                    );
                    false
                }
            };
            self.send_goal
                .reply(header, (accepted, Time::from_secs(now_s)));
        }
        while let Some((header, info)) = self.cancel_goal.next_request() {
            let reply = self.cancel(info, to_session);
            self.cancel_goal.reply(header, reply);
        }
        self.goals.follow(run, now_s);
        self.goals.take_ended(|_| ());
        while let Some((header, goal_id)) = self.get_result.next_request() {
            self.waiting.push((header, goal_id));
        }
        self.answer_results();
        if now_s + 1e-9 >= self.next_feedback_s {
            self.next_feedback_s = now_s + FEEDBACK_PERIOD_S;
            self.publish_feedback(update, now_s);
        }
        if self.goals.take_changed() {
            let status_list = self
                .goals
                .goals
                .iter()
                .map(|g| GoalStatus {
                    goal_info: goal_info(g),
                    status: status_of(g.state),
                })
                .collect();
            if let Err(e) = self.status.write(GoalStatusArray { status_list }, None) {
                tracing::warn!("ROS 2: {} status not sent ({e})", self.goals.controller);
            }
        }
    }

    /// Cancels the goals `info` names (a zero id: all accepted up to its stamp, or all with a
    /// zero stamp too); the joints stop where they are.
    fn cancel(&mut self, info: GoalInfo, to_session: &Sender<Action>) -> (i8, Vec<GoalInfo>) {
        let all = info.goal_id == Uuid::default();
        let until = f64::from(info.stamp.sec) + f64::from(info.stamp.nanosec) * 1e-9;
        let named = |g: &Goal<Uuid>| {
            if all {
                until == 0.0 || g.accepted_s <= until
            } else {
                g.id == info.goal_id
            }
        };
        let (cancelled, ended_before) = self.goals.cancel_trajectory(named, to_session);
        if cancelled.is_empty() {
            let code = if ended_before {
                CANCEL_ERROR_GOAL_TERMINATED
            } else {
                CANCEL_ERROR_UNKNOWN_GOAL_ID
            };
            return (code, Vec::new());
        }
        let infos = cancelled
            .iter()
            .filter_map(|id| self.goals.goal(id))
            .map(goal_info)
            .collect();
        (CANCEL_ERROR_NONE, infos)
    }

    /// Replies to the get_result requests whose goal has ended (an unknown goal: aborted,
    /// INVALID_GOAL, at once).
    fn answer_results(&mut self) {
        let goals = &self.goals;
        let mut replies = Vec::new();
        self.waiting.retain(|(header, id)| match goals.goal(id) {
            Some(g) if !g.ended() => true,
            Some(g) => {
                replies.push((*header, (status_of(g.state), result(g))));
                false
            }
            None => {
                let result = FollowJointTrajectoryResult {
                    error_code: code::INVALID_GOAL,
                    error_string: "unknown goal".to_owned(),
                };
                replies.push((*header, (STATUS_ABORTED, result)));
                false
            }
        });
        for (header, reply) in replies {
            self.get_result.reply(header, reply);
        }
    }

    /// The executing goal's feedback: the joints' setpoints, positions and their difference.
    fn publish_feedback(&mut self, update: &ControlUpdate, now_s: f64) {
        let arrays = &mut self.feedback_arrays;
        let Some(g) = self.goals.feedback(update, now_s, arrays) else {
            return;
        };
        let m = &mut self.feedback_msg;
        m.goal_id = g.id;
        m.header.stamp = Time::from_secs(now_s);
        m.joint_names.clone_from(&self.goals.joint_names);
        // The points' arrays are copied in place: no allocation once warm.
        m.desired.positions.clone_from(&arrays.desired);
        m.actual.positions.clone_from(&arrays.actual);
        m.actual.velocities.clone_from(&arrays.actual_velocities);
        m.error.positions.clone_from(&arrays.error);
        m.index = i32::try_from(arrays.index).unwrap_or(i32::MAX);
        if let Err(e) = self.feedback.write(m.clone(), None) {
            tracing::warn!("ROS 2: {} feedback not sent ({e})", self.goals.controller);
        }
    }
}
