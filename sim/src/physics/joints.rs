//! The robot's moving joints in rapier: built as multibody (reduced-coordinate) joints or as
//! impulse joints, read back as positions and velocities, and given motors.
//!
//! Impulse joints (the default) solve each joint between its two bodies. With `[physics]
//! joints = "multibody"` the arm joints (actuated ones and those that mimic them) are solved
//! in joint space instead, so a joint motor pushes everything it carries (UR5's outstretched
//! arm needs that); wheels and passive joints stay impulse joints either way, so a car drives
//! the same. docs/ARM.md has the measured comparison.

use glam::{Quat, Vec3};
use rapier3d::prelude::*;

use crate::geometry::Pose;
use crate::model::robot::{JointKind, RobotModel};
use crate::model::world::JointSolver;

/// A joint in the physics scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum JointRef {
    Impulse(ImpulseJointHandle),
    Multibody(MultibodyJointHandle),
}

/// A moving URDF joint as built: its handle, the two bodies and the joint frames in them (the
/// free axis is each frame's x).
#[derive(Debug, Clone, Copy)]
pub(crate) struct BuiltJoint {
    pub(crate) handle: JointRef,
    pub(crate) parent: RigidBodyHandle,
    pub(crate) child: RigidBodyHandle,
    pub(crate) parent_from_frame: Pose,
    pub(crate) child_from_frame: Pose,
    /// The free axis: `LinX` for prismatic joints, `AngX` for the others.
    pub(crate) axis: JointAxis,
}

impl BuiltJoint {
    /// The joint's position (rad or m) from the two bodies' poses; revolute and continuous
    /// joints give the angle in (-pi, pi].
    pub(crate) fn position(&self, bodies: &RigidBodySet) -> f64 {
        let (Some(p), Some(c)) = (bodies.get(self.parent), bodies.get(self.child)) else {
            return 0.0;
        };
        let frame1 = *p.position() * self.parent_from_frame;
        let frame2 = *c.position() * self.child_from_frame;
        let relative = frame1.inverse() * frame2;
        match self.axis {
            JointAxis::LinX => f64::from(relative.translation.x),
            _ => {
                let q = relative.rotation;
                // The twist about x: 2 atan2(q.x, q.w), folded into (-pi, pi].
                let angle = 2.0 * f64::from(q.x).atan2(f64::from(q.w));
                crate::physics::diff_drive::wrap_angle(angle)
            }
        }
    }

    /// The joint's velocity (rad/s or m/s): the child's motion relative to the parent along
    /// the axis.
    pub(crate) fn velocity(&self, bodies: &RigidBodySet) -> f64 {
        let (Some(p), Some(c)) = (bodies.get(self.parent), bodies.get(self.child)) else {
            return 0.0;
        };
        let axis_world = (c.position().rotation * self.child_from_frame.rotation) * Vec3::X;
        match self.axis {
            JointAxis::LinX => {
                let at = (*c.position() * self.child_from_frame).translation;
                let v_child = c.velocity_at_point(at);
                let v_parent = p.velocity_at_point(at);
                f64::from((v_child - v_parent).dot(axis_world))
            }
            _ => f64::from((c.angvel() - p.angvel()).dot(axis_world)),
        }
    }
}

/// The joint's data (limits, motors) in the scene.
pub(crate) fn joint_data_mut(
    physics: &mut PhysicsWorld,
    handle: JointRef,
) -> Option<&mut GenericJoint> {
    match handle {
        JointRef::Impulse(h) => physics.impulse_joints.get_mut(h, true).map(|j| &mut j.data),
        JointRef::Multibody(h) => physics
            .multibody_joints
            .get_mut(h)
            .and_then(|(mb, link)| mb.link_mut(link))
            .map(|l| &mut l.joint.data),
    }
}

