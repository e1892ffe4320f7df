//! The messages rover publishes and subscribes. Big payloads (images, scans) are plain `Vec`s
//! the caller can move in and take back, so steady publishing reuses them.

use crate::error::Result;
use crate::msg::{Decode, Message, Reader, wire};

mod actions;

pub use actions::{
    FollowJointTrajectoryActionFeedback, FollowJointTrajectoryActionGoal,
    FollowJointTrajectoryActionResult, FollowJointTrajectoryFeedback, FollowJointTrajectoryGoal,
    FollowJointTrajectoryResult, GoalId, GoalStatus, GoalStatusArray, GripperCommand,
    GripperCommandActionFeedback, GripperCommandActionGoal, GripperCommandActionResult,
    GripperCommandResult, JointTolerance,
};

/// `std_msgs/Header`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Header {
    /// Sequence number.
    pub seq: u32,
    /// Stamp (s).
    pub stamp_s: f64,
    /// Frame id.
    pub frame_id: String,
}

impl Header {
    fn encode(&self, out: &mut Vec<u8>) {
        wire::u32(out, self.seq);
        wire::time(out, self.stamp_s);
        wire::string(out, &self.frame_id);
    }
    fn decode(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            seq: r.u32()?,
            stamp_s: r.time_s(false)?,
            frame_id: r.string()?,
        })
    }
}

rover_msgs::wire_messages!(Header, Vec<u8>, Vec<f32>);

/// The geometry types' fields in ROS 1's serialization (they are written in `rover-msgs`).
trait Geometry: Sized {
    fn encode(&self, out: &mut Vec<u8>);
    fn decode(r: &mut Reader<'_>) -> Result<Self>;
}

impl Geometry for Vector3 {
    fn encode(&self, out: &mut Vec<u8>) {
        wire::f64_fixed(out, &[self.x, self.y, self.z]);
    }
    fn decode(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            x: r.f64()?,
            y: r.f64()?,
            z: r.f64()?,
        })
    }
}

impl Geometry for Quaternion {
    fn encode(&self, out: &mut Vec<u8>) {
        wire::f64_fixed(out, &[self.x, self.y, self.z, self.w]);
    }
    fn decode(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            x: r.f64()?,
            y: r.f64()?,
            z: r.f64()?,
            w: r.f64()?,
        })
    }
}

impl Geometry for Pose {
    fn encode(&self, out: &mut Vec<u8>) {
        self.position.encode(out);
        self.orientation.encode(out);
    }
    fn decode(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            position: Vector3::decode(r)?,
            orientation: Quaternion::decode(r)?,
        })
    }
}

impl Message for Twist {
    const TYPE: &'static str = "geometry_msgs/Twist";
    fn encode(&self, out: &mut Vec<u8>) {
        Geometry::encode(&self.linear, out);
        Geometry::encode(&self.angular, out);
    }
}

impl Decode for Twist {
    fn decode(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes);
        Ok(Self {
            linear: Vector3::decode(&mut r)?,
            angular: Vector3::decode(&mut r)?,
        })
    }
}

impl Message for TwistStamped {
    const TYPE: &'static str = "geometry_msgs/TwistStamped";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        Message::encode(&self.twist, out);
    }
}

impl Decode for TwistStamped {
    fn decode(bytes: &[u8]) -> Result<Self> {
        let mut r = Reader::new(bytes);
        Ok(Self {
            header: Header::decode(&mut r)?,
            twist: Twist {
                linear: Vector3::decode(&mut r)?,
                angular: Vector3::decode(&mut r)?,
            },
        })
    }
}

impl Geometry for Wrench {
    fn encode(&self, out: &mut Vec<u8>) {
        self.force.encode(out);
        self.torque.encode(out);
    }
    fn decode(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            force: Vector3::decode(r)?,
            torque: Vector3::decode(r)?,
        })
    }
}

