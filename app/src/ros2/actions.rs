//! `follow_joint_trajectory` for each joint trajectory controller, as ros2_control's
//! joint_trajectory_controller serves it (`/<controller>/follow_joint_trajectory`,
//! control_msgs/action/FollowJointTrajectory): the send_goal, cancel_goal and get_result
//! services and the feedback and status topics, as rcl maps an action onto them
//! (`rq/<action>/_action/send_goalRequest`, `rt/<action>/_action/feedback`, ...).
//!
//! A topic family on the publishing thread: at every control update it takes the requests
//! that came, hands an accepted goal's trajectory to the session (through the input, as a
//! command on `~/joint_trajectory` would go), and follows the controller's run in the
//! update's samples: executing while it runs, then SUCCEEDED, ABORTED (with the tolerance
//! violated) or CANCELED. A new goal preempts the one executing (CANCELED, as
//! joint_trajectory_controller does); a cancel stops the joints where they are. Feedback at
//! 20 Hz (joint_trajectory_controller's `action_monitor_rate`): desired (the actuators'
//! setpoints), actual and error. The goal's tolerances and `goal_time_tolerance` are not
//! read: the controller's own, from the controllers file, apply.

use std::sync::mpsc::Sender;

use anyhow::{Context, Result};
use rover_core::{Action, JointAction};
use rover_sim::{JointTrajectory, TrajectoryOutcome, TrajectoryPoint};
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
use crate::bridge::events::{ControlUpdate, JointSample, RunSample, TopicFamily};

/// How long a goal may wait for its controller to start it (s of sim time).
const START_TIMEOUT_S: f64 = 1.0;
/// Seconds between feedback messages (20 Hz).
const FEEDBACK_PERIOD_S: f64 = 0.05;
/// Ended goals kept in the status list and for late get_result requests.
const ENDED_KEPT: usize = 16;

/// One goal.
struct Goal {
    info: GoalInfo,
    status: i8,
    result: FollowJointTrajectoryResult,
    /// The controller's run count when it was accepted: its own run is the next.
    runs_before: u64,
    /// Its run started.
    started: bool,
    accepted_s: f64,
    /// Its points' times from the start (s), for the feedback's index.
    point_times_s: Vec<f64>,
}

impl Goal {
    fn ended(&self) -> bool {
        self.status != STATUS_EXECUTING
    }

    fn end(&mut self, status: i8, error_code: i32, why: &str) {
        self.status = status;
        self.result = FollowJointTrajectoryResult {
            error_code,
            error_string: why.to_owned(),
        };
    }
}

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