/// Every moving URDF joint (joint order; `None` for fixed and floating ones), parents before
/// children so each multibody grows from the robot's root.
pub(crate) fn add_joints(
    physics: &mut PhysicsWorld,
    robot: &RobotModel,
    link_body: &[RigidBodyHandle],
    body_from_link: &[Pose],
    solver: JointSolver,
) -> Vec<Option<BuiltJoint>> {
    let mut joints = vec![None; robot.joints.len()];
    // Arm joints (actuated, or following one) are articulated; wheels and passive joints stay
    // impulse joints, so a car drives the same whichever solver its arm uses.
    let mut articulated = vec![false; robot.joints.len()];
    if solver == JointSolver::Multibody {
        for id in robot.actuated_joints() {
            articulated[id.0] = true;
        }
        for (i, j) in robot.joints.iter().enumerate() {
            articulated[i] |= j.mimic.is_some();
        }
    }
    for index in tree_order(robot) {
        let joint = &robot.joints[index];
        let (parent, child) = (link_body[joint.parent.0], link_body[joint.child.0]);
        if parent == child {
            continue;
        }
        let axis_frame = Pose::from_rotation(Quat::from_rotation_arc(Vec3::X, joint.axis));
        let frame1 = body_from_link[joint.parent.0] * joint.parent_from_child * axis_frame;
        let frame2 = body_from_link[joint.child.0] * axis_frame;
        let (builder, axis) = match joint.kind {
            JointKind::Fixed | JointKind::Floating => continue,
            JointKind::Continuous => (
                GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES),
                JointAxis::AngX,
            ),
            JointKind::Revolute {
                lower_rad,
                upper_rad,
            } => (
                GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                    .limits(JointAxis::AngX, [lower_rad, upper_rad]),
                JointAxis::AngX,
            ),
            JointKind::Prismatic { lower_m, upper_m } => (
                GenericJointBuilder::new(JointAxesMask::LOCKED_PRISMATIC_AXES)
                    .limits(JointAxis::LinX, [lower_m, upper_m]),
                JointAxis::LinX,
            ),
        };
        let mut builder = builder
            .local_frame1(frame1)
            .local_frame2(frame2)
            .contacts_enabled(false);
        if !articulated[index] && joint.damping > 0.0 {
            // Impulse joints have no per-axis damping: a zero-speed motor stands in for it.
            builder = builder
                .motor_model(axis, MotorModel::ForceBased)
                .motor_velocity(axis, 0.0, joint.damping);
        }
        let data = builder.build();
        let handle = if articulated[index] {
            physics
                .insert_multibody_joint(parent, child, data)
                .map(JointRef::Multibody)
        } else {
            Some(JointRef::Impulse(
                physics.insert_impulse_joint(parent, child, data),
            ))
        };
        let Some(handle) = handle else {
            tracing::warn!(
                "{}: joint \"{}\" closes a loop; it is left out",
                robot.source.display(),
                joint.name
            );
            continue;
        };
        joints[index] = Some(BuiltJoint {
            handle,
            parent,
            child,
            parent_from_frame: frame1,
            child_from_frame: frame2,
            axis,
        });
    }
    if solver == JointSolver::Multibody {
        set_multibody_dynamics(physics, robot, &joints);
    }
    joints
}

/// Joint indices ordered so that a joint comes after the joint that places its parent link.
fn tree_order(robot: &RobotModel) -> Vec<usize> {
    let mut placed = vec![false; robot.links.len()];
    placed[robot.root.0] = true;
    let mut order = Vec::with_capacity(robot.joints.len());
    let mut done = vec![false; robot.joints.len()];
    let mut progress = true;
    while progress {
        progress = false;
        for (i, joint) in robot.joints.iter().enumerate() {
            if !done[i] && placed[joint.parent.0] {
                placed[joint.child.0] = true;
                done[i] = true;
                order.push(i);
                progress = true;
            }
        }
    }
    order
}

/// URDF `<dynamics damping friction>` as the multibody's per-axis damping and dry friction;
/// the free root gets no damping (rapier's default damps its rotation a little).
fn set_multibody_dynamics(
    physics: &mut PhysicsWorld,
    robot: &RobotModel,
    joints: &[Option<BuiltJoint>],
) {
    for (joint, built) in robot.joints.iter().zip(joints) {
        let Some(BuiltJoint {
            handle: JointRef::Multibody(h),
            ..
        }) = built
        else {
            continue;
        };
        let Some((mb, link)) = physics.multibody_joints.get_mut(*h) else {
            continue;
        };
        let Some(dof) = mb.link(link).map(|l| l.assembly_id()) else {
            continue;
        };
        if dof < mb.damping().len() {
            mb.damping_mut()[dof] = joint.damping;
            mb.frictions_mut()[dof] = joint.friction;
        }
    }
    // Once per multibody: its root's free dofs come first.
    let mut roots = Vec::new();
    for built in joints.iter().flatten() {
        let JointRef::Multibody(h) = built.handle else {
            continue;
        };
        let Some((mb, _)) = physics.multibody_joints.get_mut(h) else {
            continue;
        };
        let root = mb.root().rigid_body_handle();
        if roots.contains(&root) {
            continue;
        }
        roots.push(root);
        let root_dofs = mb.link(1).map_or(0, |l| l.assembly_id());
        for i in 0..root_dofs.min(mb.damping().len()) {
            mb.damping_mut()[i] = 0.0;
        }
    }
}
