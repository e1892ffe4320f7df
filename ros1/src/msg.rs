//! Message definitions, their MD5 sums (genmsg's rules) and the ROS 1 wire format.
//!
//! Definitions are written here as field lists, so nothing from a ROS install is needed at
//! build time. The MD5 sum of a type is computed from them the way genmsg does (constants,
//! then fields; a field of message type contributes that type's MD5 instead of its name), and
//! the full text sent as `message_definition` (which rosbag stores) is the type's fields
//! followed by each dependency's, as gendeps writes it.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::OnceLock;

use md5::{Digest, Md5};

use crate::error::{Error, Result};

/// The definitions this client knows: full type name and its fields, one per line.
const DEFINITIONS: &[(&str, &str)] = &[
    ("std_msgs/Header", "uint32 seq\ntime stamp\nstring frame_id"),
    ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z"),
    ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z"),
    (
        "geometry_msgs/Quaternion",
        "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
    ),
    (
        "geometry_msgs/Twist",
        "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    ),
    (
        "geometry_msgs/TwistStamped",
        "Header header\ngeometry_msgs/Twist twist",
    ),
    (
        "geometry_msgs/Pose",
        "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    ),
    (
        "gazebo_msgs/ModelStates",
        "string[] name\ngeometry_msgs/Pose[] pose\ngeometry_msgs/Twist[] twist",
    ),
    (
        "geometry_msgs/PoseWithCovariance",
        "geometry_msgs/Pose pose\nfloat64[36] covariance",
    ),
    (
        "geometry_msgs/TwistWithCovariance",
        "geometry_msgs/Twist twist\nfloat64[36] covariance",
    ),
    (
        "geometry_msgs/Transform",
        "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation",
    ),
    (
        "geometry_msgs/TransformStamped",
        "Header header\nstring child_frame_id\ngeometry_msgs/Transform transform",
    ),
    (
        "nav_msgs/Odometry",
        "Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist",
    ),
    (
        "tf2_msgs/TFMessage",
        "geometry_msgs/TransformStamped[] transforms",
    ),
    (
        "sensor_msgs/Image",
        "Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data",
    ),
    (
        "sensor_msgs/RegionOfInterest",
        "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify",
    ),
    (
        "sensor_msgs/CameraInfo",
        "Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] D\nfloat64[9] K\nfloat64[9] R\nfloat64[12] P\nuint32 binning_x\nuint32 binning_y\nsensor_msgs/RegionOfInterest roi",
    ),
    (
        "sensor_msgs/JointState",
        "Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort",
    ),
    (
        "sensor_msgs/LaserScan",
        "Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities",
    ),
    (
        "sensor_msgs/Imu",
        "Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance",
    ),
    (
        "sensor_msgs/NavSatStatus",
        "int8 STATUS_NO_FIX=-1\nint8 STATUS_FIX=0\nint8 STATUS_SBAS_FIX=1\nint8 STATUS_GBAS_FIX=2\nuint16 SERVICE_GPS=1\nuint16 SERVICE_GLONASS=2\nuint16 SERVICE_COMPASS=4\nuint16 SERVICE_GALILEO=8\nint8 status\nuint16 service",
    ),
    (
        "sensor_msgs/NavSatFix",
        "uint8 COVARIANCE_TYPE_UNKNOWN=0\nuint8 COVARIANCE_TYPE_APPROXIMATED=1\nuint8 COVARIANCE_TYPE_DIAGONAL_KNOWN=2\nuint8 COVARIANCE_TYPE_KNOWN=3\nHeader header\nsensor_msgs/NavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\nuint8 position_covariance_type",
    ),
    (
        "geometry_msgs/Vector3Stamped",
        "Header header\ngeometry_msgs/Vector3 vector",
    ),
    (
        "sensor_msgs/PointField",
        "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count",
    ),
    (
        "sensor_msgs/PointCloud2",
        "Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\nbool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense",
    ),
    (
        "geometry_msgs/Wrench",
        "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque",
    ),
    (
        "gazebo_msgs/ContactState",
        "string info\nstring collision1_name\nstring collision2_name\ngeometry_msgs/Wrench[] wrenches\ngeometry_msgs/Wrench total_wrench\ngeometry_msgs/Vector3[] contact_positions\ngeometry_msgs/Vector3[] contact_normals\nfloat64[] depths",
    ),
    (
        "gazebo_msgs/ContactsState",
        "Header header\ngazebo_msgs/ContactState[] states",
    ),
    ("rosgraph_msgs/Clock", "time clock"),
    ("std_msgs/String", "string data"),
    (
        "geometry_msgs/PointStamped",
        "Header header\ngeometry_msgs/Point point",
    ),
    ("std_msgs/Float64", "float64 data"),
    (
        "trajectory_msgs/JointTrajectoryPoint",
        "float64[] positions\nfloat64[] velocities\nfloat64[] accelerations\nfloat64[] effort\nduration time_from_start",
    ),
    (
        "trajectory_msgs/JointTrajectory",
        "Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint[] points",
    ),
    (
        "control_msgs/JointControllerState",
        "Header header\nfloat64 set_point\nfloat64 process_value\nfloat64 process_value_dot\nfloat64 error\nfloat64 time_step\nfloat64 command\nfloat64 p\nfloat64 i\nfloat64 d\nfloat64 i_clamp\nbool antiwindup",
    ),
    (
        "control_msgs/JointTrajectoryControllerState",
        "Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint desired\ntrajectory_msgs/JointTrajectoryPoint actual\ntrajectory_msgs/JointTrajectoryPoint error",
    ),
    (
        "darknet_ros_msgs/BoundingBox",
        "float64 probability\nint64 xmin\nint64 ymin\nint64 xmax\nint64 ymax\nint16 id\nstring Class",
    ),
    (
        "darknet_ros_msgs/BoundingBoxes",
        "Header header\nHeader image_header\ndarknet_ros_msgs/BoundingBox[] bounding_boxes",
    ),
    ("darknet_ros_msgs/ObjectCount", "Header header\nint8 count"),
    ("actionlib_msgs/GoalID", "time stamp\nstring id"),
    (
        "actionlib_msgs/GoalStatus",
        "uint8 PENDING=0\nuint8 ACTIVE=1\nuint8 PREEMPTED=2\nuint8 SUCCEEDED=3\nuint8 ABORTED=4\nuint8 REJECTED=5\nuint8 PREEMPTING=6\nuint8 RECALLING=7\nuint8 RECALLED=8\nuint8 LOST=9\nactionlib_msgs/GoalID goal_id\nuint8 status\nstring text",
    ),
    (
        "actionlib_msgs/GoalStatusArray",
        "Header header\nactionlib_msgs/GoalStatus[] status_list",
    ),
    (
        "control_msgs/JointTolerance",
        "string name\nfloat64 position\nfloat64 velocity\nfloat64 acceleration",
    ),
    (
        "control_msgs/FollowJointTrajectoryGoal",
        "trajectory_msgs/JointTrajectory trajectory\ncontrol_msgs/JointTolerance[] path_tolerance\ncontrol_msgs/JointTolerance[] goal_tolerance\nduration goal_time_tolerance",
    ),
    (
        "control_msgs/FollowJointTrajectoryResult",
        "int32 SUCCESSFUL=0\nint32 INVALID_GOAL=-1\nint32 INVALID_JOINTS=-2\nint32 OLD_HEADER_TIMESTAMP=-3\nint32 PATH_TOLERANCE_VIOLATED=-4\nint32 GOAL_TOLERANCE_VIOLATED=-5\nint32 error_code\nstring error_string",
    ),
    (
        "control_msgs/FollowJointTrajectoryFeedback",
        "Header header\nstring[] joint_names\ntrajectory_msgs/JointTrajectoryPoint desired\ntrajectory_msgs/JointTrajectoryPoint actual\ntrajectory_msgs/JointTrajectoryPoint error",
    ),
    (
        "control_msgs/FollowJointTrajectoryActionGoal",
        "Header header\nactionlib_msgs/GoalID goal_id\ncontrol_msgs/FollowJointTrajectoryGoal goal",
    ),
    (
        "control_msgs/FollowJointTrajectoryActionResult",
        "Header header\nactionlib_msgs/GoalStatus status\ncontrol_msgs/FollowJointTrajectoryResult result",
    ),
    (
        "control_msgs/FollowJointTrajectoryActionFeedback",
        "Header header\nactionlib_msgs/GoalStatus status\ncontrol_msgs/FollowJointTrajectoryFeedback feedback",
    ),
    (
        "control_msgs/GripperCommand",
        "float64 position\nfloat64 max_effort",
    ),
    (
        "control_msgs/GripperCommandGoal",
        "control_msgs/GripperCommand command",
    ),
    (
        "control_msgs/GripperCommandResult",
        "float64 position\nfloat64 effort\nbool stalled\nbool reached_goal",
    ),
    (
        "control_msgs/GripperCommandFeedback",
        "float64 position\nfloat64 effort\nbool stalled\nbool reached_goal",
    ),
    (
        "control_msgs/GripperCommandActionGoal",
        "Header header\nactionlib_msgs/GoalID goal_id\ncontrol_msgs/GripperCommandGoal goal",
    ),
    (
        "control_msgs/GripperCommandActionResult",
        "Header header\nactionlib_msgs/GoalStatus status\ncontrol_msgs/GripperCommandResult result",
    ),
    (
        "control_msgs/GripperCommandActionFeedback",
        "Header header\nactionlib_msgs/GoalStatus status\ncontrol_msgs/GripperCommandFeedback feedback",
    ),
];

const BUILTIN: &[&str] = &[
    "bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "float32",
    "float64", "string", "time", "duration", "byte", "char",
];

fn definition(type_name: &str) -> Result<&'static str> {
    DEFINITIONS
        .iter()
        .find(|(name, _)| *name == type_name)
        .map(|(_, text)| *text)
        .ok_or_else(|| Error::UnknownType(type_name.to_owned()))
}

/// The full name a field's type refers to (`Header` is `std_msgs/Header`), without array
/// brackets; `None` for built-in types.
fn message_type_of(field_type: &str) -> Option<&str> {
    let base = field_type.split('[').next().unwrap_or(field_type);
    if BUILTIN.contains(&base) {
        None
    } else if base == "Header" {
        Some("std_msgs/Header")
    } else {
        Some(base)
    }
}

fn fields(text: &str) -> impl Iterator<Item = (&str, &str)> {
    text.lines()
        .filter_map(|line| line.trim().split_once(' '))
        .map(|(t, n)| (t.trim(), n.trim()))
}

fn compute_md5(type_name: &str, memo: &mut BTreeMap<String, String>) -> Result<String> {
    if let Some(sum) = memo.get(type_name) {
        return Ok(sum.clone());
    }
    let mut text = String::new();
    for (field_type, name) in fields(definition(type_name)?) {
        if !text.is_empty() {
            text.push('\n');
        }
        match message_type_of(field_type) {
            None => {
                let _ = write!(text, "{field_type} {name}");
            }
            Some(sub) => {
                let sum = compute_md5(sub, memo)?;
                let _ = write!(text, "{sum} {name}");
            }
        }
    }
    let digest = Md5::digest(text.as_bytes());
    let mut hex = String::with_capacity(32);
    for b in digest {
        let _ = write!(hex, "{b:02x}");
    }
    memo.insert(type_name.to_owned(), hex.clone());
    Ok(hex)
}

/// The MD5 sum of a message type, as genmsg computes it.
pub fn md5sum(type_name: &str) -> Result<String> {
    static MEMO: OnceLock<std::sync::Mutex<BTreeMap<String, String>>> = OnceLock::new();
    let memo = MEMO.get_or_init(Default::default);
    let mut memo = memo
        .lock()
        .map_err(|_| Error::protocol("message MD5 table poisoned"))?;
    compute_md5(type_name, &mut memo)
}

fn collect_dependencies(type_name: &str, out: &mut Vec<&'static str>) -> Result<()> {
    for (field_type, _) in fields(definition(type_name)?) {
        if let Some(sub) = message_type_of(field_type) {
            let (name, _) = DEFINITIONS
                .iter()
                .find(|(n, _)| *n == sub)
                .ok_or_else(|| Error::UnknownType(sub.to_owned()))?;
            if !out.contains(name) {
                out.push(name);
                collect_dependencies(name, out)?;
            }
        }
    }
    Ok(())
}

/// The `message_definition` of a type: its fields, then each message type it uses.
pub fn full_definition(type_name: &str) -> Result<String> {
    let mut text = String::from(definition(type_name)?);
    text.push('\n');
    let mut deps = Vec::new();
    collect_dependencies(type_name, &mut deps)?;
    for dep in deps {
        text.push_str(&"=".repeat(80));
        text.push_str("\nMSG: ");
        text.push_str(dep);
        text.push('\n');
        text.push_str(definition(dep)?);
        text.push('\n');
    }
    Ok(text)
}

/// Every type this client can publish or subscribe.
pub fn known_types() -> impl Iterator<Item = &'static str> {
    DEFINITIONS.iter().map(|(name, _)| *name)
}

