//! The ROS 1 bridge (`rover --ros`): an adapter at the edge of the loop, like the window and
//! the recorder. As an [`Observer`] it hands what the session does to a publishing thread,
//! under the names Gazebo's plugins and darknet_ros would use for this robot; as an
//! [`InputSource`](rover_core::InputSource) ([`RosInput`]) it feeds `/cmd_vel` to the session
//! like manual input, and the controllers' `command` topics to the robot's joints.
//!
//! The loop thread only copies (into recycled buffers) and never waits: when the publishing
//! thread falls behind, events are dropped and counted. Stamps are sim time.
//!
//! One file per topic family, as OpenRR's arci-ros has one adapter per family: `clock.rs`,
//! `odom.rs`, `tf.rs` (`/tf`, `/tf_static`), `joint_states.rs`, `camera.rs` (image,
//! camera_info), `detections.rs` (darknet_ros), `laser.rs`, `controller_states.rs` (the
//! controllers' `state`), `arm.rs` (the arm's look and reach: task in, state and points out),
//! and `cmd_vel.rs` and `controllers.rs` (the controllers' `command` topics) in. Each publishing
//! family implements `TopicFamily` (`events.rs`, with what travels between the threads) and is
//! listed once in `families` below; `plan.rs` names the topics, frames and moving joints,
//! `publisher.rs` is the thread. A new topic is a new file beside them and a line in `families`.

mod arm;
mod camera;
mod clock;
mod cmd_vel;
mod controller_states;
mod controllers;
mod convert;
mod detections;
mod events;
mod ground_truth;
mod joint_states;
mod laser;
mod odom;
mod plan;
mod publisher;
mod tf;

use std::sync::mpsc::{SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use rover_core::{Action, InputSource, LoopStats, Observer};
use rover_perception::BoundingBoxes;
use rover_ros1::{Node, NodeOptions, Value};
use rover_sim::{
    CameraFrame, CameraInfo, ControlSample, GroundTruthBox, LaserScan, Pose, RobotModel, Simulation,
};

pub use cmd_vel::RosCmdVel;

/// What the ROS 2 bridge shares with this one: the static transforms, the moving joints'
/// sampling, and their types.
pub(crate) mod shared {
    pub(crate) use super::arm_sample;
    pub(crate) use super::camera::capture as capture_image;
    pub(crate) use super::controllers::poll_in_turn;
    pub(crate) use super::detections::{
        BOUNDING_BOXES_TOPIC, DETECTION_IMAGE_TOPIC, DetectionImages, FOUND_OBJECT_TOPIC,
        capture as capture_detections,
    };
    pub(crate) use super::events::{
        ArmSample, BufferPool, BufferReturn, Detections, ImageFrame, JointSample, buffer_pool,
    };
    pub(crate) use super::joint_states::sample as sample_joints;
    pub(crate) use super::laser::capture as capture_scan;
    pub(crate) use super::odom::odom_pose;
    pub(crate) use super::tf::{joints_on_tf, static_transforms};
}
use controllers::ControllerCommands;
pub use plan::RosPlan;

use events::{BufferPool, ControlUpdate, Event, Start, TopicFamily};
use plan::MovingJoint;

/// `--ros` settings.
#[derive(Debug, Clone)]
pub struct RosOptions {
    /// Node name (`rover` -> `/rover`).
    pub name: String,
    /// Also set `/use_sim_time` so ROS nodes follow `/clock`.
    pub sim_time: bool,
    /// The run measures ground truth (`--ground-truth`): publish it on
    /// `/rover/ground_truth/bounding_boxes`.
    pub ground_truth: bool,
}

/// The topic families the bridge publishes, advertised in this order and shown every event in
/// it.
fn families(
    node: &Node,
    plan: &RosPlan,
    options: &RosOptions,
) -> Result<Vec<Box<dyn TopicFamily>>> {
    let mut families: Vec<Box<dyn TopicFamily>> = vec![
        Box::new(clock::Clock::advertise(node, plan)?),
        Box::new(odom::Odom::advertise(node, plan)?),
        Box::new(tf::Tf::advertise(node, plan)?),
        Box::new(joint_states::JointStates::advertise(node, plan)?),
        Box::new(camera::Camera::advertise(node, plan)?),
        Box::new(detections::DarknetTopics::advertise(node, plan)?),
        Box::new(laser::Laser::advertise(node, plan)?),
        Box::new(controller_states::ControllerStates::advertise(node, plan)?),
        Box::new(arm::ArmTopics::advertise(node, plan)?),
    ];
    if options.ground_truth {
        families.push(Box::new(ground_truth::GroundTruthTopic::advertise(node)?));
    }
    Ok(families)
}

/// The input half of the bridge: `/cmd_vel`, the controllers' `command` topics and the arm's
/// task.
#[derive(Debug)]
pub struct RosInput {
    cmd_vel: RosCmdVel,
    controllers: ControllerCommands,
    arm: arm::ArmTaskInput,
}

impl InputSource for RosInput {
    fn poll(&mut self) -> Option<Action> {
        self.cmd_vel
            .poll()
            .or_else(|| self.controllers.poll())
            .or_else(|| self.arm.poll())
    }
}

/// The observer half of the bridge.
pub struct RosBridge {
    tx: Option<SyncSender<Event>>,
    buffers: BufferPool,
    thread: Option<JoinHandle<()>>,
    joints: Vec<MovingJoint>,
    camera_link: Option<String>,
    now_s: f64,
    dropped: u64,
    warned: bool,
    /// Time spent in this observer's callbacks on the loop thread.
    busy: std::time::Duration,
}

impl std::fmt::Debug for RosBridge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RosBridge")
            .field("dropped", &self.dropped)
            .finish_non_exhaustive()
    }
}

