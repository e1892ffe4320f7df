//! The ROS 2 bridge's writers, one per topic, and the messages they fill: on the publishing
//! thread. Names, frames and joints come from the ROS 1 bridge's plan ([`RosPlan`]); stamps
//! are sim time.

use anyhow::Result;
use rover_sim::{ControlSample, LaserScan, ODOM_POSE_COVARIANCE_DIAGONAL, Pose};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{DomainParticipant, GUID, QosPolicies, QosPolicyBuilder, RTPSEntity};

use super::dds::{Writer, default_qos, writer};
use super::mcap::{McapRecorder, McapSummary};
use super::msgs::{self, Covariance, Header, Lent, RosMessage, Time};
use crate::ros::RosPlan;
use crate::ros::shared::{
    ArmSample, BOUNDING_BOXES_TOPIC, DETECTION_IMAGE_TOPIC, DetectionImages, Detections,
    FOUND_OBJECT_TOPIC, ImageFrame, JointSample, joints_on_tf, odom_pose,
};
use rover_core::{ArmMode, ReachState};

/// Where robot_state_publisher keeps the URDF in ROS 2.
const ROBOT_DESCRIPTION_TOPIC: &str = "/robot_description";
/// The arm's task and reach state (`off`, `look`, `reach <state>`), on every change.
const ARM_STATE_TOPIC: &str = "/rover/arm/state";
/// The object reach goes for, in the base frame.
const ARM_OBJECT_TOPIC: &str = "/rover/arm/object";
/// The pre-grasp point the tool is sent to, in the base frame.
const ARM_GOAL_TOPIC: &str = "/rover/arm/goal";

/// `/tf_static`'s QoS: reliable, transient local, keep last 1 (tf2's static broadcaster): a
/// late joiner gets it.
fn latched_qos() -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_millis(100),
        })
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1 })
        .build()
}

/// rclcpp's SensorDataQoS: best effort, volatile, keep last 5 (images, scans).
fn sensor_qos() -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(Reliability::BestEffort)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 5 })
        .build()
}

/// A 6x6 covariance with `diagonal` on its diagonal.
fn covariance(diagonal: [f64; 6]) -> Covariance {
    let mut c = [0.0; 36];
    for (i, d) in diagonal.iter().enumerate() {
        c[i * 7] = *d;
    }
    Covariance(c)
}

fn header(frame_id: &str) -> Header {
    Header {
        stamp: Time::default(),
        frame_id: frame_id.to_owned(),
    }
}

/// A pose as a geometry_msgs Transform.
fn transform_of(pose: Pose) -> msgs::Transform {
    let (t, r) = (pose.translation, pose.rotation);
    msgs::Transform {
        translation: msgs::Vector3 {
            x: f64::from(t.x),
            y: f64::from(t.y),
            z: f64::from(t.z),
        },
        rotation: msgs::Quaternion {
            x: f64::from(r.x),
            y: f64::from(r.y),
            z: f64::from(r.z),
            w: f64::from(r.w),
        },
    }
}

fn transform(parent: &str, child: &str, pose: Pose) -> msgs::TransformStamped {
    msgs::TransformStamped {
        header: header(parent),
        child_frame_id: child.to_owned(),
        transform: transform_of(pose),
    }
}

/// Where one topic's messages go: its DDS writer (`--ros2`) and its MCAP channel
/// (`--record-mcap`), either or both.
struct Out<M: RosMessage> {
    dds: Option<Writer<M>>,
    channel: Option<u16>,
}

/// What the topics are created on.
pub(super) struct Sinks<'a> {
    /// The DDS participant and its publisher, with `--ros2`.
    pub dds: Option<(&'a DomainParticipant, &'a rustdds::Publisher)>,
    /// The MCAP file, with `--record-mcap`.
    pub mcap: Option<McapRecorder>,
    /// The DDS writers made so far (for `ros_discovery_info`).
    pub writers: Vec<GUID>,
}