impl Message for ContactsState {
    const TYPE: &'static str = "gazebo_msgs/ContactsState";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::len(out, self.states.len());
        for s in &self.states {
            wire::string(out, &s.info);
            wire::string(out, &s.collision1_name);
            wire::string(out, &s.collision2_name);
            wire::len(out, s.wrenches.len());
            for w in &s.wrenches {
                w.encode(out);
            }
            s.total_wrench.encode(out);
            for points in [&s.contact_positions, &s.contact_normals] {
                wire::len(out, points.len());
                for p in points {
                    p.encode(out);
                }
            }
            wire::f64_array(out, &s.depths);
        }
    }
}

impl Message for ModelStates {
    const TYPE: &'static str = "gazebo_msgs/ModelStates";
    fn encode(&self, out: &mut Vec<u8>) {
        wire::len(out, self.name.len());
        for n in &self.name {
            wire::string(out, n);
        }
        wire::len(out, self.pose.len());
        for p in &self.pose {
            p.encode(out);
        }
        wire::len(out, self.twist.len());
        for t in &self.twist {
            t.encode(out);
        }
    }
}

/// `geometry_msgs/Transform` (with its parent and child frames: `TransformStamped`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TransformStamped {
    /// Parent frame and stamp.
    pub header: Header,
    /// Child frame.
    pub child_frame_id: String,
    /// Translation (m).
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

impl TransformStamped {
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::string(out, &self.child_frame_id);
        self.translation.encode(out);
        self.rotation.encode(out);
    }
}

/// `tf2_msgs/TFMessage`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TfMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

impl Message for TfMessage {
    const TYPE: &'static str = "tf2_msgs/TFMessage";
    fn encode(&self, out: &mut Vec<u8>) {
        wire::len(out, self.transforms.len());
        for t in &self.transforms {
            t.encode(out);
        }
    }
}

impl Message for NavSatFix {
    const TYPE: &'static str = "sensor_msgs/NavSatFix";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::i8(out, self.status.status);
        wire::u16(out, self.status.service);
        for v in [self.latitude, self.longitude, self.altitude] {
            wire::f64(out, v);
        }
        wire::f64_fixed(out, &self.position_covariance);
        wire::u8(out, self.position_covariance_type);
    }
}

impl Message for Vector3Stamped {
    const TYPE: &'static str = "geometry_msgs/Vector3Stamped";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        Geometry::encode(&self.vector, out);
    }
}

impl Message for Imu {
    const TYPE: &'static str = "sensor_msgs/Imu";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        Geometry::encode(&self.orientation, out);
        wire::f64_fixed(out, &self.orientation_covariance);
        Geometry::encode(&self.angular_velocity, out);
        wire::f64_fixed(out, &self.angular_velocity_covariance);
        Geometry::encode(&self.linear_acceleration, out);
        wire::f64_fixed(out, &self.linear_acceleration_covariance);
    }
}

/// `nav_msgs/Odometry`.
#[derive(Debug, Clone, PartialEq)]
pub struct Odometry {
    /// Odometry frame and stamp.
    pub header: Header,
    /// The base frame.
    pub child_frame_id: String,
    /// Position (m).
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
    /// Pose covariance, row-major 6x6 (x, y, z, roll, pitch, yaw).
    pub pose_covariance: [f64; 36],
    /// Linear velocity in the base frame (m/s).
    pub linear: Vector3,
    /// Angular velocity (rad/s).
    pub angular: Vector3,
    /// Twist covariance, row-major 6x6.
    pub twist_covariance: [f64; 36],
}

impl Message for Odometry {
    const TYPE: &'static str = "nav_msgs/Odometry";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::string(out, &self.child_frame_id);
        self.position.encode(out);
        self.orientation.encode(out);
        wire::f64_fixed(out, &self.pose_covariance);
        self.linear.encode(out);
        self.angular.encode(out);
        wire::f64_fixed(out, &self.twist_covariance);
    }
}

