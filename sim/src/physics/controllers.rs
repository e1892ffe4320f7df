//! The robot's ros_control controllers on sim time: single-joint controllers turn a command
//! (a number, as std_msgs/Float64 carries it) into a joint command, and joint trajectory
//! controllers sample a trajectory_msgs/JointTrajectory every control update and feed the
//! samples to the actuators, checking the path and goal tolerances as ros_control's
//! joint_trajectory_controller does — except that a failure names the joint, its error and the
//! tolerance.
//!
//! Between two points a joint moves as ros_control interpolates: linearly when the points give
//! positions only, on a cubic when they give velocities, on a quintic when they give
//! accelerations too. A trajectory starts from where the joints are held now.

use crate::error::{Result, SimError};
use crate::model::controllers::{
    CommandKind, ControllerConfig, ControllerKind, GripperSpec, TrajectoryConstraints,
};
use crate::model::robot::{JointId, RobotModel};
use crate::physics::actuators::{Actuators, JointCommand};
use crate::physics::trajectory::JointTrajectory;

/// What a trajectory controller is doing, for its `state` topic.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrajectoryState {
    /// Its joints, in the controller's order.
    pub joints: Vec<JointId>,
    /// Where the trajectory wants each joint now (rad or m).
    pub desired_positions: Vec<f64>,
    /// How fast it wants each joint to move now.
    pub desired_velocities: Vec<f64>,
    /// Whether a trajectory is running.
    pub active: bool,
    /// Trajectories started so far (a new one replaces the one running).
    pub runs: u64,
    /// How the last trajectory ended; `None` while it runs or before the first.
    pub outcome: Option<TrajectoryOutcome>,
}

/// How a trajectory ended, as joint_trajectory_controller's action reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrajectoryOutcome {
    /// Within the goal tolerances, stopped, in time: SUCCESSFUL.
    Reached,
    /// A joint left its path tolerance while it ran: PATH_TOLERANCE_VIOLATED (-4).
    PathToleranceViolated,
    /// Not within the goal tolerances, or still moving, after `goal_time`:
    /// GOAL_TOLERANCE_VIOLATED (-5).
    GoalToleranceViolated,
    /// Stopped by an empty trajectory (a cancel).
    Stopped,
}

/// A controller's setpoint, for the `state` topic of a single-joint controller.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ControllerCommandState {
    /// The joint it drives.
    pub joint: Option<JointId>,
    /// The last command (rad, rad/s or N m, per the controller's type).
    pub command: f64,
}

/// A gripper controller's command and what came of it, as control_msgs/GripperCommand's
/// result reports it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GripperState {
    /// The finger joint.
    pub joint: Option<JointId>,
    /// The commanded position (m or rad).
    pub goal: f64,
    /// The finger joint's position now.
    pub position: f64,
    /// The effort its motor exerts now (N or N m).
    pub effort: f64,
    /// A command is being carried out.
    pub active: bool,
    /// Commands taken so far.
    pub runs: u64,
    /// The last command ended short of its goal with the fingers not moving (closed on
    /// something).
    pub stalled: bool,
    /// The last command ended within `goal_tolerance`.
    pub reached_goal: bool,
}

#[derive(Debug, Clone)]
struct GripperRun {
    spec: GripperSpec,
    state: GripperState,
    /// Where the finger was when it last moved (m or rad), and when (sim s).
    last_moved: (f64, f64),
}

/// The least band (m or rad) a finger must leave to count as moving: the fingers of a closed
/// gripper jitter by ~0.5 mm in rapier's contacts, which an instantaneous speed would read as
/// moving.
const STALL_BAND_MIN: f64 = 0.001;

#[derive(Debug, Clone)]
enum Running {
    JointState,
    Joint {
        joint: JointId,
        command: CommandKind,
        last: f64,
    },
    Trajectory(Box<TrajectoryRun>),
    Gripper(Box<GripperRun>),
}

#[derive(Debug, Clone)]
struct TrajectoryRun {
    joints: Vec<JointId>,
    constraints: TrajectoryConstraints,
    /// Absolute knots: the start state, then the points (sim time).
    knots: Vec<Knot>,
    state: TrajectoryState,
    /// When the last point is due (sim time); `None` when idle.
    end_s: Option<f64>,
}

