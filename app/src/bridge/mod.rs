//! What the ROS 1 bridge (`--ros`, app/src/ros/) and the ROS 2 bridge (`--ros2` and
//! `--record-mcap`, app/src/ros2/) share: everything but the wire.
//!
//! - [`RosPlan`] (`plan.rs`): the topic names, frames, rates and moving joints, from the robot's
//!   Gazebo plugins and controllers file.
//! - [`Bridge`] (this file): the [`Observer`] both transports are. On the loop thread it only
//!   copies what the session does into recycled buffers (`capture.rs`) and hands it on as one
//!   [`Event`](events::Event) per callback (`events.rs`); it never waits, unless a recording
//!   asks that nothing be lost. The publishing thread shows each event to every topic family
//!   in turn and sends the buffers back.
//! - The topic families, one file each: `clock.rs`, `odom.rs`, `tf.rs`, `joint_states.rs`,
//!   `camera.rs`, `darknet.rs`, `laser.rs`, `cloud.rs`, `imu.rs`, `p3d.rs`, `gps.rs`, `bumper.rs`, `arm.rs`, `ground_truth.rs`, `status.rs`, `model_states.rs`. A family
//!   decides when and what is published (rates, changes, which frames, drawing the detection
//!   image); its wire trait (`OdomWire`, ...) is what a transport implements to put that on
//!   the wire: ROS 1's encoders in app/src/ros/, ROS 2's in app/src/ros2/. [`Transport`]
//!   makes a family's encoder; [`families`] lists the families once for both.
//! - `input.rs`: what comes in (controller commands, the arm's task) as rover's actions.
//!
//! A new topic: a family file here, its encoder in each transport (a `Transport` method each),
//! and a line in [`families`]; docs/ARCHITECTURE.md walks through `/rover/status`.

pub(crate) mod action_goals;
pub(crate) mod action_intake;
pub(crate) mod arm;
pub(crate) mod bumper;
pub(crate) mod camera;
pub(crate) mod capture;
pub(crate) mod clock;
pub(crate) mod cloud;
pub(crate) mod darknet;
pub(crate) mod events;
pub(crate) mod gps;
pub(crate) mod ground_truth;
pub(crate) mod imu;
pub(crate) mod input;
pub(crate) mod joint_states;
pub(crate) mod laser;
pub(crate) mod model_states;
pub(crate) mod odom;
pub(crate) mod p3d;
pub(crate) mod plan;
pub(crate) mod status;
pub(crate) mod tf;

use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use rover_core::{LoopStats, Observer};
use rover_perception::BoundingBoxes;
use rover_sim::{
    geometry::Pose,
    model::{CameraInfo, RobotModel},
    physics::{ControlSample, Simulation},
    sensors::{
        CameraFrame, ContactsReading, FixReading, GroundTruthBox, ImuReading, LaserScan,
        PointCloud, PoseReading,
    },
};

use events::{BufferPool, BufferReturn, ControlUpdate, Event, Start, TopicFamily};
use plan::MovingJoint;
pub(crate) use plan::RosPlan;

/// Copies the fields named, from `$from` to `$to`: `copy_fields!(msg, info; width, height)` is
/// `msg.width = info.width; msg.height = info.height;`. ROS 1's and ROS 2's messages name
/// their fields as the `.msg` files do, and rover's types mostly do too (camera_info's
/// calibration, a box's corners); the encoders write such a mapping once, here.
macro_rules! copy_fields {
    ($to:expr, $from:expr; $($field:ident),+ $(,)?) => {
        $( $to.$field = $from.$field; )+
    };
}
pub(crate) use copy_fields;

/// A row-major `N` x `N` covariance (`NN` = `N` x `N` entries) with `diagonal` on its diagonal
/// and zeros elsewhere, as gazebo_ros fills odometry's, an IMU's and a fix's.
pub(crate) fn diagonal<const N: usize, const NN: usize>(diagonal: [f64; N]) -> [f64; NN] {
    debug_assert_eq!(N * N, NN, "an N x N covariance has N * N entries");
    let mut c = [0.0; NN];
    for (i, d) in diagonal.into_iter().enumerate() {
        c[i * (N + 1)] = d;
    }
    c
}