impl Message for Image {
    const TYPE: &'static str = "sensor_msgs/Image";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::u32(out, self.height);
        wire::u32(out, self.width);
        wire::string(out, &self.encoding);
        wire::u8(out, self.is_bigendian);
        wire::u32(out, self.step);
        wire::bytes(out, &self.data);
    }
}

impl Message for PointCloud2 {
    const TYPE: &'static str = "sensor_msgs/PointCloud2";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::u32(out, self.height);
        wire::u32(out, self.width);
        wire::len(out, self.fields.len());
        for f in &self.fields {
            wire::string(out, &f.name);
            wire::u32(out, f.offset);
            wire::u8(out, f.datatype);
            wire::u32(out, f.count);
        }
        wire::u8(out, u8::from(self.is_bigendian));
        wire::u32(out, self.point_step);
        wire::u32(out, self.row_step);
        wire::bytes(out, &self.data);
        wire::u8(out, u8::from(self.is_dense));
    }
}

impl Message for CameraInfo {
    const TYPE: &'static str = "sensor_msgs/CameraInfo";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::u32(out, self.height);
        wire::u32(out, self.width);
        wire::string(out, &self.distortion_model);
        wire::f64_array(out, &self.d);
        wire::f64_fixed(out, &self.k);
        wire::f64_fixed(out, &self.r);
        wire::f64_fixed(out, &self.p);
        wire::u32(out, self.binning_x);
        wire::u32(out, self.binning_y);
        let roi = &self.roi;
        for v in [roi.x_offset, roi.y_offset, roi.height, roi.width] {
            wire::u32(out, v);
        }
        wire::u8(out, u8::from(roi.do_rectify));
    }
}

/// `rosgraph_msgs/Clock`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Clock {
    /// Sim time (s).
    pub clock_s: f64,
}

impl Message for Clock {
    const TYPE: &'static str = "rosgraph_msgs/Clock";
    fn encode(&self, out: &mut Vec<u8>) {
        wire::time(out, self.clock_s);
    }
}

impl Message for JointState {
    const TYPE: &'static str = "sensor_msgs/JointState";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::len(out, self.name.len());
        for n in &self.name {
            wire::string(out, n);
        }
        wire::f64_array(out, &self.position);
        wire::f64_array(out, &self.velocity);
        wire::f64_array(out, &self.effort);
    }
}

/// `std_msgs/Float64`: what a ros_control joint controller's `command` topic takes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Float64 {
    /// The value.
    pub data: f64,
}

impl Message for Float64 {
    const TYPE: &'static str = "std_msgs/Float64";
    fn encode(&self, out: &mut Vec<u8>) {
        wire::f64(out, self.data);
    }
}

impl Decode for Float64 {
    fn decode(bytes: &[u8]) -> Result<Self> {
        Ok(Self {
            data: Reader::new(bytes).f64()?,
        })
    }
}

impl Message for Text {
    const TYPE: &'static str = "std_msgs/String";
    fn encode(&self, out: &mut Vec<u8>) {
        wire::string(out, &self.data);
    }
}

impl Decode for Text {
    fn decode(bytes: &[u8]) -> Result<Self> {
        Ok(Self {
            data: Reader::new(bytes).string()?,
        })
    }
}

impl Message for PointStamped {
    const TYPE: &'static str = "geometry_msgs/PointStamped";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.point.encode(out);
    }
}

/// `trajectory_msgs/JointTrajectoryPoint`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointTrajectoryPoint {
    /// Positions (rad or m).
    pub positions: Vec<f64>,
    /// Velocities; may be empty.
    pub velocities: Vec<f64>,
    /// Accelerations; may be empty.
    pub accelerations: Vec<f64>,
    /// Efforts; may be empty.
    pub effort: Vec<f64>,
    /// When the point is due after the trajectory's start (s).
    pub time_from_start_s: f64,
}

