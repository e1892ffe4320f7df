//! Static friction on a gripper's finger pads: friction anchors.
//!
//! Rapier, like ODE, solves friction on velocities only: a contact well inside its friction
//! cone still slides a little every step the solver leaves a residual speed, and nothing
//! brings it back. Held in two fingers squeezing it with 5 N (a friction capacity ten times its
//! weight), a tennis ball crept 4-5 mm/s down the pads while the car drove, until it reached
//! the palm (measured with the hold test in tests/tests/pick.rs). A real pad sticks.
//!
//! rover gives each contact between a finger pad and a world object an anchor, as PhysX's
//! friction anchors do: the points where the two surfaces touched when the contact stuck, each
//! kept in its body's frame. After every step the distance between them in the contact's
//! tangent plane is the slip so far, and the next step's friction is asked to take it back
//! (rapier's per-contact `tangent_velocity`, which its friction constraint tracks within its
//! Coulomb bound, mu times the normal force). So the grip holds what static friction holds and
//! no more: a load beyond mu N still slides, and a slip of more than [`SLIPPED_M`] is taken as
//! sliding, the anchor starting afresh where the surfaces touch then.

use std::collections::HashMap;

use glam::Vec3;
use rapier3d::prelude::*;

use crate::error::Result;
use crate::geometry::Pose;
use crate::model::robot::RobotModel;
use crate::model::world::GraspMode;
use crate::physics::build::other_body;
use crate::physics::grasp::{GraspAssist, gripper_bodies};

use crate::physics::contact_springs::ContactSprings;

/// How fast a slip is taken back (s): the correction asks for the slip over this time.
pub const ANCHOR_TIME_S: f32 = 0.05;
/// The fastest correction asked for (m/s): a kick-free pull back.
pub const MAX_CORRECTION_MPS: f32 = 0.05;
/// A slip longer than this (m) is sliding, not a residual: the anchor starts afresh.
pub const SLIPPED_M: f32 = 0.005;

/// One anchored contact: where it touched on each body when it stuck, in that body's frame
/// (collider1's and collider2's bodies, m), and the velocity of collider2's surface relative to
/// collider1's the next step's friction asks for (world frame, m/s).
#[derive(Debug, Clone, Copy)]
struct Anchor {
    on1: Vec3,
    on2: Vec3,
    correction_mps: Vec3,
}

/// The anchors of one gripper's finger pads.
#[derive(Debug, Clone, Default)]
pub(crate) struct FrictionAnchors {
    /// The finger pads' colliders.
    pads: Vec<ColliderHandle>,
    /// The anchored contacts, by rapier's collider pair.
    anchors: HashMap<(ColliderHandle, ColliderHandle), Anchor>,
    /// The anchors being gathered by an update (kept to reuse its memory).
    next: HashMap<(ColliderHandle, ColliderHandle), Anchor>,
}

impl FrictionAnchors {
    /// Anchors for the colliders of `fingers` (the gripper's finger link bodies); marks those
    /// colliders for the contact hook.
    pub(crate) fn new(physics: &mut PhysicsWorld, fingers: &[RigidBodyHandle]) -> Self {
        let pads: Vec<ColliderHandle> = fingers
            .iter()
            .filter_map(|f| physics.bodies.get(*f))
            .flat_map(|b| b.colliders().iter().copied())
            .collect();
        for collider in &pads {
            if let Some(c) = physics.colliders.get_mut(*collider) {
                c.set_active_hooks(c.active_hooks() | ActiveHooks::MODIFY_SOLVER_CONTACTS);
            }
        }
        Self {
            pads,
            ..Self::default()
        }
    }

    /// Whether there are no pads.
    pub(crate) fn is_empty(&self) -> bool {
        self.pads.is_empty()
    }

