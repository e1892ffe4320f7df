//! The ROS message types rover's two wires share field for field: geometry_msgs' `Vector3`
//! (also `Point`), `Quaternion`, `Pose` and `Twist`, and the messages whose fields are alike
//! in ROS 1 and ROS 2 but for their header (`JointState<H>`, `LaserScan<H, R>`,
//! `BoundingBoxes<H>`, ...: each wire names them with its own `Header`), are written once,
//! here. How each travels is its wire's: `rover-ros1` encodes them in
//! ROS 1's serialization (`Message`), `rover-ros2` in CDR through serde (`RosMessage`); both
//! crates re-export them in their `msgs`.
//!
//! The messages whose fields differ between ROS 1 and ROS 2 (std_msgs/Header's `seq`, Time's
//! layout, Odometry's and TF's shapes in rover's ROS 1 encoder) stay in each wire's crate.

use serde::{Deserialize, Serialize};

/// `geometry_msgs/Vector3`, and `geometry_msgs/Point` (the same three `float64`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl From<[f64; 3]> for Vector3 {
    fn from([x, y, z]: [f64; 3]) -> Self {
        Self { x, y, z }
    }
}

/// `geometry_msgs/Quaternion` (the identity by default).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

impl From<[f64; 4]> for Quaternion {
    fn from([x, y, z, w]: [f64; 4]) -> Self {
        Self { x, y, z, w }
    }
}

impl Quaternion {
    /// A rotation about z by `yaw_rad`.
    pub fn from_yaw(yaw_rad: f64) -> Self {
        let (s, c) = (yaw_rad / 2.0).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position (m).
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity (m/s).
    pub linear: Vector3,
    /// Angular velocity (rad/s).
    pub angular: Vector3,
}

/// `geometry_msgs/TwistStamped`, with the wire's header `H` (what Jazzy's TurtleBot3 bridge
/// file puts on cmd_vel).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistStamped<H> {
    /// Stamp and frame.
    pub header: H,
    /// The twist.
    pub twist: Twist,
}

/// `sensor_msgs/JointState`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointState<H> {
    /// Stamp (the frame is empty).
    pub header: H,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions (rad or m).
    pub position: Vec<f64>,
    /// Velocities (rad/s or m/s).
    pub velocity: Vec<f64>,
    /// Efforts (N m or N).
    pub effort: Vec<f64>,
}

/// `sensor_msgs/LaserScan`, with the wire's header `H` and its buffer of ranges `R`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LaserScan<H, R> {
    /// Stamp and the scanner's frame.
    pub header: H,
    /// First ray's angle (rad).
    pub angle_min: f32,
    /// Last ray's angle (rad).
    pub angle_max: f32,
    /// Between rays (rad).
    pub angle_increment: f32,
    /// Between rays (s).
    pub time_increment: f32,
    /// Between scans (s).
    pub scan_time: f32,
    /// Shortest range (m).
    pub range_min: f32,
    /// Longest range (m).
    pub range_max: f32,
    /// Ranges (m); infinity where a ray hits nothing.
    pub ranges: R,
    /// Intensities (empty: rover's laser measures none).
    pub intensities: Vec<f32>,
}

