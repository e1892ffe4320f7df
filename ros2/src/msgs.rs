//! ROS 2 messages as rover publishes and reads them: plain structs whose serde layout is the
//! message's CDR layout (fields in the `.msg` order; fixed arrays without a length, sequences
//! and strings with one), and their DDS type names (`geometry_msgs::msg::dds_::Twist_`), as
//! rmw_cyclonedds and rmw_fastrtps name them. Written from the ROS 2 message definitions
//! (Humble and Jazzy agree on every one here); no ROS install is needed.

use serde::{Deserialize, Serialize};

/// A message with its DDS type name.
pub trait RosMessage: Serialize + Send + 'static {
    /// `pkg::msg::dds_::Type_`.
    const DDS_TYPE: &'static str;
    /// The `.msg` definition with its dependencies, as MCAP's `ros2msg` schemas carry it.
    const DEFINITION: &'static str;
}

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, 0..1e9.
    pub nanosec: u32,
}

impl Time {
    /// Sim time in seconds as a ROS 2 stamp (rounded to the nanosecond).
    pub fn from_secs(t_s: f64) -> Self {
        let total_ns = (t_s.max(0.0) * 1e9).round() as u64;
        Self {
            sec: i32::try_from(total_ns / 1_000_000_000).unwrap_or(i32::MAX),
            nanosec: (total_ns % 1_000_000_000) as u32,
        }
    }

    /// Seconds.
    #[cfg(test)]
    pub fn as_secs(self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}

/// `std_msgs/msg/Header` (no `seq` in ROS 2).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Stamp.
    pub stamp: Time,
    /// Frame id.
    pub frame_id: String,
}

rover_msgs::wire_messages!(Header, Lent<u8>, Lent<f32>);

impl RosMessage for Twist {
    const DDS_TYPE: &'static str = "geometry_msgs::msg::dds_::Twist_";
    const DEFINITION: &'static str = crate::definitions::TWIST;
}

impl RosMessage for TwistStamped {
    const DDS_TYPE: &'static str = "geometry_msgs::msg::dds_::TwistStamped_";
    const DEFINITION: &'static str = crate::definitions::TWIST_STAMPED;
}

/// A 6x6 row-major covariance: `float64[36]`, written without a length as CDR fixed arrays are
/// (serde's arrays stop at 32, hence the tuple).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Default for Covariance {
    fn default() -> Self {
        Self([0.0; 36])
    }
}

impl Serialize for Covariance {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeTuple;
        let mut t = s.serialize_tuple(36)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Covariance {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visit;
        impl<'de> serde::de::Visitor<'de> for Visit {
            type Value = Covariance;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("36 float64")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut a: A,
            ) -> Result<Covariance, A::Error> {
                let mut out = [0.0; 36];
                for (i, v) in out.iter_mut().enumerate() {
                    *v = a
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
                }
                Ok(Covariance(out))
            }
        }
        d.deserialize_tuple(36, Visit)
    }
}

/// `geometry_msgs/msg/PoseWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// Pose.
    pub pose: Pose,
    /// Covariance (x, y, z, roll, pitch, yaw).
    pub covariance: Covariance,
}

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// Twist.
    pub twist: Twist,
    /// Covariance.
    pub covariance: Covariance,
}

/// `nav_msgs/msg/Odometry`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// Stamp and odometry frame.
    pub header: Header,
    /// The base frame.
    pub child_frame_id: String,
    /// Pose in the odometry frame.
    pub pose: PoseWithCovariance,
    /// Velocity in the base frame.
    pub twist: TwistWithCovariance,
}

impl RosMessage for Odometry {
    const DDS_TYPE: &'static str = "nav_msgs::msg::dds_::Odometry_";
    const DEFINITION: &'static str = crate::definitions::ODOMETRY;
}

/// `rosgraph_msgs/msg/Clock`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Clock {
    /// Sim time.
    pub clock: Time,
}

impl RosMessage for Clock {
    const DDS_TYPE: &'static str = "rosgraph_msgs::msg::dds_::Clock_";
    const DEFINITION: &'static str = crate::definitions::CLOCK;
}

/// `geometry_msgs/msg/Transform`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation (m).
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// Child frame.
    pub child_frame_id: String,
    /// The child's frame in the parent's.
    pub transform: Transform,
}

/// `tf2_msgs/msg/TFMessage`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// Transforms.
    pub transforms: Vec<TransformStamped>,
}

impl RosMessage for TfMessage {
    const DDS_TYPE: &'static str = "tf2_msgs::msg::dds_::TFMessage_";
    const DEFINITION: &'static str = crate::definitions::TF_MESSAGE;
}

impl RosMessage for JointState {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::JointState_";
    const DEFINITION: &'static str = crate::definitions::JOINT_STATE;
}

