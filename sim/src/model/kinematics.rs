//! Kinematics of a robot's joint chains: forward kinematics for given joint positions and
//! inverse kinematics to an end-effector point or pose by damped least squares (nalgebra, f64).
//!
//! A [`KinematicChain`] runs from a base link down the URDF tree to a tip link (the end
//! effector). [`IkSolver`] moves its joints so the tip reaches a target given in the base
//! link's frame: each iteration solves `(J Jᵀ + λ² I) y = e` for the 6-row error `e` (position,
//! and orientation weighted when the target has one), steps `Jᵀ y`, adds the null-space pull
//! `(I - J⁺ J) k (q_rest - q)` toward a rest pose, and clamps the result to the joint limits.
//! A solve that does not converge from the start pose is restarted from in-limit poses drawn
//! from a seeded [`SplitMix64`] (deterministic), and the best result is kept. The solver owns
//! its scratch matrices: a solve allocates only its result.

use nalgebra::{
    DVector, Dyn, Isometry3, Matrix6, OMatrix, Quaternion, Translation3, U6, UnitQuaternion,
    Vector3, Vector6,
};

use super::robot::{JointId, JointKind, LinkId, RobotModel};
use crate::geometry::Pose;
use crate::noise::SplitMix64;

/// Below this error (m) the damping fades toward a twentieth of [`IkOptions::damping`].
const DAMPING_FADE_M: f64 = 0.05;

/// Why a chain cannot be built or a solve cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// No link of that name.
    #[error("no link named \"{name}\" in robot \"{robot}\"; its links are: {known}")]
    NoLink {
        /// The name asked for.
        name: String,
        /// The robot.
        robot: String,
        /// Its link names, comma-separated.
        known: String,
    },
    /// The tip is not below the base in the URDF tree.
    #[error(
        "link \"{tip}\" is not below link \"{base}\" in the robot's tree: no chain between them"
    )]
    NotAChain {
        /// Base link.
        base: String,
        /// Tip link.
        tip: String,
    },
    /// The chain has no joint that moves.
    #[error("the chain from \"{base}\" to \"{tip}\" has no moving joint")]
    NoMovingJoint {
        /// Base link.
        base: String,
        /// Tip link.
        tip: String,
    },
    /// A joint the chain cannot move on its own.
    #[error("joint \"{joint}\" in the chain {why}")]
    Unsupported {
        /// The joint.
        joint: String,
        /// What is wrong with it.
        why: &'static str,
    },
    /// Joint positions of the wrong length.
    #[error("{expected} joint positions expected (the chain's moving joints), {got} given")]
    Length {
        /// The chain's moving joints.
        expected: usize,
        /// What was given.
        got: usize,
    },
}

/// A moving joint of a chain.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainJoint {
    /// The joint in its robot.
    pub id: JointId,
    /// Its name.
    pub name: String,
    /// Lower position limit (rad or m; -inf for a continuous joint).
    pub lower: f64,
    /// Upper position limit (rad or m; +inf for a continuous joint).
    pub upper: f64,
    /// Whether it slides (prismatic) rather than turns.
    pub prismatic: bool,
    /// Its `<limit velocity>` (rad/s or m/s), when given.
    pub velocity_limit: Option<f64>,
    /// Unit axis in the joint's own frame.
    axis: Vector3<f64>,
}

impl ChainJoint {
    /// `q` clamped to the limits.
    pub fn clamp(&self, q: f64) -> f64 {
        q.clamp(self.lower, self.upper)
    }

    /// The middle of the range (0 for a continuous joint): the solver's default rest pose.
    pub fn middle(&self) -> f64 {
        if self.lower.is_finite() && self.upper.is_finite() {
            (self.lower + self.upper) / 2.0
        } else {
            0.0
        }
    }
}

/// One step down the chain: a joint's origin (fixed joints folded in) and, for a moving joint,
/// its index in [`KinematicChain::joints`].
#[derive(Debug, Clone, PartialEq)]
struct Segment {
    origin: Isometry3<f64>,
    joint: Option<usize>,
}

/// A serial chain of a robot from a base link to a tip link.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicChain {
    base: LinkId,
    tip: LinkId,
    base_name: String,
    tip_name: String,
    segments: Vec<Segment>,
    joints: Vec<ChainJoint>,
}

