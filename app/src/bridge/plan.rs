//! The names and frames the bridge uses for a robot, as Gazebo's plugins would choose them, and
//! the moving joints it reports.

use rover_sim::{
    geometry::Pose,
    model::{CommandKind, ControllerKind, DiffDriveConfig, JointId, LinkId, RobotModel},
    physics::ControlSample,
};

/// Topic names and frames, from the robot's Gazebo plugins.
#[derive(Debug, Clone)]
pub struct RosPlan {
    /// `/cmd_vel` (diff drive `commandTopic`).
    pub cmd_topic: String,
    /// The command topic carries geometry_msgs/TwistStamped (a ros_gz_bridge map says so),
    /// not Twist.
    pub cmd_stamped: bool,
    /// Odometry messages and transforms per second of sim time (0: every control update;
    /// gz-sim's DiffDrive: its `odom_publish_frequency`).
    pub odom_rate_hz: f64,
    /// Where the joints' states go: `/joint_states`, or gz-sim's JointStatePublisher `<topic>`.
    pub joint_states_topic: String,
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
    /// A depth camera's depth image topic (`/<cameraName>/<depthImageTopicName>`, 32FC1).
    pub depth_image_topic: Option<String>,
    /// A depth camera's depth camera_info topic
    /// (`/<cameraName>/<depthImageCameraInfoTopicName>`).
    pub depth_info_topic: Option<String>,
    /// A depth camera's point cloud topic (`/<cameraName>/<pointCloudTopicName>`).
    pub depth_cloud_topic: Option<String>,
    /// The first laser's topic (`topicName`).
    pub scan_topic: Option<String>,
    /// Each 3D lidar's cloud topic (`topicName`), in `RobotModel::lidars` order.
    pub lidar_topics: Vec<String>,
    /// Each IMU's topic and `frame_id`, in `RobotModel::imus` order.
    pub imus: Vec<(String, String)>,
    /// Each p3d's topic and frames, in `RobotModel::p3ds` order.
    pub p3ds: Vec<P3dTopic>,
    /// Each GPS receiver's topics and frame, in `RobotModel::gpss` order.
    pub gpss: Vec<GpsTopics>,
    /// Each bumper's topic, in `RobotModel::bumpers` order.
    pub bumpers: Vec<String>,
    /// Every moving joint the session reports, in `/joint_states` order.
    pub(crate) joints: Vec<MovingJoint>,
    /// `/joint_states` rate from a joint_state_controller's `publish_rate` (Hz); `None`:
    /// every control update.
    pub joint_states_hz: Option<f64>,
    /// The controllers file's command topics.
    pub(crate) controllers: Vec<ControllerTopic>,
    /// The controllers file's gripper controllers: their names and action namespaces
    /// (`/<namespace>/<controller>/gripper_cmd`).
    pub(crate) grippers: Vec<(String, String)>,
}

/// A p3d plugin's topic and frames.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct P3dTopic {
    /// `topicName` in `robotNamespace`.
    pub topic: String,
    /// `frameName`: the messages' `frame_id`.
    pub frame: String,
    /// `bodyName`: the messages' `child_frame_id`.
    pub child_frame: String,
}

/// A GPS receiver's topics and frame.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GpsTopics {
    /// `topicName` (NavSatFix).
    pub topic: String,
    /// `velocityTopicName` (Vector3Stamped); `None` for gz-sim's NavSat (no velocity topic).
    pub velocity_topic: Option<String>,
    /// `frameId`.
    pub frame: String,
}

/// A controller's topics (`/<namespace>/<controller>/command`).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ControllerTopic {
    /// Controller name.
    pub name: String,
    /// Its `command` topic.
    pub command_topic: String,
    /// Whether the command is a trajectory_msgs/JointTrajectory (else std_msgs/Float64).
    pub trajectory: bool,
    /// Its `state` topic (control_msgs/JointTrajectoryControllerState for trajectory
    /// controllers, control_msgs/JointControllerState for position controllers).
    pub state_topic: Option<String>,
    /// Its joints, as indices into the plan's `joints`.
    pub joints: Vec<usize>,
    /// The topic is gz-sim's own (a joint controller system's `<topic>`): the same on ROS 1
    /// and ROS 2, a single value as std_msgs/Float64.
    pub explicit: bool,
    /// The gains a position controller reports in its state.
    pub pid: Option<rover_sim::model::Pid>,
    /// How often `state` goes out (Hz).
    pub state_hz: f64,
}

