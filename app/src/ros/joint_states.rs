//! `/joint_states` (sensor_msgs/JointState): every moving joint of the plan, in its order, with
//! its position, velocity and effort, every control update (or at a joint_state_controller's
//! `publish_rate`).

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::{ControlSample, Simulation};

use super::convert::{header, seq_of};
use super::events::{ControlUpdate, JointSample, TopicFamily};
use super::plan::{JointSource, MovingJoint, RosPlan};

/// Publishes `/joint_states`.
pub(super) struct JointStates {
    publisher: Publisher<msgs::JointState>,
    joints: Vec<MovingJoint>,
    msg: msgs::JointState,
    /// Seconds between messages (0: every control update).
    period_s: f64,
    /// Sim time of the next message.
    next_s: f64,
}

impl JointStates {
    /// Advertises `/joint_states`.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise("/joint_states", 50, false)?,
            joints: plan.joints.clone(),
            period_s: plan.joint_states_hz.map_or(0.0, |hz| 1.0 / hz),
            next_s: 0.0,
            msg: msgs::JointState {
                header: header(""),
                name: plan.joints.iter().map(|j| j.name.clone()).collect(),
                ..msgs::JointState::default()
            },
        })
    }
}

/// The joint's angle: its rotation since its rest pose, about its axis (rad).
fn angle_rad(joint: &MovingJoint, now: &JointSample) -> f64 {
    let rel = joint.parent_from_child_at_rest.rotation.inverse() * now.parent_from_child.rotation;
    let along = glam::Vec3::new(rel.x, rel.y, rel.z).dot(joint.axis);
    2.0 * f64::from(along).atan2(f64::from(rel.w))
}

impl TopicFamily for JointStates {
    fn control(&mut self, update: &ControlUpdate) {
        let now_s = update.sample.sim_time_s;
        if self.msg.name.is_empty() || now_s + 1e-9 < self.next_s {
            return;
        }
        self.next_s = now_s + self.period_s;
        self.msg.position.clear();
        self.msg.velocity.clear();
        self.msg.effort.clear();
        for (joint, now) in self.joints.iter().zip(&update.joints) {
            let position = match joint.source {
                JointSource::Wheel { .. } => angle_rad(joint, now),
                JointSource::Joint(_) => now.position,
            };
            self.msg.position.push(position);
            self.msg.velocity.push(now.velocity_radps);
            self.msg.effort.push(now.effort);
        }
        self.msg.header.seq = seq_of(&self.publisher);
        self.msg.header.stamp_s = update.sample.sim_time_s;
        self.publisher.publish(&self.msg);
    }
}

/// Samples every joint of `joints` at a control update (on the loop thread), into `out`.
pub(crate) fn sample(
    sim: &Simulation,
    sample: &ControlSample,
    joints: &[MovingJoint],
    out: &mut Vec<JointSample>,
) {
    out.clear();
    out.extend(joints.iter().map(|j| {
        let state = match j.source {
            JointSource::Joint(id) => sim.joint_state(id).unwrap_or_default(),
            JointSource::Wheel { .. } => rover_sim::JointState {
                velocity: j.source.velocity_radps(sample),
                ..rover_sim::JointState::default()
            },
        };
        let setpoint = match j.source {
            JointSource::Joint(id) => sim.joint_setpoint(id).unwrap_or(state.position),
            JointSource::Wheel { .. } => state.position,
        };
        JointSample {
            parent_from_child: sim.world_from_link(j.parent).inverse()
                * sim.world_from_link(j.child),
            velocity_radps: state.velocity,
            position: state.position,
            effort: state.effort,
            setpoint,
        }
    }));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::plan::JointSource;
    use rover_sim::Pose;

    #[test]
    fn a_joints_angle_is_its_turn_about_its_axis_since_rest() -> anyhow::Result<()> {
        // The links only name the joint's frames; the angle depends on the poses alone.
        let robot = rover_sim::RobotModel::load(&rover_core::default_robot_path())?;
        let at_rest = Pose::from_parts(
            glam::Vec3::new(0.0, 0.2, 0.0),
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        );
        let joint = MovingJoint {
            name: "left_wheel_joint".into(),
            parent: robot.root,
            child: robot.root,
            parent_link: "base_link".into(),
            child_link: "left_wheel".into(),
            parent_from_child_at_rest: at_rest,
            axis: glam::Vec3::Z,
            source: JointSource::Wheel { side: 0 },
        };
        for turn_rad in [0.0f32, 0.3, -1.2, 3.0] {
            let now = JointSample {
                parent_from_child: Pose::from_parts(
                    at_rest.translation,
                    at_rest.rotation * glam::Quat::from_rotation_z(turn_rad),
                ),
                velocity_radps: 1.0,
                position: 0.0,
                effort: 0.0,
                setpoint: 0.0,
            };
            let angle = angle_rad(&joint, &now);
            assert!(
                (angle - f64::from(turn_rad)).abs() < 1e-6,
                "{angle} for {turn_rad}"
            );
        }
        Ok(())
    }
}