/// A rover pose (glam, f32) as an nalgebra isometry (f64).
pub fn isometry_from_pose(pose: &Pose) -> Isometry3<f64> {
    let t = pose.translation;
    let r = pose.rotation;
    Isometry3::from_parts(
        Translation3::new(f64::from(t.x), f64::from(t.y), f64::from(t.z)),
        UnitQuaternion::from_quaternion(Quaternion::new(
            f64::from(r.w),
            f64::from(r.x),
            f64::from(r.y),
            f64::from(r.z),
        )),
    )
}

fn link_id(robot: &RobotModel, name: &str) -> Result<LinkId, KinematicsError> {
    robot.link_id(name).ok_or_else(|| KinematicsError::NoLink {
        name: name.to_owned(),
        robot: robot.name.clone(),
        known: robot
            .links
            .iter()
            .map(|l| l.name.as_str())
            .collect::<Vec<_>>()
            .join(", "),
    })
}

impl KinematicChain {
    /// The chain from link `base` down to link `tip` of `robot`.
    pub fn new(robot: &RobotModel, base: &str, tip: &str) -> Result<Self, KinematicsError> {
        let (base_id, tip_id) = (link_id(robot, base)?, link_id(robot, tip)?);
        let not_a_chain = || KinematicsError::NotAChain {
            base: base.to_owned(),
            tip: tip.to_owned(),
        };
        // Walk up from the tip to the base: each link has one parent joint.
        let mut path = Vec::new();
        let mut link = tip_id;
        while link != base_id {
            let (id, joint) = robot
                .joint_ids()
                .find(|(_, j)| j.child == link)
                .ok_or_else(not_a_chain)?;
            if path.len() > robot.joints.len() {
                return Err(not_a_chain());
            }
            path.push(id);
            link = joint.parent;
        }
        path.reverse();
        let mut segments = Vec::new();
        let mut joints = Vec::new();
        let mut origin = Isometry3::identity();
        for id in path {
            let j = robot.joint(id);
            origin *= isometry_from_pose(&j.parent_from_child);
            let axis = Vector3::new(
                f64::from(j.axis.x),
                f64::from(j.axis.y),
                f64::from(j.axis.z),
            );
            let (lower, upper, prismatic) = match j.kind {
                JointKind::Fixed => continue,
                JointKind::Floating => {
                    return Err(KinematicsError::Unsupported {
                        joint: j.name.clone(),
                        why: "is floating",
                    });
                }
                _ if j.mimic.is_some() => {
                    return Err(KinematicsError::Unsupported {
                        joint: j.name.clone(),
                        why: "mimics another joint (not supported in an IK chain)",
                    });
                }
                JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY, false),
                JointKind::Revolute {
                    lower_rad,
                    upper_rad,
                } => (f64::from(lower_rad), f64::from(upper_rad), false),
                JointKind::Prismatic { lower_m, upper_m } => {
                    (f64::from(lower_m), f64::from(upper_m), true)
                }
            };
            segments.push(Segment {
                origin,
                joint: Some(joints.len()),
            });
            origin = Isometry3::identity();
            joints.push(ChainJoint {
                id,
                name: j.name.clone(),
                lower,
                upper,
                prismatic,
                velocity_limit: j
                    .velocity_limit
                    .map(f64::from)
                    .filter(|v| v.is_finite() && *v > 0.0),
                axis: axis.try_normalize(1e-9).unwrap_or_else(Vector3::z),
            });
        }
        segments.push(Segment {
            origin,
            joint: None,
        });
        if joints.is_empty() {
            return Err(KinematicsError::NoMovingJoint {
                base: base.to_owned(),
                tip: tip.to_owned(),
            });
        }
        Ok(Self {
            base: base_id,
            tip: tip_id,
            base_name: base.to_owned(),
            tip_name: tip.to_owned(),
            segments,
            joints,
        })
    }

    /// The chain's moving joints, base to tip.
    pub fn joints(&self) -> &[ChainJoint] {
        &self.joints
    }

    /// The base link.
    pub fn base(&self) -> LinkId {
        self.base
    }

    /// The tip link (end effector).
    pub fn tip(&self) -> LinkId {
        self.tip
    }

    /// The base link's name.
    pub fn base_name(&self) -> &str {
        &self.base_name
    }

    /// The tip link's name.
    pub fn tip_name(&self) -> &str {
        &self.tip_name
    }

    fn check(&self, q: &[f64]) -> Result<(), KinematicsError> {
        if q.len() == self.joints.len() {
            Ok(())
        } else {
            Err(KinematicsError::Length {
                expected: self.joints.len(),
                got: q.len(),
            })
        }
    }

    /// The tip's pose in the base link's frame with the joints at `q` (rad or m, in
    /// [`KinematicChain::joints`] order).
    pub fn base_from_tip(&self, q: &[f64]) -> Result<Isometry3<f64>, KinematicsError> {
        self.check(q)?;
        Ok(self.walk(q, |_, _, _| {}))
    }

    /// The first moving joint's origin and unit axis in the base frame with every joint at
    /// zero (a pan joint's axis is vertical: the arm turns about it); `None` for a chain with
    /// no moving joint.
    pub fn first_axis(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let mut first = None;
        self.walk(&vec![0.0; self.joints.len()], |i, origin, axis| {
            if i == 0 {
                first = Some((origin, axis));
            }
        });
        first
    }

    /// Whether every joint that turns has a vertical axis (base frame, within about 8
    /// degrees): the tip then never tilts, whatever the joints do (a lift, a telescoping arm
    /// and a wrist's yaw, as Hello Robot's Stretch): its orientation is not the planner's to
    /// choose beyond a turn about the vertical.
    pub fn holds_level(&self) -> bool {
        let mut level = true;
        self.walk(&vec![0.0; self.joints.len()], |i, _, axis| {
            if !self.joints[i].prismatic && axis.z.abs() < 0.99 {
                level = false;
            }
        });
        level && !self.joints.is_empty()
    }

    /// Forward kinematics: calls `visit(i, origin, axis)` with each moving joint's origin and
    /// axis in the base frame, and returns base_from_tip.
    fn walk(
        &self,
        q: &[f64],
        mut visit: impl FnMut(usize, Vector3<f64>, Vector3<f64>),
    ) -> Isometry3<f64> {
        let mut pose = Isometry3::identity();
        for s in &self.segments {
            pose *= s.origin;
            let Some(i) = s.joint else {
                continue;
            };
            let joint = &self.joints[i];
            let axis = pose.rotation * joint.axis;
            visit(i, pose.translation.vector, axis);
            let motion = if joint.prismatic {
                Isometry3::from_parts(
                    Translation3::from(joint.axis * q[i]),
                    UnitQuaternion::identity(),
                )
            } else {
                Isometry3::from_parts(
                    Translation3::identity(),
                    UnitQuaternion::from_scaled_axis(joint.axis * q[i]),
                )
            };
            pose *= motion;
        }
        pose
    }

    /// Joint changes (clamped so the result stays within the limits) that turn `axis_tip` (a
    /// unit vector in the tip's frame, e.g. a camera's optical axis) toward `toward_tip`
    /// (a unit vector in the tip's frame, e.g. the ray through a pixel), by damped least
    /// squares on the chain's angular Jacobian: a pan-tilt head or a wrist looks at a point.
    pub fn pointing_step(
        &self,
        q: &[f64],
        axis_tip: Vector3<f64>,
        toward_tip: Vector3<f64>,
        damping: f64,
    ) -> Result<Vec<f64>, KinematicsError> {
        self.check(q)?;
        let mut axes = vec![Vector3::zeros(); self.joints.len()];
        let tip = self.walk(q, |i, _, axis| axes[i] = axis);
        let (from, to) = (tip.rotation * axis_tip, tip.rotation * toward_tip);
        let cross = from.cross(&to);
        let angle = cross.norm().atan2(from.dot(&to));
        let rotation = match cross.try_normalize(1e-12) {
            Some(unit) => unit * angle,
            None => return Ok(vec![0.0; q.len()]),
        };
        // J_w is 3 x n: columns are the revolute joints' axes (a slide turns nothing).
        let mut a = nalgebra::Matrix3::identity() * damping * damping;
        for (axis, joint) in axes.iter().zip(&self.joints) {
            if !joint.prismatic {
                a += axis * axis.transpose();
            }
        }
        let Some(cholesky) = a.cholesky() else {
            return Ok(vec![0.0; q.len()]);
        };
        let y = cholesky.solve(&rotation);
        Ok(axes
            .iter()
            .zip(&self.joints)
            .zip(q)
            .map(|((axis, joint), q)| {
                let step = if joint.prismatic { 0.0 } else { axis.dot(&y) };
                joint.clamp(q + step) - q
            })
            .collect())
    }

    /// An in-limit pose drawn from `rng` (continuous joints within ±π).
    pub fn random_pose(&self, rng: &mut SplitMix64) -> Vec<f64> {
        let mut q = vec![0.0; self.joints.len()];
        self.fill_random_pose(rng, &mut q);
        q
    }

    /// [`Self::random_pose`] into `q` (the chain's length).
    fn fill_random_pose(&self, rng: &mut SplitMix64, q: &mut [f64]) {
        use std::f64::consts::PI;
        for (q, j) in q.iter_mut().zip(&self.joints) {
            let (lo, hi) = (j.lower.max(-PI), j.upper.min(PI));
            *q = lo + (hi - lo) * rng.unit();
        }
    }
}

