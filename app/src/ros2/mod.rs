//! The ROS 2 bridge (`rover --ros2`): the ROS 1 bridge's topics, names and frames
//! ([`RosPlan`]) spoken over DDS (RTPS) as ROS 2 nodes speak it, with RustDDS (pure Rust, no
//! ROS install): topic `/odom` is DDS topic `rt/odom`, type `nav_msgs/msg/Odometry` is
//! `nav_msgs::msg::dds_::Odometry_`, CDR little-endian, domain `ROS_DOMAIN_ID`.
//!
//! It is the shared bridge (app/src/bridge/: the plan, the observer, the publishing thread,
//! the topic families) on this wire: here are the encoders, one file per topic family, each
//! implementing its family's wire trait with ROS 2's messages (the `rover-ros2` crate's `msgs`)
//! on the topic's sinks
//! (`sinks.rs`: its DDS writer, its MCAP channel, or both): `clock.rs`, `odom.rs`, `tf.rs`,
//! `joint_states.rs`, `camera.rs`, `detections.rs` (darknet_ros and the ground truth),
//! `laser.rs`, `cloud.rs`, `imu.rs`, `p3d.rs`, `gps.rs`, `bumper.rs`, `arm.rs`, `status.rs`, `rosout.rs` (rover's log lines); `/robot_description`
//! is written once, at the start (transient local, as robot_state_publisher keeps it). The input half (`input.rs`) turns
//! `rt/cmd_vel`, the controllers' commands and `/rover/arm/task` into rover input like a key
//! press. Stamps are sim time; `/clock` carries it.
//!
//! QoS as ROS 2 nodes expect: reliable, volatile, keep last 10 for `/odom`, `/tf`, `/clock` and
//! the command topics (rclcpp's default); sensor data (images, camera_info, scans) best
//! effort, keep last 5 (rclcpp's SensorDataQoS); `/tf_static` and the other latched topics
//! transient local, keep last 1 (a late joiner gets them).
//!
//! With `--record-mcap` the same messages go into an MCAP file (`mcap.rs`), with DDS or
//! without; recording never drops an event (the loop waits for the disk), DDS alone drops what
//! its thread cannot keep up with.
//!
//! The wire itself is the `rover-ros2` crate: `ros_discovery_info` names rover's node and its
//! readers and writers, so `ros2 node list` finds it (`discovery`); the node's parameters are
//! read through rclcpp's parameter services (`parameters`, on `services`: Fast DDS's and
//! Cyclone DDS's request/reply mappings, chosen per request). Here, each trajectory
//! controller and gripper serves its action (`actions.rs`) from the bridge's goals.
//!
//! Why RustDDS and not ros2-client (the ROS 2 client library on top of it): ros2-client picks
//! the distribution, and with it the size of `ros_discovery_info`'s ids, with a cargo feature,
//! where rover picks it per run (`--ros-distro`); and the bridge needs topics, writers and
//! readers with chosen QoS, which RustDDS offers directly (docs/ROS2.md).

mod actions;
mod arm;
mod bumper;
mod camera;
mod clock;
mod cloud;
mod convert;
mod detections;
mod gps;
mod imu;
mod input;
mod joint_states;
mod laser;
mod mcap;
mod model_states;
mod odom;
mod p3d;
mod rosout;
mod sinks;
mod status;
mod tf;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use anyhow::{Context, Result};
use rover_sim::model::RobotModel;
use rustdds::DomainParticipant;

use crate::bridge::action_intake::{self, ActionFamily};
use crate::bridge::{Backlog, Bridge, RosPlan, Transport};
use crate::bridge::{arm as arm_family, camera as camera_family, clock as clock_family};
use crate::bridge::{darknet, joint_states as joint_states_family, laser as laser_family};
use crate::bridge::{odom as odom_family, status as status_family, tf as tf_family};
use sinks::{Sinks, latched_qos};