#[derive(Debug, Clone, Default)]
struct Knot {
    t_s: f64,
    positions: Vec<f64>,
    velocities: Option<Vec<f64>>,
    accelerations: Option<Vec<f64>>,
}

/// The controllers of one robot, in the file's order.
#[derive(Debug, Clone, Default)]
pub(crate) struct Controllers {
    names: Vec<String>,
    list: Vec<Running>,
    /// What happened since the last drain (a trajectory reached its goal or failed).
    events: Vec<String>,
}

impl Controllers {
    /// Sets up `config`'s controllers on the actuators (their gains; commands start where the
    /// joints are).
    pub(crate) fn new(
        config: &ControllerConfig,
        robot: &RobotModel,
        actuators: &mut Actuators,
    ) -> Result<Self> {
        let id_of = |actuators: &Actuators, name: &str| -> Result<JointId> {
            let id = robot.joint_id(name).ok_or_else(|| {
                SimError::Setup(format!(
                    "{}: no joint \"{name}\" in robot \"{}\"",
                    config.source.display(),
                    robot.name
                ))
            })?;
            if actuators.of(id).is_none() {
                return Err(SimError::Setup(format!(
                    "{}: joint \"{name}\" has no actuator in the scene",
                    config.source.display()
                )));
            }
            Ok(id)
        };
        for (joint, pid) in &config.pid_gains {
            actuators.set_pid(id_of(actuators, joint)?, *pid);
        }
        let mut out = Self::default();
        for spec in &config.controllers {
            let running = match &spec.kind {
                ControllerKind::JointState { .. } => Running::JointState,
                ControllerKind::Joint { joint, command } => {
                    let id = id_of(actuators, joint)?;
                    let last = match command {
                        CommandKind::PositionPid(pid) => {
                            actuators.set_pid(id, *pid);
                            actuators.setpoint(id)
                        }
                        CommandKind::Position => actuators.setpoint(id),
                        CommandKind::Velocity | CommandKind::Effort => {
                            let c = if matches!(command, CommandKind::Velocity) {
                                JointCommand::Velocity(0.0)
                            } else {
                                JointCommand::Effort(0.0)
                            };
                            actuators.command(robot, id, c)?;
                            0.0
                        }
                    };
                    Running::Joint {
                        joint: id,
                        command: *command,
                        last,
                    }
                }
                ControllerKind::Gripper(g) => {
                    let id = id_of(actuators, &g.joint)?;
                    if let Some(pid) = &g.gains {
                        actuators.set_pid(id, *pid);
                    }
                    Running::Gripper(Box::new(GripperRun {
                        spec: g.clone(),
                        state: GripperState {
                            joint: Some(id),
                            goal: actuators.setpoint(id),
                            position: actuators.position(id),
                            ..GripperState::default()
                        },
                        last_moved: (0.0, 0.0),
                    }))
                }
                ControllerKind::Trajectory(t) => {
                    let joints = t
                        .joints
                        .iter()
                        .map(|j| id_of(actuators, j))
                        .collect::<Result<Vec<_>>>()?;
                    if let Some(gains) = &t.gains {
                        for (id, pid) in joints.iter().zip(gains) {
                            actuators.set_pid(*id, *pid);
                        }
                    }
                    let n = joints.len();
                    Running::Trajectory(Box::new(TrajectoryRun {
                        state: TrajectoryState {
                            desired_positions: joints
                                .iter()
                                .map(|j| actuators.setpoint(*j))
                                .collect(),
                            desired_velocities: vec![0.0; n],
                            joints: joints.clone(),
                            active: false,
                            runs: 0,
                            outcome: None,
                        },
                        joints,
                        constraints: t.constraints.clone(),
                        knots: Vec::new(),
                        end_s: None,
                    }))
                }
            };
            out.names.push(spec.name.clone());
            out.list.push(running);
        }
        Ok(out)
    }

    fn index(&self, name: &str) -> Result<usize> {
        self.names.iter().position(|n| n == name).ok_or_else(|| {
            SimError::Setup(format!(
                "no controller \"{name}\"; the robot's controllers: {}",
                crate::error::quoted_list(self.names.iter())
            ))
        })
    }