/// Where the tip should go, in the chain's base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkTarget {
    /// The tip's origin (m).
    pub position_m: Vector3<f64>,
    /// The tip's orientation, when it matters.
    pub orientation: Option<UnitQuaternion<f64>>,
    /// Where the tip's z axis should point (a unit vector, base frame) when only that matters
    /// (a gripper's approach: the turn about it is free); ignored when `orientation` is given.
    pub approach: Option<Vector3<f64>>,
}

impl IkTarget {
    /// A point: any orientation will do.
    pub fn point(position_m: Vector3<f64>) -> Self {
        Self {
            position_m,
            orientation: None,
            approach: None,
        }
    }

    /// A point with the tip's z axis along `direction` (base frame; any length but zero): a
    /// gripper coming in along `direction`, its turn about it free.
    pub fn approach(position_m: Vector3<f64>, direction: Vector3<f64>) -> Self {
        Self {
            position_m,
            orientation: None,
            approach: direction.try_normalize(1e-12),
        }
    }

    /// A full pose.
    pub fn pose(base_from_tip: &Isometry3<f64>) -> Self {
        Self {
            position_m: base_from_tip.translation.vector,
            orientation: Some(base_from_tip.rotation),
            approach: None,
        }
    }
}

/// Solver settings.
#[derive(Debug, Clone, PartialEq)]
pub struct IkOptions {
    /// Damping λ (m): larger is steadier near singularities, slower to converge.
    pub damping: f64,
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Converged when the position error is below this (m) ...
    pub tolerance_m: f64,
    /// ... and the orientation error below this (rad), for a pose target.
    pub tolerance_rad: f64,
    /// Metres an orientation error of one radian counts as.
    pub orientation_weight_m: f64,
    /// Largest change of one joint per iteration (rad or m).
    pub max_step: f64,
    /// Gain of the null-space pull toward the rest pose (per iteration).
    pub rest_gain: f64,
    /// The rest pose the null space pulls toward (the chain's joints); `None`: the middle of
    /// each joint's range (0 for a continuous joint).
    pub rest: Option<Vec<f64>>,
    /// Attempts from seeded random poses after the first fails.
    pub restarts: usize,
    /// Seed of the restarts' poses.
    pub seed: u64,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            damping: 0.02,
            max_iterations: 150,
            tolerance_m: 1e-4,
            tolerance_rad: 1e-3,
            orientation_weight_m: 0.3,
            max_step: 0.25,
            rest_gain: 0.02,
            rest: None,
            restarts: 10,
            seed: 0,
        }
    }
}