/// A message that can be written in the ROS 1 wire format (little-endian; strings and
/// variable-length arrays prefixed with a u32 length; fixed arrays without).
pub trait Message {
    /// Full type name, `pkg/Type`.
    const TYPE: &'static str;
    /// Appends the serialized message to `out`.
    fn encode(&self, out: &mut Vec<u8>);
}

/// A message that can be read from the wire.
pub trait Decode: Message + Sized {
    /// Reads a message; an error on short or malformed input.
    fn decode(bytes: &[u8]) -> Result<Self>;
}

/// Wire-format writers.
pub mod wire {
    /// A u8.
    pub fn u8(out: &mut Vec<u8>, v: u8) {
        out.push(v);
    }
    /// An i8.
    pub fn i8(out: &mut Vec<u8>, v: i8) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// An i16.
    pub fn i16(out: &mut Vec<u8>, v: i16) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// A u16.
    pub fn u16(out: &mut Vec<u8>, v: u16) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// A u32.
    pub fn u32(out: &mut Vec<u8>, v: u32) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// An i32.
    pub fn i32(out: &mut Vec<u8>, v: i32) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// An i64.
    pub fn i64(out: &mut Vec<u8>, v: i64) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// An f32.
    pub fn f32(out: &mut Vec<u8>, v: f32) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// An f64.
    pub fn f64(out: &mut Vec<u8>, v: f64) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    /// A length prefix (saturating at u32::MAX, which no real message reaches).
    pub fn len(out: &mut Vec<u8>, n: usize) {
        u32(out, u32::try_from(n).unwrap_or(u32::MAX));
    }
    /// A string.
    pub fn string(out: &mut Vec<u8>, s: &str) {
        len(out, s.len());
        out.extend_from_slice(s.as_bytes());
    }
    /// A `time` from seconds (u32 s + u32 ns; negative times clamp to 0).
    pub fn time(out: &mut Vec<u8>, t_s: f64) {
        let (s, ns) = super::secs_nsecs(t_s);
        u32(out, s);
        u32(out, ns);
    }
    /// A `duration` from seconds (i32 s + i32 ns, the nanoseconds in 0..1e9).
    pub fn duration(out: &mut Vec<u8>, t_s: f64) {
        let t_s = if t_s.is_finite() { t_s } else { 0.0 };
        let total_ns = (t_s * 1e9).round() as i64;
        let secs = total_ns.div_euclid(1_000_000_000);
        let nsecs = total_ns.rem_euclid(1_000_000_000);
        out.extend_from_slice(&(i32::try_from(secs).unwrap_or(i32::MAX)).to_le_bytes());
        out.extend_from_slice(&(nsecs as i32).to_le_bytes());
    }
    /// A fixed array of f64 (no length prefix).
    pub fn f64_fixed(out: &mut Vec<u8>, v: &[f64]) {
        for x in v {
            f64(out, *x);
        }
    }
    /// A variable-length array of f64.
    pub fn f64_array(out: &mut Vec<u8>, v: &[f64]) {
        len(out, v.len());
        f64_fixed(out, v);
    }
    /// A variable-length array of f32.
    pub fn f32_array(out: &mut Vec<u8>, v: &[f32]) {
        len(out, v.len());
        for x in v {
            f32(out, *x);
        }
    }
    /// A variable-length byte array.
    pub fn bytes(out: &mut Vec<u8>, v: &[u8]) {
        len(out, v.len());
        out.extend_from_slice(v);
    }
}

