//! Grasp assist (`[robot] grasp = "assist"`): gazebo_grasp_fix's rule, the fix Gazebo users
//! reach for when objects slip out of a gripper. At [`CHECK_HZ`], each world object and each
//! link of the world's Gazebo models (a Coke can) the gripper's fingers touch is checked: two
//! or more finger links pushing on it with forces whose directions differ by more than
//! [`FORCES_ANGLE_TOLERANCE_DEG`] count as a grip. The count
//! goes up (to [`MAX_GRIP_COUNT`]) on a grip and down otherwise; past
//! [`GRIP_COUNT_THRESHOLD`] the object is attached to the palm with a fixed joint where it is.
//! It is let go when a finger (its centre of mass: a turning finger's link origin is its pivot,
//! which stays put as it opens) moves more than [`RELEASE_TOLERANCE_M`] further from it than
//! it was when attached (the gripper opening). The constants stand for gazebo_grasp_fix's
//! parameters of the same names (`forces_angle_tolerance`, `update_rate`,
//! `grip_count_threshold`, `max_grip_count`, `release_tolerance`): a grip held for about a
//! second attaches.

use glam::Vec3;
use rapier3d::prelude::*;

use crate::error::{Result, SimError};
use crate::geometry::Pose;
use crate::model::robot::RobotModel;

/// How often grips are checked (Hz; gazebo_grasp_fix's `update_rate`).
pub const CHECK_HZ: f64 = 5.0;
/// The least angle between two fingers' forces on an object for a grip (deg).
pub const FORCES_ANGLE_TOLERANCE_DEG: f32 = 120.0;
/// Grip checks in a row (net) before the object is attached.
pub const GRIP_COUNT_THRESHOLD: u32 = 4;
/// The most the grip count goes up to.
pub const MAX_GRIP_COUNT: u32 = 8;
/// How much further (m) a finger may move from the held object before it is let go.
pub const RELEASE_TOLERANCE_M: f32 = 0.005;

/// What the assist holds: a world object (`[[object]]`) or a link of a world's model
/// (`[[model]]`), by its index among them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grasped {
    /// The world object of this index.
    Object(usize),
    /// The model link of this index (as [`crate::physics::Simulation::model_link_poses_into`]
    /// lists them).
    ModelLink(usize),
}

impl std::fmt::Display for Grasped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Object(k) => write!(f, "object {k}"),
            Self::ModelLink(k) => write!(f, "model link {k}"),
        }
    }
}

/// The bodies the assist may hold: the world's objects, then its models' links.
pub(crate) type Graspables<'a> = [&'a [RigidBodyHandle]; 2];

/// The `k`th of `bodies` (objects first) and what it is.
fn graspable(bodies: Graspables<'_>, k: usize) -> Option<(RigidBodyHandle, Grasped)> {
    let [objects, links] = bodies;
    match objects.get(k) {
        Some(body) => Some((*body, Grasped::Object(k))),
        None => {
            let link = k - objects.len();
            Some((*links.get(link)?, Grasped::ModelLink(link)))
        }
    }
}

/// An object held by the assist.
#[derive(Debug, Clone)]
struct Held {
    /// Its index among the graspable bodies (objects, then model links).
    index: usize,
    /// What it is.
    what: Grasped,
    joint: ImpulseJointHandle,
    /// Each finger's distance to the object's centre when attached (m).
    finger_distance_m: Vec<f32>,
}

/// The assist for one gripper.
#[derive(Debug, Clone)]
pub(crate) struct GraspAssist {
    palm: RigidBodyHandle,
    fingers: Vec<RigidBodyHandle>,
    /// Grip count per graspable body (objects, then model links).
    counts: Vec<u32>,
    held: Option<Held>,
    next_check_s: f64,
}

impl GraspAssist {
    /// The assist for the robot's first gripper controller: its palm is the finger joint's
    /// parent link, its fingers the finger joint's child link and those of the joints that
    /// mimic it.
    pub(crate) fn new(
        robot: &RobotModel,
        link_body: &[RigidBodyHandle],
        graspables: usize,
    ) -> Result<Self> {
        let (palm, fingers) = gripper_bodies(robot, link_body)?.ok_or_else(|| {
            SimError::Setup(format!(
                "grasp = \"assist\" needs a gripper controller (position_controllers/GripperActionController) in \"{}\"'s controllers file",
                robot.name
            ))
        })?;
        Ok(Self {
            palm,
            fingers,
            counts: vec![0; graspables],
            held: None,
            next_check_s: 0.0,
        })
    }

    /// What is held, if anything.
    pub(crate) fn held(&self) -> Option<Grasped> {
        self.held.as_ref().map(|h| h.what)
    }