/// A moving joint the bridge reports (`/joint_states`; `/tf` for wheels with
/// `publishWheelTF`).
#[derive(Debug, Clone)]
pub(crate) struct MovingJoint {
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
pub(crate) enum JointSource {
    /// A drive wheel: `side` indexes the control sample's wheel speeds (0 left, 1 right).
    Wheel {
        /// 0 for the left wheel, 1 for the right.
        side: usize,
    },
    /// Any other moving joint (an arm's, a head's, a caster's): the simulation's joint state.
    Joint(JointId),
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
            Self::Joint(_) => 0.0,
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
            cmd_stamped: drive.command_stamped,
            odom_rate_hz: drive.odometry_rate_hz.unwrap_or(0.0),
            joint_states_topic: robot
                .joint_state_publisher
                .as_ref()
                .map_or_else(|| "/joint_states".to_owned(), |j| topic(&j.topic)),
            odom_topic: topic(&drive.odometry_topic),
            odom_frame: drive.odometry_frame.clone(),
            base_frame: drive.robot_base_frame.clone(),
            odom_tf: drive.publish_odom_tf,
            wheel_tf: drive.publish_wheel_tf,
            image_topic: camera_topic(camera.map_or("image_raw", |c| c.image_topic.as_str())),
            info_topic: camera_topic(camera.map_or("camera_info", |c| c.info_topic.as_str())),
            depth_image_topic: camera
                .and_then(|c| c.depth.as_ref())
                .and_then(|d| camera_topic(&d.image_topic)),
            depth_info_topic: camera
                .and_then(|c| c.depth.as_ref())
                .and_then(|d| camera_topic(&d.info_topic)),
            depth_cloud_topic: camera
                .and_then(|c| c.depth.as_ref())
                .and_then(|d| camera_topic(&d.cloud_topic)),
            scan_topic: robot.lasers.first().map(|l| topic(&l.topic)),
            lidar_topics: robot.lidars.iter().map(|l| topic(&l.rays.topic)).collect(),
            imus: robot
                .imus
                .iter()
                .map(|i| (topic(&i.topic), i.frame_name.clone()))
                .collect(),
            p3ds: robot
                .p3ds
                .iter()
                .map(|p| P3dTopic {
                    topic: topic(&p.topic),
                    frame: p.frame_name.clone(),
                    child_frame: p.link.clone(),
                })
                .collect(),
            bumpers: robot.bumpers.iter().map(|b| topic(&b.topic)).collect(),
            gpss: robot
                .gpss
                .iter()
                .map(|g| GpsTopics {
                    topic: topic(&g.topic),
                    velocity_topic: (!g.velocity_topic.is_empty())
                        .then(|| topic(&g.velocity_topic)),
                    frame: g.frame_id.clone(),
                })
                .collect(),
            joints: moving_joints(robot, &drive),
            joint_states_hz: robot.controllers.as_ref().and_then(|c| {
                c.controllers.iter().find_map(|s| match s.kind {
                    ControllerKind::JointState { publish_rate_hz } => Some(publish_rate_hz),
                    _ => None,
                })
            }),
            controllers: Vec::new(),
            grippers: Vec::new(),
        }
        .with_controllers(robot)
    }

    /// The controllers' topics, their joints found among the plan's.
    fn with_controllers(mut self, robot: &RobotModel) -> Self {
        let mut topics = controller_topics(robot);
        for t in &mut topics {
            let names: Vec<String> = robot
                .controllers
                .as_ref()
                .and_then(|c| c.controller(&t.name))
                .map(|c| c.joints().to_vec())
                .unwrap_or_default();
            t.joints = names
                .iter()
                .filter_map(|n| self.joints.iter().position(|j| &j.name == n))
                .collect();
        }
        self.controllers = topics;
        self.grippers = robot
            .controllers
            .iter()
            .flat_map(|config| &config.controllers)
            .filter(|c| matches!(c.kind, ControllerKind::Gripper(_)))
            .map(|c| {
                let ns = namespace_prefix(robot, &c.namespace);
                (c.name.clone(), format!("{ns}/{}/gripper_cmd", c.name))
            })
            .collect();
        self
    }
}

