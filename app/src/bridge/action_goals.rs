//! The controllers' action goals as ros_control serves them, for both transports:
//! control_msgs FollowJointTrajectory as joint_trajectory_controller handles it, and
//! GripperCommand as gripper_action_controller does. Here: which goals are refused and with
//! which result code, how an accepted goal reaches the session, how its run ends (SUCCEEDED,
//! ABORTED with the tolerance violated or the gripper stalled, or CANCELED), preemption by a
//! newer goal or a command on the controller's topic, cancels that stop the joints where they
//! are, and the feedback's arrays. The transports keep only their wire: ROS 1's actionlib
//! topics (app/src/ros/actions.rs), ROS 2's action services (app/src/ros2/actions.rs). A goal's
//! id is the transport's own (actionlib's string, ROS 2's UUID).
//!
//! A trajectory goal's tolerances and `goal_time_tolerance` are not read: the controller's own,
//! from the controllers file, apply.

use std::sync::mpsc::Sender;

use rover_core::{Action, JointAction};
use rover_sim::physics::{JointTrajectory, TrajectoryOutcome};

use super::RosPlan;
use super::events::{ControlUpdate, GripperSample, JointSample, RunSample};

/// How long a goal may wait for its controller to start it (s of sim time).
const START_TIMEOUT_S: f64 = 1.0;
/// Ended goals kept for the status list and for late result requests.
const ENDED_KEPT: usize = 16;

/// control_msgs' FollowJointTrajectory result codes.
pub(crate) mod code {
    /// The trajectory was followed.
    pub const SUCCESSFUL: i32 = 0;
    /// The goal is malformed (no points, values that are not finite, short arrays), or the
    /// controller did not start it.
    pub const INVALID_GOAL: i32 = -1;
    /// Its joints are not the controller's.
    pub const INVALID_JOINTS: i32 = -2;
    /// A path tolerance was exceeded.
    pub const PATH_TOLERANCE_VIOLATED: i32 = -4;
    /// The goal tolerance was not met in time.
    pub const GOAL_TOLERANCE_VIOLATED: i32 = -5;
}

/// Where a goal stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum GoalState {
    /// Its trajectory runs, or is about to.
    Executing,
    /// Reached within the tolerances.
    Succeeded,
    /// Stopped by a tolerance, or never started.
    Aborted,
    /// Cancelled, or preempted by a newer goal or command.
    Canceled,
}

/// Why a goal was refused: control_msgs' result code and a reason.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Rejection {
    /// One of [`code`]'s.
    pub code: i32,
    /// For people.
    pub why: String,
}

/// One accepted goal.
#[derive(Debug)]
pub(crate) struct Goal<Id> {
    /// The transport's id for it.
    pub id: Id,
    /// Where it stands.
    pub state: GoalState,
    /// Its result code (see [`code`]) once ended.
    pub error_code: i32,
    /// Its result's text.
    pub error_string: String,
    /// When it was accepted (sim s).
    pub accepted_s: f64,
    /// The controller's run when it ended (a gripper's result is read from it).
    pub last_run: RunSample,
    /// Its ending was handed to the transport ([`ActionGoals::take_ended`]).
    reported: bool,
    /// The controller's run count when it was accepted: its own run is the next.
    runs_before: u64,
    /// Its run started.
    started: bool,
    /// Its points' times from the start (s), for the feedback's index.
    point_times_s: Vec<f64>,
}

impl<Id> Goal<Id> {
    /// Whether it has ended.
    pub fn ended(&self) -> bool {
        self.state != GoalState::Executing
    }

    fn end(&mut self, state: GoalState, error_code: i32, why: &str) {
        self.state = state;
        self.error_code = error_code;
        why.clone_into(&mut self.error_string);
    }
}

/// The feedback's arrays for the executing goal, refilled in place.
#[derive(Debug, Default)]
pub(crate) struct FeedbackArrays {
    /// The actuators' setpoints.
    pub desired: Vec<f64>,
    /// The joints' positions.
    pub actual: Vec<f64>,
    /// Their velocities.
    pub actual_velocities: Vec<f64>,
    /// desired - actual.
    pub error: Vec<f64>,
    /// The point the trajectory is heading for.
    pub index: usize,
}

