//! The ROS 2 bridge (`rover --ros2`): the ROS 1 bridge's topics, names and frames
//! ([`RosPlan`]) spoken over DDS (RTPS) as ROS 2 nodes speak it, with RustDDS (pure Rust, no
//! ROS install): topic `/odom` is DDS topic `rt/odom`, type `nav_msgs/msg/Odometry` is
//! `nav_msgs::msg::dds_::Odometry_`, CDR little-endian, domain `ROS_DOMAIN_ID`.
//!
//! Like the ROS 1 bridge it is an adapter at the edge: an [`Observer`] that copies what the
//! session does into a channel for its publishing thread (never waiting: a full channel drops
//! the event and counts it), and an [`InputSource`] ([`Ros2Input`]) that turns `rt/cmd_vel`
//! into rover input like a key press. Stamps are sim time; `/clock` carries it.
//!
//! QoS as ROS 2 nodes expect: reliable, volatile, keep last 10 for `/odom`, `/tf`, `/clock` and
//! the command topic (rclcpp's default).
//!
//! Sensor data (the camera's image and camera_info, the laser's scan) best effort, keep last 5
//! (rclcpp's SensorDataQoS); `/tf_static` transient local, keep last 1 (a late joiner gets it).
//!
//! Carried: `/cmd_vel`, the controllers' commands and `/rover/arm/task` in (`input.rs`);
//! `/clock`, odometry, `/tf`, `/tf_static`, `/joint_states`, `/robot_description`, the camera's
//! image and camera_info (and a depth camera's), darknet_ros's boxes and object count, the
//! arm's state and points, the laser's scan out (`topics.rs`). The same messages can go into
//! an MCAP file (`--record-mcap`, `mcap.rs`), with DDS or without; recording never drops an
//! event (the loop waits for the disk), DDS alone drops what its thread cannot keep up with.
//!
//! `ros_discovery_info` names rover's node and its readers and writers, so `ros2 node list`
//! finds it (`discovery.rs`).
//!
//! Why RustDDS and not ros2-client (the ROS 2 client library on top of it): ros2-client picks
//! the distribution, and with it the size of `ros_discovery_info`'s ids, with a cargo feature,
//! where rover picks it per run (`--ros-distro`); and the bridge needs topics, writers and
//! readers with chosen QoS, which RustDDS offers directly (docs/ROS2.md).

mod dds;
mod definitions;
mod discovery;
mod input;
mod mcap;
mod msgs;
mod topics;

use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use rover_core::{LoopStats, Observer};
use rover_perception::BoundingBoxes;
use rover_sim::{ControlSample, LaserScan, Pose, RobotModel, Simulation};
use rustdds::DomainParticipant;

use crate::ros::RosPlan;
use crate::ros::shared::{
    ArmSample, BufferPool, BufferReturn, Detections, ImageFrame, JointSample, arm_sample,
    buffer_pool, capture_detections, capture_image, capture_scan, sample_joints, static_transforms,
};
use topics::{Sinks, Topics};

pub use dds::dds_topic;
use dds::default_qos;
pub use discovery::RosDistro;
pub use input::Ros2Input;
pub use mcap::McapSummary;

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

/// What the loop thread hands the publishing thread.
enum Event {
    /// The run starts: the static transforms and the camera's calibration.
    Start {
        static_tf: Vec<rover_ros1::msgs::TransformStamped>,
        camera: Option<rover_sim::CameraInfo>,
    },
    /// A control update: its sample, the moving joints (the plan's order), the arm's task.
    Control(ControlSample, Vec<JointSample>, ArmSample),
    /// A camera image (and a depth camera's depth image).
    Image(ImageFrame),
    /// A laser scan.
    Scan(LaserScan),
    /// A detector result.
    Detections(Detections),
}

/// The observer half of the bridge.
pub struct Ros2Bridge {
    tx: Option<SyncSender<Event>>,
    thread: Option<JoinHandle<Option<Result<McapSummary>>>>,
    dropped: u64,
    /// Recording: every event is sent, waiting for the thread when it is behind (nothing
    /// lost); DDS alone drops what the thread cannot keep up with.
    lossless: bool,
    /// The MCAP file's summary, once finished.
    recorded: Option<Result<McapSummary>>,
    /// The newest control update's sim time: detector results are published then.
    now_s: f64,
    /// Recycled buffers for the events (joints, pixels, ranges).
    buffers: BufferPool,
    plan: RosPlan,
    camera_link: Option<String>,
}

impl std::fmt::Debug for Ros2Bridge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Bridge")
            .field("dropped", &self.dropped)
            .finish_non_exhaustive()
    }
}