/// What a solve found.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    /// Joint positions (the chain's joints), within their limits.
    pub q: Vec<f64>,
    /// Distance from the tip to the target (m).
    pub position_error_m: f64,
    /// Angle between the tip's and the target's orientation (rad; 0 for a point target).
    pub orientation_error_rad: f64,
    /// Iterations run, over every attempt.
    pub iterations: usize,
    /// Whether both errors are within the tolerances.
    pub converged: bool,
}

/// Damped-least-squares IK on one chain.
#[derive(Debug, Clone)]
pub struct IkSolver {
    chain: KinematicChain,
    options: IkOptions,
    rest: Vec<f64>,
    jacobian: OMatrix<f64, U6, Dyn>,
    q: Vec<f64>,
    frames: Vec<(Vector3<f64>, Vector3<f64>)>,
    best_q: Vec<f64>,
    step: DVector<f64>,
    pull: DVector<f64>,
    scratch: DVector<f64>,
}

impl IkSolver {
    /// A solver for `chain`.
    pub fn new(chain: KinematicChain, options: IkOptions) -> Result<Self, KinematicsError> {
        let n = chain.joints.len();
        let rest = match &options.rest {
            Some(rest) => {
                chain.check(rest)?;
                rest.clone()
            }
            None => chain.joints.iter().map(ChainJoint::middle).collect(),
        };
        Ok(Self {
            chain,
            options,
            rest,
            jacobian: OMatrix::<f64, U6, Dyn>::zeros(n),
            q: vec![0.0; n],
            frames: vec![(Vector3::zeros(), Vector3::zeros()); n],
            best_q: vec![0.0; n],
            step: DVector::zeros(n),
            pull: DVector::zeros(n),
            scratch: DVector::zeros(n),
        })
    }