    /// A single-joint controller's command (its `command` topic).
    pub(crate) fn command(
        &mut self,
        name: &str,
        value: f64,
        robot: &RobotModel,
        actuators: &mut Actuators,
    ) -> Result<()> {
        let i = self.index(name)?;
        let Running::Joint {
            joint,
            command,
            last,
        } = &mut self.list[i]
        else {
            return Err(SimError::Setup(format!(
                "controller \"{name}\" takes no single command (it is a joint state or trajectory controller)"
            )));
        };
        let c = match command {
            CommandKind::PositionPid(_) | CommandKind::Position => JointCommand::Position(value),
            CommandKind::Velocity => JointCommand::Velocity(value),
            CommandKind::Effort => JointCommand::Effort(value),
        };
        actuators.command(robot, *joint, c)?;
        *last = value;
        Ok(())
    }

    /// Starts a trajectory on a trajectory controller (its `command` topic). A trajectory
    /// with no points stops the one running and holds where the joints are.
    pub(crate) fn follow(
        &mut self,
        name: &str,
        trajectory: &JointTrajectory,
        robot: &RobotModel,
        (actuators, now_s): (&mut Actuators, f64),
    ) -> Result<()> {
        let i = self.index(name)?;
        let Running::Trajectory(run) = &mut self.list[i] else {
            return Err(SimError::Setup(format!(
                "controller \"{name}\" is not a joint trajectory controller"
            )));
        };
        let joints: Vec<&str> = run
            .joints
            .iter()
            .map(|j| robot.joint(*j).name.as_str())
            .collect();
        let order = trajectory
            .check(&joints)
            .map_err(|error| SimError::Trajectory {
                controller: name.to_owned(),
                error,
            })?;
        let start_s = if trajectory.start_s > 0.0 {
            trajectory.start_s
        } else {
            now_s
        };
        let n = run.joints.len();
        let mut knots = Vec::with_capacity(trajectory.points.len() + 1);
        knots.push(Knot {
            t_s: now_s,
            positions: run.joints.iter().map(|j| actuators.setpoint(*j)).collect(),
            velocities: Some(
                run.joints
                    .iter()
                    .map(|j| actuators.setpoint_velocity(*j))
                    .collect(),
            ),
            accelerations: Some(vec![0.0; n]),
        });
        let pick = |values: &[f64]| -> Vec<f64> { order.iter().map(|&k| values[k]).collect() };
        for p in &trajectory.points {
            let t_s = start_s + p.time_from_start_s;
            if t_s <= now_s {
                continue;
            }
            knots.push(Knot {
                t_s,
                positions: pick(&p.positions),
                velocities: (!p.velocities.is_empty()).then(|| pick(&p.velocities)),
                accelerations: (!p.accelerations.is_empty() && !p.velocities.is_empty())
                    .then(|| pick(&p.accelerations)),
            });
        }
        if trajectory.points.is_empty() {
            if run.state.active {
                run.state.outcome = Some(TrajectoryOutcome::Stopped);
            }
            run.stop(robot, actuators, true);
            return Ok(());
        }
        if knots.len() < 2 {
            return Err(SimError::Setup(format!(
                "controller \"{name}\": every point of the trajectory is already past (sim time {now_s:.3} s)"
            )));
        }
        run.end_s = knots.last().map(|k| k.t_s);
        run.knots = knots;
        run.state.active = true;
        run.state.runs += 1;
        run.state.outcome = None;
        Ok(())
    }