impl Sinks<'_> {
    /// The topic `ros_name` of messages `M` on every sink, with `qos` on DDS.
    fn out<M: RosMessage>(&mut self, ros_name: &str, qos: &QosPolicies) -> Result<Out<M>> {
        Ok(Out {
            dds: match self.dds {
                Some((participant, publisher)) => {
                    let w = writer(participant, publisher, ros_name, qos)?;
                    self.writers.push(w.guid());
                    Some(w)
                }
                None => None,
            },
            channel: match &mut self.mcap {
                Some(mcap) => Some(mcap.channel::<M>(ros_name)?),
                None => None,
            },
        })
    }
}

/// Puts `msg`, stamped `stamp`, on `out`'s sinks: into the MCAP file, then to DDS (RustDDS
/// takes what it writes, so DDS gets a copy).
fn put<M: RosMessage + Clone>(out: &Out<M>, mcap: &mut Option<McapRecorder>, stamp: Time, msg: &M) {
    if let (Some(file), Some(channel)) = (mcap.as_mut(), out.channel) {
        file.write(channel, stamp, msg);
    }
    if let Some(w) = &out.dds {
        let _ = w.write(msg.clone(), None);
    }
}

/// Puts `data` (`encoding`, `(width, height)`) on `out` as an Image with `header`: lent to
/// the message, back in `data` once it is written.
fn put_image(
    out: &Out<msgs::Image>,
    mcap: &mut Option<McapRecorder>,
    header: &Header,
    (width, height): (u32, u32),
    encoding: &str,
    data: &mut Vec<u8>,
) {
    let bytes_per_px = if encoding == "32FC1" { 4 } else { 3 };
    let lent = Lent::new(std::mem::take(data));
    let msg = msgs::Image {
        header: header.clone(),
        height,
        width,
        encoding: encoding.to_owned(),
        is_bigendian: 0,
        step: width * bytes_per_px,
        data: lent.clone(),
    };
    put(out, mcap, header.stamp, &msg);
    drop(msg);
    // A buffer still held elsewhere is let go; the pool makes a new one.
    *data = lent.take_back().unwrap_or_default();
}

/// The topics and the messages they reuse.
pub(super) struct Topics {
    mcap: Option<McapRecorder>,
    /// The DDS writers' GUIDs (none without DDS).
    writer_gids: Vec<GUID>,
    /// Kept for late joiners (transient local): written once, at creation.
    _robot_description: Out<msgs::Text>,
    clock: Out<msgs::Clock>,
    odom: Out<msgs::Odometry>,
    tf: Out<msgs::TfMessage>,
    tf_static: Out<msgs::TfMessage>,
    joint_states: Out<msgs::JointState>,
    image: Option<(Out<msgs::Image>, Out<msgs::CameraInfo>)>,
    /// A depth camera's depth image and camera_info.
    depth: Option<(Out<msgs::Image>, Out<msgs::CameraInfo>)>,
    scan: Option<Out<msgs::LaserScan>>,
    boxes: Out<msgs::BoundingBoxes>,
    found: Out<msgs::ObjectCount>,
    detection_image: Out<msgs::Image>,
    /// The newest images, for the detection image.
    detection_images: DetectionImages,
    /// The detection image's pixels, reused.
    detection_pixels: Vec<u8>,
    arm_state: Out<msgs::Text>,
    arm_object: Out<msgs::PointStamped>,
    arm_goal: Out<msgs::PointStamped>,
    odom_msg: msgs::Odometry,
    /// odom -> base (with `publishOdomTF`), then the moving joints' links.
    tf_msg: msgs::TfMessage,
    odom_tf: bool,
    /// Indices (plan joints) of the joints whose links go on `/tf`, in `tf_msg` order.
    joints_on_tf: Vec<usize>,
    joints_msg: msgs::JointState,
    info_msg: Option<msgs::CameraInfo>,
    boxes_msg: msgs::BoundingBoxes,
    found_msg: msgs::ObjectCount,
    arm_text: msgs::Text,
    arm_point: msgs::PointStamped,
    /// The arm's task and reach state last published.
    arm_last: Option<(ArmMode, ReachState)>,
}

