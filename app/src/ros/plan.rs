//! The names and frames the bridge uses for a robot, as Gazebo's plugins would choose them, and
//! the moving joints it reports.

use rover_sim::{ControlSample, DiffDriveConfig, LinkId, Pose, RobotModel};

/// Topic names and frames, from the robot's Gazebo plugins.
#[derive(Debug, Clone)]
pub struct RosPlan {
    /// `/cmd_vel` (diff drive `commandTopic`).
    pub cmd_topic: String,
    /// `/odom` (diff drive `odometryTopic`).
    pub odom_topic: String,
    /// Odometry frame (`odometryFrame`).
    pub odom_frame: String,
    /// Base frame (`robotBaseFrame`).
    pub base_frame: String,
    /// Whether odom -> base goes on `/tf` (`publishOdomTF`).
    pub odom_tf: bool,
    /// Whether the wheels' transforms go on `/tf` (`publishWheelTF`).
    pub wheel_tf: bool,
    /// Camera image topic (`/<cameraName>/<imageTopicName>`).
    pub image_topic: Option<String>,
    /// Camera info topic (`/<cameraName>/<cameraInfoTopicName>`).
    pub info_topic: Option<String>,
    /// The first laser's topic (`topicName`).
    pub scan_topic: Option<String>,
    /// Every moving joint the session reports, in `/joint_states` order.
    pub(super) joints: Vec<MovingJoint>,
}

/// A moving joint the bridge reports (`/joint_states`; `/tf` for wheels with
/// `publishWheelTF`).
#[derive(Debug, Clone)]
pub(super) struct MovingJoint {
    /// Joint name.
    pub name: String,
    /// Parent link.
    pub parent: LinkId,
    /// Child link.
    pub child: LinkId,
    /// Parent link name (the TF parent frame).
    pub parent_link: String,
    /// Child link name (the TF child frame).
    pub child_link: String,
    /// The joint at rest: the child link's frame in the parent link's.
    pub parent_from_child_at_rest: Pose,
    /// Unit axis in the child link's frame.
    pub axis: glam::Vec3,
    /// What moves it, and where the session reports its speed.
    pub source: JointSource,
}

/// What moves a joint, and where the session reports its speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum JointSource {
    /// A drive wheel: `side` indexes the control sample's wheel speeds (0 left, 1 right).
    Wheel {
        /// 0 for the left wheel, 1 for the right.
        side: usize,
    },
}

impl JointSource {
    /// The joint's measured speed at a control update (rad/s).
    pub fn velocity_radps(self, sample: &ControlSample) -> f64 {
        match self {
            Self::Wheel { side } => sample
                .wheel_measured_radps
                .get(side)
                .copied()
                .unwrap_or_default(),
        }
    }
}

/// A global topic name (`cmd_vel` -> `/cmd_vel`).
fn topic(name: &str) -> String {
    if name.starts_with('/') {
        name.to_owned()
    } else {
        format!("/{name}")
    }
}

impl RosPlan {
    /// The names Gazebo's plugins would use for `robot`.
    pub fn for_robot(robot: &RobotModel) -> Self {
        let drive = robot.diff_drive.clone().unwrap_or_default();
        let camera = robot.cameras.first();
        let camera_topic = |leaf: &str| {
            camera.map(|c| {
                let ns = c.camera_name.trim_matches('/');
                if ns.is_empty() {
                    topic(leaf)
                } else {
                    format!("/{ns}/{}", leaf.trim_start_matches('/'))
                }
            })
        };
        Self {
            cmd_topic: topic(&drive.command_topic),
            odom_topic: topic(&drive.odometry_topic),
            odom_frame: drive.odometry_frame.clone(),
            base_frame: drive.robot_base_frame.clone(),
            odom_tf: drive.publish_odom_tf,
            wheel_tf: drive.publish_wheel_tf,
            image_topic: camera_topic(camera.map_or("image_raw", |c| c.image_topic.as_str())),
            info_topic: camera_topic(camera.map_or("camera_info", |c| c.info_topic.as_str())),
            scan_topic: robot.lasers.first().map(|l| topic(&l.topic)),
            joints: moving_joints(robot, &drive),
        }
    }
}

/// The robot's moving joints that the session reports: today the drive's wheels (left, right).
fn moving_joints(robot: &RobotModel, drive: &DiffDriveConfig) -> Vec<MovingJoint> {
    let link_name = |id: LinkId| robot.link(id).name.clone();
    [&drive.left_joint, &drive.right_joint]
        .into_iter()
        .enumerate()
        .filter_map(|(side, name)| {
            let j = robot.joints.iter().find(|j| &j.name == name)?;
            Some(MovingJoint {
                name: j.name.clone(),
                parent: j.parent,
                child: j.child,
                parent_link: link_name(j.parent),
                child_link: link_name(j.child),
                parent_from_child_at_rest: j.parent_from_child,
                axis: j.axis,
                source: JointSource::Wheel { side },
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tutorial_car_gets_gazebos_topic_names() -> anyhow::Result<()> {
        let robot = RobotModel::load(&rover_core::default_robot_path())?;
        let plan = RosPlan::for_robot(&robot);
        assert_eq!(plan.cmd_topic, "/cmd_vel");
        assert_eq!(plan.odom_topic, "/odom");
        assert_eq!(plan.odom_frame, "odom");
        assert_eq!(plan.base_frame, "base_link");
        assert!(plan.wheel_tf);
        assert_eq!(plan.image_topic.as_deref(), Some("/camera/image_raw"));
        assert_eq!(plan.info_topic.as_deref(), Some("/camera/camera_info"));
        assert_eq!(plan.scan_topic, None);
        let joints: Vec<(&str, JointSource)> = plan
            .joints
            .iter()
            .map(|j| (j.name.as_str(), j.source))
            .collect();
        assert_eq!(
            joints,
            [
                ("left_wheel_joint", JointSource::Wheel { side: 0 }),
                ("right_wheel_joint", JointSource::Wheel { side: 1 })
            ]
        );
        Ok(())
    }
}
