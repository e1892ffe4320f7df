//! `follow_joint_trajectory` for each joint trajectory controller, as ros2_control's
//! joint_trajectory_controller serves it (`/<controller>/follow_joint_trajectory`,
//! control_msgs/action/FollowJointTrajectory), and `gripper_cmd` for each gripper controller,
//! as its gripper_action_controller does (`/<controller>/gripper_cmd`,
//! control_msgs/action/GripperCommand): the send_goal, cancel_goal and get_result services and
//! the feedback and status topics, as rcl maps an action onto them
//! (`rq/<action>/_action/send_goalRequest`, `rt/<action>/_action/feedback`, ...). One server
//! serves either action ([`ActionType`] says what differs).
//!
//! A topic family on the publishing thread: at every control update it takes the requests
//! that came and answers them. What a goal means (which are refused, how its run ends,
//! preemption, cancels) is the shared bridge's (app/src/bridge/action_goals.rs); here is
//! ROS 2's wire: a refused trajectory goal is accepted and ends ABORTED with its control_msgs
//! code and reason (INVALID_JOINTS, INVALID_GOAL; ros2_controllers' JTC rejects it, and a
//! rejected goal has no result to say why), a refused gripper goal is not accepted (its reason
//! in rover's log); an ended one is SUCCEEDED, ABORTED or CANCELED in the status list and
//! get_result's reply. Feedback at 20 Hz (joint_trajectory_controller's
//! `action_monitor_rate`).

use std::sync::mpsc::Sender;

use anyhow::{Context, Result};
use rover_core::Action;
use rover_sim::model::RobotModel;
use rustdds::no_key::DataWriter;
use rustdds::{CDRSerializerAdapter, DomainParticipant, GUID, QosPolicies, RTPSEntity, TopicKind};
use serde::Serialize;

use super::convert::sim_trajectory;
use crate::bridge::RosPlan;
use crate::bridge::action_goals::{
    ActionGoals, FeedbackArrays, Goal, GoalState, Rejection, check_gripper, code,
};
use crate::bridge::action_intake::ActionWire;
use crate::bridge::events::{ControlUpdate, GripperSample, RunSample};
use rover_ros2::action_msgs::{
    CANCEL_ERROR_GOAL_TERMINATED, CANCEL_ERROR_NONE, CANCEL_ERROR_UNKNOWN_GOAL_ID, CancelGoal,
    FEEDBACK_TYPE, FeedbackMessage, FollowJointTrajectoryGoal, FollowJointTrajectoryResult,
    GRIPPER_FEEDBACK_TYPE, GetResult, GoalInfo, GoalStatus, GoalStatusArray, GripperCommandGoal,
    GripperCommandResult, GripperFeedbackMessage, GripperGetResult, GripperSendGoal,
    STATUS_ABORTED, STATUS_CANCELED, STATUS_EXECUTING, STATUS_SUCCEEDED, STATUS_TYPE, SendGoal,
    Uuid,
};
use rover_ros2::dds::{default_qos, latched_qos};
use rover_ros2::discovery::RosDistro;
use rover_ros2::msgs::Time;
use rover_ros2::services::{RequestId, Server, ServiceType};

/// Seconds between feedback messages (20 Hz).
const FEEDBACK_PERIOD_S: f64 = 0.05;

/// What one control_msgs action is on ROS 2's wire, and how its goals go to the shared book.
trait ActionType {
    /// Its send_goal service.
    type SendGoal: ServiceType<Response = (bool, Time)>;
    /// Its get_result service.
    type GetResult: ServiceType<Request = Uuid>;
    /// What the server keeps to publish feedback.
    type Feedback;
    /// Its feedback message.
    type FeedbackMessage: Serialize + Clone;
    /// The feedback topic's type name.
    const FEEDBACK_TYPE: &'static str;
    /// The action's type, for the log.
    const NAME: &'static str;
    /// A refused goal is accepted and ends ABORTED with its code in the result (`true`: the
    /// result has an error code), or is not accepted.
    const REFUSED_ABORTS: bool;