    /// The chain.
    pub fn chain(&self) -> &KinematicChain {
        &self.chain
    }

    /// Joint positions that put the tip on `target`, starting from `start` (the chain's
    /// joints, e.g. the robot's current positions). The best attempt is returned; check
    /// [`IkSolution::converged`].
    pub fn solve(
        &mut self,
        target: &IkTarget,
        start: &[f64],
    ) -> Result<IkSolution, KinematicsError> {
        self.chain.check(start)?;
        for (q, (s, j)) in self.q.iter_mut().zip(start.iter().zip(&self.chain.joints)) {
            *q = j.clamp(*s);
        }
        let mut rng = SplitMix64(self.options.seed);
        let weight = self.options.orientation_weight_m;
        let mut best: Option<(f64, f64)> = None;
        let mut iterations = 0;
        for attempt in 0..=self.options.restarts {
            if attempt > 0 {
                self.chain.fill_random_pose(&mut rng, &mut self.q);
            }
            let (position_m, rotation_rad, used) = self.descend(target);
            iterations += used;
            if best.is_none_or(|(p, r)| position_m + weight * rotation_rad < p + weight * r) {
                best = Some((position_m, rotation_rad));
                self.best_q.copy_from_slice(&self.q);
            }
            if position_m <= self.options.tolerance_m && rotation_rad <= self.options.tolerance_rad
            {
                break;
            }
        }
        let (position_error_m, orientation_error_rad) =
            best.unwrap_or((f64::INFINITY, f64::INFINITY));
        Ok(IkSolution {
            q: self.best_q.clone(),
            position_error_m,
            orientation_error_rad,
            iterations,
            converged: position_error_m <= self.options.tolerance_m
                && orientation_error_rad <= self.options.tolerance_rad,
        })
    }

    /// Errors of the tip at `self.q` (the weighted 6-vector, position m, orientation rad),
    /// filling the Jacobian (orientation rows weighted the same).
    fn errors(&mut self, target: &IkTarget) -> (Vector6<f64>, f64, f64) {
        let approach = target.approach.filter(|_| target.orientation.is_none());
        let weight = if target.orientation.is_some() || approach.is_some() {
            self.options.orientation_weight_m
        } else {
            0.0
        };
        let frames = &mut self.frames;
        let tip = self
            .chain
            .walk(&self.q, |i, origin, axis| frames[i] = (origin, axis));
        let p_tip = tip.translation.vector;
        let tip_z = tip.rotation * Vector3::z();
        for (i, joint) in self.chain.joints.iter().enumerate() {
            let (origin, axis) = self.frames[i];
            let (linear, angular) = if joint.prismatic {
                (axis, Vector3::zeros())
            } else if approach.is_some() {
                // A turn about the tip's own z leaves its direction as it is: only the rest
                // of the joint's turn counts.
                (
                    axis.cross(&(p_tip - origin)),
                    (axis - tip_z * tip_z.dot(&axis)) * weight,
                )
            } else {
                (axis.cross(&(p_tip - origin)), axis * weight)
            };
            let mut column = self.jacobian.column_mut(i);
            column.fixed_rows_mut::<3>(0).copy_from(&linear);
            column.fixed_rows_mut::<3>(3).copy_from(&angular);
        }
        let position = target.position_m - p_tip;
        let rotation = match (target.orientation, approach) {
            (Some(r), _) => (r * tip.rotation.inverse()).scaled_axis(),
            (None, Some(d)) => UnitQuaternion::rotation_between(&tip_z, &d).map_or_else(
                // Opposite: half a turn about any axis across the tip's z.
                || tip.rotation * Vector3::x() * std::f64::consts::PI,
                |r| r.scaled_axis(),
            ),
            (None, None) => Vector3::zeros(),
        };
        let mut error = Vector6::zeros();
        error.fixed_rows_mut::<3>(0).copy_from(&position);
        error.fixed_rows_mut::<3>(3).copy_from(&(rotation * weight));
        (error, position.norm(), rotation.norm())
    }