impl JointTrajectoryPoint {
    fn encode(&self, out: &mut Vec<u8>) {
        wire::f64_array(out, &self.positions);
        wire::f64_array(out, &self.velocities);
        wire::f64_array(out, &self.accelerations);
        wire::f64_array(out, &self.effort);
        wire::duration(out, self.time_from_start_s);
    }
    fn decode(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            positions: r.f64_array()?,
            velocities: r.f64_array()?,
            accelerations: r.f64_array()?,
            effort: r.f64_array()?,
            time_from_start_s: r.time_s(true)?,
        })
    }
}

/// `trajectory_msgs/JointTrajectory`: what a joint trajectory controller's `command` topic
/// takes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointTrajectory {
    /// Stamp: when it starts (0: on arrival).
    pub header: Header,
    /// The joints each point lists.
    pub joint_names: Vec<String>,
    /// The points.
    pub points: Vec<JointTrajectoryPoint>,
}

impl Message for JointTrajectory {
    const TYPE: &'static str = "trajectory_msgs/JointTrajectory";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::len(out, self.joint_names.len());
        for n in &self.joint_names {
            wire::string(out, n);
        }
        wire::len(out, self.points.len());
        for p in &self.points {
            p.encode(out);
        }
    }
}

impl Decode for JointTrajectory {
    fn decode(bytes: &[u8]) -> Result<Self> {
        Self::read(&mut Reader::new(bytes))
    }
}

impl JointTrajectory {
    fn read(r: &mut Reader<'_>) -> Result<Self> {
        let header = Header::decode(r)?;
        let n = r.len(4)?;
        let joint_names = (0..n).map(|_| r.string()).collect::<Result<_>>()?;
        // Each point is at least its four array lengths and a duration.
        let n = r.len(24)?;
        let points = (0..n)
            .map(|_| JointTrajectoryPoint::decode(r))
            .collect::<Result<_>>()?;
        Ok(Self {
            header,
            joint_names,
            points,
        })
    }
}

/// `control_msgs/JointControllerState`: a single-joint position controller's `state`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointControllerState {
    /// Stamp.
    pub header: Header,
    /// The setpoint (rad or m).
    pub set_point: f64,
    /// The joint's position.
    pub process_value: f64,
    /// The joint's velocity.
    pub process_value_dot: f64,
    /// set_point - process_value.
    pub error: f64,
    /// Control period (s).
    pub time_step: f64,
    /// The effort commanded.
    pub command: f64,
    /// Gains.
    pub p: f64,
    /// Gains.
    pub i: f64,
    /// Gains.
    pub d: f64,
    /// Integral bound.
    pub i_clamp: f64,
    /// Anti-windup (rover's loop always bounds its integral).
    pub antiwindup: bool,
}

impl Message for JointControllerState {
    const TYPE: &'static str = "control_msgs/JointControllerState";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::f64_fixed(
            out,
            &[
                self.set_point,
                self.process_value,
                self.process_value_dot,
                self.error,
                self.time_step,
                self.command,
                self.p,
                self.i,
                self.d,
                self.i_clamp,
            ],
        );
        wire::u8(out, u8::from(self.antiwindup));
    }
}

/// `control_msgs/JointTrajectoryControllerState`: a joint trajectory controller's `state`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointTrajectoryControllerState {
    /// Stamp.
    pub header: Header,
    /// Its joints.
    pub joint_names: Vec<String>,
    /// Where the trajectory wants the joints.
    pub desired: JointTrajectoryPoint,
    /// Where they are.
    pub actual: JointTrajectoryPoint,
    /// desired - actual.
    pub error: JointTrajectoryPoint,
}

impl Message for JointTrajectoryControllerState {
    const TYPE: &'static str = "control_msgs/JointTrajectoryControllerState";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::len(out, self.joint_names.len());
        for n in &self.joint_names {
            wire::string(out, n);
        }
        self.desired.encode(out);
        self.actual.encode(out);
        self.error.encode(out);
    }
}