    /// The feedback's first state.
    fn feedback(distro: RosDistro) -> Self::Feedback;
    /// Checks a send_goal request's goal and, if it is good, accepts it; else its id and why.
    fn take(
        goals: &mut ActionGoals<Uuid>,
        request: <Self::SendGoal as ServiceType>::Request,
        now: (f64, RunSample),
        to_session: &Sender<Action>,
    ) -> Result<(), (Uuid, Rejection)>;
    /// Cancels the goals `named` picks, stopping the joints.
    fn cancel(
        goals: &mut ActionGoals<Uuid>,
        named: impl Fn(&Goal<Uuid>) -> bool,
        run: RunSample,
        to_session: &Sender<Action>,
    ) -> (Vec<Uuid>, bool);
    /// An ended goal's get_result reply; `None`: a goal the server does not know.
    fn result(g: Option<&Goal<Uuid>>) -> <Self::GetResult as ServiceType>::Response;
    /// The executing goal's feedback, if one executes.
    fn fill<'f>(
        feedback: &'f mut Self::Feedback,
        goals: &ActionGoals<Uuid>,
        update: &ControlUpdate,
        now_s: f64,
    ) -> Option<&'f Self::FeedbackMessage>;
}

/// control_msgs/action/FollowJointTrajectory.
struct FollowJointTrajectory;

impl ActionType for FollowJointTrajectory {
    type SendGoal = SendGoal;
    type GetResult = GetResult;
    type Feedback = (FeedbackArrays, FeedbackMessage);
    type FeedbackMessage = FeedbackMessage;
    const FEEDBACK_TYPE: &'static str = FEEDBACK_TYPE;
    const NAME: &'static str = "control_msgs/action/FollowJointTrajectory";
    const REFUSED_ABORTS: bool = true;

    fn feedback(distro: RosDistro) -> Self::Feedback {
        let msg = FeedbackMessage {
            with_index: distro >= RosDistro::Lyrical,
            ..FeedbackMessage::default()
        };
        (FeedbackArrays::default(), msg)
    }

    fn take(
        goals: &mut ActionGoals<Uuid>,
        (id, goal): (Uuid, FollowJointTrajectoryGoal),
        now: (f64, RunSample),
        to_session: &Sender<Action>,
    ) -> Result<(), (Uuid, Rejection)> {
        let multi_dof = !goal.multi_dof_trajectory.points.is_empty();
        let trajectory = sim_trajectory(goal.trajectory);
        goals.check(&trajectory, multi_dof).map_err(|r| (id, r))?;
        goals.accept_trajectory(id, trajectory, now, to_session);
        Ok(())
    }

    fn cancel(
        goals: &mut ActionGoals<Uuid>,
        named: impl Fn(&Goal<Uuid>) -> bool,
        _run: RunSample,
        to_session: &Sender<Action>,
    ) -> (Vec<Uuid>, bool) {
        goals.cancel_trajectory(named, to_session)
    }

    fn result(g: Option<&Goal<Uuid>>) -> (i8, FollowJointTrajectoryResult) {
        match g {
            Some(g) => (
                status_of(g.state),
                FollowJointTrajectoryResult {
                    error_code: g.error_code,
                    error_string: g.error_string.clone(),
                },
            ),
            None => (
                STATUS_ABORTED,
                FollowJointTrajectoryResult {
                    error_code: code::INVALID_GOAL,
                    error_string: "unknown goal".to_owned(),
                },
            ),
        }
    }

    fn fill<'f>(
        (arrays, m): &'f mut Self::Feedback,
        goals: &ActionGoals<Uuid>,
        update: &ControlUpdate,
        now_s: f64,
    ) -> Option<&'f FeedbackMessage> {
        let g = goals.feedback(update, now_s, arrays)?;
        m.goal_id = g.id;
        m.header.stamp = Time::from_secs(now_s);
        m.joint_names.clone_from(&goals.joint_names);
        // The points' arrays are copied in place: no allocation once warm.
        m.desired.positions.clone_from(&arrays.desired);
        m.actual.positions.clone_from(&arrays.actual);
        m.actual.velocities.clone_from(&arrays.actual_velocities);
        m.error.positions.clone_from(&arrays.error);
        m.index = i32::try_from(arrays.index).unwrap_or(i32::MAX);
        Some(m)
    }
}

/// control_msgs/action/GripperCommand.
struct GripperCommand;