    /// One damped-least-squares step into `self.step` from the current Jacobian: the task
    /// step `Jᵀ (J Jᵀ + λ² I)⁻¹ e` plus the null-space pull toward the rest pose less what
    /// would move the tip, `z - J⁺ (J z)`. False when the system cannot be solved.
    fn dls_step(
        &mut self,
        error: &Vector6<f64>,
        regulariser: &Matrix6<f64>,
        rest_gain: f64,
    ) -> bool {
        // J Jᵀ + λ² I as a sum of the columns' outer products (no allocation).
        let mut a = *regulariser;
        for column in self.jacobian.column_iter() {
            let c: Vector6<f64> = column.into_owned();
            a.ger(1.0, &c, &c, 1.0);
        }
        let Some(cholesky) = a.cholesky() else {
            return false;
        };
        self.jacobian
            .tr_mul_to(&cholesky.solve(error), &mut self.step);
        for (i, (p, (q, r))) in self
            .pull
            .iter_mut()
            .zip(self.q.iter().zip(&self.rest))
            .enumerate()
        {
            // A joint left out does not take part in the pull either.
            *p = if self.jacobian.column(i).amax() > 0.0 {
                rest_gain * (r - q)
            } else {
                0.0
            };
        }
        let moved = &self.jacobian * &self.pull;
        self.jacobian
            .tr_mul_to(&cholesky.solve(&moved), &mut self.scratch);
        self.step += &self.pull;
        self.step -= &self.scratch;
        true
    }

    /// Damped least squares from `self.q`: (position error, orientation error, iterations).
    fn descend(&mut self, target: &IkTarget) -> (f64, f64, usize) {
        let (damping, rest_gain, max_step) = (
            self.options.damping,
            self.options.rest_gain,
            self.options.max_step,
        );
        let (tolerance_m, tolerance_rad) = (self.options.tolerance_m, self.options.tolerance_rad);
        let regulariser = Matrix6::identity() * damping * damping;
        for iteration in 0..self.options.max_iterations {
            let (error, position_m, rotation_rad) = self.errors(target);
            if position_m <= tolerance_m && rotation_rad <= tolerance_rad {
                return (position_m, rotation_rad, iteration);
            }
            // Damping fades near the target (DLS converges slowly once the error is smaller
            // than λ would allow for).
            let fade = (error.norm() / DAMPING_FADE_M).clamp(0.05, 1.0);
            let regulariser = regulariser * (fade * fade);
            // A joint at a limit that the step would push further is left out (its Jacobian
            // column zeroed) and the step solved again: the others do the work.
            for _ in 0..=self.chain.joints.len() {
                if !self.dls_step(&error, &regulariser, rest_gain) {
                    return (position_m, rotation_rad, iteration);
                }
                let mut blocked = false;
                for (i, joint) in self.chain.joints.iter().enumerate() {
                    let pushing_out = (self.q[i] <= joint.lower && self.step[i] < 0.0)
                        || (self.q[i] >= joint.upper && self.step[i] > 0.0);
                    if pushing_out && self.jacobian.column(i).amax() > 0.0 {
                        self.jacobian.column_mut(i).fill(0.0);
                        blocked = true;
                    }
                }
                if !blocked {
                    break;
                }
            }
            let largest = self.step.amax();
            let scale = if largest > max_step {
                max_step / largest
            } else {
                1.0
            };
            for (i, joint) in self.chain.joints.iter().enumerate() {
                self.q[i] = joint.clamp(self.q[i] + scale * self.step[i]);
            }
        }
        let (_, position_m, rotation_rad) = self.errors(target);
        (position_m, rotation_rad, self.options.max_iterations)
    }
}

#[cfg(test)]
#[allow(
    clippy::expect_used,
    reason = "tests: a failed expect is a failed test"
)]
mod tests {
    use super::*;