/// Which action a controller serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// FollowJointTrajectory.
    Trajectory,
    /// GripperCommand; a stall ends the goal succeeded with `allow_stalling`, else aborted.
    Gripper { allow_stalling: bool },
}

/// One controller's goals.
#[derive(Debug)]
pub(crate) struct ActionGoals<Id> {
    /// The controller's name.
    pub controller: String,
    /// The action's name: the controller's namespace, `/follow_joint_trajectory` or
    /// `/gripper_cmd`.
    pub action: String,
    /// Its joints' names, in the controller's order.
    pub joint_names: Vec<String>,
    /// The goals accepted, the ended ones kept a while.
    pub goals: Vec<Goal<Id>>,
    /// Which action it serves.
    kind: Kind,
    /// The controller's index among the update's run samples.
    index: usize,
    /// Its joints' indices in the plan.
    joints: Vec<usize>,
    /// A goal's state changed since [`Self::take_changed`].
    changed: bool,
    /// Why a goal ended when a command on the controller's topic replaced it (the topic as
    /// the transport names it).
    preempted_by_topic: String,
}

impl<Id: Clone + PartialEq> ActionGoals<Id> {
    /// One for each of the plan's trajectory controllers; `command_topic` is the controller's
    /// trajectory topic as the transport names it (`~/command`, `~/joint_trajectory`).
    pub fn trajectories(plan: &RosPlan, command_topic: &str) -> Vec<Self> {
        plan.controllers
            .iter()
            .enumerate()
            .filter(|(_, c)| c.trajectory)
            .map(|(index, c)| {
                let base = c
                    .command_topic
                    .strip_suffix("/command")
                    .unwrap_or(&c.command_topic);
                Self {
                    controller: c.name.clone(),
                    action: format!("{base}/follow_joint_trajectory"),
                    joint_names: c
                        .joints
                        .iter()
                        .map(|&j| plan.joints[j].name.clone())
                        .collect(),
                    goals: Vec::new(),
                    kind: Kind::Trajectory,
                    index,
                    joints: c.joints.clone(),
                    changed: false,
                    preempted_by_topic: format!("preempted by a command on {command_topic}"),
                }
            })
            .collect()
    }

    /// One for each of the plan's gripper controllers (`robot` says whether a stall succeeds).
    pub fn grippers(plan: &RosPlan, robot: &rover_sim::model::RobotModel) -> Vec<Self> {
        plan.grippers
            .iter()
            .enumerate()
            .map(|(k, (name, action))| {
                let spec = robot
                    .controllers
                    .as_ref()
                    .and_then(|c| c.controller(name))
                    .map(|c| &c.kind);
                let allow_stalling = matches!(
                    spec,
                    Some(rover_sim::model::ControllerKind::Gripper(g)) if g.allow_stalling
                );
                Self {
                    controller: name.clone(),
                    action: action.clone(),
                    joint_names: Vec::new(),
                    goals: Vec::new(),
                    kind: Kind::Gripper { allow_stalling },
                    index: plan.controllers.len() + k,
                    joints: Vec::new(),
                    changed: false,
                    preempted_by_topic: String::new(),
                }
            })
            .collect()
    }

    /// Accepts a gripper command: the goal executing is preempted, the command goes to the
    /// session.
    pub fn accept_gripper(
        &mut self,
        id: Id,
        (position, max_effort): (f64, f64),
        (now_s, run): (f64, RunSample),
        to_session: &Sender<Action>,
    ) {
        let action = Action::Joint(JointAction::Gripper {
            controller: self.controller.clone(),
            position,
            max_effort,
        });
        self.accept(id, action, Vec::new(), (now_s, run), to_session);
    }

    /// Cancels the executing gripper goals `named` picks; the fingers hold where they are
    /// (`position`, the finger's now), as gripper_action_controller does.
    pub fn cancel_gripper(
        &mut self,
        named: impl Fn(&Goal<Id>) -> bool,
        position: f64,
        to_session: &Sender<Action>,
    ) -> (Vec<Id>, bool) {
        let hold = Action::Joint(JointAction::Gripper {
            controller: self.controller.clone(),
            position,
            max_effort: 0.0,
        });
        self.cancel(named, hold, to_session)
    }

    /// This controller's run in `update`.
    pub fn run(&self, update: &ControlUpdate) -> RunSample {
        update.runs.get(self.index).copied().unwrap_or_default()
    }