/// Makes each family's encoder on one transport (advertising its topics there).
pub(crate) trait Transport {
    /// `/clock`.
    fn clock(&mut self) -> Result<Box<dyn clock::ClockWire>>;
    /// The diff drive's odometry.
    fn odom(&mut self, plan: &RosPlan) -> Result<Box<dyn odom::OdomWire>>;
    /// `/tf` and `/tf_static`.
    fn tf(&mut self) -> Result<Box<dyn tf::TfWire>>;
    /// `/joint_states`.
    fn joint_states(&mut self, plan: &RosPlan) -> Result<Box<dyn joint_states::JointStatesWire>>;
    /// The camera's images and camera_info.
    fn camera(&mut self, plan: &RosPlan) -> Result<Box<dyn camera::CameraWire>>;
    /// darknet_ros's topics.
    fn darknet(&mut self) -> Result<Box<dyn darknet::DarknetWire>>;
    /// The laser's scans.
    fn laser(&mut self, plan: &RosPlan) -> Result<Box<dyn laser::ScanWire>>;
    /// The 3D lidars' and the depth camera's point clouds.
    fn cloud(&mut self, plan: &RosPlan) -> Result<Box<dyn cloud::CloudWire>>;
    /// The IMUs' readings.
    fn imu(&mut self, plan: &RosPlan) -> Result<Box<dyn imu::ImuWire>>;
    /// p3d's ground-truth poses.
    fn p3d(&mut self, plan: &RosPlan) -> Result<Box<dyn p3d::P3dWire>>;
    /// hector's GPS fixes and velocities.
    fn gps(&mut self, plan: &RosPlan) -> Result<Box<dyn gps::GpsWire>>;
    /// The bumpers' contacts.
    fn bumper(&mut self, plan: &RosPlan) -> Result<Box<dyn bumper::BumperWire>>;
    /// The arm's state and points.
    fn arm(&mut self, plan: &RosPlan) -> Result<Box<dyn arm::ArmWire>>;
    /// `/rover/ground_truth/bounding_boxes`.
    fn ground_truth(&mut self) -> Result<Box<dyn darknet::BoxesWire>>;
    /// `/rover/status`.
    fn status(&mut self) -> Result<Box<dyn status::StatusWire>>;
    /// `/gazebo/model_states`.
    fn model_states(&mut self) -> Result<Box<dyn model_states::ModelStatesWire>>;
}

/// The topic families both transports publish, advertised in this order and shown every event
/// in it; the ground truth with `ground_truth` (`--ground-truth`).
pub(crate) fn families(
    transport: &mut dyn Transport,
    plan: &RosPlan,
    ground_truth: bool,
) -> Result<Vec<Box<dyn TopicFamily>>> {
    let mut families: Vec<Box<dyn TopicFamily>> = vec![
        Box::new(clock::Clock::new(transport.clock()?)),
        Box::new(odom::Odom::new(transport.odom(plan)?, plan)),
        Box::new(tf::Tf::new(transport.tf()?, plan)),
        Box::new(joint_states::JointStates::new(
            transport.joint_states(plan)?,
            plan,
        )),
        Box::new(camera::Camera::new(transport.camera(plan)?)),
        Box::new(darknet::Darknet::new(transport.darknet()?)),
        Box::new(laser::Laser::new(transport.laser(plan)?)),
        Box::new(cloud::Clouds::new(transport.cloud(plan)?, plan)),
        Box::new(imu::Imu::new(transport.imu(plan)?)),
        Box::new(p3d::P3d::new(transport.p3d(plan)?)),
        Box::new(gps::Gps::new(transport.gps(plan)?)),
        Box::new(bumper::Bumper::new(transport.bumper(plan)?)),
        Box::new(arm::Arm::new(transport.arm(plan)?)),
        Box::new(status::Status::new(transport.status()?)),
        Box::new(model_states::ModelStates::new(transport.model_states()?)),
    ];
    if ground_truth {
        families.push(Box::new(ground_truth::GroundTruth::new(
            transport.ground_truth()?,
        )));
    }
    Ok(families)
}