impl Ros2Bridge {
    /// Joins DDS domain `options.domain_id` (when set) and creates the robot's topics there,
    /// opens the MCAP file (when set), and starts the publishing thread. The input half
    /// (`rt/cmd_vel`) comes with DDS.
    pub fn start(options: &Ros2Options, robot: &RobotModel) -> Result<(Self, Option<Ros2Input>)> {
        let plan = RosPlan::for_robot(robot);
        let participant = match options.domain_id {
            Some(domain) => Some(
                DomainParticipant::new(domain)
                    .with_context(|| format!("joining DDS domain {domain}"))?,
            ),
            None => None,
        };
        let input = match &participant {
            Some(p) => Some(Ros2Input::subscribe(p, &plan)?),
            None => None,
        };
        let publisher = match &participant {
            Some(p) => Some(
                p.create_publisher(&default_qos())
                    .context("creating the DDS publisher")?,
            ),
            None => None,
        };
        let mcap = match &options.mcap {
            Some(path) => Some(mcap::McapRecorder::create(path)?),
            None => None,
        };
        let sinks = Sinks {
            dds: participant.as_ref().zip(publisher.as_ref()),
            mcap,
            writers: Vec::new(),
        };
        let topics = Topics::create(sinks, &plan, &robot.description)?;
        let discovery = match (&participant, &publisher, &input) {
            (Some(p), Some(publisher), Some(input)) => {
                let mut d =
                    discovery::Discovery::new(p, publisher, &options.node_name, options.distro)?;
                d.add(&input.reader_gids(), topics.writer_gids())?;
                Some(d)
            }
            _ => None,
        };
        let (tx, rx) = sync_channel::<Event>(64);
        let (buffers, returns) = buffer_pool();
        let thread = std::thread::Builder::new()
            .name("ros2-bridge".into())
            .spawn(move || {
                let recorded = run(topics, &rx, &returns);
                drop(discovery);
                drop(publisher);
                drop(participant);
                recorded
            })
            .context("starting the ROS 2 bridge thread")?;
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
        Ok((
            Self {
                tx: Some(tx),
                thread: Some(thread),
                dropped: 0,
                lossless: options.mcap.is_some(),
                recorded: None,
                now_s: 0.0,
                buffers,
                plan,
                camera_link: robot.cameras.first().map(|c| c.link.clone()),
            },
            input,
        ))
    }

    /// Events dropped because the publishing thread was behind.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Sends what is queued, stops the thread and closes the MCAP file: what it holds, when
    /// one is recorded (an error when it could not be written in full).
    pub fn finish(&mut self) -> Option<Result<McapSummary>> {
        self.tx = None;
        if let Some(thread) = self.thread.take() {
            self.recorded = match thread.join() {
                Ok(recorded) => recorded,
                Err(_) => Some(Err(anyhow::anyhow!("the ROS 2 bridge thread panicked"))),
            };
        }
        self.recorded.take()
    }

    fn send(&mut self, event: Event) {
        let Some(tx) = &self.tx else { return };
        let sent = if self.lossless {
            tx.send(event).map_err(|_| ())
        } else {
            match tx.try_send(event) {
                Ok(()) => Ok(()),
                Err(TrySendError::Full(_)) => {
                    self.dropped += 1;
                    Ok(())
                }
                Err(TrySendError::Disconnected(_)) => Err(()),
            }
        };
        if sent.is_err() {
            self.tx = None;
        }
    }
}

impl Drop for Ros2Bridge {
    fn drop(&mut self) {
        self.finish();
    }
}

impl Observer for Ros2Bridge {
    fn start(&mut self, sim: &Simulation, camera: Option<&rover_sim::CameraInfo>, _: &[String]) {
        let static_tf = static_transforms(sim.robot(), camera, self.camera_link.as_deref());
        self.send(Event::Start {
            static_tf,
            camera: camera.cloned(),
        });
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        self.now_s = sample.sim_time_s;
        let mut joints = self.buffers.take_joints();
        sample_joints(sim, sample, &self.plan.joints, &mut joints);
        self.send(Event::Control(*sample, joints, arm_sample(sim, &stats.arm)));
    }

    fn camera_frame(&mut self, frame: &rover_sim::CameraFrame<'_>, _world_from_camera: Pose) {
        let depth = if frame.depth_m.is_some() {
            self.buffers.take_pixels()
        } else {
            Vec::new()
        };
        let image = capture_image(frame, self.buffers.take_pixels(), depth);
        self.send(Event::Image(image));
    }

    fn laser_scan(&mut self, scan: &LaserScan, _world_from_laser: Pose) {
        let scan = capture_scan(scan, self.buffers.take_ranges());
        self.send(Event::Scan(scan));
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        let detections = capture_detections(boxes, self.now_s, self.buffers.take_boxes());
        self.send(Event::Detections(detections));
    }
}

/// The publishing thread: every event to the topics, until the bridge hangs up; then the MCAP
/// file is closed. The buffers events carry go back to the loop thread once published.
fn run(
    mut topics: Topics,
    events: &Receiver<Event>,
    returns: &BufferReturn,
) -> Option<Result<McapSummary>> {
    for event in events {
        match event {
            Event::Start { static_tf, camera } => topics.start(&static_tf, camera.as_ref()),
            Event::Control(sample, joints, arm) => {
                topics.control(&sample, &joints);
                topics.arm(sample.sim_time_s, &arm);
                returns.joints(joints);
            }
            Event::Image(mut frame) => {
                topics.image(&mut frame);
                returns.pixels(frame.pixels);
                returns.pixels(frame.depth);
            }
            Event::Scan(scan) => {
                if let Some(ranges) = topics.scan(scan) {
                    returns.ranges(ranges);
                }
            }
            Event::Detections(d) => {
                topics.detections(&d);
                returns.boxes(d.boxes);
            }
        }
    }
    topics.finish()
}