    /// A gripper controller's command (control_msgs/GripperCommand): the finger joint to
    /// `position`, pushing with at most `max_effort` (0 or less: its `<limit effort>`). A new
    /// command replaces the one running.
    pub(crate) fn command_gripper(
        &mut self,
        name: &str,
        (position, max_effort): (f64, f64),
        robot: &RobotModel,
        (actuators, now_s): (&mut Actuators, f64),
    ) -> Result<()> {
        let i = self.index(name)?;
        let Running::Gripper(run) = &mut self.list[i] else {
            return Err(SimError::Setup(format!(
                "controller \"{name}\" is not a gripper controller (GripperActionController)"
            )));
        };
        if !(position.is_finite() && max_effort.is_finite()) {
            return Err(SimError::Setup(format!(
                "controller \"{name}\": a gripper command needs finite numbers, got position {position}, max_effort {max_effort}"
            )));
        }
        let Some(joint) = run.state.joint else {
            return Err(SimError::Setup(format!(
                "controller \"{name}\" has no joint"
            )));
        };
        actuators.set_effort_cap(joint, (max_effort > 0.0).then_some(max_effort));
        actuators.restart_setpoint(joint);
        actuators.command(robot, joint, JointCommand::Position(position))?;
        let s = &mut run.state;
        s.goal = actuators.target(joint);
        s.active = true;
        s.runs += 1;
        s.stalled = false;
        s.reached_goal = false;
        run.last_moved = (actuators.position(joint), now_s);
        Ok(())
    }

    /// One control update: samples running trajectories into the actuators' commands, checks
    /// their tolerances; follows the grippers' commands to their goal or a stall.
    pub(crate) fn update(&mut self, robot: &RobotModel, actuators: &mut Actuators, now_s: f64) {
        for (name, running) in self.names.iter().zip(&mut self.list) {
            if let Running::Gripper(run) = running {
                if let Some(event) = run.update(name, actuators, now_s) {
                    self.events.push(event);
                }
                continue;
            }
            let Running::Trajectory(run) = running else {
                continue;
            };
            let Some(end_s) = run.end_s else {
                continue;
            };
            if let Some((event, hold_here, outcome)) =
                run.update(name, robot, actuators, now_s, end_s)
            {
                run.state.outcome = Some(outcome);
                run.stop(robot, actuators, hold_here);
                self.events.push(event);
            }
        }
    }

    /// Records something that happened (a grasp attached or let go), for the same log.
    pub(crate) fn note(&mut self, event: String) {
        self.events.push(event);
    }

    /// Takes what happened since the last call (trajectory outcomes), oldest first.
    pub(crate) fn drain_events(&mut self) -> std::vec::Drain<'_, String> {
        self.events.drain(..)
    }

    /// The state of the trajectory controller `name`.
    pub(crate) fn trajectory_state(&self, name: &str) -> Option<&TrajectoryState> {
        let i = self.index(name).ok()?;
        match &self.list[i] {
            Running::Trajectory(run) => Some(&run.state),
            _ => None,
        }
    }

    /// The state of the gripper controller `name`.
    pub(crate) fn gripper_state(&self, name: &str) -> Option<&GripperState> {
        let i = self.index(name).ok()?;
        match &self.list[i] {
            Running::Gripper(run) => Some(&run.state),
            _ => None,
        }
    }

    /// The joint and last command of the single-joint controller `name`.
    pub(crate) fn command_state(&self, name: &str) -> Option<ControllerCommandState> {
        let i = self.index(name).ok()?;
        match &self.list[i] {
            Running::Joint { joint, last, .. } => Some(ControllerCommandState {
                joint: Some(*joint),
                command: *last,
            }),
            Running::JointState | Running::Trajectory(_) | Running::Gripper(_) => None,
        }
    }
}

impl GripperRun {
    /// Measures the finger; ends the command at its goal or at a stall (what ended it, for
    /// the log). The position command stays: a stalled gripper keeps squeezing.
    fn update(&mut self, name: &str, actuators: &Actuators, now_s: f64) -> Option<String> {
        let joint = self.state.joint?;
        let s = &mut self.state;
        s.position = actuators.position(joint);
        s.effort = actuators.of(joint).map_or(0.0, |a| a.effort);
        if !s.active {
            return None;
        }
        // Moving: out of the band the threshold speed covers in `stall_timeout` since it last
        // moved (gripper_action_controller reads the instantaneous speed; rover the distance,
        // which the fingers' jitter on a held object does not reset).
        let band =
            (self.spec.stalled_velocity_threshold * self.spec.stall_timeout_s).max(STALL_BAND_MIN);
        if (s.position - self.last_moved.0).abs() > band {
            self.last_moved = (s.position, now_s);
        }
        if (s.goal - s.position).abs() <= self.spec.goal_tolerance {
            s.active = false;
            s.reached_goal = true;
            return Some(format!(
                "controller {name}: gripper reached {:.4} (goal {:.4})",
                s.position, s.goal
            ));
        }
        if now_s - self.last_moved.1 > self.spec.stall_timeout_s {
            s.active = false;
            s.stalled = true;
            return Some(format!(
                "controller {name}: gripper stalled at {:.4} (goal {:.4}), pushing with {:.2}",
                s.position, s.goal, s.effort
            ));
        }
        None
    }
}