/// `sensor_msgs/Imu`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Imu<H> {
    /// Stamp and the sensor's frame.
    pub header: H,
    /// Orientation of the sensor.
    pub orientation: Quaternion,
    /// Its covariance, row-major 3x3 (about x, y, z).
    pub orientation_covariance: [f64; 9],
    /// Angular velocity (rad/s) about the sensor's axes.
    pub angular_velocity: Vector3,
    /// Its covariance.
    pub angular_velocity_covariance: [f64; 9],
    /// Linear acceleration (m/s^2) along the sensor's axes, gravity included.
    pub linear_acceleration: Vector3,
    /// Its covariance.
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/NavSatStatus`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatStatus {
    /// -1 no fix, 0 fix, 1 SBAS fix, 2 GBAS fix.
    pub status: i8,
    /// Bits: 1 GPS, 2 GLONASS, 4 COMPASS, 8 GALILEO.
    pub service: u16,
}

/// `sensor_msgs/NavSatFix`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatFix<H> {
    /// Stamp and the receiver's frame.
    pub header: H,
    /// Fix status and satellite services.
    pub status: NavSatStatus,
    /// Latitude (deg, north positive).
    pub latitude: f64,
    /// Longitude (deg, east positive).
    pub longitude: f64,
    /// Altitude (m).
    pub altitude: f64,
    /// Position covariance (m^2), row-major 3x3 in east, north, up.
    pub position_covariance: [f64; 9],
    /// 0 unknown, 1 approximated, 2 diagonal known, 3 known.
    pub position_covariance_type: u8,
}

/// `geometry_msgs/Vector3Stamped`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3Stamped<H> {
    /// Stamp and frame.
    pub header: H,
    /// The vector.
    pub vector: Vector3,
}

/// `darknet_ros_msgs/BoundingBox` (ROS 1 names the class `Class`, ROS 2 `class_id`; both
/// write it last).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct BoundingBox {
    /// Confidence, 0..1.
    pub probability: f64,
    /// Left edge (px).
    pub xmin: i64,
    /// Top edge (px).
    pub ymin: i64,
    /// Right edge (px).
    pub xmax: i64,
    /// Bottom edge (px).
    pub ymax: i64,
    /// Class index.
    pub id: i16,
    /// Class name (ROS 1's `Class`).
    pub class_id: String,
}

/// `darknet_ros_msgs/BoundingBoxes`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct BoundingBoxes<H> {
    /// When published.
    pub header: H,
    /// The detected image's header.
    pub image_header: H,
    /// The boxes, highest probability first.
    pub bounding_boxes: Vec<BoundingBox>,
}

/// `darknet_ros_msgs/ObjectCount`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ObjectCount<H> {
    /// When published.
    pub header: H,
    /// Boxes.
    pub count: i8,
}

/// `geometry_msgs/PointStamped`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PointStamped<H> {
    /// Stamp and frame.
    pub header: H,
    /// The point (m).
    pub point: Vector3,
}

/// `gazebo_msgs/ModelStates`: every model's name, world pose and world twist.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelStates {
    /// Model names.
    pub name: Vec<String>,
    /// Their poses in the world.
    pub pose: Vec<Pose>,
    /// Their twists in the world.
    pub twist: Vec<Twist>,
}

/// `std_msgs/String`: a line of text.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Text {
    /// The text.
    pub data: String,
}

/// `sensor_msgs/Image`, with the wire's header `H` and its pixel buffer `B`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Image<H, B> {
    /// Stamp and optical frame.
    pub header: H,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// `rgb8`, `32FC1`, ...
    pub encoding: String,
    /// 0: little-endian.
    pub is_bigendian: u8,
    /// Bytes per row.
    pub step: u32,
    /// Pixels, rows top to bottom.
    pub data: B,
}

/// `sensor_msgs/RegionOfInterest` (all zero: the full image).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RegionOfInterest {
    /// Left (px).
    pub x_offset: u32,
    /// Top (px).
    pub y_offset: u32,
    /// Height (px).
    pub height: u32,
    /// Width (px).
    pub width: u32,
    /// Whether to rectify.
    pub do_rectify: bool,
}

/// `sensor_msgs/CameraInfo`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CameraInfo<H> {
    /// Stamp and optical frame.
    pub header: H,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// `plumb_bob`.
    pub distortion_model: String,
    /// Distortion coefficients.
    pub d: Vec<f64>,
    /// Intrinsics, row-major 3x3.
    pub k: [f64; 9],
    /// Rectification, row-major 3x3.
    pub r: [f64; 9],
    /// Projection, row-major 3x4.
    pub p: [f64; 12],
    /// Horizontal binning (0 or 1: none).
    pub binning_x: u32,
    /// Vertical binning.
    pub binning_y: u32,
    /// Region of interest.
    pub roi: RegionOfInterest,
}

/// `sensor_msgs/PointField`: one field of every point of a [`PointCloud2`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PointField {
    /// Its name (`x`, `rgb`, `ring`, ...).
    pub name: String,
    /// Where it starts in the point (bytes).
    pub offset: u32,
    /// `INT8 = 1` ... `FLOAT64 = 8`.
    pub datatype: u8,
    /// Values in the field.
    pub count: u32,
}

/// `sensor_msgs/PointCloud2`, with the wire's header `H` and its byte buffer `B`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PointCloud2<H, B> {
    /// Stamp and the points' frame.
    pub header: H,
    /// Rows (1: unorganized).
    pub height: u32,
    /// Points per row.
    pub width: u32,
    /// What each point holds.
    pub fields: Vec<PointField>,
    /// Big-endian data (rover: never).
    pub is_bigendian: bool,
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes per row.
    pub row_step: u32,
    /// The points.
    pub data: B,
    /// No point is invalid (NaN).
    pub is_dense: bool,
}

/// `geometry_msgs/Wrench`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Wrench {
    /// Force (N).
    pub force: Vector3,
    /// Torque (N m).
    pub torque: Vector3,
}

/// `gazebo_msgs/ContactState`: one collision touching another.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactState {
    /// Free text.
    pub info: String,
    /// The bumper's collision, scoped (`model::link::collision`).
    pub collision1_name: String,
    /// The other collision.
    pub collision2_name: String,
    /// The wrench at each contact point, on collision 1.
    pub wrenches: Vec<Wrench>,
    /// Their sum.
    pub total_wrench: Wrench,
    /// Contact points.
    pub contact_positions: Vec<Vector3>,
    /// Contact normals.
    pub contact_normals: Vec<Vector3>,
    /// Penetration depths (m).
    pub depths: Vec<f64>,
}

/// `gazebo_msgs/ContactsState`, with the wire's header `H`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactsState<H> {
    /// Stamp and the frame of the points, normals and wrenches.
    pub header: H,
    /// One per collision touched.
    pub states: Vec<ContactState>,
}

/// Names, in a wire's `msgs` module, the messages above that carry a header, with the wire's
/// header type, pixel buffer and range buffer: `wire_messages!(Header, Vec<u8>, Vec<f32>)`
/// declares `Image`, `CameraInfo`, `JointState`, `LaserScan`, `Imu`, `NavSatFix`,
/// `Vector3Stamped`, `BoundingBoxes`, `ObjectCount`, `PointStamped`, `PointCloud2` and `ContactsState` there.
#[macro_export]
macro_rules! wire_messages {
    ($header:ty, $pixels:ty, $ranges:ty) => {
        /// `sensor_msgs/Image`.
        pub type Image = $crate::Image<$header, $pixels>;
        /// `sensor_msgs/CameraInfo`.
        pub type CameraInfo = $crate::CameraInfo<$header>;
        /// `sensor_msgs/JointState`.
        pub type JointState = $crate::JointState<$header>;
        /// `geometry_msgs/TwistStamped`.
        pub type TwistStamped = $crate::TwistStamped<$header>;
        /// `sensor_msgs/LaserScan`.
        pub type LaserScan = $crate::LaserScan<$header, $ranges>;
        /// `sensor_msgs/Imu`.
        pub type Imu = $crate::Imu<$header>;
        /// `sensor_msgs/NavSatFix`.
        pub type NavSatFix = $crate::NavSatFix<$header>;
        /// `geometry_msgs/Vector3Stamped`.
        pub type Vector3Stamped = $crate::Vector3Stamped<$header>;
        /// `darknet_ros_msgs/BoundingBoxes`.
        pub type BoundingBoxes = $crate::BoundingBoxes<$header>;
        /// `darknet_ros_msgs/ObjectCount`.
        pub type ObjectCount = $crate::ObjectCount<$header>;
        /// `geometry_msgs/PointStamped`.
        pub type PointStamped = $crate::PointStamped<$header>;
        /// `sensor_msgs/PointCloud2`.
        pub type PointCloud2 = $crate::PointCloud2<$header, $pixels>;
        /// `gazebo_msgs/ContactsState`.
        pub type ContactsState = $crate::ContactsState<$header>;
        pub use $crate::{
            BoundingBox, ContactState, ModelStates, NavSatStatus, PointField, Pose, Quaternion,
            RegionOfInterest, Text, Twist, Vector3, Wrench,
        };
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_yaw_is_a_rotation_about_z() {
        let q = Quaternion::from_yaw(std::f64::consts::FRAC_PI_2);
        let half = std::f64::consts::FRAC_1_SQRT_2;
        assert!((q.z - half).abs() < 1e-12 && (q.w - half).abs() < 1e-12);
        assert_eq!((q.x, q.y), (0.0, 0.0));
        assert_eq!(Quaternion::default(), Quaternion::from_yaw(0.0));
    }
}
