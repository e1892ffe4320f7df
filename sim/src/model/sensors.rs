//! Sensors a robot carries, as its `<gazebo>` `<sensor>` blocks and their plugins describe them.

use crate::geometry::Pose;

/// Pixel format of a camera image (`<image><format>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelFormat {
    /// `R8G8B8` (ROS encoding `rgb8`).
    Rgb8,
    /// `B8G8R8` (ROS encoding `bgr8`).
    Bgr8,
    /// `L8` (ROS encoding `mono8`).
    Mono8,
}

/// Gaussian noise (`<noise type="gaussian">`): on the 0..1 scale per channel for a camera, in
/// metres for a laser's ranges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianNoise {
    /// Mean.
    pub mean: f64,
    /// Standard deviation.
    pub stddev: f64,
}

/// Brown-Conrady lens distortion (`<distortion>` or the camera plugin's `distortionK1`...).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Distortion {
    /// Radial k1.
    pub k1: f64,
    /// Radial k2.
    pub k2: f64,
    /// Radial k3.
    pub k3: f64,
    /// Tangential p1 (Gazebo's t1).
    pub p1: f64,
    /// Tangential p2 (Gazebo's t2).
    pub p2: f64,
}

impl Distortion {
    /// True when every coefficient is zero.
    pub fn is_zero(&self) -> bool {
        [self.k1, self.k2, self.k3, self.p1, self.p2]
            .iter()
            .all(|c| *c == 0.0)
    }

    /// Brown-Conrady lens distortion as gazebo_ros_camera applies it, on normalised image
    /// coordinates (x = (u - cx) / fx, y = (v - cy) / fy): the distorted point of an ideal one.
    pub fn distort(&self, x: f64, y: f64) -> (f64, f64) {
        let r2 = x * x + y * y;
        let radial = 1.0 + self.k1 * r2 + self.k2 * r2 * r2 + self.k3 * r2 * r2 * r2;
        let dx = 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x);
        let dy = self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y;
        (x * radial + dx, y * radial + dy)
    }
}

/// A `<sensor type="camera">` attached to a link.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraConfig {
    /// Sensor `name`.
    pub name: String,
    /// Link the sensor is attached to (`<gazebo reference>`).
    pub link: String,
    /// `<update_rate>` (Hz, sim time).
    pub update_rate_hz: f64,
    /// `<horizontal_fov>` (rad).
    pub horizontal_fov_rad: f64,
    /// `<image><width>` (px).
    pub width_px: u32,
    /// `<image><height>` (px).
    pub height_px: u32,
    /// `<image><format>`.
    pub format: PixelFormat,
    /// `<clip><near>` (m).
    pub clip_near_m: f64,
    /// `<clip><far>` (m).
    pub clip_far_m: f64,
    /// Optional gaussian noise.
    pub noise: Option<GaussianNoise>,
    /// Lens distortion (zero when absent).
    pub distortion: Distortion,
    /// The camera plugin's `<cameraName>` (default: the sensor name).
    pub camera_name: String,
    /// The camera plugin's `<frameName>` (default: the link).
    pub frame_name: String,
    /// The camera plugin's `<imageTopicName>` (default `image_raw`).
    pub image_topic: String,
    /// The camera plugin's `<cameraInfoTopicName>` (default `camera_info`).
    pub info_topic: String,
    /// A depth camera's depth outputs (`<sensor type="depth">`); `None` for a colour camera.
    pub depth: Option<DepthOutput>,
    /// Line of the `<sensor>` element, for messages.
    pub line: Option<u32>,
}

/// What a depth camera (`<sensor type="depth">`, gazebo_ros_openni_kinect) publishes besides
/// its colour image: a 32FC1 depth image (metres along the optical axis), its camera_info and
/// an organized point cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthOutput {
    /// `<depthImageTopicName>` (default `depth/image_raw`).
    pub image_topic: String,
    /// `<depthImageCameraInfoTopicName>` (default `depth/camera_info`).
    pub info_topic: String,
    /// `<pointCloudTopicName>` (default `points`): the organized cloud, x y z rgb.
    pub cloud_topic: String,
    /// `<pointCloudCutoff>` (m, default 0.4): nearer depths are no point (NaN).
    pub cloud_cutoff_m: f64,
    /// `<pointCloudCutoffMax>` (m; 5.0 for gazebo_ros_openni_kinect, none for
    /// gazebo_ros_depth_camera): farther depths are no point (NaN).
    pub cloud_cutoff_max_m: f64,
}

impl Default for DepthOutput {
    fn default() -> Self {
        Self {
            image_topic: "depth/image_raw".to_owned(),
            info_topic: "depth/camera_info".to_owned(),
            cloud_topic: "points".to_owned(),
            cloud_cutoff_m: 0.4,
            cloud_cutoff_max_m: 5.0,
        }
    }
}