pub use input::Ros2Input;
pub use mcap::McapSummary;
pub use rosout::layer as rosout_layer;
pub use rover_ros2::dds::dds_topic;
use rover_ros2::dds::default_qos;
pub use rover_ros2::discovery::RosDistro;
use rover_ros2::{discovery, msgs};

/// Where robot_state_publisher keeps the URDF in ROS 2.
const ROBOT_DESCRIPTION_TOPIC: &str = "/robot_description";

/// `--ros2` and `--record-mcap` settings.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Ros2Options {
    /// Join this DDS domain (`--ros2`; `ROS_DOMAIN_ID`, 0 by default).
    pub domain_id: Option<u16>,
    /// Record the topics into this MCAP file (`--record-mcap`).
    pub mcap: Option<PathBuf>,
    /// The node's name as ROS 2's tools list it (`--ros-name`).
    pub node_name: String,
    /// The distribution the peers run (`--ros-distro`, else `ROS_DISTRO`, else the newest
    /// LTS): what `ros_discovery_info`'s ids look like.
    pub distro: RosDistro,
}

impl Ros2Options {
    /// `--ros2` (`dds`: its domain from the environment) and/or `--record-mcap`; `None` when
    /// neither is asked for. `distro`: `--ros-distro`, when given.
    pub fn new(
        dds: bool,
        mcap: Option<&Path>,
        node_name: &str,
        distro: Option<RosDistro>,
    ) -> Result<Option<Self>> {
        if !dds && mcap.is_none() {
            return Ok(None);
        }
        let distro = distro
            .or_else(|| {
                std::env::var("ROS_DISTRO")
                    .ok()
                    .and_then(|name| RosDistro::from_name(&name))
            })
            .unwrap_or_default();
        Ok(Some(Self {
            domain_id: if dds { Some(domain_from_env()?) } else { None },
            mcap: mcap.map(Path::to_owned),
            node_name: node_name.to_owned(),
            distro,
        }))
    }
}

/// The DDS domain from `ROS_DOMAIN_ID` (0..=232, as ROS 2 allows; 0 when unset).
fn domain_from_env() -> Result<u16> {
    {
        let domain_id = match std::env::var("ROS_DOMAIN_ID") {
            Ok(text) if !text.trim().is_empty() => {
                let id: u16 = text.trim().parse().with_context(|| {
                    format!("ROS_DOMAIN_ID must be a number 0..=232, found \"{text}\"")
                })?;
                anyhow::ensure!(id <= 232, "ROS_DOMAIN_ID must be 0..=232, found {id}");
                id
            }
            _ => 0,
        };
        Ok(domain_id)
    }
}