    /// Why joint_trajectory_controller would refuse `t` as a goal (with `multi_dof` points
    /// too), if it would: the controller's own check ([`JointTrajectory::check`], in sim),
    /// its error as control_msgs' code, and what a goal must have besides (points, no
    /// multi-DOF part).
    pub fn check(&self, t: &JointTrajectory, multi_dof: bool) -> Result<(), Rejection> {
        let joints: Vec<&str> = self.joint_names.iter().map(String::as_str).collect();
        if let Err(e) = t.check(&joints) {
            let code = if e.is_about_joints() {
                code::INVALID_JOINTS
            } else {
                code::INVALID_GOAL
            };
            return Err(Rejection {
                code,
                why: format!("{}: {e}", self.controller),
            });
        }
        let reject = |why: &str| {
            Err(Rejection {
                code: code::INVALID_GOAL,
                why: format!("{}: {why}", self.controller),
            })
        };
        if t.points.is_empty() {
            return reject("the trajectory has no points");
        }
        if multi_dof {
            return reject("multi-DOF trajectories are not supported");
        }
        Ok(())
    }

    /// Accepts a checked trajectory goal: the goal executing is preempted (CANCELED, as
    /// joint_trajectory_controller does) and the trajectory goes to the session.
    pub fn accept_trajectory(
        &mut self,
        id: Id,
        trajectory: JointTrajectory,
        (now_s, run): (f64, RunSample),
        to_session: &Sender<Action>,
    ) {
        let point_times_s = trajectory
            .points
            .iter()
            .map(|p| p.time_from_start_s)
            .collect();
        let action = Action::Joint(JointAction::Trajectory {
            controller: self.controller.clone(),
            trajectory: Box::new(trajectory),
        });
        self.accept(id, action, point_times_s, (now_s, run), to_session);
    }

    fn accept(
        &mut self,
        id: Id,
        action: Action,
        point_times_s: Vec<f64>,
        (now_s, run): (f64, RunSample),
        to_session: &Sender<Action>,
    ) {
        for g in self.goals.iter_mut().filter(|g| !g.ended()) {
            g.end(
                GoalState::Canceled,
                code::SUCCESSFUL,
                "preempted by a new goal",
            );
        }
        let _ = to_session.send(action);
        self.goals.push(Goal {
            id,
            state: GoalState::Executing,
            error_code: code::SUCCESSFUL,
            error_string: String::new(),
            accepted_s: now_s,
            last_run: run,
            reported: false,
            runs_before: run.runs,
            started: false,
            point_times_s,
        });
        self.changed = true;
    }

    /// Books a goal refused for `rejection` as accepted and ended at once, ABORTED with its
    /// code (ROS 2's FollowJointTrajectory: a result is the only place for the code); the goal
    /// executing goes on.
    pub fn refuse(&mut self, id: Id, rejection: Rejection, (now_s, run): (f64, RunSample)) {
        self.goals.push(Goal {
            id,
            state: GoalState::Aborted,
            error_code: rejection.code,
            error_string: rejection.why,
            accepted_s: now_s,
            last_run: run,
            reported: false,
            runs_before: run.runs,
            started: false,
            point_times_s: Vec::new(),
        });
        self.changed = true;
    }

    /// Cancels the executing trajectory goals `named` picks; the joints stop where they are
    /// (a trajectory without points). The ids cancelled, and whether a named goal had already
    /// ended.
    pub fn cancel_trajectory(
        &mut self,
        named: impl Fn(&Goal<Id>) -> bool,
        to_session: &Sender<Action>,
    ) -> (Vec<Id>, bool) {
        let stop = Action::Joint(JointAction::Trajectory {
            controller: self.controller.clone(),
            trajectory: Box::new(JointTrajectory {
                start_s: 0.0,
                joint_names: self.joint_names.clone(),
                points: Vec::new(),
            }),
        });
        self.cancel(named, stop, to_session)
    }

