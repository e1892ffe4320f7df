//! The ROS 1 bridge (`rover --ros`): an adapter at the edge of the loop, like the window and
//! the recorder. As an [`Observer`] it hands what the session does to a publishing thread,
//! under the names Gazebo's plugins and darknet_ros would use for this robot; as an
//! [`InputSource`] it feeds `/cmd_vel` to the session like manual input.
//!
//! The loop thread only copies (into recycled buffers) and never waits: when the publishing
//! thread falls behind, events are dropped and counted. Stamps are sim time.

use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use rover_core::{Action, InputSource, LoopStats, Observer};
use rover_perception::BoundingBoxes;
use rover_ros1::msgs::{self, Header, Quaternion, TransformStamped, Vector3};
use rover_ros1::{Node, NodeOptions, Publisher, Subscriber, Value};
use rover_sim::{
    CameraFrame, CameraInfo, ControlSample, JointKind, LaserScan, ODOM_POSE_COVARIANCE_DIAGONAL,
    Pose, RobotModel, Simulation, Twist, link_from_optical,
};

/// `--ros` settings.
#[derive(Debug, Clone)]
pub struct RosOptions {
    /// Node name (`rover` -> `/rover`).
    pub name: String,
    /// Also set `/use_sim_time` so ROS nodes follow `/clock`.
    pub sim_time: bool,
}

/// darknet_ros's output topics.
pub const BOUNDING_BOXES_TOPIC: &str = "/darknet_ros/bounding_boxes";
/// darknet_ros's per-image object count.
pub const FOUND_OBJECT_TOPIC: &str = "/darknet_ros/found_object";
/// darknet_ros's image with boxes drawn (latched).
pub const DETECTION_IMAGE_TOPIC: &str = "/darknet_ros/detection_image";

/// Images kept for drawing the detection image (detections arrive after their image).
const IMAGE_RING: usize = 4;

/// One wheel's state at a control update.
#[derive(Debug, Clone, Copy)]
struct WheelSample {
    parent_from_child: Pose,
    velocity_radps: f64,
}

enum Event {
    Start {
        static_tf: Vec<TransformStamped>,
        camera: Option<CameraInfo>,
    },
    Control {
        sample: ControlSample,
        wheels: [WheelSample; 2],
    },
    Image {
        stamp_s: f64,
        seq: u64,
        width: u32,
        height: u32,
        pixels: Vec<u8>,
    },
    Boxes {
        stamp_s: f64,
        image_stamp_s: f64,
        image_seq: u64,
        boxes: Vec<msgs::BoundingBox>,
    },
    Scan {
        scan: Box<LaserScanMeta>,
        ranges: Vec<f32>,
    },
}

struct LaserScanMeta {
    stamp_s: f64,
    seq: u64,
    frame_id: String,
    angle_min: f32,
    angle_max: f32,
    angle_increment: f32,
    time_increment: f32,
    scan_time: f32,
    range_min: f32,
    range_max: f32,
}

/// A wheel joint the bridge reports (`/joint_states`, wheel TF).
#[derive(Debug, Clone)]
struct Wheel {
    joint: String,
    parent: usize,
    child: usize,
    parent_link: String,
    child_link: String,
    origin: Pose,
    axis: glam::Vec3,
}

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
    wheels: Vec<Wheel>,
}

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
        let link_name = |i: usize| {
            robot
                .links
                .get(i)
                .map(|l| l.name.clone())
                .unwrap_or_default()
        };
        let wheels = [&drive.left_joint, &drive.right_joint]
            .into_iter()
            .filter_map(|name| robot.joints.iter().find(|j| &j.name == name))
            .map(|j| Wheel {
                joint: j.name.clone(),
                parent: j.parent,
                child: j.child,
                parent_link: link_name(j.parent),
                child_link: link_name(j.child),
                origin: j.parent_from_child,
                axis: j.axis,
            })
            .collect();
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
            wheels,
        }
    }
}

/// `/cmd_vel` as rover input: the newest command since the last poll, as manual input (it
/// takes control from the follower; `--cmd-timeout` applies).
#[derive(Debug)]
pub struct RosCmdVel {
    sub: Subscriber<msgs::Twist>,
}