impl Topics {
    /// The robot's topics on `sinks`; `/robot_description` (the URDF, transient local, as
    /// robot_state_publisher keeps it) goes out at once.
    pub(super) fn create(mut sinks: Sinks<'_>, plan: &RosPlan, description: &str) -> Result<Self> {
        let qos = default_qos();
        let robot_description: Out<msgs::Text> =
            sinks.out(ROBOT_DESCRIPTION_TOPIC, &latched_qos())?;
        let msg = msgs::Text {
            data: description.to_owned(),
        };
        put(&robot_description, &mut sinks.mcap, Time::default(), &msg);
        let cov = covariance(ODOM_POSE_COVARIANCE_DIAGONAL);
        let mut odom_msg = msgs::Odometry {
            header: header(&plan.odom_frame),
            child_frame_id: plan.base_frame.clone(),
            ..msgs::Odometry::default()
        };
        odom_msg.pose.covariance = cov;
        odom_msg.twist.covariance = cov;
        let mut transforms = Vec::new();
        if plan.odom_tf {
            let odom = &plan.odom_frame;
            transforms.push(transform(odom, &plan.base_frame, Pose::IDENTITY));
        }
        let joints_on_tf = joints_on_tf(plan);
        transforms.extend(joints_on_tf.iter().map(|&i| {
            let j = &plan.joints[i];
            transform(&j.parent_link, &j.child_link, j.parent_from_child_at_rest)
        }));
        let sensor = sensor_qos();
        let image = match (&plan.image_topic, &plan.info_topic) {
            (Some(image), Some(info)) => {
                Some((sinks.out(image, &sensor)?, sinks.out(info, &sensor)?))
            }
            _ => None,
        };
        let depth = match (&plan.depth_image_topic, &plan.depth_info_topic) {
            (Some(image), Some(info)) => {
                Some((sinks.out(image, &sensor)?, sinks.out(info, &sensor)?))
            }
            _ => None,
        };
        let scan = match &plan.scan_topic {
            Some(topic) => Some(sinks.out(topic, &sensor)?),
            None => None,
        };
        Ok(Self {
            clock: sinks.out("/clock", &qos)?,
            odom: sinks.out(&plan.odom_topic, &qos)?,
            tf: sinks.out("/tf", &qos)?,
            tf_static: sinks.out("/tf_static", &latched_qos())?,
            joint_states: sinks.out("/joint_states", &qos)?,
            image,
            depth,
            scan,
            boxes: sinks.out(BOUNDING_BOXES_TOPIC, &qos)?,
            found: sinks.out(FOUND_OBJECT_TOPIC, &qos)?,
            detection_image: sinks.out(DETECTION_IMAGE_TOPIC, &latched_qos())?,
            detection_images: DetectionImages::default(),
            detection_pixels: Vec::new(),
            _robot_description: robot_description,
            arm_state: sinks.out(ARM_STATE_TOPIC, &latched_qos())?,
            arm_object: sinks.out(ARM_OBJECT_TOPIC, &qos)?,
            arm_goal: sinks.out(ARM_GOAL_TOPIC, &qos)?,
            mcap: sinks.mcap,
            odom_msg,
            tf_msg: msgs::TfMessage { transforms },
            odom_tf: plan.odom_tf,
            joints_on_tf,
            joints_msg: msgs::JointState {
                header: Header::default(),
                name: plan.joints.iter().map(|j| j.name.clone()).collect(),
                ..msgs::JointState::default()
            },
            info_msg: None,
            boxes_msg: msgs::BoundingBoxes {
                header: header("detection"),
                ..msgs::BoundingBoxes::default()
            },
            found_msg: msgs::ObjectCount {
                header: header("detection"),
                count: 0,
            },
            arm_text: msgs::Text::default(),
            arm_point: msgs::PointStamped {
                header: header(&plan.base_frame),
                ..msgs::PointStamped::default()
            },
            arm_last: None,
            writer_gids: std::mem::take(&mut sinks.writers),
        })
    }

    /// The DDS writers' GUIDs, for `ros_discovery_info`.
    pub(super) fn writer_gids(&self) -> &[GUID] {
        &self.writer_gids
    }

    /// Closes the MCAP file, if one is written: what it holds.
    pub(super) fn finish(self) -> Option<Result<McapSummary>> {
        self.mcap.map(McapRecorder::finish)
    }