/// A 2D laser scanner: `<sensor type="ray">` (or `gpu_ray`) with `libgazebo_ros_laser.so`'s
/// parameters. One horizontal plane of rays, as Gazebo's ray sensor with one vertical sample.
#[derive(Debug, Clone, PartialEq)]
pub struct LaserConfig {
    /// Sensor `name`.
    pub name: String,
    /// Link the sensor is attached to (`<gazebo reference>`).
    pub link: String,
    /// The sensor's `<pose>` in its link (x y z roll pitch yaw).
    pub link_from_sensor: Pose,
    /// `<update_rate>` (Hz, sim time).
    pub update_rate_hz: f64,
    /// `<scan><horizontal><samples>` times `<resolution>`: rays per scan.
    pub samples: u32,
    /// `<min_angle>` (rad, counter-clockwise from the sensor's x axis).
    pub min_angle_rad: f64,
    /// `<max_angle>` (rad).
    pub max_angle_rad: f64,
    /// `<range><min>` (m): closer returns read as -inf (REP-117).
    pub range_min_m: f64,
    /// `<range><max>` (m): no return within it reads as +inf (REP-117).
    pub range_max_m: f64,
    /// `<range><resolution>` (m): ranges are rounded to multiples of it.
    pub range_resolution_m: f64,
    /// Gaussian range noise (m), `<ray><noise>`.
    pub noise: Option<GaussianNoise>,
    /// The laser plugin's `<topicName>` (default `scan`).
    pub topic: String,
    /// The laser plugin's `<frameName>` (default: the link).
    pub frame_name: String,
    /// Line of the `<sensor>` element, for messages.
    pub line: Option<u32>,
}

impl LaserConfig {
    /// Angle between two rays (rad): Gazebo spreads the samples from min to max inclusive.
    pub fn angle_increment_rad(&self) -> f64 {
        if self.samples > 1 {
            (self.max_angle_rad - self.min_angle_rad) / f64::from(self.samples - 1)
        } else {
            0.0
        }
    }
}

/// A 3D lidar: a `<sensor type="ray">` (or `gpu_ray`) whose `<scan><vertical><samples>` is more
/// than one, published as a sensor_msgs/PointCloud2 of x y z intensity ring (the fields
/// velodyne_pointcloud uses), never flattened to a LaserScan. velodyne_simulator's
/// `libgazebo_ros_velodyne_laser.so` (and `_gpu_laser`) parameters; any other ray plugin's
/// `topicName` and `frameName`.
#[derive(Debug, Clone, PartialEq)]
pub struct LidarConfig {
    /// The ray sensor as a 2D laser reads it: name, link, pose, rate, the horizontal scan,
    /// `<range>`, `<noise>`, the plugin's topic (default `points`) and frame.
    pub rays: LaserConfig,
    /// `<vertical><samples>` times `<resolution>`: beams (rings).
    pub vertical_samples: u32,
    /// `<vertical><min_angle>` (rad, elevation of the lowest beam, up positive).
    pub vertical_min_angle_rad: f64,
    /// `<vertical><max_angle>` (rad).
    pub vertical_max_angle_rad: f64,
    /// The plugin's `<min_range>` (m, default 0): returns at or inside it are dropped.
    pub min_range_m: f64,
    /// The plugin's `<max_range>` (m, default none): returns at or beyond it are dropped.
    pub max_range_m: f64,
    /// The plugin's `<gaussianNoise>` (m, stddev; default 0).
    pub gaussian_noise_m: f64,
    /// The plugin's `<organize_cloud>` (default false): rings as rows with NaN where a beam
    /// has no return; otherwise one row of the returns only.
    pub organize: bool,
}

impl LidarConfig {
    /// Angle between two beams (rad): the samples spread from min to max inclusive.
    pub fn vertical_increment_rad(&self) -> f64 {
        if self.vertical_samples > 1 {
            (self.vertical_max_angle_rad - self.vertical_min_angle_rad)
                / f64::from(self.vertical_samples - 1)
        } else {
            0.0
        }
    }

    /// Elevation of ring `ring` (rad; ring 0 is the lowest beam).
    pub fn ring_elevation_rad(&self, ring: u32) -> f64 {
        self.vertical_min_angle_rad + f64::from(ring) * self.vertical_increment_rad()
    }

    /// Rays per scan (beams times horizontal samples).
    pub fn rays_per_scan(&self) -> u64 {
        u64::from(self.vertical_samples) * u64::from(self.rays.samples)
    }
}

/// Rays per scan rover accepts (a 0.1 deg lidar has 3600; more is a typo, not a sensor).
pub const MAX_LASER_SAMPLES: u32 = 100_000;