impl InputSource for RosCmdVel {
    fn poll(&mut self) -> Option<Action> {
        self.sub
            .latest()
            .map(|t| Action::CmdVel(Twist::new(t.linear.x, t.angular.z)))
    }
}

/// The observer half of the bridge.
pub struct RosBridge {
    tx: Option<SyncSender<Event>>,
    recycled_pixels: Receiver<Vec<u8>>,
    recycled_ranges: Receiver<Vec<f32>>,
    recycled_boxes: Receiver<Vec<msgs::BoundingBox>>,
    thread: Option<JoinHandle<()>>,
    wheels: Vec<Wheel>,
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

struct Publishers {
    clock: Publisher<msgs::Clock>,
    odom: Publisher<msgs::Odometry>,
    tf: Publisher<msgs::TfMessage>,
    tf_static: Publisher<msgs::TfMessage>,
    joints: Publisher<msgs::JointState>,
    image: Option<Publisher<msgs::Image>>,
    info: Option<Publisher<msgs::CameraInfo>>,
    boxes: Publisher<msgs::BoundingBoxes>,
    found: Publisher<msgs::ObjectCount>,
    detection_image: Publisher<msgs::Image>,
    scan: Option<Publisher<msgs::LaserScan>>,
}

impl RosBridge {
    /// Starts the node (registering with `ROS_MASTER_URI` as soon as a master answers),
    /// advertises the robot's topics, sets `/robot_description` (and `/use_sim_time`), and
    /// subscribes to its command topic.
    pub fn start(options: &RosOptions, robot: &RobotModel) -> Result<(Self, RosCmdVel)> {
        let node_options = NodeOptions::from_env(&options.name)?;
        let node = Node::start(node_options.clone()).context("starting the ROS node")?;
        let plan = RosPlan::for_robot(robot);
        node.set_param("robot_description", Value::from(robot.description.as_str()))?;
        if options.sim_time {
            node.set_param("use_sim_time", Value::Bool(true))?;
        }
        let publishers = Publishers {
            clock: node.advertise("/clock", 10, false)?,
            odom: node.advertise(&plan.odom_topic, 50, false)?,
            tf: node.advertise("/tf", 100, false)?,
            tf_static: node.advertise("/tf_static", 10, true)?,
            joints: node.advertise("/joint_states", 50, false)?,
            image: plan
                .image_topic
                .as_deref()
                .map(|t| node.advertise(t, 2, false))
                .transpose()?,
            info: plan
                .info_topic
                .as_deref()
                .map(|t| node.advertise(t, 10, false))
                .transpose()?,
            boxes: node.advertise(BOUNDING_BOXES_TOPIC, 10, false)?,
            found: node.advertise(FOUND_OBJECT_TOPIC, 10, false)?,
            detection_image: node.advertise(DETECTION_IMAGE_TOPIC, 2, true)?,
            scan: plan
                .scan_topic
                .as_deref()
                .map(|t| node.advertise(t, 10, false))
                .transpose()?,
        };
        let cmd = RosCmdVel {
            sub: node.subscribe(&plan.cmd_topic, 10)?,
        };
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
        let (pixels_back, recycled_pixels) = sync_channel::<Vec<u8>>(IMAGE_RING + 4);
        let (ranges_back, recycled_ranges) = sync_channel::<Vec<f32>>(4);
        let (boxes_back, recycled_boxes) = sync_channel::<Vec<msgs::BoundingBox>>(4);
        let worker = Worker::new(
            node,
            plan.clone(),
            publishers,
            pixels_back,
            ranges_back,
            boxes_back,
        );
        let thread = std::thread::Builder::new()
            .name("ros-bridge".into())
            .spawn(move || worker.run(rx))
            .context("starting the ROS bridge thread")?;
        Ok((
            Self {
                tx: Some(tx),
                recycled_pixels,
                recycled_ranges,
                recycled_boxes,
                thread: Some(thread),
                wheels: plan.wheels,
                camera_link: robot.cameras.first().map(|c| c.link.clone()),
                now_s: 0.0,
                dropped: 0,
                warned: false,
                busy: std::time::Duration::ZERO,
            },
            cmd,
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

fn vec3(v: glam::Vec3) -> Vector3 {
    Vector3 {
        x: f64::from(v.x),
        y: f64::from(v.y),
        z: f64::from(v.z),
    }
}

fn quat(q: glam::Quat) -> Quaternion {
    Quaternion {
        x: f64::from(q.x),
        y: f64::from(q.y),
        z: f64::from(q.z),
        w: f64::from(q.w),
    }
}

fn transform(parent: &str, child: &str, stamp_s: f64, pose: Pose) -> TransformStamped {
    TransformStamped {
        header: Header {
            seq: 0,
            stamp_s,
            frame_id: parent.to_owned(),
        },
        child_frame_id: child.to_owned(),
        translation: vec3(pose.translation),
        rotation: quat(pose.rotation),
    }
}

impl Observer for RosBridge {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, _labels: &[String]) {
        let robot = sim.robot();
        let mut static_tf: Vec<TransformStamped> = robot
            .joints
            .iter()
            .filter(|j| matches!(j.kind, JointKind::Fixed))
            .filter_map(|j| {
                let parent = robot.links.get(j.parent)?;
                let child = robot.links.get(j.child)?;
                Some(transform(
                    &parent.name,
                    &child.name,
                    0.0,
                    j.parent_from_child,
                ))
            })
            .collect();
        if let (Some(info), Some(link)) = (camera, &self.camera_link) {
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
        self.send(Event::Start {
            static_tf,
            camera: camera.cloned(),
        });
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, _stats: &LoopStats) {
        let started = std::time::Instant::now();
        self.now_s = sample.sim_time_s;
        let mut wheels = [WheelSample {
            parent_from_child: Pose::IDENTITY,
            velocity_radps: 0.0,
        }; 2];
        for (i, (w, out)) in self.wheels.iter().zip(wheels.iter_mut()).enumerate() {
            out.parent_from_child =
                sim.world_from_link(w.parent).inverse() * sim.world_from_link(w.child);
            out.velocity_radps = sample.wheel_measured_radps[i.min(1)];
        }
        self.send(Event::Control {
            sample: *sample,
            wheels,
        });
        self.busy += started.elapsed();
    }

    fn camera_frame(&mut self, frame: &CameraFrame<'_>, _world_from_camera: Pose) {
        let started = std::time::Instant::now();
        let mut pixels = self.recycled_pixels.try_recv().unwrap_or_default();
        pixels.clear();
        pixels.extend_from_slice(frame.rgb);
        self.send(Event::Image {
            stamp_s: frame.sim_time_s,
            seq: frame.seq,
            width: frame.width,
            height: frame.height,
            pixels,
        });
        self.busy += started.elapsed();
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        let started = std::time::Instant::now();
        // Recycled boxes keep their class strings' capacity: no allocation once warm.
        let mut out = self.recycled_boxes.try_recv().unwrap_or_default();
        out.resize_with(boxes.bounding_boxes.len(), msgs::BoundingBox::default);
        for (m, b) in out.iter_mut().zip(&boxes.bounding_boxes) {
            m.probability = b.probability;
            m.xmin = b.xmin;
            m.ymin = b.ymin;
            m.xmax = b.xmax;
            m.ymax = b.ymax;
            m.id = b.id;
            m.class.clone_from(&b.class);
        }
        // Published now, which is never before the image was taken.
        self.send(Event::Boxes {
            stamp_s: self.now_s.max(boxes.image_stamp.sim_time_s),
            image_stamp_s: boxes.image_stamp.sim_time_s,
            image_seq: boxes.image_stamp.frame,
            boxes: out,
        });
        self.busy += started.elapsed();
    }

    fn laser_scan(&mut self, scan: &LaserScan, _world_from_laser: Pose) {
        let started = std::time::Instant::now();
        let mut ranges = self.recycled_ranges.try_recv().unwrap_or_default();
        ranges.clear();
        ranges.extend_from_slice(&scan.ranges_m);
        self.send(Event::Scan {
            scan: Box::new(LaserScanMeta {
                stamp_s: scan.stamp_s,
                seq: scan.seq,
                frame_id: scan.frame_id.clone(),
                angle_min: scan.angle_min_rad,
                angle_max: scan.angle_max_rad,
                angle_increment: scan.angle_increment_rad,
                time_increment: scan.time_increment_s,
                scan_time: scan.scan_time_s,
                range_min: scan.range_min_m,
                range_max: scan.range_max_m,
            }),
            ranges,
        });
        self.busy += started.elapsed();
    }
}

struct Worker {
    node: Node,
    plan: RosPlan,
    publishers: Publishers,
    pixels_back: SyncSender<Vec<u8>>,
    ranges_back: SyncSender<Vec<f32>>,
    boxes_back: SyncSender<Vec<msgs::BoundingBox>>,
    camera: Option<CameraInfo>,
    /// The newest images (seq, stamp, width, height, pixels), for the detection image.
    images: Vec<(u64, f64, u32, u32, Vec<u8>)>,
    // Messages kept from one update to the next: only their numbers change, so steady
    // publishing allocates nothing.
    clock: msgs::Clock,
    odom: msgs::Odometry,
    tf: msgs::TfMessage,
    joints: msgs::JointState,
    info: msgs::CameraInfo,
    image: msgs::Image,
    detection: msgs::Image,
    found: msgs::ObjectCount,
    boxes: msgs::BoundingBoxes,
    scan: msgs::LaserScan,
}

fn covariance(diagonal: [f64; 6]) -> [f64; 36] {
    let mut c = [0.0; 36];
    for (i, d) in diagonal.iter().enumerate() {
        c[i * 7] = *d;
    }
    c
}

fn header(frame_id: &str) -> Header {
    Header {
        seq: 0,
        stamp_s: 0.0,
        frame_id: frame_id.to_owned(),
    }
}

/// A per-topic sequence number, as roscpp and rospy set `header.seq`: messages published so far.
fn seq_of<T: rover_ros1::Message>(p: &Publisher<T>) -> u32 {
    p.published() as u32
}

impl Worker {
    fn new(
        node: Node,
        plan: RosPlan,
        publishers: Publishers,
        pixels_back: SyncSender<Vec<u8>>,
        ranges_back: SyncSender<Vec<f32>>,
        boxes_back: SyncSender<Vec<msgs::BoundingBox>>,
    ) -> Self {
        let cov = covariance(ODOM_POSE_COVARIANCE_DIAGONAL);
        let odom = msgs::Odometry {
            header: header(&plan.odom_frame),
            child_frame_id: plan.base_frame.clone(),
            position: Vector3::default(),
            orientation: Quaternion::default(),
            pose_covariance: cov,
            linear: Vector3::default(),
            angular: Vector3::default(),
            twist_covariance: cov,
        };
        let mut transforms = Vec::new();
        if plan.odom_tf {
            transforms.push(transform(
                &plan.odom_frame,
                &plan.base_frame,
                0.0,
                Pose::IDENTITY,
            ));
        }
        if plan.wheel_tf {
            for w in &plan.wheels {
                transforms.push(transform(&w.parent_link, &w.child_link, 0.0, w.origin));
            }
        }
        let joints = msgs::JointState {
            header: header(""),
            name: plan.wheels.iter().map(|w| w.joint.clone()).collect(),
            ..msgs::JointState::default()
        };
        Self {
            node,
            plan,
            publishers,
            pixels_back,
            ranges_back,
            boxes_back,
            camera: None,
            images: Vec::with_capacity(IMAGE_RING),
            clock: msgs::Clock::default(),
            odom,
            tf: msgs::TfMessage { transforms },
            joints,
            info: msgs::CameraInfo::default(),
            image: msgs::Image {
                encoding: "rgb8".into(),
                ..msgs::Image::default()
            },
            detection: msgs::Image {
                encoding: "rgb8".into(),
                ..msgs::Image::default()
            },
            found: msgs::ObjectCount {
                header: header("detection"),
                count: 0,
            },
            boxes: msgs::BoundingBoxes {
                header: header("detection"),
                ..msgs::BoundingBoxes::default()
            },
            scan: msgs::LaserScan::default(),
        }
    }

    fn run(mut self, rx: Receiver<Event>) {
        for event in rx {
            match event {
                Event::Start { static_tf, camera } => self.start(static_tf, camera),
                Event::Control { sample, wheels } => self.control(&sample, &wheels),
                Event::Image {
                    stamp_s,
                    seq,
                    width,
                    height,
                    pixels,
                } => self.image(stamp_s, seq, width, height, pixels),
                Event::Boxes {
                    stamp_s,
                    image_stamp_s,
                    image_seq,
                    boxes,
                } => self.boxes(stamp_s, image_stamp_s, image_seq, boxes),
                Event::Scan { scan, ranges } => self.scan(&scan, ranges),
            }
        }
        drop(self.node);
    }

    fn start(&mut self, static_tf: Vec<TransformStamped>, camera: Option<CameraInfo>) {
        self.publishers.tf_static.publish(&msgs::TfMessage {
            transforms: static_tf,
        });
        if let Some(c) = &camera {
            self.info = msgs::CameraInfo {
                header: header(&c.frame_id),
                height: c.height,
                width: c.width,
                distortion_model: c.distortion_model.to_owned(),
                d: c.d.to_vec(),
                k: c.k,
                r: c.r,
                p: c.p,
            };
            self.image.header.frame_id = c.frame_id.clone();
            self.boxes.image_header.frame_id = c.frame_id.clone();
        }
        self.camera = camera;
    }

    fn control(&mut self, sample: &ControlSample, wheels: &[WheelSample; 2]) {
        let t = sample.sim_time_s;
        let o = sample.odometry;
        let p = &mut self.publishers;
        self.clock.clock_s = t;
        p.clock.publish(&self.clock);
        let orientation = Quaternion::from_yaw(o.yaw_rad);
        let position = Vector3 {
            x: o.x_m,
            y: o.y_m,
            z: 0.0,
        };
        let odom = &mut self.odom;
        odom.header.seq = seq_of(&p.odom);
        odom.header.stamp_s = t;
        odom.position = position;
        odom.orientation = orientation;
        odom.linear.x = o.linear_mps;
        odom.angular.z = o.angular_radps;
        p.odom.publish(odom);

        let mut next = self.tf.transforms.iter_mut();
        if self.plan.odom_tf
            && let Some(tr) = next.next()
        {
            tr.header.stamp_s = t;
            tr.translation = position;
            tr.rotation = orientation;
        }
        self.joints.position.clear();
        self.joints.velocity.clear();
        for (w, s) in self.plan.wheels.iter().zip(wheels) {
            if self.plan.wheel_tf
                && let Some(tr) = next.next()
            {
                tr.header.stamp_s = t;
                tr.translation = vec3(s.parent_from_child.translation);
                tr.rotation = quat(s.parent_from_child.rotation);
            }
            // The joint angle: the rotation since the joint's rest pose, about its axis.
            let rel = w.origin.rotation.inverse() * s.parent_from_child.rotation;
            let along = glam::Vec3::new(rel.x, rel.y, rel.z).dot(w.axis);
            self.joints
                .position
                .push(2.0 * f64::from(along).atan2(f64::from(rel.w)));
            self.joints.velocity.push(s.velocity_radps);
        }
        if !self.tf.transforms.is_empty() {
            p.tf.publish(&self.tf);
        }
        if !self.joints.name.is_empty() {
            self.joints.header.seq = seq_of(&p.joints);
            self.joints.header.stamp_s = t;
            p.joints.publish(&self.joints);
        }
    }

    fn image(&mut self, stamp_s: f64, seq: u64, width: u32, height: u32, pixels: Vec<u8>) {
        // The camera's frame number, which the boxes' image_header names too.
        let seq = seq as u32;
        if self.camera.is_some()
            && let Some(p) = self.publishers.info.as_mut()
        {
            self.info.header.seq = seq;
            self.info.header.stamp_s = stamp_s;
            p.publish(&self.info);
        }
        let msg = &mut self.image;
        msg.header.seq = seq;
        msg.header.stamp_s = stamp_s;
        msg.width = width;
        msg.height = height;
        msg.step = width * 3;
        msg.data = pixels;
        if let Some(p) = self.publishers.image.as_mut() {
            p.publish(msg);
        }
        let pixels = std::mem::take(&mut msg.data);
        if self.images.len() >= IMAGE_RING {
            let (_, _, _, _, old) = self.images.remove(0);
            let _ = self.pixels_back.try_send(old);
        }
        self.images
            .push((seq.into(), stamp_s, width, height, pixels));
    }

    fn boxes(
        &mut self,
        stamp_s: f64,
        image_stamp_s: f64,
        image_seq: u64,
        mut boxes: Vec<msgs::BoundingBox>,
    ) {
        let p = &mut self.publishers;
        self.found.header.seq = seq_of(&p.found);
        self.found.header.stamp_s = stamp_s;
        self.found.count = i8::try_from(boxes.len()).unwrap_or(i8::MAX);
        p.found.publish(&self.found);

        let out = &mut self.boxes;
        out.header.seq = seq_of(&p.boxes);
        out.header.stamp_s = stamp_s;
        out.image_header.seq = image_seq as u32;
        out.image_header.stamp_s = image_stamp_s;
        // The new boxes go in; the previous ones go back to the loop thread for reuse.
        std::mem::swap(&mut out.bounding_boxes, &mut boxes);
        if !out.bounding_boxes.is_empty() {
            p.boxes.publish(out);
        }
        if let Some((_, _, width, height, pixels)) =
            self.images.iter().find(|(seq, ..)| *seq == image_seq)
        {
            let d = &mut self.detection;
            d.header.clone_from(&out.image_header);
            d.width = *width;
            d.height = *height;
            d.step = width * 3;
            d.data.clear();
            d.data.extend_from_slice(pixels);
            for b in &out.bounding_boxes {
                draw_box(&mut d.data, *width, *height, b);
            }
            p.detection_image.publish(d);
        }
        let _ = self.boxes_back.try_send(boxes);
    }

    fn scan(&mut self, meta: &LaserScanMeta, ranges: Vec<f32>) {
        let Some(p) = self.publishers.scan.as_mut() else {
            return;
        };
        let msg = &mut self.scan;
        msg.header.seq = meta.seq as u32;
        msg.header.stamp_s = meta.stamp_s;
        if msg.header.frame_id != meta.frame_id {
            msg.header.frame_id = meta.frame_id.clone();
        }
        msg.angle_min = meta.angle_min;
        msg.angle_max = meta.angle_max;
        msg.angle_increment = meta.angle_increment;
        msg.time_increment = meta.time_increment;
        msg.scan_time = meta.scan_time;
        msg.range_min = meta.range_min;
        msg.range_max = meta.range_max;
        msg.ranges = ranges;
        p.publish(msg);
        let _ = self.ranges_back.try_send(std::mem::take(&mut msg.ranges));
    }
}

/// A 2-px rectangle in the class colour, as darknet_ros draws its detection image.
fn draw_box(rgb: &mut [u8], width: u32, height: u32, b: &msgs::BoundingBox) {
    let (w, h) = (i64::from(width), i64::from(height));
    if w == 0 || h == 0 {
        return;
    }
    let colour = crate::palette::class_color(b.id).0;
    let x0 = b.xmin.clamp(0, w - 1);
    let x1 = b.xmax.clamp(0, w - 1);
    let y0 = b.ymin.clamp(0, h - 1);
    let y1 = b.ymax.clamp(0, h - 1);
    let mut put = |x: i64, y: i64| {
        let i = ((y * w + x) * 3) as usize;
        if let Some(px) = rgb.get_mut(i..i + 3) {
            px.copy_from_slice(&colour);
        }
    };
    for t in 0..2 {
        for x in x0..=x1 {
            put(x, (y0 + t).min(h - 1));
            put(x, (y1 - t).max(0));
        }
        for y in y0..=y1 {
            put((x0 + t).min(w - 1), y);
            put((x1 - t).max(0), y);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tutorial_car_gets_gazebos_topic_names() -> Result<()> {
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
        let joints: Vec<&str> = plan.wheels.iter().map(|w| w.joint.as_str()).collect();
        assert_eq!(joints, ["left_wheel_joint", "right_wheel_joint"]);
        Ok(())
    }

    #[test]
    fn boxes_are_drawn_inside_the_image() {
        let (w, h) = (8u32, 6u32);
        let mut rgb = vec![0u8; (w * h * 3) as usize];
        draw_box(
            &mut rgb,
            w,
            h,
            &msgs::BoundingBox {
                xmin: -5,
                ymin: 1,
                xmax: 100,
                ymax: 4,
                ..msgs::BoundingBox::default()
            },
        );
        let lit = |x: u32, y: u32| rgb[((y * w + x) * 3) as usize..][..3] != [0, 0, 0];
        assert!(lit(0, 1) && lit(7, 4) && lit(3, 1));
        assert!(!lit(3, 0) && !lit(3, 5));
    }
}
