//! The robot's joint actuators: ros_control's hardware interfaces on sim time.
//!
//! Every actuated joint ([`RobotModel::actuated_joints`]) gets one. Left alone it holds the
//! pose it started in — a PID whose gains come from the inertia the joint carries (a critically
//! damped loop at [`HOLD_BANDWIDTH_HZ`], integral time [`HOLD_INTEGRAL_S`]) with the carried
//! weight fed forward, so an arm neither sags under gravity nor jitters, and no one has to
//! write gains first. A position command moves the setpoint toward the target on a trapezoid
//! within the URDF `<limit velocity>` and the effort the load leaves; the effort never exceeds
//! `<limit effort>` (the motor's force cap). Velocity and effort commands follow
//! gazebo_ros_control's VelocityJointInterface and EffortJointInterface.
//!
//! The proportional and derivative terms are solved implicitly by rapier's joint motor (stable
//! at any gain on a 59 g link), the integral and weight terms explicitly, as a shift of the
//! motor's target.

use glam::Vec3;
use rapier3d::prelude::*;

use crate::error::{Result, SimError};
use crate::model::actuation::Pid;
use crate::model::robot::{JointId, JointKind, RobotModel};
use crate::physics::diff_drive::wrap_angle;
use crate::physics::joints::{BuiltJoint, JointRef, joint_data_mut};

/// Bandwidth of the default holding loop (Hz).
pub const HOLD_BANDWIDTH_HZ: f64 = 8.0;
/// Integral time of the default holding loop (s): how fast a steady load (gravity) is
/// cancelled.
pub const HOLD_INTEGRAL_S: f64 = 0.15;
/// How far the default hold's integral may go, in effort limits.
const HOLD_INTEGRAL_HEADROOM: f64 = 4.0;
/// The speed an effort command's motor chases on a multibody joint (rad/s or m/s): far beyond
/// any joint's, so the motor always pushes with its force cap, the commanded effort.
const EFFORT_CHASE_SPEED: f64 = 1.0e4;
/// That motor's damping (N m s/rad): large enough to saturate at any speed a joint reaches.
const EFFORT_CHASE_DAMPING: f32 = 1.0e6;
/// Below this the carried inertia is not known yet (kg m^2 or kg).
const MIN_INERTIA: f64 = 1e-9;
/// The share of the velocity limit a position move plans for (the loop's tracking error
/// takes the rest).
const PROFILE_VELOCITY_SHARE: f64 = 0.9;
/// How far a `<mimic>` joint may be from where its leader puts it when pushing with its full
/// effort (m or rad): the coupling's stiffness.
const MIMIC_HOLD_ERROR: f64 = 0.001;
/// A `<mimic>` joint's effort cap while its leader's is lowered (a gripper's squeeze), as a
/// multiple of the leader's.
const MIMIC_CAP_RATIO: f64 = 2.0;

/// The share of the effort left over from carrying the load that a position move plans to
/// accelerate and brake with (the loop's corrections take the rest).
const PROFILE_EFFORT_SHARE: f64 = 0.3;
/// The default hold integrates only errors smaller than this (rad or m): the integral is for
/// what the weight estimate leaves, not for catching up after a move.
const HOLD_INTEGRAL_BAND: f64 = 0.2;
/// The largest error the default hold leaves to a joint's dry friction (`<dynamics
/// friction>`, rad or m): its stiffness is at least friction / this.
pub const HOLD_FRICTION_ERROR: f64 = 0.002;

/// What a joint is told to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointCommand {
    /// Go to and hold a position (rad or m); clamped into the joint's limits.
    Position(f64),
    /// Turn or slide at a speed (rad/s or m/s); capped by the velocity limit.
    Velocity(f64),
    /// Apply a torque (N m) or force (N); capped by the effort limit.
    Effort(f64),
    /// Follow a moving setpoint (a trajectory controller's sample): held at `position` now,
    /// moving at `velocity`, with no profile of rover's own. Clamped into the limits.
    Track {
        /// Where the joint should be now (rad or m).
        position: f64,
        /// How fast the setpoint moves (rad/s or m/s).
        velocity: f64,
    },
}

impl JointCommand {
    /// Whether every number in it is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            Self::Position(v) | Self::Velocity(v) | Self::Effort(v) => v.is_finite(),
            Self::Track { position, velocity } => position.is_finite() && velocity.is_finite(),
        }
    }
}