/// A buffer lent to a message: the writer serializes the message and drops it, and the bridge
/// takes the buffer back ([`Lent::take_back`]) for the next one, so steady publishing
/// allocates nothing.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Lent<T>(std::sync::Arc<Vec<T>>);

impl<T> Lent<T> {
    /// Lends `buffer`.
    pub fn new(buffer: Vec<T>) -> Self {
        Self(std::sync::Arc::new(buffer))
    }

    /// What is lent.
    pub fn as_slice(&self) -> &[T] {
        &self.0
    }

    /// The buffer, once no message holds it any more.
    pub fn take_back(self) -> Option<Vec<T>> {
        std::sync::Arc::try_unwrap(self.0).ok()
    }
}

/// `uint8[]`: a length and the bytes.
impl Serialize for Lent<u8> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(&self.0)
    }
}

/// `float32[]`: a length and the values.
impl Serialize for Lent<f32> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.as_slice().serialize(s)
    }
}

impl RosMessage for Image {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::Image_";
    const DEFINITION: &'static str = crate::definitions::IMAGE;
}

impl RosMessage for CameraInfo {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::CameraInfo_";
    const DEFINITION: &'static str = crate::definitions::CAMERA_INFO;
}

impl RosMessage for LaserScan {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::LaserScan_";
    const DEFINITION: &'static str = crate::definitions::LASER_SCAN;
}

impl RosMessage for PointCloud2 {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::PointCloud2_";
    const DEFINITION: &'static str = crate::definitions::POINT_CLOUD2;
}

impl RosMessage for ContactsState {
    const DDS_TYPE: &'static str = "gazebo_msgs::msg::dds_::ContactsState_";
    const DEFINITION: &'static str = crate::definitions::CONTACTS_STATE;
}

impl RosMessage for Imu {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::Imu_";
    const DEFINITION: &'static str = crate::definitions::IMU;
}

impl RosMessage for NavSatFix {
    const DDS_TYPE: &'static str = "sensor_msgs::msg::dds_::NavSatFix_";
    const DEFINITION: &'static str = crate::definitions::NAV_SAT_FIX;
}

impl RosMessage for Vector3Stamped {
    const DDS_TYPE: &'static str = "geometry_msgs::msg::dds_::Vector3Stamped_";
    const DEFINITION: &'static str = crate::definitions::VECTOR3_STAMPED;
}

impl RosMessage for BoundingBoxes {
    const DDS_TYPE: &'static str = "darknet_ros_msgs::msg::dds_::BoundingBoxes_";
    const DEFINITION: &'static str = crate::definitions::BOUNDING_BOXES;
}

impl RosMessage for ObjectCount {
    const DDS_TYPE: &'static str = "darknet_ros_msgs::msg::dds_::ObjectCount_";
    const DEFINITION: &'static str = crate::definitions::OBJECT_COUNT;
}

impl RosMessage for ModelStates {
    const DDS_TYPE: &'static str = "gazebo_msgs::msg::dds_::ModelStates_";
    const DEFINITION: &'static str = crate::definitions::MODEL_STATES;
}

impl RosMessage for Text {
    const DDS_TYPE: &'static str = "std_msgs::msg::dds_::String_";
    const DEFINITION: &'static str = crate::definitions::STRING;
}

impl RosMessage for PointStamped {
    const DDS_TYPE: &'static str = "geometry_msgs::msg::dds_::PointStamped_";
    const DEFINITION: &'static str = crate::definitions::POINT_STAMPED;
}

/// `rcl_interfaces/msg/Log`: one line of a node's log, as every rclcpp and rclpy node
/// publishes it on `/rosout`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Log {
    /// When it was logged (wall clock, as rcl stamps it).
    pub stamp: Time,
    /// [`Log::DEBUG`] .. [`Log::FATAL`].
    pub level: u8,
    /// The logger: the node's name (`rover`).
    pub name: String,
    /// The text.
    pub msg: String,
    /// The source file that logged it.
    pub file: String,
    /// The function (rover: its module) that logged it.
    pub function: String,
    /// The line that logged it.
    pub line: u32,
}

impl Log {
    /// Debug (and tracing's trace).
    pub const DEBUG: u8 = 10;
    /// Info.
    pub const INFO: u8 = 20;
    /// Warning.
    pub const WARN: u8 = 30;
    /// Error.
    pub const ERROR: u8 = 40;
    /// Fatal (rover logs none).
    pub const FATAL: u8 = 50;
}

impl RosMessage for Log {
    const DDS_TYPE: &'static str = "rcl_interfaces::msg::dds_::Log_";
    const DEFINITION: &'static str = crate::definitions::LOG;
}