    /// A planar arm: a shoulder turning about z at the base, two 0.5 m links, an elbow about z,
    /// a fixed tool 0.1 m further, and a prismatic lift at the bottom.
    fn arm() -> RobotModel {
        let urdf = r#"<robot name="planar">
  <link name="base"/><link name="lift"/><link name="upper"/><link name="lower"/><link name="tool"/>
  <joint name="lift_joint" type="prismatic"><parent link="base"/><child link="lift"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.3" effort="100" velocity="1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="lift"/><child link="upper"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="10" velocity="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="lower"/><child link="tool"/>
    <origin xyz="0.6 0 0"/></joint>
</robot>"#;
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("planar.urdf");
        std::fs::write(&path, urdf).expect("write");
        RobotModel::load(&path).expect("planar arm loads")
    }

    #[test]
    fn forward_kinematics_of_a_planar_arm() {
        let chain = KinematicChain::new(&arm(), "base", "tool").expect("chain");
        let names: Vec<&str> = chain.joints().iter().map(|j| j.name.as_str()).collect();
        assert_eq!(names, ["lift_joint", "shoulder", "elbow"]);
        let (a, b) = (0.4f64, -0.9f64);
        let tip = chain.base_from_tip(&[0.1, a, b]).expect("fk");
        let expected = Vector3::new(
            0.5 * a.cos() + 0.6 * (a + b).cos(),
            0.5 * a.sin() + 0.6 * (a + b).sin(),
            0.3,
        );
        assert!((tip.translation.vector - expected).norm() < 1e-6, "{tip:?}");
        assert!((tip.rotation.angle() - (a + b).abs()).abs() < 1e-6);
        assert!(matches!(
            chain.base_from_tip(&[0.0]),
            Err(KinematicsError::Length {
                expected: 3,
                got: 1
            })
        ));
    }

    #[test]
    fn a_pointing_step_turns_the_tip_toward_a_direction() {
        // The planar arm's tool x axis, turned toward a direction 0.3 rad to its left: the
        // revolute joints turn by 0.3 rad between them (least squares splits it).
        let chain = KinematicChain::new(&arm(), "base", "tool").expect("chain");
        let q = [0.1, 0.2, -0.4];
        let toward = Vector3::new(0.3f64.cos(), 0.3f64.sin(), 0.0);
        let step = chain
            .pointing_step(&q, Vector3::x(), toward, 1e-3)
            .expect("step");
        assert!(step[0].abs() < 1e-12, "the lift does not turn: {step:?}");
        assert!((step[1] + step[2] - 0.3).abs() < 1e-3, "{step:?}");
        // Already pointing there: no change.
        let none = chain
            .pointing_step(&q, Vector3::x(), Vector3::x(), 1e-3)
            .expect("step");
        assert!(none.iter().all(|s| s.abs() < 1e-12), "{none:?}");
    }

    #[test]
    fn ik_reaches_points_and_poses_within_limits_and_refuses_bad_chains() {
        let robot = arm();
        let chain = KinematicChain::new(&robot, "base", "tool").expect("chain");
        let mut solver = IkSolver::new(chain.clone(), IkOptions::default()).expect("solver");
        let mut rng = SplitMix64(7);
        for _ in 0..20 {
            let goal_q = chain.random_pose(&mut rng);
            let goal = chain.base_from_tip(&goal_q).expect("fk");
            for target in [
                IkTarget::point(goal.translation.vector),
                IkTarget::pose(&goal),
            ] {
                let s = solver.solve(&target, &[0.15, 0.0, 0.3]).expect("solve");
                assert!(s.converged, "{s:?} for {goal_q:?}");
                let reached = chain.base_from_tip(&s.q).expect("fk");
                assert!((reached.translation.vector - target.position_m).norm() < 1e-3);
                for (q, j) in s.q.iter().zip(chain.joints()) {
                    assert!(*q >= j.lower && *q <= j.upper, "{q} outside {j:?}");
                }
            }
        }
        // Out of reach (1.1 m arm): the best it can do, not converged.
        let far = solver
            .solve(
                &IkTarget::point(Vector3::new(2.0, 0.0, 0.3)),
                &[0.0, 0.0, 0.0],
            )
            .expect("solve");
        assert!(
            !far.converged && (far.position_error_m - 0.9).abs() < 0.01,
            "{far:?}"
        );
        assert!(matches!(
            KinematicChain::new(&robot, "tool", "base"),
            Err(KinematicsError::NotAChain { .. })
        ));
        let missing = KinematicChain::new(&robot, "base", "hand").expect_err("no hand");
        assert!(
            missing
                .to_string()
                .contains("base, lift, upper, lower, tool"),
            "{missing}"
        );
    }
}