/// A joint's state, as `/joint_states` reports it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointState {
    /// Position (rad or m).
    pub position: f64,
    /// Velocity (rad/s or m/s).
    pub velocity: f64,
    /// The actuator's effort at the last control update (N m or N); 0 for passive joints.
    pub effort: f64,
}

#[derive(Debug, Clone)]
pub(crate) struct Actuator {
    built: BuiltJoint,
    continuous: bool,
    limits: Option<(f64, f64)>,
    effort_max: f64,
    /// A lower cap a gripper command sets (its `max_effort`); `None`: `effort_max`.
    effort_cap: Option<f64>,
    /// A `<mimic>` joint: held to its leader stiffly (its full effort within
    /// [`MIMIC_HOLD_ERROR`]), as a coupling.
    coupling: bool,
    velocity_max: Option<f64>,
    command: JointCommand,
    /// User gains (a controllers YAML); `None`: derived from the inertia.
    pid: Option<Pid>,
    /// The position the loop holds now (moves toward a position target at the velocity limit).
    setpoint: f64,
    setpoint_velocity: f64,
    /// The integral term (N m or N).
    integral: f64,
    /// Effective inertia about the axis (kg m^2 or kg), measured every control update.
    inertia: f64,
    /// The effort that holds the carried bodies against gravity now (N m or N).
    gravity_hold: f64,
    /// `<dynamics friction>` (N m or N).
    friction: f64,
    /// The effort at the last control update (N m or N).
    pub(crate) effort: f64,
    /// Position and velocity measured at the last control update.
    measured: (f64, f64),
    /// The bodies the joint carries (its child and everything beyond it).
    carried: Vec<RigidBodyHandle>,
}

impl Actuator {
    /// The most effort the motor may use now (N m or N).
    fn cap(&self) -> f64 {
        self.effort_cap
            .map_or(self.effort_max, |c| c.min(self.effort_max))
    }

    fn gains(&self) -> Pid {
        self.pid.unwrap_or_else(|| {
            let omega = 2.0 * std::f64::consts::PI * HOLD_BANDWIDTH_HZ;
            let mut p = (self.inertia * omega * omega).max(self.friction / HOLD_FRICTION_ERROR);
            // A joint without an effort limit (`effort_max` is f32::MAX) keeps the default
            // hold: no finite stiffness puts an unlimited effort within the error.
            if self.coupling && self.effort_max < f64::from(f32::MAX) {
                p = p.max(self.cap() / MIMIC_HOLD_ERROR);
            }
            Pid {
                p,
                i: p / HOLD_INTEGRAL_S,
                // Critically damped at whichever stiffness won.
                d: 2.0 * (p * self.inertia).sqrt(),
                i_clamp: 0.0,
            }
        })
    }

    /// Moves the setpoint toward `target` on a trapezoid: at [`PROFILE_VELOCITY_SHARE`] of the
    /// velocity limit at most, accelerating and braking with [`PROFILE_EFFORT_SHARE`] of the
    /// effort left over from carrying the load, so the loop that follows it is not driven into
    /// its effort limit. User gains get no acceleration bound (ros_control has none).
    fn advance_setpoint(&mut self, target: f64, dt_s: f64) {
        let to_go = self.error(target, self.setpoint);
        let v_max = self.velocity_max.unwrap_or(f64::INFINITY) * PROFILE_VELOCITY_SHARE;
        let spare = (self.effort_max - self.gravity_hold.abs()).max(0.1 * self.effort_max);
        let accel = if self.pid.is_none() {
            PROFILE_EFFORT_SHARE * spare / self.inertia
        } else {
            f64::INFINITY
        };
        let wanted = to_go.signum() * v_max.min((2.0 * accel * to_go.abs()).sqrt());
        let dv = (wanted - self.setpoint_velocity).clamp(-accel * dt_s, accel * dt_s);
        let mut velocity = self.setpoint_velocity + dv;
        if !velocity.is_finite() {
            velocity = wanted;
        }
        let mut step = velocity * dt_s;
        if step.abs() >= to_go.abs() || to_go == 0.0 {
            step = to_go;
            velocity = 0.0;
        }
        self.setpoint = self.clamp_position(self.setpoint + step);
        self.setpoint_velocity = velocity;
    }

    fn clamp_position(&self, q: f64) -> f64 {
        match self.limits {
            Some((lo, hi)) => q.clamp(lo, hi),
            None => q,
        }
    }

    /// Error from `q` to `target`; the short way round for a continuous joint.
    fn error(&self, target: f64, q: f64) -> f64 {
        if self.continuous {
            wrap_angle(target - q)
        } else {
            target - q
        }
    }
}