/// How a bridge treats a publishing thread that falls behind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Backlog {
    /// Drop the event and count it: the loop never waits (ROS peers).
    Drop,
    /// Wait for the thread: nothing is lost (a recording).
    Wait,
}

/// A bridge's observer half: copies what the session does for its publishing thread. `R` is
/// what the thread hands back when it ends (the recording's summary).
pub(crate) struct Bridge<R: Send + 'static> {
    /// `ROS` or `ROS 2`, for messages.
    label: &'static str,
    tx: Option<SyncSender<Event>>,
    thread: Option<JoinHandle<R>>,
    buffers: BufferPool,
    joints: Vec<MovingJoint>,
    /// The plan's controllers' names, in its order.
    controllers: Vec<String>,
    camera_link: Option<String>,
    backlog: Backlog,
    /// The newest control update's sim time: detector results are published then.
    now_s: f64,
    dropped: u64,
    warned: bool,
    /// Time spent in this observer's callbacks on the loop thread.
    busy: std::time::Duration,
}

impl<R: Send + 'static> std::fmt::Debug for Bridge<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bridge")
            .field("label", &self.label)
            .field("dropped", &self.dropped)
            .finish_non_exhaustive()
    }
}

impl<R: Send + 'static> Bridge<R> {
    /// Starts the publishing thread (named `thread_name`) with `families`; when the bridge
    /// hangs up it runs `finish` on them and hands back what that returns.
    pub fn spawn(
        label: &'static str,
        thread_name: &str,
        plan: &RosPlan,
        robot: &RobotModel,
        backlog: Backlog,
        families: Vec<Box<dyn TopicFamily>>,
        finish: impl FnOnce(Vec<Box<dyn TopicFamily>>) -> R + Send + 'static,
    ) -> Result<Self> {
        let (tx, rx) = sync_channel::<Event>(64);
        let (buffers, returns) = events::buffer_pool();
        let thread = std::thread::Builder::new()
            .name(thread_name.into())
            .spawn(move || finish(publish(families, &returns, &rx)))
            .with_context(|| format!("starting the {label} bridge thread"))?;
        Ok(Self {
            label,
            tx: Some(tx),
            thread: Some(thread),
            buffers,
            joints: plan.joints.clone(),
            controllers: plan
                .controllers
                .iter()
                .map(|c| c.name.clone())
                .chain(plan.grippers.iter().map(|(name, _)| name.clone()))
                .collect(),
            camera_link: robot.cameras.first().map(|c| c.link.clone()),
            backlog,
            now_s: 0.0,
            dropped: 0,
            warned: false,
            busy: std::time::Duration::ZERO,
        })
    }

    /// Events the publishing thread could not take (it was behind).
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Time the bridge took on the loop thread so far (copies and hand-offs).
    pub fn loop_time(&self) -> std::time::Duration {
        self.busy
    }

    /// Lets the thread publish what is queued, stops it, and hands back what it returned
    /// (`None` once finished, or when the thread panicked: said as a warning).
    pub fn finish(&mut self) -> Option<R> {
        self.tx = None;
        let thread = self.thread.take()?;
        match thread.join() {
            Ok(r) => Some(r),
            Err(_) => {
                tracing::warn!("the {} bridge thread panicked", self.label);
                None
            }
        }
    }

    fn send(&mut self, event: Event) {
        let Some(tx) = &self.tx else {
            return;
        };
        let sent = match self.backlog {
            Backlog::Wait => tx.send(event).map_err(|_| ()),
            Backlog::Drop => match tx.try_send(event) {
                Ok(()) => Ok(()),
                Err(TrySendError::Full(_)) => {
                    self.dropped += 1;
                    if !std::mem::replace(&mut self.warned, true) {
                        tracing::warn!(
                            "{} bridge is behind the simulation: dropping messages (the loop never waits for it)",
                            self.label
                        );
                    }
                    Ok(())
                }
                Err(TrySendError::Disconnected(_)) => Err(()),
            },
        };
        if sent.is_err() {
            tracing::warn!(
                "{} bridge thread stopped; the run goes on without it",
                self.label
            );
            self.tx = None;
        }
    }

    /// Runs `f` on the loop thread, its time counted as the bridge's.
    fn timed(&mut self, f: impl FnOnce(&mut Self)) {
        let started = std::time::Instant::now();
        f(self);
        self.busy += started.elapsed();
    }
}

