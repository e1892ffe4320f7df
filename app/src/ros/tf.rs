//! `/tf` (odom -> base with `publishOdomTF`, the wheels' links with `publishWheelTF`, every
//! control update) and the latched `/tf_static` (fixed joints, the camera's optical frame, laser
//! frames), as tf2_msgs/TFMessage.

use anyhow::Result;
use rover_ros1::msgs::{self, TransformStamped};
use rover_ros1::{Node, Publisher};
use rover_sim::{CameraInfo, JointKind, Pose, RobotModel, link_from_optical};

use super::convert::{quat, transform, vec3};
use super::events::{ControlUpdate, Start, TopicFamily};
use super::odom::odom_pose_msg;
use super::plan::{JointSource, RosPlan};

/// Publishes `/tf` and `/tf_static`.
pub(super) struct Tf {
    tf: Publisher<msgs::TfMessage>,
    tf_static: Publisher<msgs::TfMessage>,
    /// Whether the first transform is odom -> base.
    odom_tf: bool,
    /// Indices (in the plan's joints) of the joints whose links go on `/tf`, in `msg` order
    /// after odom -> base.
    joints_on_tf: Vec<usize>,
    msg: msgs::TfMessage,
}

impl Tf {
    /// Advertises `/tf` and `/tf_static`.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let mut transforms = Vec::new();
        if plan.odom_tf {
            transforms.push(transform(
                &plan.odom_frame,
                &plan.base_frame,
                0.0,
                Pose::IDENTITY,
            ));
        }
        let joints_on_tf = joints_on_tf(plan);
        transforms.extend(joints_on_tf.iter().map(|&i| {
            let j = &plan.joints[i];
            transform(
                &j.parent_link,
                &j.child_link,
                0.0,
                j.parent_from_child_at_rest,
            )
        }));
        Ok(Self {
            tf: node.advertise("/tf", 100, false)?,
            tf_static: node.advertise("/tf_static", 10, true)?,
            odom_tf: plan.odom_tf,
            joints_on_tf,
            msg: msgs::TfMessage { transforms },
        })
    }
}

impl TopicFamily for Tf {
    fn start(&mut self, start: &Start) {
        self.tf_static.publish(&msgs::TfMessage {
            transforms: start.static_tf.clone(),
        });
    }

    fn control(&mut self, update: &ControlUpdate) {
        let t = update.sample.sim_time_s;
        let mut next = self.msg.transforms.iter_mut();
        if self.odom_tf
            && let Some(tr) = next.next()
        {
            tr.header.stamp_s = t;
            (tr.translation, tr.rotation) = odom_pose_msg(&update.sample);
        }
        for (&i, tr) in self.joints_on_tf.iter().zip(next) {
            if let Some(s) = update.joints.get(i) {
                tr.header.stamp_s = t;
                tr.translation = vec3(s.parent_from_child.translation);
                tr.rotation = quat(s.parent_from_child.rotation);
            }
        }
        if !self.msg.transforms.is_empty() {
            self.tf.publish(&self.msg);
        }
    }
}

/// Indices (in the plan's joints) of the joints whose links go on `/tf`: wheels as
/// `publishWheelTF` says; every other moving joint's link always, as robot_state_publisher
/// would from `/joint_states`.
pub(crate) fn joints_on_tf(plan: &RosPlan) -> Vec<usize> {
    plan.joints
        .iter()
        .enumerate()
        .filter(|(_, j)| plan.wheel_tf || !matches!(j.source, JointSource::Wheel { .. }))
        .map(|(i, _)| i)
        .collect()
}

/// What `/tf_static` says for `robot` (on the loop thread, once): every fixed joint, the
/// camera's optical frame under `camera_link` when the URDF has no link of that name, and each
/// laser's frame when it is not its link.
pub(crate) fn static_transforms(
    robot: &RobotModel,
    camera: Option<&CameraInfo>,
    camera_link: Option<&str>,
) -> Vec<TransformStamped> {
    let mut static_tf: Vec<TransformStamped> = robot
        .joints
        .iter()
        .filter(|j| matches!(j.kind, JointKind::Fixed))
        .map(|j| {
            let (parent, child) = (robot.link(j.parent), robot.link(j.child));
            transform(&parent.name, &child.name, 0.0, j.parent_from_child)
        })
        .collect();
    // The camera's optical frame, unless the URDF has it (TIAGo's xtion_rgb_optical_frame: its
    // own fixed joint is above).
    if let (Some(info), Some(link)) = (camera, camera_link)
        && robot.link_id(&info.frame_id).is_none()
    {
        let optical = Pose::from_parts(glam::Vec3::ZERO, link_from_optical());
        static_tf.push(transform(link, &info.frame_id, 0.0, optical));
    }
    for laser in &robot.lasers {
        if laser.frame_name != laser.link {
            static_tf.push(transform(
                &laser.link,
                &laser.frame_name,
                0.0,
                laser.link_from_sensor,
            ));
        }
    }
    static_tf
}