/// A `<mimic>` joint's actuator and the joint it follows: each control update it tracks
/// `multiplier x leader + offset` (and the leader's speed times the multiplier), as Gazebo's
/// mimic joint plugins drive a gripper's second finger, with its own motor's effort cap.
#[derive(Debug, Clone, Copy)]
struct Follower {
    /// The mimic joint's actuator.
    actuator: usize,
    /// The joint it follows, as built.
    leader: BuiltJoint,
    multiplier: f64,
    offset: f64,
}

/// The actuators of one robot, run at the control period.
#[derive(Debug, Clone, Default)]
pub(crate) struct Actuators {
    list: Vec<Actuator>,
    /// Actuator index per joint (joint order).
    by_joint: Vec<Option<usize>>,
    /// The `<mimic>` joints' actuators, driven from their leaders.
    followers: Vec<Follower>,
}

impl Actuators {
    /// One actuator per actuated joint that the scene has, holding where it starts.
    pub(crate) fn new(
        robot: &RobotModel,
        (joints, link_body): (&[Option<BuiltJoint>], &[RigidBodyHandle]),
        physics: &mut PhysicsWorld,
    ) -> Self {
        let mut out = Self {
            by_joint: vec![None; robot.joints.len()],
            ..Self::default()
        };
        let mimics = robot
            .joints
            .iter()
            .enumerate()
            .filter(|(_, j)| j.is_moving() && j.mimic.is_some())
            .map(|(i, _)| JointId(i));
        for id in robot.actuated_joints().into_iter().chain(mimics) {
            let Some(built) = joints[id.index()] else {
                continue;
            };
            let joint = robot.joint(id);
            let limits = joint
                .position_limits()
                .map(|(lo, hi)| (f64::from(lo), f64::from(hi)));
            let start = built.position(&physics.bodies);
            let effort_max = joint
                .effort_limit
                .filter(|e| *e > 0.0)
                .map_or(f64::from(f32::MAX), f64::from);
            let mut actuator = Actuator {
                built,
                continuous: matches!(joint.kind, JointKind::Continuous),
                limits,
                effort_max,
                effort_cap: None,
                coupling: joint.mimic.is_some(),
                velocity_max: joint.velocity_limit.filter(|v| *v > 0.0).map(f64::from),
                command: JointCommand::Position(start),
                pid: None,
                setpoint: start,
                setpoint_velocity: 0.0,
                integral: 0.0,
                inertia: 1.0,
                gravity_hold: 0.0,
                friction: f64::from(joint.friction),
                effort: 0.0,
                measured: (start, 0.0),
                carried: carried_bodies(robot, id, link_body),
            };
            actuator.setpoint = actuator.clamp_position(start);
            actuator.command = JointCommand::Position(actuator.setpoint);
            if let Some(data) = joint_data_mut(physics, built.handle) {
                data.set_motor_model(built.axis, MotorModel::ForceBased)
                    .set_motor_max_force(built.axis, effort_max as f32);
            }
            if let Some(m) = &joint.mimic {
                let Some(leader) = joints.get(m.joint.index()).copied().flatten() else {
                    // A leader the scene does not move (fixed): the follower holds.
                    out.by_joint[id.index()] = Some(out.list.len());
                    out.list.push(actuator);
                    continue;
                };
                out.followers.push(Follower {
                    actuator: out.list.len(),
                    leader,
                    multiplier: f64::from(m.multiplier),
                    offset: f64::from(m.offset),
                });
            }
            out.by_joint[id.index()] = Some(out.list.len());
            out.list.push(actuator);
        }
        out
    }

    /// Whether `joint` follows another (`<mimic>`): it takes no commands of its own.
    fn is_follower(&self, joint: JointId) -> bool {
        let Some(i) = self.by_joint.get(joint.index()).copied().flatten() else {
            return false;
        };
        self.followers.iter().any(|f| f.actuator == i)
    }

    /// Points every `<mimic>` joint at its leader's position now.
    fn follow_leaders(&mut self, physics: &PhysicsWorld) {
        for f in &self.followers {
            let q = f.leader.position(&physics.bodies);
            // A multibody's link bodies do not carry its joints' speeds (they are recomputed
            // from its own coordinates), so there the follower tracks the position alone.
            let v = match f.leader.handle {
                JointRef::Impulse(_) => f.leader.velocity(&physics.bodies),
                JointRef::Multibody(_) => 0.0,
            };
            if let Some(a) = self.list.get_mut(f.actuator) {
                let cap = a.velocity_max.unwrap_or(f64::INFINITY);
                a.command = JointCommand::Track {
                    position: a.clamp_position(f.multiplier * q + f.offset),
                    velocity: (f.multiplier * v).clamp(-cap, cap),
                };
            }
        }
    }