impl Transport for Sinks<'_> {
    fn clock(&mut self) -> Result<Box<dyn clock_family::ClockWire>> {
        Ok(Box::new(clock::Clock::create(self)?))
    }

    fn odom(&mut self, plan: &RosPlan) -> Result<Box<dyn odom_family::OdomWire>> {
        Ok(Box::new(odom::Odom::create(self, plan)?))
    }

    fn tf(&mut self) -> Result<Box<dyn tf_family::TfWire>> {
        Ok(Box::new(tf::Tf::create(self)?))
    }

    fn joint_states(
        &mut self,
        plan: &RosPlan,
    ) -> Result<Box<dyn joint_states_family::JointStatesWire>> {
        Ok(Box::new(joint_states::JointStates::create(self, plan)?))
    }

    fn camera(&mut self, plan: &RosPlan) -> Result<Box<dyn camera_family::CameraWire>> {
        Ok(Box::new(camera::Camera::create(self, plan)?))
    }

    fn darknet(&mut self) -> Result<Box<dyn darknet::DarknetWire>> {
        Ok(Box::new(detections::Darknet::create(self)?))
    }

    fn laser(&mut self, plan: &RosPlan) -> Result<Box<dyn laser_family::ScanWire>> {
        Ok(Box::new(laser::Laser::create(self, plan)?))
    }

    fn p3d(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::p3d::P3dWire>> {
        Ok(Box::new(p3d::P3d::create(self, plan)?))
    }

    fn gps(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::gps::GpsWire>> {
        Ok(Box::new(gps::Gps::create(self, plan)?))
    }

    fn bumper(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::bumper::BumperWire>> {
        Ok(Box::new(bumper::Bumper::create(self, plan)?))
    }

    fn cloud(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::cloud::CloudWire>> {
        Ok(Box::new(cloud::Clouds::create(self, plan)?))
    }

    fn imu(&mut self, plan: &RosPlan) -> Result<Box<dyn crate::bridge::imu::ImuWire>> {
        Ok(Box::new(imu::Imu::create(self, plan)?))
    }

    fn arm(&mut self, plan: &RosPlan) -> Result<Box<dyn arm_family::ArmWire>> {
        Ok(Box::new(arm::Arm::create(self, plan)?))
    }

    fn ground_truth(&mut self) -> Result<Box<dyn darknet::BoxesWire>> {
        let topic = crate::bridge::ground_truth::GROUND_TRUTH_TOPIC;
        Ok(Box::new(detections::Boxes::create(
            self,
            topic,
            "ground_truth",
        )?))
    }

    fn status(&mut self) -> Result<Box<dyn status_family::StatusWire>> {
        Ok(Box::new(status::Status::create(self)?))
    }

    fn model_states(&mut self) -> Result<Box<dyn crate::bridge::model_states::ModelStatesWire>> {
        Ok(Box::new(model_states::ModelStates::create(self)?))
    }
}

/// What the ROS 2 bridge's thread hands back: the MCAP file's summary, when one is recorded
/// (an error when it could not be written in full).
pub(crate) type Recorded = Option<Result<McapSummary>>;

/// The observer half of the bridge: the shared bridge, its thread publishing on DDS and/or
/// into the MCAP file.
pub(crate) type Ros2Bridge = Bridge<Recorded>;

impl Bridge<Recorded> {
    /// Joins DDS domain `options.domain_id` (when set) and creates the robot's topics there,
    /// opens the MCAP file (when set), and starts the publishing thread. The input half
    /// (`rt/cmd_vel`) comes with DDS. `ground_truth`: the run measures it (`--ground-truth`).
    pub fn start(
        options: &Ros2Options,
        robot: &RobotModel,
        ground_truth: bool,
    ) -> Result<(Self, Option<Ros2Input>)> {
        let plan = RosPlan::for_robot(robot);
        let dds = match options.domain_id {
            Some(domain) => Some(DdsNode::join(domain, options, &plan, robot)?),
            None => None,
        };
        let mcap = match &options.mcap {
            Some(path) => Some(Arc::new(Mutex::new(mcap::McapRecorder::create(path)?))),
            None => None,
        };
        let mut sinks = Sinks {
            dds: dds.as_ref().map(|n| (&n.participant, &n.publisher)),
            mcap: mcap.clone(),
            writers: Vec::new(),
        };
        let mut description = sinks.out(ROBOT_DESCRIPTION_TOPIC, &latched_qos())?;
        description.put(
            msgs::Time::default(),
            &msgs::Text {
                data: robot.description.clone(),
            },
        );
        let mut families = crate::bridge::families(&mut sinks, &plan, ground_truth)?;
        let writers = std::mem::take(&mut sinks.writers);
        drop(sinks);
        let (input, held) = match dds {
            Some(node) => {
                let (input, held, actions, rosout) = node.announce(options, writers)?;
                families.push(Box::new(actions));
                families.push(Box::new(rosout));
                (Some(input), Some(held))
            }
            None => (None, None),
        };
        let backlog = if mcap.is_some() {
            Backlog::Wait
        } else {
            Backlog::Drop
        };
        let bridge = Bridge::spawn(
            "ROS 2",
            "ros2-bridge",
            &plan,
            robot,
            backlog,
            families,
            move |families| {
                // The topics (and their hold on the file) go first; then the file is closed.
                drop(families);
                drop(description);
                let recorded = mcap.map(|file| match Arc::try_unwrap(file) {
                    Ok(file) => file
                        .into_inner()
                        .unwrap_or_else(PoisonError::into_inner)
                        .finish(),
                    Err(_) => Err(anyhow::anyhow!("the MCAP file is still in use")),
                });
                // ros_discovery_info, then the participant, go last.
                drop(held);
                recorded
            },
        )?;
        if let Some(domain) = options.domain_id {
            tracing::info!(
                "ROS 2: node {} ({}'s ros_discovery_info) in DDS domain {domain}; cmd_vel on {}, odometry on {}",
                options.node_name,
                options.distro.as_str(),
                dds_topic(&plan.cmd_topic),
                dds_topic(&plan.odom_topic)
            );
        }
        if let Some(path) = &options.mcap {
            tracing::info!("recording the ROS 2 topics to {}", path.display());
        }
        Ok((bridge, input))
    }
}

/// What `--ros2` adds on DDS: the participant and its publisher, the input half (topics,
/// parameter services), the controllers' action servers and `/rosout` (with its writer's
/// GUID).
struct DdsNode {
    participant: DomainParticipant,
    publisher: rustdds::Publisher,
    input: Ros2Input,
    /// The action servers' family, and their readers and writers.
    actions: (ActionFamily, actions::Gids),
    rosout: (rosout::Rosout, rustdds::GUID),
}

/// What the publishing thread keeps alive until it ends: `ros_discovery_info`'s writer, the
/// publisher and the participant.
type Held = (discovery::Discovery, rustdds::Publisher, DomainParticipant);

impl DdsNode {
    /// Joins DDS domain `domain`, subscribes to the input topics and serves the parameters
    /// and actions of the node `options` names.
    fn join(
        domain: u16,
        options: &Ros2Options,
        plan: &RosPlan,
        robot: &RobotModel,
    ) -> Result<Self> {
        let participant = DomainParticipant::new(domain)
            .with_context(|| format!("joining DDS domain {domain}"))?;
        let publisher = participant
            .create_publisher(&default_qos())
            .context("creating the DDS publisher")?;
        let (namespace, name) = discovery::split_node_name(&options.node_name);
        let node = format!("{}/{name}", namespace.trim_end_matches('/'));
        let subscriber = participant
            .create_subscriber(&default_qos())
            .context("creating the DDS subscriber")?;
        let (servers, action_gids) = actions::serve(
            (&participant, &subscriber, &publisher),
            (plan, robot),
            options.distro,
        )?;
        let (family, goal_commands) = action_intake::intake(servers);
        let input = Ros2Input::subscribe(
            &participant,
            &publisher,
            plan,
            &node,
            &robot.description,
            goal_commands,
        )?;
        let actions = (family, action_gids);
        let rosout = rosout::Rosout::create(&participant, &publisher, &node)?;
        Ok(Self {
            participant,
            publisher,
            input,
            actions,
            rosout,
        })
    }

    /// Publishes `ros_discovery_info` for the node: the input's and the actions' readers and
    /// writers, `/rosout`'s and the topics' `writers`. What the bridge runs with: the input,
    /// what its thread holds, the action servers and `/rosout` (topic families).
    fn announce(
        self,
        options: &Ros2Options,
        writers: Vec<rustdds::GUID>,
    ) -> Result<(Ros2Input, Held, ActionFamily, rosout::Rosout)> {
        let mut d = discovery::Discovery::new(
            &self.participant,
            &self.publisher,
            &options.node_name,
            options.distro,
        )?;
        let (mut readers, mut all_writers) = self.input.gids();
        let (actions, (action_readers, action_writers)) = self.actions;
        readers.extend(action_readers);
        all_writers.extend(action_writers);
        all_writers.extend(writers);
        let (rosout, rosout_writer) = self.rosout;
        all_writers.push(rosout_writer);
        d.add(&readers, &all_writers)?;
        Ok((
            self.input,
            (d, self.publisher, self.participant),
            actions,
            rosout,
        ))
    }
}