/// GripperCommand's result fields from a sample.
fn gripper_result(g: GripperSample) -> GripperCommandResult {
    GripperCommandResult {
        position: g.position,
        effort: g.effort,
        stalled: g.stalled,
        reached_goal: g.reached_goal,
    }
}

impl ActionType for GripperCommand {
    type SendGoal = GripperSendGoal;
    type GetResult = GripperGetResult;
    type Feedback = GripperFeedbackMessage;
    type FeedbackMessage = GripperFeedbackMessage;
    const FEEDBACK_TYPE: &'static str = GRIPPER_FEEDBACK_TYPE;
    const NAME: &'static str = "control_msgs/action/GripperCommand";
    const REFUSED_ABORTS: bool = false;

    fn feedback(_distro: RosDistro) -> Self::Feedback {
        GripperFeedbackMessage::default()
    }

    fn take(
        goals: &mut ActionGoals<Uuid>,
        (id, goal): (Uuid, GripperCommandGoal),
        now: (f64, RunSample),
        to_session: &Sender<Action>,
    ) -> Result<(), (Uuid, Rejection)> {
        let c = goal.command;
        check_gripper(c.position, c.max_effort).map_err(|r| (id, r))?;
        goals.accept_gripper(id, (c.position, c.max_effort), now, to_session);
        Ok(())
    }

    fn cancel(
        goals: &mut ActionGoals<Uuid>,
        named: impl Fn(&Goal<Uuid>) -> bool,
        run: RunSample,
        to_session: &Sender<Action>,
    ) -> (Vec<Uuid>, bool) {
        goals.cancel_gripper(named, run.gripper.position, to_session)
    }

    fn result(g: Option<&Goal<Uuid>>) -> (i8, GripperCommandResult) {
        match g {
            Some(g) => (status_of(g.state), gripper_result(g.last_run.gripper)),
            None => (STATUS_ABORTED, GripperCommandResult::default()),
        }
    }

    fn fill<'f>(
        m: &'f mut Self::Feedback,
        goals: &ActionGoals<Uuid>,
        update: &ControlUpdate,
        _now_s: f64,
    ) -> Option<&'f GripperFeedbackMessage> {
        let g = goals.goals.iter().find(|g| !g.ended())?;
        m.goal_id = g.id;
        m.feedback = gripper_result(goals.run(update).gripper);
        Some(m)
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

/// One controller's action server.
struct ActionServer<A: ActionType> {
    goals: ActionGoals<Uuid>,
    send_goal: Server<A::SendGoal>,
    cancel_goal: Server<CancelGoal>,
    get_result: Server<A::GetResult>,
    feedback: DataWriter<A::FeedbackMessage, CDRSerializerAdapter<A::FeedbackMessage>>,
    status: DataWriter<GoalStatusArray, CDRSerializerAdapter<GoalStatusArray>>,
    /// get_result requests waiting for their goal to end.
    waiting: Vec<(RequestId, Uuid)>,
    next_feedback_s: f64,
    feedback_state: A::Feedback,
}

/// The DDS entities an action server is made on.
struct Dds<'a> {
    participant: &'a DomainParticipant,
    subscriber: &'a rustdds::Subscriber,
    publisher: &'a rustdds::Publisher,
    distro: RosDistro,
}