    /// The actuator of `joint`, if it has one.
    pub(crate) fn of(&self, joint: JointId) -> Option<&Actuator> {
        self.index(joint).map(|i| &self.list[i])
    }

    fn of_mut(&mut self, joint: JointId) -> Option<&mut Actuator> {
        let i = self.index(joint)?;
        self.list.get_mut(i)
    }

    /// Where `joint`'s actuator is in the list, if it has one.
    fn index(&self, joint: JointId) -> Option<usize> {
        self.by_joint.get(joint.index()).copied().flatten()
    }

    /// Sets a joint's command. Non-finite values and joints without an actuator are errors;
    /// positions outside the limits are clamped to them.
    pub(crate) fn command(
        &mut self,
        robot: &RobotModel,
        joint: JointId,
        command: JointCommand,
    ) -> Result<()> {
        let name = &robot.joint(joint).name;
        if !command.is_finite() {
            return Err(SimError::Setup(format!(
                "joint \"{name}\": command {command:?} is not finite"
            )));
        }
        if self.is_follower(joint) {
            let leader = robot
                .joint(joint)
                .mimic
                .as_ref()
                .map(|m| robot.joint(m.joint).name.clone())
                .unwrap_or_default();
            return Err(SimError::Setup(format!(
                "joint \"{name}\" mimics \"{leader}\" and follows it: command \"{leader}\" instead"
            )));
        }
        let Some(a) = self.of_mut(joint) else {
            return Err(SimError::Setup(format!(
                "joint \"{name}\" has no actuator (it is fixed, passive or a drive wheel)"
            )));
        };
        a.command = match command {
            JointCommand::Position(q) => JointCommand::Position(a.clamp_position(q)),
            JointCommand::Velocity(v) => {
                let cap = a.velocity_max.unwrap_or(f64::INFINITY);
                JointCommand::Velocity(v.clamp(-cap, cap))
            }
            JointCommand::Effort(e) => JointCommand::Effort(e.clamp(-a.effort_max, a.effort_max)),
            JointCommand::Track { position, velocity } => {
                let cap = a.velocity_max.unwrap_or(f64::INFINITY);
                JointCommand::Track {
                    position: a.clamp_position(position),
                    velocity: velocity.clamp(-cap, cap),
                }
            }
        };
        Ok(())
    }

    /// The position the actuator holds now (its setpoint; rad or m); 0 without an actuator.
    pub(crate) fn setpoint(&self, joint: JointId) -> f64 {
        self.of(joint).map_or(0.0, |a| a.setpoint)
    }

    /// Where the joint's command sends it (rad or m): a position command's target, a
    /// trajectory's sample, else the setpoint; 0 without an actuator.
    pub(crate) fn target(&self, joint: JointId) -> f64 {
        self.of(joint).map_or(0.0, |a| match a.command {
            JointCommand::Position(q) => q,
            JointCommand::Track { position, .. } => position,
            JointCommand::Velocity(_) | JointCommand::Effort(_) => a.setpoint,
        })
    }

    /// How fast the setpoint moves now; 0 without an actuator.
    pub(crate) fn setpoint_velocity(&self, joint: JointId) -> f64 {
        self.of(joint).map_or(0.0, |a| a.setpoint_velocity)
    }

    /// The joint's position at the last control update.
    pub(crate) fn position(&self, joint: JointId) -> f64 {
        self.of(joint).map_or(0.0, |a| a.measured.0)
    }

    /// The joint's velocity at the last control update.
    pub(crate) fn velocity(&self, joint: JointId) -> f64 {
        self.of(joint).map_or(0.0, |a| a.measured.1)
    }

    /// Caps the effort of `joint` (a gripper command's `max_effort`); `None` lifts the cap
    /// back to its `<limit effort>`. The joints that mimic it are a coupling, holding their
    /// finger where the leader's puts it, so the leader's cap is the squeeze; theirs becomes
    /// [`MIMIC_CAP_RATIO`] times it (and their stiffness with it, [`MIMIC_HOLD_ERROR`]): enough
    /// to hold the grip centred, not a 100 N spring on a 15 g finger kicking what it holds
    /// whenever the leader moves between two control updates.
    pub(crate) fn set_effort_cap(&mut self, joint: JointId, cap: Option<f64>) {
        let Some(i) = self.index(joint) else {
            return;
        };
        self.list[i].effort_cap = cap;
        let leader = self.list[i].built.handle;
        for f in &self.followers {
            if f.leader.handle == leader
                && let Some(a) = self.list.get_mut(f.actuator)
            {
                a.effort_cap = cap.map(|c| c * MIMIC_CAP_RATIO);
            }
        }
    }