impl TrajectoryRun {
    /// Samples the trajectory at `now_s`, commands the joints, and checks the tolerances;
    /// returns what ended it, if it ended, and whether the joints should stop where they are.
    fn update(
        &mut self,
        name: &str,
        robot: &RobotModel,
        actuators: &mut Actuators,
        now_s: f64,
        end_s: f64,
    ) -> Option<(String, bool, TrajectoryOutcome)> {
        let t = now_s.min(end_s);
        let seg = self
            .knots
            .windows(2)
            .position(|w| t <= w[1].t_s)
            .unwrap_or(self.knots.len().saturating_sub(2));
        let (a, b) = (&self.knots[seg], &self.knots[seg + 1]);
        for (k, joint) in self.joints.iter().enumerate() {
            let (q, v) = interpolate(a, b, k, t);
            self.state.desired_positions[k] = q;
            self.state.desired_velocities[k] = v;
            let command = if now_s >= end_s {
                JointCommand::Position(q)
            } else {
                JointCommand::Track {
                    position: q,
                    velocity: v,
                }
            };
            // The joints were checked when the controller was set up; a failure here is a bug,
            // and the joint keeps its last command.
            let _ = actuators.command(robot, *joint, command);
        }
        let c = &self.constraints;
        let worst = |tolerances: &[f64]| {
            self.joints
                .iter()
                .enumerate()
                .filter(|(k, _)| tolerances[*k] > 0.0)
                .map(|(k, j)| {
                    let q = actuators.position(*j);
                    (k, (self.state.desired_positions[k] - q).abs())
                })
                .find(|(k, e)| *e > tolerances[*k])
        };
        let joint_name = |k: usize| robot.joint(self.joints[k]).name.clone();
        if now_s < end_s {
            let (k, error) = worst(&c.trajectory)?;
            return Some((
                format!(
                    "controller {name}: PATH_TOLERANCE_VIOLATED: joint {} is {error:.4} from the trajectory, tolerance {:.4}; holding where it is",
                    joint_name(k),
                    c.trajectory[k]
                ),
                true,
                TrajectoryOutcome::PathToleranceViolated,
            ));
        }
        let moving = self
            .joints
            .iter()
            .enumerate()
            .find(|(_, j)| {
                c.stopped_velocity_tolerance > 0.0
                    && actuators.velocity(**j).abs() > c.stopped_velocity_tolerance
            })
            .map(|(k, _)| k);
        let off = worst(&c.goal);
        if off.is_none() && moving.is_none() {
            return Some((
                format!("controller {name}: trajectory reached its goal at {now_s:.3} s"),
                false,
                TrajectoryOutcome::Reached,
            ));
        }
        if now_s <= end_s + c.goal_time_s {
            return None;
        }
        let message = match (off, moving) {
            (Some((k, error)), _) => format!(
                "controller {name}: GOAL_TOLERANCE_VIOLATED: joint {} ended {error:.4} from its goal {:.4}, tolerance {:.4} (goal_time {:.2} s)",
                joint_name(k),
                self.state.desired_positions[k],
                c.goal[k],
                c.goal_time_s
            ),
            (None, Some(k)) => format!(
                "controller {name}: GOAL_TOLERANCE_VIOLATED: joint {} still moving at {:.4}, stopped_velocity_tolerance {:.4} (goal_time {:.2} s)",
                joint_name(k),
                actuators.velocity(self.joints[k]),
                c.stopped_velocity_tolerance,
                c.goal_time_s
            ),
            (None, None) => format!("controller {name}: trajectory ended"),
        };
        Some((message, false, TrajectoryOutcome::GoalToleranceViolated))
    }