/// Noise of one axis of an IMU channel, SDF's `<noise type="gaussian">` with a bias: every
/// sample gets white noise of `mean` and `stddev`; the bias is drawn once, at start, from
/// `bias_mean` and `bias_stddev` and given a random sign, as Gazebo draws it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AxisNoise {
    /// `<mean>` of the white noise.
    pub mean: f64,
    /// `<stddev>` of the white noise.
    pub stddev: f64,
    /// `<bias_mean>`: the bias's magnitude on average.
    pub bias_mean: f64,
    /// `<bias_stddev>`: the spread of the bias drawn at start.
    pub bias_stddev: f64,
}

impl AxisNoise {
    /// True when the axis reads exactly (every parameter zero).
    pub fn is_zero(&self) -> bool {
        [self.mean, self.stddev, self.bias_mean, self.bias_stddev]
            .iter()
            .all(|v| *v == 0.0)
    }
}

/// What an IMU's orientation is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrientationReference {
    /// The world's axes (REP-103/REP-145: x east... as the world's x, z up).
    World,
    /// The sensor's own orientation when the simulation starts (Gazebo classic's `ImuSensor`
    /// by default; `initialOrientationAsReference` true).
    Initial,
}

/// Which Gazebo plugin declared an IMU: their defaults differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuPlugin {
    /// `<sensor type="imu">` with `libgazebo_ros_imu_sensor.so` inside it.
    Sensor,
    /// The model plugin `libgazebo_ros_imu.so` (TurtleBot3's), naming its link by `<bodyName>`.
    Model,
}

/// An IMU: orientation, angular velocity and linear acceleration (gravity included, as a real
/// accelerometer reads it: +9.81 m/s^2 up at rest), published as sensor_msgs/Imu.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuConfig {
    /// Sensor (or plugin) `name`.
    pub name: String,
    /// Which plugin declared it.
    pub plugin: ImuPlugin,
    /// Link the IMU is fixed to (`<gazebo reference>`, or the model plugin's `<bodyName>`).
    pub link: String,
    /// The sensor's `<pose>` in its link (identity for the model plugin).
    pub link_from_sensor: Pose,
    /// Readings per second of sim time (0: every physics step).
    pub update_rate_hz: f64,
    /// Topic, resolved as the plugin resolves it (without a leading `/` when relative).
    pub topic: String,
    /// `frame_id` of the messages (`<frameName>`).
    pub frame_name: String,
    /// `<rpyOffset>` (rad): a fixed rotation applied to the reported orientation.
    pub rpy_offset_rad: [f64; 3],
    /// What the orientation is relative to.
    pub reference: OrientationReference,
    /// The plugin's `<gaussianNoise>`: white noise of this stddev on every component (the
    /// quaternion's too, as gazebo_ros does), and the messages' covariance diagonals.
    pub gaussian_noise: f64,
    /// SDF `<imu>` noise of the angular velocity, per axis x, y, z (rad/s).
    pub angular_velocity_noise: [AxisNoise; 3],
    /// SDF `<imu>` noise of the linear acceleration, per axis x, y, z (m/s^2).
    pub linear_acceleration_noise: [AxisNoise; 3],
    /// Line of the declaring element, for messages.
    pub line: Option<u32>,
}

/// Ground truth of a link's pose and velocity: the model plugin `libgazebo_ros_p3d.so`,
/// published as nav_msgs/Odometry.
#[derive(Debug, Clone, PartialEq)]
pub struct P3dConfig {
    /// Plugin `name`.
    pub name: String,
    /// The link whose pose is reported (`<bodyName>`).
    pub link: String,
    /// Topic (`<topicName>`, in `<robotNamespace>`).
    pub topic: String,
    /// `<frameName>` (default `world`): `world` or `map` for the world, else a link of the robot
    /// the pose and velocity are measured against. The messages' `frame_id`.
    pub frame_name: String,
    /// The link measured against, `None` for the world.
    pub reference_link: Option<String>,
    /// `<xyzOffsets>` (m), added to the position.
    pub xyz_offset_m: [f64; 3],
    /// `<rpyOffsets>` (rad), turning the orientation.
    pub rpy_offset_rad: [f64; 3],
    /// `<gaussianNoise>`: white noise of this stddev on position and velocities, and the
    /// covariance diagonals.
    pub gaussian_noise: f64,
    /// `<updateRate>` (Hz; 0: every physics step).
    pub update_rate_hz: f64,
    /// Line of the plugin element, for messages.
    pub line: Option<u32>,
}

/// Which GPS model a receiver follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GpsSource {
    /// hector_gazebo_plugins' model plugin, `libhector_gazebo_ros_gps.so`: its own reference
    /// point and heading, WGS-84's radii at the reference latitude.
    Hector,
    /// Gazebo's `<sensor type="gps">` with `libgazebo_ros_gps_sensor.so`: the world's
    /// `<spherical_coordinates>`, exact on the WGS-84 ellipsoid; the position the sensor's,
    /// the velocity east, north, up.
    Sensor,
}