impl RosBridge {
    /// Starts the node (registering with `ROS_MASTER_URI` as soon as a master answers),
    /// advertises the robot's topics, sets `/robot_description` (and `/use_sim_time`), and
    /// subscribes to its command topic.
    pub fn start(options: &RosOptions, robot: &RobotModel) -> Result<(Self, RosInput)> {
        let node_options = NodeOptions::from_env(&options.name)?;
        let node = Node::start(node_options).context("starting the ROS node")?;
        let plan = RosPlan::for_robot(robot);
        node.set_param("robot_description", Value::from(robot.description.as_str()))?;
        if options.sim_time {
            node.set_param("use_sim_time", Value::Bool(true))?;
        }
        let families = families(&node, &plan, options)?;
        let cmd = RosCmdVel::subscribe(&node, &plan)?;
        let controllers = ControllerCommands::subscribe(&node, &plan)?;
        let arm_task = arm::ArmTaskInput::subscribe(&node)?;
        for c in &plan.controllers {
            tracing::info!(
                "ROS: controller {} takes {} on {}",
                c.name,
                if c.trajectory {
                    "trajectory_msgs/JointTrajectory"
                } else {
                    "std_msgs/Float64"
                },
                c.command_topic
            );
        }
        tracing::info!(
            "ROS: node {} at {}; master {}; cmd_vel on {}, odometry on {}{}",
            node.name(),
            node.uri(),
            node.master_uri(),
            plan.cmd_topic,
            plan.odom_topic,
            plan.image_topic
                .as_deref()
                .map(|t| format!(", camera on {t}"))
                .unwrap_or_default()
        );
        let (tx, rx) = sync_channel::<Event>(64);
        let (buffers, returns) = events::buffer_pool();
        let thread = publisher::spawn(node, families, returns, rx)?;
        Ok((
            Self {
                tx: Some(tx),
                buffers,
                thread: Some(thread),
                joints: plan.joints,
                camera_link: robot.cameras.first().map(|c| c.link.clone()),
                now_s: 0.0,
                dropped: 0,
                warned: false,
                busy: std::time::Duration::ZERO,
            },
            RosInput {
                cmd_vel: cmd,
                controllers,
                arm: arm_task,
            },
        ))
    }

    /// Events the publishing thread could not take (it was behind).
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Time the bridge took on the loop thread so far (copies and hand-offs).
    pub fn loop_time(&self) -> std::time::Duration {
        self.busy
    }

    fn send(&mut self, event: Event) {
        let Some(tx) = &self.tx else {
            return;
        };
        match tx.try_send(event) {
            Ok(()) => {}
            Err(TrySendError::Full(_)) => {
                self.dropped += 1;
                if !self.warned {
                    self.warned = true;
                    tracing::warn!(
                        "ROS bridge is behind the simulation: dropping messages (the loop never waits for it)"
                    );
                }
            }
            Err(TrySendError::Disconnected(_)) => {
                tracing::warn!("ROS bridge thread stopped; the run goes on without ROS");
                self.tx = None;
            }
        }
    }

    /// Stops the publishing thread and unregisters from the master.
    pub fn finish(&mut self) {
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for RosBridge {
    fn drop(&mut self) {
        self.finish();
    }
}

impl Observer for RosBridge {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, _labels: &[String]) {
        let static_tf = tf::static_transforms(sim.robot(), camera, self.camera_link.as_deref());
        self.send(Event::Start(Start {
            static_tf,
            camera: camera.cloned(),
        }));
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        let started = std::time::Instant::now();
        self.now_s = sample.sim_time_s;
        let mut joints = self.buffers.take_joints();
        joint_states::sample(sim, sample, &self.joints, &mut joints);
        self.send(Event::Control(ControlUpdate {
            sample: *sample,
            joints,
            arm: arm_sample(sim, &stats.arm),
        }));
        self.busy += started.elapsed();
    }

    fn camera_frame(&mut self, frame: &CameraFrame<'_>, _world_from_camera: Pose) {
        let started = std::time::Instant::now();
        let depth = if frame.depth_m.is_some() {
            self.buffers.take_pixels()
        } else {
            Vec::new()
        };
        let image = camera::capture(frame, self.buffers.take_pixels(), depth);
        self.send(Event::Image(image));
        self.busy += started.elapsed();
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        let started = std::time::Instant::now();
        let detections = detections::capture(boxes, self.now_s, self.buffers.take_boxes());
        self.send(Event::Detections(detections));
        self.busy += started.elapsed();
    }

    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        let started = std::time::Instant::now();
        let truth = ground_truth::capture(boxes, truth, self.now_s, self.buffers.take_boxes());
        self.send(Event::Truth(truth));
        self.busy += started.elapsed();
    }

    fn laser_scan(&mut self, scan: &LaserScan, _world_from_laser: Pose) {
        let started = std::time::Instant::now();
        let scan = laser::capture(scan, self.buffers.take_ranges());
        self.send(Event::Scan(scan));
        self.busy += started.elapsed();
    }
}

/// The arm's status with its points moved from the world into the robot's base frame.
pub(crate) fn arm_sample(sim: &Simulation, arm: &rover_core::ArmStatus) -> events::ArmSample {
    let base_from_world = sim.world_from_base().inverse();
    let to_base = |p: Option<[f64; 3]>| {
        p.map(|[x, y, z]| {
            let b = base_from_world.transform_point(glam::Vec3::new(x as f32, y as f32, z as f32));
            [f64::from(b.x), f64::from(b.y), f64::from(b.z)]
        })
    };
    events::ArmSample {
        mode: arm.mode,
        reach: arm.reach,
        object_base_m: to_base(arm.object_world_m),
        goal_base_m: to_base(arm.goal_world_m),
    }
}