    /// Cancels the executing goals `named` picks and sends `stop` if any was. The ids
    /// cancelled, and whether a named goal had already ended.
    fn cancel(
        &mut self,
        named: impl Fn(&Goal<Id>) -> bool,
        stop: Action,
        to_session: &Sender<Action>,
    ) -> (Vec<Id>, bool) {
        let mut cancelled = Vec::new();
        let mut ended_before = false;
        for g in self.goals.iter_mut().filter(|g| named(g)) {
            if g.ended() {
                ended_before = true;
                continue;
            }
            g.end(GoalState::Canceled, code::SUCCESSFUL, "cancelled");
            cancelled.push(g.id.clone());
        }
        if !cancelled.is_empty() {
            let _ = to_session.send(stop);
            self.changed = true;
        }
        (cancelled, ended_before)
    }

    /// Follows the executing goal's run: started, then how it ended.
    pub fn follow(&mut self, run: RunSample, now_s: f64) {
        let Some(g) = self.goals.iter_mut().find(|g| !g.ended()) else {
            return;
        };
        if !g.started && run.runs > g.runs_before {
            g.started = true;
        }
        if !g.started {
            if now_s - g.accepted_s > START_TIMEOUT_S {
                g.end(
                    GoalState::Aborted,
                    code::INVALID_GOAL,
                    "the controller did not start the trajectory (rover's log says why)",
                );
                self.changed = true;
            }
            return;
        }
        if run.runs > g.runs_before + 1 {
            // Another trajectory (a command on the controller's topic) replaced the goal's, as
            // joint_trajectory_controller preempts an action goal for a topic command.
            g.end(
                GoalState::Canceled,
                code::SUCCESSFUL,
                &self.preempted_by_topic,
            );
            self.changed = true;
            return;
        }
        if run.active {
            return;
        }
        g.last_run = run;
        let (state, code, why) = match self.kind {
            Kind::Trajectory => trajectory_ending(run),
            Kind::Gripper { allow_stalling } => gripper_ending(run.gripper, allow_stalling),
        };
        g.end(state, code, why);
        self.changed = true;
    }

    /// Goals that ended since the last call, each handed out once (for a transport that
    /// publishes results as they come); ended goals beyond the kept number are forgotten.
    pub fn take_ended(&mut self, mut each: impl FnMut(&Goal<Id>)) {
        for g in self.goals.iter_mut().filter(|g| g.ended() && !g.reported) {
            g.reported = true;
            each(g);
        }
        let ended = self.goals.iter().filter(|g| g.ended()).count();
        if ended > ENDED_KEPT {
            let mut extra = ended - ENDED_KEPT;
            self.goals.retain(|g| {
                let drop = extra > 0 && g.ended() && g.reported;
                extra -= usize::from(drop);
                !drop
            });
        }
    }

    /// Whether a goal's state changed since the last call.
    pub fn take_changed(&mut self) -> bool {
        std::mem::take(&mut self.changed)
    }

    /// The goal with `id`.
    pub fn goal(&self, id: &Id) -> Option<&Goal<Id>> {
        self.goals.iter().find(|g| g.id == *id)
    }

    /// The executing goal's feedback, filled into `out`: the joints' setpoints, positions,
    /// velocities and the difference; `None` while no started goal executes.
    pub fn feedback(
        &self,
        update: &ControlUpdate,
        now_s: f64,
        out: &mut FeedbackArrays,
    ) -> Option<&Goal<Id>> {
        let g = self.goals.iter().find(|g| !g.ended() && g.started)?;
        let samples = || self.joints.iter().filter_map(|&j| update.joints.get(j));
        let fill = |to: &mut Vec<f64>, f: fn(&JointSample) -> f64| {
            to.clear();
            to.extend(samples().map(f));
        };
        fill(&mut out.desired, |s| s.setpoint);
        fill(&mut out.actual, |s| s.position);
        fill(&mut out.actual_velocities, |s| s.velocity_radps);
        fill(&mut out.error, |s| s.setpoint - s.position);
        let elapsed_s = now_s - g.accepted_s;
        out.index = g
            .point_times_s
            .iter()
            .position(|&t| t >= elapsed_s)
            .unwrap_or(g.point_times_s.len().saturating_sub(1));
        Some(g)
    }
}

/// Why gripper_action_controller would refuse a GripperCommand, if it would.
pub(crate) fn check_gripper(position: f64, max_effort: f64) -> Result<(), Rejection> {
    if position.is_finite() && max_effort.is_finite() {
        Ok(())
    } else {
        Err(Rejection {
            code: code::INVALID_GOAL,
            why: format!("position {position} and max_effort {max_effort} must be finite numbers"),
        })
    }
}