impl Message for LaserScan {
    const TYPE: &'static str = "sensor_msgs/LaserScan";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        for v in [
            self.angle_min,
            self.angle_max,
            self.angle_increment,
            self.time_increment,
            self.scan_time,
            self.range_min,
            self.range_max,
        ] {
            wire::f32(out, v);
        }
        wire::f32_array(out, &self.ranges);
        wire::f32_array(out, &self.intensities);
    }
}

impl Message for BoundingBoxes {
    const TYPE: &'static str = "darknet_ros_msgs/BoundingBoxes";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.image_header.encode(out);
        wire::len(out, self.bounding_boxes.len());
        for b in &self.bounding_boxes {
            wire::f64(out, b.probability);
            wire::i64(out, b.xmin);
            wire::i64(out, b.ymin);
            wire::i64(out, b.xmax);
            wire::i64(out, b.ymax);
            wire::i16(out, b.id);
            wire::string(out, &b.class_id);
        }
    }
}

impl Message for ObjectCount {
    const TYPE: &'static str = "darknet_ros_msgs/ObjectCount";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::i8(out, self.count);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::{full_definition, md5sum};

    /// The sums ROS tools check (genmsg's, listed in ../shared/ros/README.md), plus JointState
    /// and LaserScan.
    #[test]
    fn md5_sums_match_genmsg() -> Result<()> {
        for (t, sum) in [
            ("geometry_msgs/Twist", "9f195f881246fdfa2798d1d3eebca84a"),
            (
                "geometry_msgs/TwistStamped",
                "98d34b0043a2093cf9d9345ab6eef12e",
            ),
            ("nav_msgs/Odometry", "cd5e73d190d741a2f92e81eda573aca7"),
            ("tf2_msgs/TFMessage", "94810edda583a504dfda3829e70d7eec"),
            ("sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743"),
            ("sensor_msgs/CameraInfo", "c9a58c1b0b154e0e6da7578cb991d214"),
            ("rosgraph_msgs/Clock", "a9c97c1d230cfc112e270351a944ee47"),
            (
                "darknet_ros_msgs/BoundingBox",
                "6b8f03f076d75c692c40b501a56253e0",
            ),
            (
                "darknet_ros_msgs/BoundingBoxes",
                "004f6f4f48a741582d10735997905846",
            ),
            (
                "darknet_ros_msgs/ObjectCount",
                "123675bf4420958597b5a78cb3800a1f",
            ),
            ("sensor_msgs/JointState", "3066dcd76a6cfaef579bd0f34173e9fd"),
            ("sensor_msgs/LaserScan", "90c7ef2dc6895d81024acba2ac42f369"),
            ("sensor_msgs/Imu", "6a62c6daae103f4ff57a132d6f95cec2"),
            ("sensor_msgs/PointField", "268eacb2962780ceac86cbd17e328150"),
            ("geometry_msgs/Wrench", "4f539cf138b23283b520fd271b567936"),
            (
                "gazebo_msgs/ContactState",
                "48c0ffb054b8c444f870cecea1ee50d9",
            ),
            (
                "gazebo_msgs/ContactsState",
                "acbcb1601a8e525bf72509f18e6f668d",
            ),
            (
                "sensor_msgs/PointCloud2",
                "1158d486dd51d683ce2f1be655c3c181",
            ),
            ("sensor_msgs/NavSatFix", "2d3a8cd499b9b4a0249fb98fd05cfa48"),
            (
                "geometry_msgs/Vector3Stamped",
                "7b324c7325e683bf02a9b14b01090ec7",
            ),
            ("std_msgs/Header", "2176decaecbce78abc3b96ef049fabed"),
            ("std_msgs/Float64", "fdb28210bfa9d7c91146260178d9a584"),
            ("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1"),
            (
                "geometry_msgs/PointStamped",
                "c63aecb41bfdfd6b7e1fac37c7cbe7bf",
            ),
            (
                "trajectory_msgs/JointTrajectoryPoint",
                "f3cd1e1c4d320c79d6985c904ae5dcd3",
            ),
            (
                "trajectory_msgs/JointTrajectory",
                "65b4f94a94d1ed67169da35a02f33d3f",
            ),
            (
                "control_msgs/JointControllerState",
                "987ad85e4756f3aef7f1e5e7fe0595d1",
            ),
        ] {
            assert_eq!(md5sum(t)?, sum, "{t}");
        }
        Ok(())
    }