    /// Checks grips at [`CHECK_HZ`] of sim time: attaches a gripped object, lets a held one go
    /// when the fingers open. What happened, for the log.
    pub(crate) fn update(
        &mut self,
        physics: &mut PhysicsWorld,
        bodies: Graspables<'_>,
        now_s: f64,
    ) -> Option<String> {
        if now_s + 1e-9 < self.next_check_s {
            return None;
        }
        self.next_check_s = now_s + 1.0 / CHECK_HZ;
        if let Some(held) = &self.held {
            let (body, _) = graspable(bodies, held.index)?;
            let centre = physics.bodies.get(body)?.translation();
            let opened = self
                .fingers
                .iter()
                .zip(&held.finger_distance_m)
                .any(|(f, d0)| {
                    physics.bodies.get(*f).is_some_and(|b| {
                        (b.center_of_mass() - centre).length() > d0 + RELEASE_TOLERANCE_M
                    })
                });
            if !opened {
                return None;
            }
            let (index, what, joint) = (held.index, held.what, held.joint);
            physics.remove_impulse_joint(joint);
            self.held = None;
            if let Some(count) = self.counts.get_mut(index) {
                *count = 0;
            }
            return Some(format!("grasp assist: let go of {what}"));
        }
        let [objects, links] = bodies;
        for (k, body) in objects.iter().chain(links).enumerate() {
            let gripped = self.gripped(physics, *body);
            let Some(count) = self.counts.get_mut(k) else {
                break;
            };
            *count = if gripped {
                (*count + 1).min(MAX_GRIP_COUNT)
            } else {
                count.saturating_sub(1)
            };
            if *count > GRIP_COUNT_THRESHOLD {
                return self.attach(physics, bodies, k);
            }
        }
        None
    }

    /// Whether two or more fingers push on `object` from opposing sides.
    fn gripped(&self, physics: &PhysicsWorld, object: RigidBodyHandle) -> bool {
        let mut forces: Vec<Vec3> = Vec::with_capacity(self.fingers.len());
        for finger in &self.fingers {
            let Some(body) = physics.bodies.get(*finger) else {
                continue;
            };
            let mut total = Vec3::ZERO;
            for collider in body.colliders() {
                for pair in physics.narrow_phase.contact_pairs_with(*collider) {
                    if !pair.has_any_active_contact() {
                        continue;
                    }
                    let parent =
                        |c: ColliderHandle| physics.colliders.get(c).and_then(|c| c.parent());
                    // The force on the object: along the normal from collider1 to collider2.
                    let impulse = pair.total_impulse();
                    if parent(pair.collider2) == Some(object) && pair.collider1 == *collider {
                        total += impulse;
                    } else if parent(pair.collider1) == Some(object) && pair.collider2 == *collider
                    {
                        total -= impulse;
                    }
                }
            }
            if total.length() > 1e-6 {
                forces.push(total);
            }
        }
        let tolerance = FORCES_ANGLE_TOLERANCE_DEG.to_radians();
        forces.iter().enumerate().any(|(i, a)| {
            forces[i + 1..]
                .iter()
                .any(|b| a.angle_between(*b) > tolerance)
        })
    }

    /// Fixes graspable body `k` to the palm where it is now.
    fn attach(
        &mut self,
        physics: &mut PhysicsWorld,
        bodies: Graspables<'_>,
        k: usize,
    ) -> Option<String> {
        let (object, what) = graspable(bodies, k)?;
        let palm_pose: Pose = *physics.bodies.get(self.palm)?.position();
        let object_pose: Pose = *physics.bodies.get(object)?.position();
        let centre = object_pose.translation;
        let finger_distance_m = self
            .fingers
            .iter()
            // One per finger, in order (a finger without a body never counts as opened).
            .map(|f| {
                physics
                    .bodies
                    .get(*f)
                    .map_or(f32::INFINITY, |b| (b.center_of_mass() - centre).length())
            })
            .collect();
        let joint = FixedJointBuilder::new()
            .local_frame1(palm_pose.inverse() * object_pose)
            .local_frame2(Pose::IDENTITY)
            .contacts_enabled(true)
            .build();
        let handle = physics.insert_impulse_joint(self.palm, object, joint);
        self.held = Some(Held {
            index: k,
            what,
            joint: handle,
            finger_distance_m,
        });
        Some(format!("grasp assist: holding {what}"))
    }
}

/// The robot's first gripper controller's palm (its finger joint's parent link's body) and
/// fingers (the bodies of that joint's child link and of those of the joints that mimic it);
/// `None` without a gripper controller.
pub(crate) fn gripper_bodies(
    robot: &RobotModel,
    link_body: &[RigidBodyHandle],
) -> Result<Option<(RigidBodyHandle, Vec<RigidBodyHandle>)>> {
    let Some(finger) = robot
        .controllers
        .as_ref()
        .and_then(|c| c.first_gripper())
        .map(|(_, g)| g.joint.clone())
    else {
        return Ok(None);
    };
    let id = robot
        .joint_id(&finger)
        .ok_or_else(|| SimError::Setup(format!("no joint \"{finger}\"")))?;
    let leader = robot.joint(id);
    let body = |link: crate::model::robot::LinkId| link_body.get(link.index()).copied();
    let palm = body(leader.parent)
        .ok_or_else(|| SimError::Setup(format!("joint \"{finger}\"'s palm has no body")))?;
    let fingers: Vec<RigidBodyHandle> = robot
        .joint_ids()
        .filter(|(other, j)| *other == id || j.mimic.as_ref().is_some_and(|m| m.joint == id))
        .filter_map(|(_, j)| body(j.child))
        .filter(|b| *b != palm)
        .collect();
    Ok(Some((palm, fingers)))
}