    /// Ends the trajectory; the joints hold its last sample, or where they are.
    fn stop(&mut self, robot: &RobotModel, actuators: &mut Actuators, hold_here: bool) {
        self.end_s = None;
        self.knots.clear();
        self.state.active = false;
        if hold_here {
            for j in &self.joints {
                let q = actuators.position(*j);
                let _ = actuators.command(robot, *j, JointCommand::Position(q));
            }
        }
    }
}

/// Position and velocity of joint `k` at `t` between knots `a` and `b`.
fn interpolate(a: &Knot, b: &Knot, k: usize, t: f64) -> (f64, f64) {
    let duration = (b.t_s - a.t_s).max(1e-9);
    let s = (t - a.t_s).clamp(0.0, duration);
    let (p0, p1) = (a.positions[k], b.positions[k]);
    let Some(bv) = &b.velocities else {
        let v = (p1 - p0) / duration;
        return (p0 + v * s, v);
    };
    let v0 = a.velocities.as_ref().map_or(0.0, |v| v[k]);
    let v1 = bv[k];
    let (a0, a1) = match (&a.accelerations, &b.accelerations) {
        (Some(x), Some(y)) => (x[k], y[k]),
        (None, Some(y)) => (0.0, y[k]),
        _ => {
            // Cubic through both positions and velocities.
            let t = duration;
            let c2 = (3.0 * (p1 - p0) - (2.0 * v0 + v1) * t) / (t * t);
            let c3 = (2.0 * (p0 - p1) + (v0 + v1) * t) / (t * t * t);
            return (
                p0 + v0 * s + c2 * s * s + c3 * s * s * s,
                v0 + 2.0 * c2 * s + 3.0 * c3 * s * s,
            );
        }
    };
    // Quintic through positions, velocities and accelerations.
    let t = duration;
    let (t2, t3, t4, t5) = (t * t, t * t * t, t * t * t * t, t * t * t * t * t);
    let c3 = (20.0 * (p1 - p0) - (8.0 * v1 + 12.0 * v0) * t - (3.0 * a0 - a1) * t2) / (2.0 * t3);
    let c4 =
        (30.0 * (p0 - p1) + (14.0 * v1 + 16.0 * v0) * t + (3.0 * a0 - 2.0 * a1) * t2) / (2.0 * t4);
    let c5 = (12.0 * (p1 - p0) - (6.0 * v1 + 6.0 * v0) * t - (a0 - a1) * t2) / (2.0 * t5);
    let c2 = a0 / 2.0;
    (
        p0 + v0 * s + c2 * s * s + c3 * s.powi(3) + c4 * s.powi(4) + c5 * s.powi(5),
        v0 + 2.0 * c2 * s + 3.0 * c3 * s * s + 4.0 * c4 * s.powi(3) + 5.0 * c5 * s.powi(4),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn knot(t_s: f64, p: f64, v: Option<f64>, a: Option<f64>) -> Knot {
        Knot {
            t_s,
            positions: vec![p],
            velocities: v.map(|v| vec![v]),
            accelerations: a.map(|a| vec![a]),
        }
    }

    #[test]
    fn segments_meet_their_ends_for_every_kind_of_point() {
        let start = knot(1.0, 0.5, Some(0.2), Some(0.0));
        for end in [
            knot(3.0, -1.0, None, None),
            knot(3.0, -1.0, Some(0.3), None),
            knot(3.0, -1.0, Some(0.3), Some(-0.1)),
        ] {
            let (q0, _) = interpolate(&start, &end, 0, 1.0);
            let (q1, v1) = interpolate(&start, &end, 0, 3.0);
            assert!((q0 - 0.5).abs() < 1e-12, "{q0}");
            assert!((q1 + 1.0).abs() < 1e-9, "{q1}");
            if let Some(v) = &end.velocities {
                assert!((v1 - v[0]).abs() < 1e-9, "{v1}");
                let (_, v0) = interpolate(&start, &end, 0, 1.0);
                assert!((v0 - 0.2).abs() < 1e-9, "{v0}");
            } else {
                assert!((v1 + 0.75).abs() < 1e-12, "{v1}");
            }
        }
    }
}