/// One of hector's error models (`SensorModel`), per axis x, y, z: a constant `offset`, a
/// drift (a first-order Gauss-Markov process of stationary stddev `drift`, mean-reverting at
/// `drift_frequency_hz`) and white `gaussian_noise`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorModel {
    /// `<offset>` (or `<velocityOffset>`).
    pub offset: [f64; 3],
    /// `<drift>`: the drift's stddev.
    pub drift: [f64; 3],
    /// `<driftFrequency>` (Hz; hector's default 1/3600).
    pub drift_frequency_hz: [f64; 3],
    /// `<gaussianNoise>`: white noise's stddev.
    pub gaussian_noise: [f64; 3],
}

impl Default for ErrorModel {
    fn default() -> Self {
        Self {
            offset: [0.0; 3],
            drift: [0.0; 3],
            drift_frequency_hz: [1.0 / 3600.0; 3],
            gaussian_noise: [0.0; 3],
        }
    }
}

/// A GPS receiver: hector_gazebo_plugins' model plugin `libhector_gazebo_ros_gps.so`, publishing
/// sensor_msgs/NavSatFix and a geometry_msgs/Vector3Stamped velocity.
#[derive(Debug, Clone, PartialEq)]
pub struct GpsConfig {
    /// Plugin `name`.
    pub name: String,
    /// Which GPS model declared it.
    pub source: GpsSource,
    /// The link whose origin is located (`<bodyName>`; default the robot's root link; the
    /// sensor form: its `<gazebo reference>`).
    pub link: String,
    /// The sensor's `<pose>` in its link (the sensor form; identity for hector's).
    pub link_from_sensor: Pose,
    /// `<updateRate>` (Hz; default 4).
    pub update_rate_hz: f64,
    /// `<frameId>` (default `/world`, as hector's; the sensor form: `<frame_name>`, default its
    /// link).
    pub frame_id: String,
    /// The fix topic (`<topicName>`, default `fix`, in `<robotNamespace>`).
    pub topic: String,
    /// The velocity topic (`<velocityTopicName>`, default `fix_velocity`).
    pub velocity_topic: String,
    /// `<referenceLatitude>` (deg; default 49.9) of the world's origin.
    pub reference_latitude_deg: f64,
    /// `<referenceLongitude>` (deg; default 8.9).
    pub reference_longitude_deg: f64,
    /// `<referenceHeading>` (deg, clockwise from north, of the world's x axis; default 0: x
    /// north, y west; 90 makes x east and y north).
    pub reference_heading_deg: f64,
    /// `<referenceAltitude>` (m) of the world's origin.
    pub reference_altitude_m: f64,
    /// `<status>` (NavSatStatus: 0 fix).
    pub status: i8,
    /// `<service>` (NavSatStatus: 1 GPS).
    pub service: u16,
    /// The position's error model.
    pub position_error: ErrorModel,
    /// The velocity's error model (`velocity...` parameters).
    pub velocity_error: ErrorModel,
    /// Line of the plugin element.
    pub line: Option<u32>,
}

/// A bumper: `<sensor type="contact">` with `libgazebo_ros_bumper.so`, reporting what its link
/// touches as gazebo_msgs/ContactsState.
#[derive(Debug, Clone, PartialEq)]
pub struct BumperConfig {
    /// Sensor `name`.
    pub name: String,
    /// Link the sensor is attached to (`<gazebo reference>`): its own collision shapes (not
    /// those of links lumped into it by fixed joints, which Gazebo names apart).
    pub link: String,
    /// `<contact><collision>`: the collision the sensor watches, as written (the messages'
    /// `collision1_name` ends with it).
    pub collision: String,
    /// `<update_rate>` (Hz, sim time; 0: every physics step).
    pub update_rate_hz: f64,
    /// The plugin's `<bumperTopicName>` (default `bumper_states`), in its `<robotNamespace>`.
    pub topic: String,
    /// The plugin's `<frameName>` (default `world`): positions, normals and forces are given
    /// in the world, or in this link's frame.
    pub frame_name: String,
    /// The link the contacts are expressed in, `None` for the world.
    pub reference_link: Option<String>,
    /// Line of the `<sensor>` element, for messages.
    pub line: Option<u32>,
}

/// gz-sim's JointStatePublisher system (`gz-sim-joint-state-publisher-system`): the joints'
/// states on a topic, every update.
#[derive(Debug, Clone, PartialEq)]
pub struct JointStatePublisherConfig {
    /// `<topic>` (gz-sim's default `/world/<world>/model/<model>/joint_state`; rover names the
    /// world `default`).
    pub topic: String,
    /// `<joint_name>`s; empty: every joint.
    pub joints: Vec<String>,
    /// Line of the `<plugin>` element, for messages.
    pub line: Option<u32>,
}