impl<R: Send + 'static> Drop for Bridge<R> {
    fn drop(&mut self) {
        self.finish();
    }
}

impl<R: Send + 'static> Observer for Bridge<R> {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, _labels: &[String]) {
        let static_tf =
            capture::static_transforms(sim.robot(), camera, self.camera_link.as_deref());
        self.send(Event::Start(Start {
            static_tf,
            camera: camera.cloned(),
            model_names: sim.model_state_names(),
        }));
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        self.timed(|b| {
            b.now_s = sample.sim_time_s;
            let mut joints = b.buffers.take_joints();
            capture::joints(sim, sample, &b.joints, &mut joints);
            let mut runs = b.buffers.take_runs();
            capture::runs(sim, &b.controllers, &mut runs);
            let mut models = b.buffers.take_models();
            sim.model_states_into(&mut models);
            b.send(Event::Control(ControlUpdate {
                sample: *sample,
                joints,
                arm: capture::arm(sim, &stats.arm),
                runs,
                models,
            }));
        });
    }

    fn camera_frame(&mut self, frame: &CameraFrame<'_>, _world_from_camera: Pose) {
        self.timed(|b| {
            let depth = if frame.depth_m.is_some() {
                b.buffers.take_pixels()
            } else {
                Vec::new()
            };
            let image = capture::image(frame, b.buffers.take_pixels(), depth);
            b.send(Event::Image(image));
        });
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        self.timed(|b| {
            let detections = capture::detections(boxes, b.now_s, b.buffers.take_boxes());
            b.send(Event::Detections(detections));
        });
    }

    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        self.timed(|b| {
            let truth = capture::ground_truth(boxes, truth, b.now_s, b.buffers.take_boxes());
            b.send(Event::Truth(truth));
        });
    }

    fn laser_scan(&mut self, scan: &LaserScan, _world_from_laser: Pose) {
        self.timed(|b| {
            let scan = capture::scan(scan, b.buffers.take_ranges());
            b.send(Event::Scan(scan));
        });
    }

    fn imu(&mut self, reading: &ImuReading) {
        self.timed(|b| b.send(Event::Imu(*reading)));
    }

    fn p3d(&mut self, reading: &PoseReading) {
        self.timed(|b| b.send(Event::Pose(*reading)));
    }

    fn gps(&mut self, fix: &FixReading) {
        self.timed(|b| b.send(Event::Fix(*fix)));
    }

    fn contacts(&mut self, reading: &ContactsReading) {
        self.timed(|b| b.send(Event::Contacts(reading.clone())));
    }

    fn point_cloud(&mut self, cloud: &PointCloud, _world_from_sensor: Pose) {
        self.timed(|b| {
            let cloud = capture::cloud(cloud, b.buffers.take_pixels());
            b.send(Event::Cloud(cloud));
        });
    }
}

/// The publishing thread: every event to every family, in order, until the bridge hangs up;
/// the buffers each event still holds afterwards go back to the loop thread. The families are
/// handed back for the transport to close.
fn publish(
    mut families: Vec<Box<dyn TopicFamily>>,
    returns: &BufferReturn,
    events: &Receiver<Event>,
) -> Vec<Box<dyn TopicFamily>> {
    for mut event in events {
        for family in &mut families {
            match &mut event {
                Event::Start(start) => family.start(start),
                Event::Control(update) => family.control(update),
                Event::Image(image) => family.image(image),
                Event::Detections(detections) => family.detections(detections),
                Event::Truth(truth) => family.ground_truth(truth),
                Event::Scan(scan) => family.scan(scan),
                Event::Imu(reading) => family.imu(reading),
                Event::Pose(reading) => family.p3d(reading),
                Event::Fix(fix) => family.gps(fix),
                Event::Cloud(cloud) => family.cloud(cloud),
                Event::Contacts(reading) => family.contacts(reading),
            }
        }
        returns.give_back(event);
    }
    families
}