    /// The run starts: `/tf_static` once (kept for late joiners), the camera's calibration.
    pub(super) fn start(
        &mut self,
        static_tf: &[rover_ros1::msgs::TransformStamped],
        camera: Option<&rover_sim::CameraInfo>,
    ) {
        let transforms = static_tf
            .iter()
            .map(|t| msgs::TransformStamped {
                header: header(&t.header.frame_id),
                child_frame_id: t.child_frame_id.clone(),
                transform: msgs::Transform {
                    translation: msgs::Vector3 {
                        x: t.translation.x,
                        y: t.translation.y,
                        z: t.translation.z,
                    },
                    rotation: msgs::Quaternion {
                        x: t.rotation.x,
                        y: t.rotation.y,
                        z: t.rotation.z,
                        w: t.rotation.w,
                    },
                },
            })
            .collect();
        let msg = msgs::TfMessage { transforms };
        put(&self.tf_static, &mut self.mcap, Time::default(), &msg);
        if let Some(c) = camera {
            self.boxes_msg.image_header.frame_id.clone_from(&c.frame_id);
        }
        self.info_msg = camera.map(|c| msgs::CameraInfo {
            header: header(&c.frame_id),
            height: c.height,
            width: c.width,
            distortion_model: c.distortion_model.to_owned(),
            d: c.d.to_vec(),
            k: c.k,
            r: c.r,
            p: c.p,
            ..msgs::CameraInfo::default()
        });
    }

    /// A control update: `/clock`, odometry, `/tf`, `/joint_states`.
    pub(super) fn control(&mut self, sample: &ControlSample, joints: &[JointSample]) {
        let stamp = Time::from_secs(sample.sim_time_s);
        let o = sample.odometry;
        let ([x, y, z], [qx, qy, qz, qw]) = odom_pose(sample);
        put(
            &self.clock,
            &mut self.mcap,
            stamp,
            &msgs::Clock { clock: stamp },
        );
        let msg = &mut self.odom_msg;
        msg.header.stamp = stamp;
        msg.pose.pose.position = msgs::Vector3 { x, y, z };
        msg.pose.pose.orientation = msgs::Quaternion {
            x: qx,
            y: qy,
            z: qz,
            w: qw,
        };
        msg.twist.twist.linear.x = o.linear_mps;
        msg.twist.twist.angular.z = o.angular_radps;
        put(&self.odom, &mut self.mcap, stamp, msg);
        let first_joint = usize::from(self.odom_tf);
        if let Some(t) = self.tf_msg.transforms.first_mut().filter(|_| self.odom_tf) {
            t.transform.translation = msg.pose.pose.position;
            t.transform.rotation = msg.pose.pose.orientation;
        }
        for (t, &i) in self.tf_msg.transforms[first_joint..]
            .iter_mut()
            .zip(&self.joints_on_tf)
        {
            if let Some(j) = joints.get(i) {
                t.transform = transform_of(j.parent_from_child);
            }
        }
        for t in &mut self.tf_msg.transforms {
            t.header.stamp = stamp;
        }
        if !self.tf_msg.transforms.is_empty() {
            put(&self.tf, &mut self.mcap, stamp, &self.tf_msg);
        }
        let js = &mut self.joints_msg;
        js.header.stamp = stamp;
        js.position.clear();
        js.position.extend(joints.iter().map(|j| j.position));
        js.velocity.clear();
        js.velocity.extend(joints.iter().map(|j| j.velocity_radps));
        js.effort.clear();
        js.effort.extend(joints.iter().map(|j| j.effort));
        if !js.name.is_empty() {
            put(&self.joint_states, &mut self.mcap, stamp, js);
        }
    }

    /// A camera image (RGB8) and its camera_info with the image's stamp; a depth camera's
    /// depth image (32FC1) and camera_info too. The frame's buffers are lent to the messages
    /// and stay with the frame.
    pub(super) fn image(&mut self, frame: &mut ImageFrame) {
        let Some(info_msg) = &mut self.info_msg else {
            return;
        };
        let stamp = Time::from_secs(frame.stamp_s);
        info_msg.header.stamp = stamp;
        let size = (frame.width, frame.height);
        if let Some((image, info)) = &self.image {
            put(info, &mut self.mcap, stamp, info_msg);
            let pixels = &mut frame.pixels;
            put_image(
                image,
                &mut self.mcap,
                &info_msg.header,
                size,
                "rgb8",
                pixels,
            );
        }
        if let (Some((image, info)), false) = (&self.depth, frame.depth.is_empty()) {
            put(info, &mut self.mcap, stamp, info_msg);
            let depth = &mut frame.depth;
            put_image(
                image,
                &mut self.mcap,
                &info_msg.header,
                size,
                "32FC1",
                depth,
            );
        }
        // Kept for the detection image; an older buffer takes its place in the frame.
        self.detection_images.keep(frame);
    }