impl<A: ActionType> ActionServer<A> {
    fn new(goals: ActionGoals<Uuid>, dds: &Dds<'_>) -> Result<Self> {
        let internal = format!("{}/_action/", goals.action);
        let topic = format!("rt{internal}");
        tracing::info!("ROS 2: action {} ({})", goals.action, A::NAME);
        let (participant, subscriber, publisher) = (dds.participant, dds.subscriber, dds.publisher);
        Ok(Self {
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
                &format!("{topic}feedback"),
                A::FEEDBACK_TYPE,
                default_qos(),
            )?,
            status: writer(
                participant,
                publisher,
                &format!("{topic}status"),
                STATUS_TYPE,
                latched_qos(),
            )?,
            goals,
            waiting: Vec::new(),
            next_feedback_s: 0.0,
            feedback_state: A::feedback(dds.distro),
        })
    }

    /// Its readers and writers, into `readers` and `writers`.
    fn gids(&self, readers: &mut Vec<GUID>, writers: &mut Vec<GUID>) {
        for (r, w) in [
            self.send_goal.gids(),
            self.cancel_goal.gids(),
            self.get_result.gids(),
        ] {
            readers.push(r);
            writers.push(w);
        }
        writers.push(self.feedback.guid());
        writers.push(self.status.guid());
    }

    /// Cancels the goals `info` names (a zero id: all accepted up to its stamp, or all with a
    /// zero stamp too); the joints stop where they are.
    fn cancel(
        &mut self,
        info: GoalInfo,
        run: RunSample,
        to_session: &Sender<Action>,
    ) -> (i8, Vec<GoalInfo>) {
        let all = info.goal_id == Uuid::default();
        let until = f64::from(info.stamp.sec) + f64::from(info.stamp.nanosec) * 1e-9;
        let named = |g: &Goal<Uuid>| {
            if all {
                until == 0.0 || g.accepted_s <= until
            } else {
                g.id == info.goal_id
            }
        };
        let (cancelled, ended_before) = A::cancel(&mut self.goals, named, run, to_session);
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

    /// Replies to the get_result requests whose goal has ended (an unknown goal: aborted, at
    /// once).
    fn answer_results(&mut self) {
        let goals = &self.goals;
        let mut replies = Vec::new();
        self.waiting.retain(|(header, id)| match goals.goal(id) {
            Some(g) if !g.ended() => true,
            found => {
                replies.push((*header, A::result(found)));
                false
            }
        });
        for (header, reply) in replies {
            self.get_result.reply(header, reply);
        }
    }
}

impl<A: ActionType + Send> ActionWire for ActionServer<A>
where
    ActionServer<A>: Send,
{
    fn update(&mut self, update: &ControlUpdate, to_session: &Sender<Action>) {
        let now_s = update.sample.sim_time_s;
        let run = self.goals.run(update);
        while let Some((header, request)) = self.send_goal.next_request() {
            let accepted = match A::take(&mut self.goals, request, (now_s, run), to_session) {
                Ok(()) => true,
                Err((id, r)) if A::REFUSED_ABORTS => {
                    tracing::warn!(
                        "ROS 2: {} aborted a goal (error code {}): {}",
                        self.goals.controller,
                        r.code,
                        r.why
                    );
                    self.goals.refuse(id, r, (now_s, run));
                    true
                }
                Err((_, r)) => {
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
            let reply = self.cancel(info, run, to_session);
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
            if let Some(m) = A::fill(&mut self.feedback_state, &self.goals, update, now_s)
                && let Err(e) = self.feedback.write(m.clone(), None)
            {
                tracing::warn!("ROS 2: {} feedback not sent ({e})", self.goals.controller);
            }
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
}

/// Readers' and writers' GUIDs, for `ros_discovery_info`.
pub(super) type Gids = (Vec<GUID>, Vec<GUID>);

/// Serves `follow_joint_trajectory` for each of the plan's trajectory controllers and
/// `gripper_cmd` for each gripper controller; the servers, and their readers and writers for
/// `ros_discovery_info`.
pub(super) fn serve(
    (participant, subscriber, publisher): (
        &DomainParticipant,
        &rustdds::Subscriber,
        &rustdds::Publisher,
    ),
    (plan, robot): (&RosPlan, &RobotModel),
    distro: RosDistro,
) -> Result<(Vec<Box<dyn ActionWire>>, Gids)> {
    let dds = Dds {
        participant,
        subscriber,
        publisher,
        distro,
    };
    let mut servers: Vec<Box<dyn ActionWire>> = Vec::new();
    let (mut readers, mut writers) = (Vec::new(), Vec::new());
    for goals in ActionGoals::trajectories(plan, "~/joint_trajectory") {
        let server = ActionServer::<FollowJointTrajectory>::new(goals, &dds)?;
        server.gids(&mut readers, &mut writers);
        servers.push(Box::new(server));
    }
    for goals in ActionGoals::grippers(plan, robot) {
        let server = ActionServer::<GripperCommand>::new(goals, &dds)?;
        server.gids(&mut readers, &mut writers);
        servers.push(Box::new(server));
    }
    Ok((servers, (readers, writers)))
}