    /// Starts `joint`'s setpoint afresh where the joint is, at rest, its integral emptied: a
    /// new gripper command moves from where the fingers are, not from where the last
    /// command's setpoint ran ahead to (a finger stalled on an object has its setpoint at the
    /// closed end, and opening would first have to wind it back).
    pub(crate) fn restart_setpoint(&mut self, joint: JointId) {
        if let Some(a) = self.of_mut(joint) {
            a.setpoint = a.measured.0;
            a.setpoint_velocity = 0.0;
            a.integral = 0.0;
        }
    }

    /// Gives a joint its own PID gains (an effort_controllers position controller).
    pub(crate) fn set_pid(&mut self, joint: JointId, pid: Pid) {
        if let Some(a) = self.of_mut(joint) {
            a.pid = Some(pid);
        }
    }
}

// Each physics step: the motors' efforts from their setpoints, applied and measured.
impl Actuators {
    /// One control update of length `dt_s`: moves setpoints, sets the motors.
    pub(crate) fn update(&mut self, physics: &mut PhysicsWorld, dt_s: f64) {
        self.measure_loads(physics);
        self.follow_leaders(physics);
        for a in &mut self.list {
            if a.inertia <= MIN_INERTIA {
                // Mass properties are computed by the first physics step.
                continue;
            }
            let q = a.built.position(&physics.bodies);
            let v = a.built.velocity(&physics.bodies);
            a.measured = (q, v);
            let gains = a.gains();
            let axis = a.built.axis;
            let Some(data) = joint_data_mut(physics, a.built.handle) else {
                continue;
            };
            match a.command {
                JointCommand::Position(_) | JointCommand::Track { .. } => {
                    if let JointCommand::Track { position, velocity } = a.command {
                        a.setpoint = position;
                        a.setpoint_velocity = velocity;
                    } else if let JointCommand::Position(target) = a.command {
                        a.advance_setpoint(target, dt_s);
                    }
                    let error = a.error(a.setpoint, q);
                    let cap = a.cap();
                    let i_cap = if gains.i_clamp > 0.0 {
                        gains.i_clamp
                    } else if a.pid.is_none() {
                        HOLD_INTEGRAL_HEADROOM * cap
                    } else {
                        cap
                    };
                    // ros_control's PID integrates always (bounded by i_clamp); the default hold
                    // only small errors, once the setpoint has arrived and the motor is not
                    // saturated, so a move does not wind it up into an overshoot.
                    let settled = a.setpoint_velocity == 0.0
                        && a.effort.abs() < cap
                        && error.abs() < HOLD_INTEGRAL_BAND;
                    // Kept as an effort, so gains that change with the pose do not rescale it.
                    if a.pid.is_some() || settled {
                        a.integral = (a.integral + gains.i * error * dt_s).clamp(-i_cap, i_cap);
                    }
                    // The default hold also carries the load's weight (ros_control's PID does
                    // not).
                    let feed_forward =
                        a.integral + if a.pid.is_none() { a.gravity_hold } else { 0.0 };
                    a.effort =
                        (gains.p * error + gains.d * (a.setpoint_velocity - v) + feed_forward)
                            .clamp(-cap, cap);
                    // The explicit terms shift the implicit PD's target by the error they
                    // stand for.
                    let shift = if gains.p > 0.0 {
                        feed_forward / gains.p
                    } else {
                        0.0
                    };
                    data.set_motor(
                        axis,
                        (q + error + shift) as f32,
                        a.setpoint_velocity as f32,
                        gains.p as f32,
                        gains.d as f32,
                    )
                    .set_motor_max_force(axis, cap as f32);
                }
                JointCommand::Velocity(target) => {
                    let gain = a.inertia / dt_s.max(1e-3);
                    a.effort = (gain * (target - v)).clamp(-a.effort_max, a.effort_max);
                    a.setpoint = q;
                    a.integral = 0.0;
                    data.set_motor_velocity(axis, target as f32, gain as f32)
                        .set_motor_max_force(axis, a.effort_max as f32);
                }
                JointCommand::Effort(effort) => {
                    a.effort = effort;
                    a.setpoint = q;
                    a.integral = 0.0;
                    if matches!(a.built.handle, JointRef::Multibody(_)) {
                        // A multibody recomputes its links' velocities from its own
                        // coordinates, so impulses on the bodies are lost: the motor applies
                        // the effort instead, chasing an unreachable speed with exactly the
                        // effort as its force cap.
                        data.set_motor(
                            axis,
                            0.0,
                            (effort.signum() * EFFORT_CHASE_SPEED) as f32,
                            0.0,
                            EFFORT_CHASE_DAMPING,
                        )
                        .set_motor_max_force(axis, effort.abs() as f32);
                    } else {
                        data.set_motor(axis, 0.0, 0.0, 0.0, 0.0)
                            .set_motor_max_force(axis, 0.0);
                    }
                }
            }
        }
    }