    #[test]
    fn full_definitions_list_each_dependency_once() -> Result<()> {
        let text = full_definition("nav_msgs/Odometry")?;
        assert!(text.starts_with("Header header\n"));
        for dep in [
            "MSG: std_msgs/Header\n",
            "MSG: geometry_msgs/PoseWithCovariance\n",
            "MSG: geometry_msgs/Point\n",
            "MSG: geometry_msgs/Vector3\n",
        ] {
            assert_eq!(text.matches(dep).count(), 1, "{dep} in\n{text}");
        }
        assert!(md5sum("nope/Nothing").is_err());
        Ok(())
    }

    #[test]
    fn joint_trajectory_round_trips_and_a_lying_length_is_an_error() -> Result<()> {
        let t = JointTrajectory {
            header: Header {
                seq: 3,
                stamp_s: 0.0,
                frame_id: String::new(),
            },
            joint_names: vec!["arm_1_joint".into(), "arm_2_joint".into()],
            points: vec![JointTrajectoryPoint {
                positions: vec![0.1, -0.8],
                velocities: vec![0.0, 0.0],
                time_from_start_s: 1.5,
                ..JointTrajectoryPoint::default()
            }],
        };
        let mut bytes = Vec::new();
        t.encode(&mut bytes);
        assert_eq!(JointTrajectory::decode(&bytes)?, t);
        // A joint count of a billion in a short message.
        let mut lying = bytes.clone();
        lying[16..20].copy_from_slice(&1_000_000_000u32.to_le_bytes());
        assert!(JointTrajectory::decode(&lying).is_err());
        assert!(Float64::decode(&[0, 0, 0]).is_err());
        Ok(())
    }

    #[test]
    fn twist_round_trips_and_short_input_is_an_error() -> Result<()> {
        let t = Twist {
            linear: Vector3 {
                x: 0.1,
                y: 0.0,
                z: -2.0,
            },
            angular: Vector3 {
                x: 0.0,
                y: 0.5,
                z: 1.5,
            },
        };
        let mut bytes = Vec::new();
        t.encode(&mut bytes);
        assert_eq!(bytes.len(), 48);
        assert_eq!(Twist::decode(&bytes)?, t);
        assert!(Twist::decode(&bytes[..47]).is_err());
        Ok(())
    }

    #[test]
    fn a_pose_is_seven_float64s_position_first() -> Result<()> {
        let pose = Pose {
            position: [1.0, -2.0, 0.5].into(),
            orientation: Quaternion::from_yaw(0.3),
        };
        let mut bytes = Vec::new();
        Geometry::encode(&pose, &mut bytes);
        assert_eq!(bytes.len(), 56);
        assert_eq!(bytes[..8], 1.0f64.to_le_bytes());
        assert_eq!(bytes[48..], pose.orientation.w.to_le_bytes());
        let mut r = Reader::new(&bytes);
        assert_eq!(<Pose as Geometry>::decode(&mut r)?, pose);
        assert!(<Pose as Geometry>::decode(&mut Reader::new(&bytes[..55])).is_err());
        Ok(())
    }

    #[test]
    fn headers_encode_stamps_as_secs_and_nsecs() {
        let mut out = Vec::new();
        Header {
            seq: 7,
            stamp_s: 12.25,
            frame_id: "odom".into(),
        }
        .encode(&mut out);
        assert_eq!(&out[0..4], &7u32.to_le_bytes());
        assert_eq!(&out[4..8], &12u32.to_le_bytes());
        assert_eq!(&out[8..12], &250_000_000u32.to_le_bytes());
        assert_eq!(&out[12..16], &4u32.to_le_bytes());
        assert_eq!(&out[16..], b"odom");
    }
}