/// `builtin_interfaces/msg/Duration`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Duration {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds, 0..1e9.
    pub nanosec: u32,
}

/// `trajectory_msgs/msg/JointTrajectoryPoint`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectoryPoint {
    /// Positions (rad or m).
    pub positions: Vec<f64>,
    /// Velocities; may be empty.
    pub velocities: Vec<f64>,
    /// Accelerations; may be empty.
    pub accelerations: Vec<f64>,
    /// Efforts; may be empty.
    pub effort: Vec<f64>,
    /// When the point is due after the trajectory's start.
    pub time_from_start: Duration,
}

/// `trajectory_msgs/msg/JointTrajectory`: what ros2_control's joint_trajectory_controller
/// takes on `~/joint_trajectory`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectory {
    /// Stamp: when it starts (0: on arrival).
    pub header: Header,
    /// The joints each point lists.
    pub joint_names: Vec<String>,
    /// The points.
    pub points: Vec<JointTrajectoryPoint>,
}

impl RosMessage for JointTrajectory {
    const DDS_TYPE: &'static str = "trajectory_msgs::msg::dds_::JointTrajectory_";
    const DEFINITION: &'static str = crate::definitions::JOINT_TRAJECTORY;
}

/// `std_msgs/msg/MultiArrayDimension`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiArrayDimension {
    /// Label.
    pub label: String,
    /// Size.
    pub size: u32,
    /// Stride.
    pub stride: u32,
}

/// `std_msgs/msg/MultiArrayLayout`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiArrayLayout {
    /// Dimensions.
    pub dim: Vec<MultiArrayDimension>,
    /// Offset of the first value.
    pub data_offset: u32,
}

/// `std_msgs/msg/Float64MultiArray`: what ros2_control's forward command controllers take on
/// `~/commands`, one value per joint.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Float64MultiArray {
    /// Layout (ignored: the values are the controller's joints in order).
    pub layout: MultiArrayLayout,
    /// Values.
    pub data: Vec<f64>,
}

/// `std_msgs/msg/Float64`: what a gz-sim joint controller system takes through ros_gz_bridge.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Float64 {
    /// The value.
    pub data: f64,
}

impl RosMessage for Float64 {
    const DDS_TYPE: &'static str = "std_msgs::msg::dds_::Float64_";
    const DEFINITION: &'static str = crate::definitions::FLOAT64;
}

impl RosMessage for Float64MultiArray {
    const DDS_TYPE: &'static str = "std_msgs::msg::dds_::Float64MultiArray_";
    const DEFINITION: &'static str = crate::definitions::FLOAT64_MULTI_ARRAY;
}

#[cfg(test)]
mod tests {
    use super::*;
    use byteorder::LittleEndian;
    use rustdds::serialization::{from_bytes, to_vec};

    fn cdr<M: Serialize>(m: &M) -> Vec<u8> {
        to_vec::<M, LittleEndian>(m).unwrap_or_default()
    }

    #[test]
    fn stamps_round_to_the_nanosecond() {
        let t = Time::from_secs(12.345_678_901_2);
        assert_eq!((t.sec, t.nanosec), (12, 345_678_901));
        assert!((t.as_secs() - 12.345_678_901).abs() < 1e-12);
        assert_eq!(Time::from_secs(-1.0), Time::default());
    }

    /// CDR layouts as a ROS 2 peer reads them: a Twist is six float64 (48 bytes, no padding);
    /// an Odometry carries its 36-entry covariances without a length and reads back equal.
    #[test]
    fn cdr_layouts_match_the_message_definitions() {
        let twist = Twist {
            linear: Vector3 {
                x: 0.5,
                y: 0.0,
                z: 0.0,
            },
            angular: Vector3 {
                x: 0.0,
                y: 0.0,
                z: -0.3,
            },
        };
        let bytes = cdr(&twist);
        assert_eq!(bytes.len(), 48);
        assert_eq!(&bytes[..8], &0.5f64.to_le_bytes());
        let mut odom = Odometry {
            header: Header {
                stamp: Time::from_secs(1.5),
                frame_id: "odom".into(),
            },
            child_frame_id: "base_footprint".into(),
            ..Odometry::default()
        };
        odom.pose.covariance.0[35] = 1e-3;
        let bytes = cdr(&odom);
        // stamp 8, "odom" 4 + 5 (+3 padding), "base_footprint" 4 + 15 (+1), pose 56 + 288,
        // twist 48 + 288.
        assert_eq!(bytes.len(), 8 + 12 + 20 + 344 + 336);
        let back = from_bytes::<Odometry, LittleEndian>(&bytes)
            .ok()
            .map(|(m, _)| m);
        assert_eq!(back.as_ref(), Some(&odom));
    }
}
