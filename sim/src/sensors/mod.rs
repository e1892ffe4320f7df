//! Sensors on sim time: the camera (`camera.rs`, rendering through `render`; its depth image
//! as a point cloud, `cloud.rs`); the 2D laser (`laser.rs`) and the 3D lidar (`lidar.rs`), ray
//! casts against the physics scene and people's bones (`rays.rs`); from a link's motion the
//! IMU (`imu.rs`), p3d's ground-truth pose (`p3d.rs`) and hector's GPS (`gps.rs`), all with
//! seeded noise; bumpers from the physics contacts (`bumper.rs`); and the camera's ground
//! truth (`ground_truth.rs`: where each labelled thing is in the image).

pub(crate) mod bumper;
pub(crate) mod camera;
pub(crate) mod cloud;
pub(crate) mod gps;
pub(crate) mod ground_truth;
pub(crate) mod imu;
pub(crate) mod laser;
pub(crate) mod lidar;
pub(crate) mod p3d;
pub(crate) mod rays;
pub(crate) mod schedule;

pub use bumper::{BumperSensor, ContactsReading};
pub use camera::{CameraFrame, CameraSensor};
pub use cloud::{
    CloudField, CloudLayout, CloudSource, DepthCloudBuilder, POINT_FIELD_FLOAT32,
    POINT_FIELD_UINT16, PointCloud,
};
pub use gps::{
    Ellipsoid, FixReading, GpsSensor, WGS84_EQUATORIAL_RADIUS_M, WGS84_FLATTENING, wgs84_radii_m,
};
pub use ground_truth::{
    GroundTruth, GroundTruthBox, MIN_VISIBILITY, MIN_VISIBLE_PX, PixelBox, copy_boxes,
};
pub use imu::{ImuReading, ImuSensor};
pub use laser::{LaserScan, LaserSensor};
pub use lidar::LidarSensor;
pub use p3d::{P3dSensor, PoseReading};
pub use schedule::Schedule;