/// Seconds as ROS `time` (secs, nsecs); negative clamps to zero.
pub fn secs_nsecs(t_s: f64) -> (u32, u32) {
    if !(t_s.is_finite() && t_s > 0.0) {
        return (0, 0);
    }
    let total_ns = (t_s * 1e9).round() as u64;
    (
        u32::try_from(total_ns / 1_000_000_000).unwrap_or(u32::MAX),
        (total_ns % 1_000_000_000) as u32,
    )
}

/// A little-endian reader over a message's bytes.
#[derive(Debug)]
pub struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    /// Reads from the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { bytes }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if self.bytes.len() < n {
            return Err(Error::protocol("message shorter than its type"));
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Ok(head)
    }

    /// An f64.
    pub fn f64(&mut self) -> Result<f64> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }

    /// A u32.
    pub fn u32(&mut self) -> Result<u32> {
        let b = self.take(4)?;
        let mut a = [0u8; 4];
        a.copy_from_slice(b);
        Ok(u32::from_le_bytes(a))
    }

    /// An i32.
    pub fn i32(&mut self) -> Result<i32> {
        Ok(self.u32()? as i32)
    }

    /// A length prefix, checked against what is left (each element at least `min_size`
    /// bytes), so a corrupt length cannot ask for a huge allocation.
    pub fn len(&mut self, min_size: usize) -> Result<usize> {
        let n = self.u32()? as usize;
        if n.saturating_mul(min_size.max(1)) > self.bytes.len() {
            return Err(Error::protocol("array longer than the message"));
        }
        Ok(n)
    }

    /// A string (UTF-8; invalid bytes are replaced).
    pub fn string(&mut self) -> Result<String> {
        let n = self.len(1)?;
        Ok(String::from_utf8_lossy(self.take(n)?).into_owned())
    }

    /// A variable-length array of f64.
    pub fn f64_array(&mut self) -> Result<Vec<f64>> {
        let n = self.len(8)?;
        (0..n).map(|_| self.f64()).collect()
    }

    /// A `time` or `duration` in seconds (secs + nsecs).
    pub fn time_s(&mut self, signed: bool) -> Result<f64> {
        let secs = if signed {
            f64::from(self.i32()?)
        } else {
            f64::from(self.u32()?)
        };
        let nsecs = if signed {
            f64::from(self.i32()?)
        } else {
            f64::from(self.u32()?)
        };
        Ok(secs + nsecs * 1e-9)
    }
}