    /// After a step: measures each pad contact's slip with the bodies in `objects` (the
    /// world's objects, the SDF models' links) since it stuck, anchors new contacts, drops
    /// those that ended, and sets the next step's corrections.
    pub(crate) fn update(&mut self, physics: &PhysicsWorld, objects: [&[RigidBodyHandle]; 2]) {
        self.next.clear();
        for pad in &self.pads {
            for pair in physics.narrow_phase.contact_pairs_with(*pad) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let other = other_body(physics, pair, *pad);
                if !other.is_some_and(|b| objects.iter().any(|o| o.contains(&b))) {
                    continue;
                }
                let key = (pair.collider1, pair.collider2);
                let Some(touch) = Touch::of(physics, pair) else {
                    continue;
                };
                let mut anchor = self
                    .anchors
                    .get(&key)
                    .copied()
                    .filter(|a| touch.slip(a).length() <= SLIPPED_M)
                    .unwrap_or_else(|| touch.anchor());
                anchor.correction_mps =
                    (-touch.slip(&anchor) / ANCHOR_TIME_S).clamp_length_max(MAX_CORRECTION_MPS);
                self.next.insert(key, anchor);
            }
        }
        std::mem::swap(&mut self.anchors, &mut self.next);
    }
}

/// How the robot's first gripper holds: the grasp assist (with `grasp = "assist"`) and the
/// friction anchors of its finger pads (none without a gripper controller). `graspables`: how
/// many world objects and model links there are.
pub(crate) fn grip(
    robot: &RobotModel,
    (link_body, graspables): (&[RigidBodyHandle], usize),
    mode: GraspMode,
    physics: &mut PhysicsWorld,
) -> Result<(Option<GraspAssist>, FrictionAnchors)> {
    let assist = match mode {
        GraspMode::Friction => None,
        GraspMode::Assist => Some(GraspAssist::new(robot, link_body, graspables)?),
    };
    let fingers = gripper_bodies(robot, link_body)?
        .map(|(_, fingers)| fingers)
        .unwrap_or_default();
    Ok((assist, FrictionAnchors::new(physics, &fingers)))
}

/// A contact pair now: its two bodies' poses, the mean contact point on each surface and the
/// normal (world frame).
struct Touch {
    pose1: Pose,
    pose2: Pose,
    at1: Vec3,
    at2: Vec3,
    normal: Vec3,
}

impl Touch {
    /// `None` without a contact point or a body on each side.
    fn of(physics: &PhysicsWorld, pair: &ContactPair) -> Option<Self> {
        let c1 = physics.colliders.get(pair.collider1)?;
        let c2 = physics.colliders.get(pair.collider2)?;
        let pose = |c: &Collider| {
            c.parent()
                .and_then(|b| physics.bodies.get(b))
                .map(|b| *b.position())
        };
        let (mut at1, mut at2, mut n) = (Vec3::ZERO, Vec3::ZERO, 0.0f32);
        for manifold in pair.manifolds() {
            for point in &manifold.points {
                at1 += *c1.position() * point.local_p1;
                at2 += *c2.position() * point.local_p2;
                n += 1.0;
            }
        }
        let normal = pair.manifolds().first()?.data.normal;
        (n > 0.0).then(|| Self {
            pose1: pose(c1).unwrap_or(Pose::IDENTITY),
            pose2: pose(c2).unwrap_or(Pose::IDENTITY),
            at1: at1 / n,
            at2: at2 / n,
            normal,
        })
    }

    /// An anchor where the surfaces touch now.
    fn anchor(&self) -> Anchor {
        Anchor {
            on1: self.pose1.inverse() * self.at1,
            on2: self.pose2.inverse() * self.at2,
            correction_mps: Vec3::ZERO,
        }
    }

    /// How far the anchor's point on collider2's body has moved along collider1's since it
    /// stuck, in the tangent plane (m, world frame).
    fn slip(&self, anchor: &Anchor) -> Vec3 {
        let apart = self.pose2 * anchor.on2 - self.pose1 * anchor.on1;
        apart - self.normal * apart.dot(self.normal)
    }
}

/// The contact hooks a step runs: `<kp>` springs and the grip's friction anchors.
pub(crate) struct ContactHooks<'a> {
    /// Contacts that give way.
    pub(crate) springs: &'a ContactSprings,
    /// The finger pads' anchors.
    pub(crate) anchors: &'a FrictionAnchors,
}

impl PhysicsHooks for ContactHooks<'_> {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        self.springs.modify_solver_contacts(context);
        let Some(correction) = self
            .anchors
            .anchors
            .get(&(context.collider1, context.collider2))
            .map(|a| a.correction_mps)
        else {
            return;
        };
        if let Some(rigid) = context.rigid_mut() {
            for contact in rigid.solver_contacts.iter_mut() {
                contact.tangent_velocity = correction;
            }
        }
    }
}