    /// A laser scan; its ranges' buffer back, for the next scan.
    pub(super) fn scan(&mut self, scan: LaserScan) -> Option<Vec<f32>> {
        let Some(writer) = &self.scan else {
            return Some(scan.ranges_m);
        };
        let ranges = Lent::new(scan.ranges_m);
        let msg = msgs::LaserScan {
            header: Header {
                stamp: Time::from_secs(scan.stamp_s),
                frame_id: scan.frame_id,
            },
            angle_min: scan.angle_min_rad,
            angle_max: scan.angle_max_rad,
            angle_increment: scan.angle_increment_rad,
            time_increment: scan.time_increment_s,
            scan_time: scan.scan_time_s,
            range_min: scan.range_min_m,
            range_max: scan.range_max_m,
            ranges: ranges.clone(),
            intensities: Vec::new(),
        };
        put(writer, &mut self.mcap, msg.header.stamp, &msg);
        drop(msg);
        ranges.take_back()
    }

    /// darknet_ros's topics for one detector result: `found_object` and `detection_image` (the
    /// boxes drawn on their image, transient local as darknet_ros latches it) always,
    /// `bounding_boxes` when there are boxes. Class strings keep their capacity.
    pub(super) fn detections(&mut self, d: &Detections) {
        let stamp = Time::from_secs(d.stamp_s);
        self.found_msg.header.stamp = stamp;
        self.found_msg.count = i8::try_from(d.boxes.len()).unwrap_or(i8::MAX);
        put(&self.found, &mut self.mcap, stamp, &self.found_msg);
        let out = &mut self.boxes_msg;
        out.header.stamp = stamp;
        out.image_header.stamp = Time::from_secs(d.image_stamp_s);
        out.bounding_boxes
            .resize_with(d.boxes.len(), msgs::BoundingBox::default);
        for (m, b) in out.bounding_boxes.iter_mut().zip(&d.boxes) {
            m.probability = b.probability;
            m.xmin = b.xmin;
            m.ymin = b.ymin;
            m.xmax = b.xmax;
            m.ymax = b.ymax;
            m.id = b.id;
            m.class_id.clone_from(&b.class);
        }
        if !d.boxes.is_empty() {
            put(&self.boxes, &mut self.mcap, stamp, out);
        }
        let pixels = &mut self.detection_pixels;
        if let Some(size) = self.detection_images.draw(d.image_seq, &d.boxes, pixels) {
            let header = &self.boxes_msg.image_header;
            put_image(
                &self.detection_image,
                &mut self.mcap,
                header,
                size,
                "rgb8",
                pixels,
            );
        }
    }

    /// The arm's topics at a control update: its state on every change; with reach on, the
    /// object and goal points it has.
    pub(super) fn arm(&mut self, sim_time_s: f64, arm: &ArmSample) {
        let stamp = Time::from_secs(sim_time_s);
        if self.arm_last != Some((arm.mode, arm.reach)) {
            self.arm_last = Some((arm.mode, arm.reach));
            let text = &mut self.arm_text.data;
            text.clear();
            text.push_str(arm.mode.as_str());
            if arm.mode == ArmMode::Reach {
                text.push(' ');
                text.push_str(arm.reach.as_str());
            }
            put(&self.arm_state, &mut self.mcap, stamp, &self.arm_text);
        }
        if arm.mode != ArmMode::Reach {
            return;
        }
        self.arm_point.header.stamp = stamp;
        for (out, p) in [
            (&self.arm_object, arm.object_base_m),
            (&self.arm_goal, arm.goal_base_m),
        ] {
            if let Some([x, y, z]) = p {
                self.arm_point.point = msgs::Vector3 { x, y, z };
                put(out, &mut self.mcap, stamp, &self.arm_point);
            }
        }
    }
}