    /// Applies effort commands for one physics step (a torque or force between the two bodies).
    pub(crate) fn apply_efforts(&self, physics: &mut PhysicsWorld, dt_s: f64) {
        for a in &self.list {
            let JointCommand::Effort(effort) = a.command else {
                continue;
            };
            if matches!(a.built.handle, JointRef::Multibody(_)) {
                // Applied by the joint's motor (see `update`).
                continue;
            }
            let Some(child) = physics.bodies.get(a.built.child) else {
                continue;
            };
            let axis_world =
                (child.position().rotation * a.built.child_from_frame.rotation) * Vec3::X;
            let impulse = axis_world * (effort * dt_s) as f32;
            let at = (*child.position() * a.built.child_from_frame).translation;
            let linear = matches!(a.built.axis, JointAxis::LinX);
            for (body, sign) in [(a.built.child, 1.0f32), (a.built.parent, -1.0)] {
                if let Some(b) = physics.bodies.get_mut(body) {
                    if linear {
                        b.apply_impulse_at_point(impulse * sign, at, true);
                    } else {
                        b.apply_torque_impulse(impulse * sign, true);
                    }
                }
            }
        }
    }

    /// Measures what each actuated joint carries: its effective inertia — the inertia about
    /// its axis (or the mass along it) of everything beyond it with those joints held still,
    /// the joint-space mass matrix's diagonal, which is what a held arm's joint feels — and
    /// the effort that holds that load against gravity.
    fn measure_loads(&mut self, physics: &PhysicsWorld) {
        let gravity = physics.gravity;
        for a in &mut self.list {
            let Some(child) = physics.bodies.get(a.built.child) else {
                continue;
            };
            let frame = *child.position() * a.built.child_from_frame;
            let axis = frame.rotation * Vec3::X;
            let linear = matches!(a.built.axis, JointAxis::LinX);
            let (mut inertia, mut hold) = (0.0f64, 0.0f64);
            for body in a.carried.iter().filter_map(|h| physics.bodies.get(*h)) {
                let mass = body.mass();
                let weight = gravity * mass;
                if linear {
                    inertia += f64::from(mass);
                    hold -= f64::from(weight.dot(axis));
                    continue;
                }
                let r = body.center_of_mass() - frame.translation;
                let off_axis = (r - axis * r.dot(axis)).length_squared();
                let local_axis = body.position().rotation.inverse() * axis;
                let about_com = local_axis.dot(
                    body.mass_properties()
                        .local_mprops
                        .reconstruct_inertia_matrix()
                        * local_axis,
                );
                inertia += f64::from(about_com + mass * off_axis);
                hold -= f64::from(r.cross(weight).dot(axis));
            }
            a.inertia = inertia.max(MIN_INERTIA);
            a.gravity_hold = hold;
        }
    }
}

/// The distinct bodies of the links beyond `joint` (its child link and its descendants).
fn carried_bodies(
    robot: &RobotModel,
    joint: JointId,
    link_body: &[RigidBodyHandle],
) -> Vec<RigidBodyHandle> {
    let mut inside = vec![false; robot.links.len()];
    inside[robot.joint(joint).child.index()] = true;
    let mut grew = true;
    while grew {
        grew = false;
        for j in &robot.joints {
            if inside[j.parent.index()] && !inside[j.child.index()] {
                inside[j.child.index()] = true;
                grew = true;
            }
        }
    }
    let mut out: Vec<RigidBodyHandle> = Vec::new();
    for (i, _) in inside.iter().enumerate().filter(|(_, x)| **x) {
        if let Some(&body) = link_body.get(i)
            && !out.contains(&body)
        {
            out.push(body);
        }
    }
    out
}