/// How often a position controller's `state` goes out (Hz).
const STATE_HZ: f64 = 50.0;

/// `/<namespace>` for a controller written under `namespace` in its file (empty: the
/// gazebo_ros_control plugin's `robotNamespace`); empty for none.
fn namespace_prefix(robot: &RobotModel, namespace: &str) -> String {
    let ns = if namespace.is_empty() {
        robot
            .ros_control
            .as_ref()
            .map_or("", |r| r.namespace.trim_matches('/'))
    } else {
        namespace.trim_matches('/')
    };
    if ns.is_empty() {
        String::new()
    } else {
        format!("/{ns}")
    }
}

/// The command topics of the robot's controllers: `/<namespace>/<controller>/command`, the
/// namespace being the one the controllers file puts them under, else the gazebo_ros_control
/// plugin's `robotNamespace`.
fn controller_topics(robot: &RobotModel) -> Vec<ControllerTopic> {
    let Some(config) = &robot.controllers else {
        return Vec::new();
    };
    config
        .controllers
        .iter()
        // Joint state controllers publish /joint_states; gripper controllers take actions
        // only (gripper_cmd), no command topic.
        .filter(|c| {
            !matches!(
                c.kind,
                ControllerKind::JointState { .. } | ControllerKind::Gripper(_)
            )
        })
        .map(|c| {
            let prefix = namespace_prefix(robot, &c.namespace);
            let (state, pid, state_hz) = match &c.kind {
                ControllerKind::Trajectory(t) => (true, None, t.state_publish_rate_hz),
                ControllerKind::Joint {
                    command: CommandKind::PositionPid(pid),
                    ..
                } => (true, Some(*pid), STATE_HZ),
                ControllerKind::Joint {
                    command: CommandKind::Position,
                    ..
                } => (true, None, STATE_HZ),
                _ => (false, None, STATE_HZ),
            };
            ControllerTopic {
                name: c.name.clone(),
                command_topic: c
                    .topic
                    .as_deref()
                    .map_or_else(|| format!("{prefix}/{}/command", c.name), topic),
                trajectory: matches!(c.kind, ControllerKind::Trajectory(_)),
                // gz-sim's joint controllers publish no state.
                state_topic: (state && c.topic.is_none())
                    .then(|| format!("{prefix}/{}/state", c.name)),
                joints: Vec::new(),
                explicit: c.topic.is_some(),
                pid,
                state_hz,
            }
        })
        .collect()
}

/// The robot's moving joints that the session reports: the drive's wheels (left, right),
/// then every other revolute, continuous or prismatic joint in file order.
fn moving_joints(robot: &RobotModel, drive: &DiffDriveConfig) -> Vec<MovingJoint> {
    let link_name = |id: LinkId| robot.link(id).name.clone();
    let entry = |id: JointId, source: JointSource| {
        let j = robot.joint(id);
        MovingJoint {
            name: j.name.clone(),
            parent: j.parent,
            child: j.child,
            parent_link: link_name(j.parent),
            child_link: link_name(j.child),
            parent_from_child_at_rest: j.parent_from_child,
            axis: j.axis,
            source,
        }
    };
    let wheels: Vec<JointId> = [&drive.left_joint, &drive.right_joint]
        .into_iter()
        .filter_map(|name| robot.joint_id(name))
        .collect();
    let mut out: Vec<MovingJoint> = wheels
        .iter()
        .enumerate()
        .map(|(side, id)| entry(*id, JointSource::Wheel { side }))
        .collect();
    out.extend(
        robot
            .joint_ids()
            .filter(|(id, j)| j.is_moving() && !wheels.contains(id))
            .map(|(id, _)| entry(id, JointSource::Joint(id))),
    );
    out
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