/// How a trajectory's run ended, as FollowJointTrajectory's result says it.
fn trajectory_ending(run: RunSample) -> (GoalState, i32, &'static str) {
    match run.outcome {
        Some(TrajectoryOutcome::Reached) | None => {
            (GoalState::Succeeded, code::SUCCESSFUL, "goal reached")
        }
        Some(TrajectoryOutcome::PathToleranceViolated) => (
            GoalState::Aborted,
            code::PATH_TOLERANCE_VIOLATED,
            "PATH_TOLERANCE_VIOLATED",
        ),
        Some(TrajectoryOutcome::GoalToleranceViolated) => (
            GoalState::Aborted,
            code::GOAL_TOLERANCE_VIOLATED,
            "GOAL_TOLERANCE_VIOLATED",
        ),
        Some(TrajectoryOutcome::Stopped) => (GoalState::Canceled, code::SUCCESSFUL, "stopped"),
    }
}

/// How a gripper command ended, as gripper_action_controller says it: at its goal, SUCCEEDED;
/// stalled on something, ABORTED (ROS 1's rule) or SUCCEEDED with `allow_stalling` (ROS 2's
/// option).
fn gripper_ending(g: GripperSample, allow_stalling: bool) -> (GoalState, i32, &'static str) {
    if g.reached_goal {
        (GoalState::Succeeded, code::SUCCESSFUL, "goal reached")
    } else if g.stalled && allow_stalling {
        (GoalState::Succeeded, code::SUCCESSFUL, "stalled (allowed)")
    } else if g.stalled {
        (GoalState::Aborted, code::SUCCESSFUL, "stalled")
    } else {
        (GoalState::Canceled, code::SUCCESSFUL, "stopped")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rover_sim::physics::TrajectoryPoint;

    fn goals() -> ActionGoals<u32> {
        ActionGoals {
            controller: "arm_controller".into(),
            action: "/arm_controller/follow_joint_trajectory".into(),
            joint_names: vec!["a".into(), "b".into()],
            goals: Vec::new(),
            kind: Kind::Trajectory,
            index: 0,
            joints: vec![0, 1],
            changed: false,
            preempted_by_topic: "preempted by a command on ~/command".into(),
        }
    }

    fn trajectory(names: &[&str], positions: Vec<f64>) -> JointTrajectory {
        JointTrajectory {
            start_s: 0.0,
            joint_names: names.iter().map(|n| (*n).to_owned()).collect(),
            points: vec![TrajectoryPoint {
                positions,
                velocities: Vec::new(),
                accelerations: Vec::new(),
                time_from_start_s: 1.0,
            }],
        }
    }

    /// The book with goal `id` accepted (its trajectory sent to the session and taken), the
    /// way to the session and the session's end.
    fn with_goal(
        id: u32,
    ) -> (
        ActionGoals<u32>,
        std::sync::mpsc::Sender<Action>,
        std::sync::mpsc::Receiver<Action>,
    ) {
        let (to_session, from) = std::sync::mpsc::channel();
        let mut g = goals();
        g.accept_trajectory(
            id,
            trajectory(&["a", "b"], vec![0.1, 0.2]),
            (0.0, RunSample::default()),
            &to_session,
        );
        assert!(from.try_recv().is_ok());
        (g, to_session, from)
    }

    #[test]
    fn bad_goals_get_control_msgs_codes() {
        let g = goals();
        let code = |t: &JointTrajectory| g.check(t, false).err().map(|r| r.code);
        assert_eq!(code(&trajectory(&["a", "b"], vec![0.1, 0.2])), None);
        assert_eq!(code(&trajectory(&["b", "a"], vec![0.1, 0.2])), None);
        assert_eq!(
            code(&trajectory(&["a", "x"], vec![0.1, 0.2])),
            Some(code::INVALID_JOINTS)
        );
        assert_eq!(
            code(&trajectory(&["a"], vec![0.1])),
            Some(code::INVALID_JOINTS)
        );
        assert_eq!(
            code(&trajectory(&["a", "b"], vec![f64::NAN, 0.2])),
            Some(code::INVALID_GOAL)
        );
        assert_eq!(
            code(&trajectory(&["a", "b"], vec![0.1])),
            Some(code::INVALID_GOAL)
        );
        let mut twice = trajectory(&["a", "b"], vec![0.1, 0.2]);
        twice.points.push(twice.points[0].clone());
        assert_eq!(code(&twice), Some(code::INVALID_GOAL));
        let mut empty = trajectory(&["a", "b"], Vec::new());
        empty.points.clear();
        assert_eq!(code(&empty), Some(code::INVALID_GOAL));
    }

    #[test]
    fn a_refused_goal_ends_aborted_with_its_code_and_the_running_one_goes_on() {
        let (mut g, _to_session, from) = with_goal(1);
        let idle = RunSample::default();
        let bad = trajectory(&["a", "x"], vec![0.1, 0.2]);
        let Err(why) = g.check(&bad, false) else {
            panic!("an unknown joint passed the check");
        };
        g.take_changed();
        g.refuse(2, why, (0.5, idle));
        assert!(g.take_changed());
        let refused = g
            .goal(&2)
            .map(|x| (x.state, x.error_code, x.error_string.clone()));
        assert_eq!(
            refused,
            Some((
                GoalState::Aborted,
                code::INVALID_JOINTS,
                "arm_controller: joint \"x\" is not one of its joints (a, b)".to_owned()
            ))
        );
        assert_eq!(g.goal(&1).map(|x| x.state), Some(GoalState::Executing));
        assert!(
            from.try_recv().is_err(),
            "a refused goal reached the session"
        );
    }

    #[test]
    fn a_goal_runs_then_succeeds_and_a_newer_one_preempts() {
        let (mut g, to_session, _from) = with_goal(1);
        let running = RunSample {
            active: true,
            runs: 1,
            ..RunSample::default()
        };
        g.follow(running, 0.1);
        assert_eq!(g.goal(&1).map(|x| x.state), Some(GoalState::Executing));
        g.accept_trajectory(
            2,
            trajectory(&["a", "b"], vec![0.0, 0.0]),
            (0.2, running),
            &to_session,
        );
        assert_eq!(g.goal(&1).map(|x| x.state), Some(GoalState::Canceled));
        g.follow(
            RunSample {
                active: false,
                runs: 2,
                outcome: Some(TrajectoryOutcome::Reached),
                ..RunSample::default()
            },
            1.5,
        );
        assert_eq!(g.goal(&2).map(|x| x.state), Some(GoalState::Succeeded));
        let mut ended = Vec::new();
        g.take_ended(|x| ended.push(x.id));
        g.take_ended(|x| ended.push(x.id));
        assert_eq!(ended, [1, 2]);
    }

    #[test]
    fn a_cancel_stops_the_joints_and_a_goal_never_started_aborts() {
        let (mut g, to_session, from) = with_goal(7);
        let (cancelled, ended_before) = g.cancel_trajectory(|x| x.id == 7, &to_session);
        assert_eq!(cancelled.len(), 1);
        assert!(!ended_before);
        match from.try_recv() {
            Ok(Action::Joint(JointAction::Trajectory { trajectory, .. })) => {
                assert!(trajectory.points.is_empty());
            }
            other => panic!("expected a stop, got {other:?}"),
        }
        assert!(g.cancel_trajectory(|x| x.id == 7, &to_session).1);
        g.accept_trajectory(
            8,
            trajectory(&["a", "b"], vec![0.1, 0.2]),
            (2.0, RunSample::default()),
            &to_session,
        );
        g.follow(RunSample::default(), 3.5);
        let goal = g.goal(&8);
        assert_eq!(goal.map(|x| x.state), Some(GoalState::Aborted));
        assert_eq!(goal.map(|x| x.error_code), Some(code::INVALID_GOAL));
    }

    #[test]
    fn a_gripper_goal_ends_as_its_command_did() {
        let stalled = GripperSample {
            position: 0.03,
            effort: 5.0,
            stalled: true,
            reached_goal: false,
        };
        assert_eq!(gripper_ending(stalled, false).0, GoalState::Aborted);
        assert_eq!(gripper_ending(stalled, true).0, GoalState::Succeeded);
        let reached = GripperSample {
            reached_goal: true,
            ..GripperSample::default()
        };
        assert_eq!(gripper_ending(reached, false).0, GoalState::Succeeded);
        assert!(check_gripper(f64::NAN, 1.0).is_err());
        assert!(check_gripper(0.01, 0.0).is_ok());
    }
}