/// One controller's action server.
struct ActionServer {
    controller: String,
    /// The controller's index in the plan (its run sample).
    index: usize,
    /// Its joints: plan joint indices and names, in the controller's order.
    joints: Vec<usize>,
    joint_names: Vec<String>,
    send_goal: Server<SendGoal>,
    cancel_goal: Server<CancelGoal>,
    get_result: Server<GetResult>,
    feedback: DataWriter<FeedbackMessage, CDRSerializerAdapter<FeedbackMessage>>,
    status: DataWriter<GoalStatusArray, CDRSerializerAdapter<GoalStatusArray>>,
    goals: Vec<Goal>,
    /// get_result requests waiting for their goal to end.
    waiting: Vec<(RequestHeader, Uuid)>,
    next_feedback_s: f64,
    feedback_msg: FeedbackMessage,
    /// The status changed since it was last published.
    status_changed: bool,
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
        for (index, c) in plan.controllers.iter().enumerate() {
            if !c.trajectory {
                continue;
            }
            let base = c
                .command_topic
                .strip_suffix("/command")
                .unwrap_or(&c.command_topic);
            let action = format!("{base}/follow_joint_trajectory");
            let internal = format!("{action}/_action/");
            let dds = format!("rt{internal}");
            tracing::info!("ROS 2: action {action} (control_msgs/action/FollowJointTrajectory)");
            servers.push(ActionServer {
                controller: c.name.clone(),
                index,
                joints: c.joints.clone(),
                joint_names: c
                    .joints
                    .iter()
                    .map(|&j| plan.joints[j].name.clone())
                    .collect(),
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
                goals: Vec::new(),
                waiting: Vec::new(),
                next_feedback_s: 0.0,
                feedback_msg: FeedbackMessage {
                    with_index: distro >= RosDistro::Lyrical,
                    ..FeedbackMessage::default()
                },
                status_changed: false,
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

impl ActionServer {
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = update.runs.get(self.index).copied().unwrap_or_default();
        while let Some((header, (goal_id, goal))) = self.send_goal.next_request() {
            let accepted = self.accept(goal_id, goal, now_s, run, to_session);
            self.send_goal
                .reply(header, (accepted, Time::from_secs(now_s)));
        }
        while let Some((header, info)) = self.cancel_goal.next_request() {
            let reply = self.cancel(info, to_session);
            self.cancel_goal.reply(header, reply);
        }
        self.follow_run(run, now_s);
        while let Some((header, goal_id)) = self.get_result.next_request() {
            self.waiting.push((header, goal_id));
        }
        self.answer_results();
        if now_s + 1e-9 >= self.next_feedback_s {
            self.next_feedback_s = now_s + FEEDBACK_PERIOD_S;
            self.publish_feedback(update, now_s);
        }
        if std::mem::take(&mut self.status_changed) {
            let status_list = self
                .goals
                .iter()
                .map(|g| GoalStatus {
                    goal_info: g.info,
                    status: g.status,
                })
                .collect();
            if let Err(e) = self.status.write(GoalStatusArray { status_list }, None) {
                tracing::warn!("ROS 2: {} status not sent ({e})", self.controller);
            }
        }
    }

    /// Checks and starts a goal; whether it is accepted.
    fn accept(
        &mut self,
        goal_id: Uuid,
        goal: FollowJointTrajectoryGoal,
        now_s: f64,
        run: RunSample,
        to_session: &Sender<Action>,
    ) -> bool {
        let t = &goal.trajectory;
        let unknown = t.joint_names.iter().find(|n| !self.joint_names.contains(n));
        let missing = self.joint_names.iter().find(|n| !t.joint_names.contains(n));
        let why = if t.points.is_empty() {
            Some("the trajectory has no points".to_owned())
        } else if let Some(n) = unknown {
            Some(format!("joint {n} is not one of {}'s", self.controller))
        } else if let Some(n) = missing {
            // joint_trajectory_controller's allow_partial_joints_goal is false by default.
            Some(format!("the trajectory does not list joint {n}"))
        } else if !goal.multi_dof_trajectory.points.is_empty() {
            Some("multi-DOF trajectories are not supported".to_owned())
        } else {
            None
        };
        if let Some(why) = why {
            tracing::warn!("ROS 2: {} rejected a goal: {why}", self.controller);
            return false;
        }
        for g in self.goals.iter_mut().filter(|g| !g.ended()) {
            g.end(STATUS_CANCELED, 0, "preempted by a new goal");
        }
        let secs = |d: Duration| f64::from(d.sec) + f64::from(d.nanosec) * 1e-9;
        let stamp = t.header.stamp;
        let trajectory = JointTrajectory {
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
        };
        let point_times_s = trajectory
            .points
            .iter()
            .map(|p| p.time_from_start_s)
            .collect();
        let _ = to_session.send(Action::Joint(JointAction::Trajectory {
            controller: self.controller.clone(),
            trajectory: Box::new(trajectory),
        }));
        self.goals.push(Goal {
            info: GoalInfo {
                goal_id,
                stamp: Time::from_secs(now_s),
            },
            status: STATUS_EXECUTING,
            result: FollowJointTrajectoryResult::default(),
            runs_before: run.runs,
            started: false,
            accepted_s: now_s,
            point_times_s,
        });
        self.status_changed = true;
        true
    }

    /// Cancels the goals `info` names (a zero id: all accepted up to its stamp, or all with a
    /// zero stamp too); the joints stop where they are.
    fn cancel(&mut self, info: GoalInfo, to_session: &Sender<Action>) -> (i8, Vec<GoalInfo>) {
        let all = info.goal_id == Uuid::default();
        let until = f64::from(info.stamp.sec) + f64::from(info.stamp.nanosec) * 1e-9;
        let named = |g: &Goal| {
            if all {
                until == 0.0 || g.accepted_s <= until
            } else {
                g.info.goal_id == info.goal_id
            }
        };
        let mut canceling = Vec::new();
        let mut ended_before = false;
        for g in self.goals.iter_mut().filter(|g| named(g)) {
            if g.ended() {
                ended_before = true;
                continue;
            }
            g.end(STATUS_CANCELED, 0, "cancelled");
            canceling.push(g.info);
        }
        if canceling.is_empty() {
            let code = if ended_before {
                CANCEL_ERROR_GOAL_TERMINATED
            } else {
                CANCEL_ERROR_UNKNOWN_GOAL_ID
            };
            return (code, canceling);
        }
        // A trajectory without points stops the controller's run and holds the joints where
        // they are.
        let _ = to_session.send(Action::Joint(JointAction::Trajectory {
            controller: self.controller.clone(),
            trajectory: Box::new(JointTrajectory {
                start_s: 0.0,
                joint_names: self.joint_names.clone(),
                points: Vec::new(),
            }),
        }));
        self.status_changed = true;
        (CANCEL_ERROR_NONE, canceling)
    }

    /// Follows the executing goal's run: started, then how it ended.
    fn follow_run(&mut self, run: RunSample, now_s: f64) {
        let Some(g) = self.goals.iter_mut().find(|g| !g.ended()) else {
            return;
        };
        if !g.started && run.runs > g.runs_before {
            g.started = true;
        }
        if !g.started {
            if now_s - g.accepted_s > START_TIMEOUT_S {
                g.end(
                    STATUS_ABORTED,
                    -1,
                    "the controller did not start the trajectory (rover's log says why)",
                );
                self.status_changed = true;
            }
            return;
        }
        if run.runs > g.runs_before + 1 {
            // Another trajectory (a command on `~/joint_trajectory`) replaced the goal's, as
            // joint_trajectory_controller preempts an action goal for a topic command.
            g.end(
                STATUS_CANCELED,
                0,
                "preempted by a command on ~/joint_trajectory",
            );
            self.status_changed = true;
            return;
        }
        if run.active {
            return;
        }
        let (status, code, why) = match run.outcome {
            Some(TrajectoryOutcome::Reached) | None => (STATUS_SUCCEEDED, 0, "goal reached"),
            Some(TrajectoryOutcome::PathToleranceViolated) => {
                (STATUS_ABORTED, -4, "PATH_TOLERANCE_VIOLATED")
            }
            Some(TrajectoryOutcome::GoalToleranceViolated) => {
                (STATUS_ABORTED, -5, "GOAL_TOLERANCE_VIOLATED")
            }
            Some(TrajectoryOutcome::Stopped) => (STATUS_CANCELED, 0, "stopped"),
        };
        g.end(status, code, why);
        self.status_changed = true;
        // Ended goals are remembered a while, for the status list and late result requests.
        let ended = self.goals.iter().filter(|g| g.ended()).count();
        if ended > ENDED_KEPT
            && let Some(oldest) = self.goals.iter().position(Goal::ended)
        {
            self.goals.remove(oldest);
        }
    }

    /// Replies to the get_result requests whose goal has ended (an unknown goal: aborted,
    /// INVALID_GOAL, at once).
    fn answer_results(&mut self) {
        let goals = &self.goals;
        let mut replies = Vec::new();
        self.waiting.retain(
            |(header, id)| match goals.iter().find(|g| g.info.goal_id == *id) {
                Some(g) if !g.ended() => true,
                Some(g) => {
                    replies.push((*header, (g.status, g.result.clone())));
                    false
                }
                None => {
                    let result = FollowJointTrajectoryResult {
                        error_code: -1,
                        error_string: "unknown goal".to_owned(),
                    };
                    replies.push((*header, (STATUS_ABORTED, result)));
                    false
                }
            },
        );
        for (header, reply) in replies {
            self.get_result.reply(header, reply);
        }
    }

    /// The executing goal's feedback: the joints' setpoints, positions and their difference.
    fn publish_feedback(&mut self, update: &ControlUpdate, now_s: f64) {
        let Some(g) = self.goals.iter().find(|g| !g.ended() && g.started) else {
            return;
        };
        let m = &mut self.feedback_msg;
        m.goal_id = g.info.goal_id;
        m.header.stamp = Time::from_secs(now_s);
        m.joint_names.clone_from(&self.joint_names);
        // The points' arrays are refilled in place: no allocation once warm.
        let samples = || self.joints.iter().filter_map(|&j| update.joints.get(j));
        let fill = |to: &mut Vec<f64>, f: fn(&JointSample) -> f64| {
            to.clear();
            to.extend(samples().map(f));
        };
        fill(&mut m.desired.positions, |s| s.setpoint);
        fill(&mut m.actual.positions, |s| s.position);
        fill(&mut m.actual.velocities, |s| s.velocity_radps);
        fill(&mut m.error.positions, |s| s.setpoint - s.position);
        let elapsed_s = now_s - g.accepted_s;
        m.index = g
            .point_times_s
            .iter()
            .position(|&t| t >= elapsed_s)
            .unwrap_or(g.point_times_s.len().saturating_sub(1)) as i32;
        if let Err(e) = self.feedback.write(m.clone(), None) {
            tracing::warn!("ROS 2: {} feedback not sent ({e})", self.controller);
        }
    }
}
