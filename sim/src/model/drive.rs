//! How a robot's wheels are driven: gazebo_ros_diff_drive's parameters (from the URDF's plugin)
//! or a world's `[robot.drive]` naming the wheels of a robot without one.

use serde::Deserialize;

/// Where the diff drive takes its odometry from (`<odometrySource>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OdometrySource {
    /// Ground truth from the simulator (`world`, Gazebo's default).
    World,
    /// Integrated from the wheel joints' measured speeds (`encoder`).
    Encoder,
}

/// gazebo_ros_diff_drive's parameters, Gazebo's defaults where the URDF is silent.
#[derive(Debug, Clone, PartialEq)]
pub struct DiffDriveConfig {
    /// Plugin `name` attribute.
    pub name: String,
    /// `<commandTopic>` (default `cmd_vel`).
    pub command_topic: String,
    /// `<odometryTopic>` (default `odom`).
    pub odometry_topic: String,
    /// `<odometryFrame>` (default `odom`).
    pub odometry_frame: String,
    /// `<robotBaseFrame>` (default `base_footprint`).
    pub robot_base_frame: String,
    /// `<leftJoint>` (default `left_joint`).
    pub left_joint: String,
    /// `<rightJoint>` (default `right_joint`).
    pub right_joint: String,
    /// More wheel joints driven like the left and right ones: a skid-steer robot's rear wheels
    /// (`leftRearJoint`, `rightRearJoint`, with `leftFrontJoint`/`rightFrontJoint` as
    /// `left_joint`/`right_joint`).
    pub extra_left_joints: Vec<String>,
    /// See [`Self::extra_left_joints`].
    pub extra_right_joints: Vec<String>,
    /// `<wheelSeparation>` (m, default 0.34).
    pub wheel_separation_m: f64,
    /// `<wheelDiameter>` (m, default 0.15).
    pub wheel_diameter_m: f64,
    /// `<wheelTorque>` (N m, default 5): the wheel motors' maximum torque.
    pub wheel_torque_nm: f64,
    /// `<wheelAcceleration>` (m/s^2 on the commanded wheel rim speed, as gazebo_ros_diff_drive
    /// applies it; default 0 = unlimited).
    pub wheel_acceleration_mps2: f64,
    /// `<updateRate>` (Hz, default 100): the control loop on sim time; 0 means every physics step.
    pub update_rate_hz: f64,
    /// `<odometrySource>` (default `world`).
    pub odometry_source: OdometrySource,
    /// `<publishWheelTF>` (default false).
    pub publish_wheel_tf: bool,
    /// `<publishOdomTF>` (default true).
    pub publish_odom_tf: bool,
    /// `<publishWheelJointState>` (default false).
    pub publish_wheel_joint_state: bool,
    /// rover's opt-in `<cmdTimeout>` (s): stop when no command arrived for this long. Gazebo has
    /// none (the last command applies forever), so the default is off.
    pub cmd_timeout_s: Option<f64>,
    /// Line of the `<plugin>` element, for messages.
    pub line: Option<u32>,
    /// Which plugin the parameters came from (names in messages, and the control rules).
    pub plugin: DrivePlugin,
    /// gz-sim DiffDrive's speed limiter on the body's forward speed (`*_linear_*` /
    /// `*_velocity`, `*_acceleration`, `*_jerk`); `None`: gazebo_ros_diff_drive's rim ramp.
    pub linear_limits: Option<SpeedLimits>,
    /// gz-sim DiffDrive's speed limiter on the turn rate (`*_angular_*`).
    pub angular_limits: Option<SpeedLimits>,
    /// gz-sim DiffDrive's `<odom_publisher_frequency>` (Hz): odometry and its transform go out
    /// at this rate; `None`: every control update, as gazebo_ros_diff_drive publishes.
    pub odometry_rate_hz: Option<f64>,
    /// gz-sim DiffDrive's `<tf_topic>`: where odom -> base goes (`None`: `/tf`).
    pub tf_topic: Option<String>,
    /// The command topic carries geometry_msgs/TwistStamped rather than Twist (a ros_gz_bridge
    /// map says so: Jazzy's TurtleBot3 bridge file does).
    pub command_stamped: bool,
}

/// The plugin a diff drive was declared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DrivePlugin {
    /// Gazebo classic's `libgazebo_ros_diff_drive.so` (or skid steer, or rover's `[robot.drive]`).
    #[default]
    GazeboRos,
    /// Modern Gazebo's `gz-sim-diff-drive-system` (`gz::sim::systems::DiffDrive`).
    GzSim,
}

impl DrivePlugin {
    /// The plugin's file name, for messages.
    pub fn filename(self) -> &'static str {
        match self {
            Self::GazeboRos => "libgazebo_ros_diff_drive.so",
            Self::GzSim => "gz-sim-diff-drive-system",
        }
    }

    /// The parameter naming the left (`right`: right) wheel joint, for messages.
    pub fn joint_parameter(self, right: bool) -> &'static str {
        match (self, right) {
            (Self::GazeboRos, false) => "leftJoint",
            (Self::GazeboRos, true) => "rightJoint",
            (Self::GzSim, false) => "left_joint",
            (Self::GzSim, true) => "right_joint",
        }
    }
}

/// gz-sim's SpeedLimiter bounds on one velocity (forward m/s or turn rad/s): each bound
/// infinite when not given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedLimits {
    /// `min_*_velocity` .. `max_*_velocity`.
    pub velocity: (f64, f64),
    /// `min_*_acceleration` .. `max_*_acceleration` (per second).
    pub acceleration: (f64, f64),
    /// `min_*_jerk` .. `max_*_jerk` (per second squared).
    pub jerk: (f64, f64),
}

impl Default for SpeedLimits {
    fn default() -> Self {
        let none = (f64::NEG_INFINITY, f64::INFINITY);
        Self {
            velocity: none,
            acceleration: none,
            jerk: none,
        }
    }
}

impl SpeedLimits {
    /// gz-sim's SpeedLimiter::Limit: `v` bounded by jerk (from the last two values `v0`,
    /// `v1`), then acceleration (from `v0`), then velocity, over the step `dt_s`.
    pub fn limit(&self, v: f64, v0: f64, v1: f64, dt_s: f64) -> f64 {
        if dt_s <= 0.0 {
            return v.clamp(self.velocity.0, self.velocity.1);
        }
        let mut out = v;
        // Jerk: the change of acceleration from (v1 -> v0) to (v0 -> out).
        let dv = out - v0;
        let dv0 = v0 - v1;
        let da = (dv - dv0).clamp(self.jerk.0 * dt_s * dt_s, self.jerk.1 * dt_s * dt_s);
        out = v0 + dv0 + da;
        let dv = (out - v0).clamp(self.acceleration.0 * dt_s, self.acceleration.1 * dt_s);
        out = v0 + dv;
        out.clamp(self.velocity.0, self.velocity.1)
    }
}

impl Default for DiffDriveConfig {
    fn default() -> Self {
        Self {
            name: "differential_drive_controller".to_owned(),
            command_topic: "cmd_vel".to_owned(),
            odometry_topic: "odom".to_owned(),
            odometry_frame: "odom".to_owned(),
            robot_base_frame: "base_footprint".to_owned(),
            left_joint: "left_joint".to_owned(),
            right_joint: "right_joint".to_owned(),
            extra_left_joints: Vec::new(),
            extra_right_joints: Vec::new(),
            wheel_separation_m: 0.34,
            wheel_diameter_m: 0.15,
            wheel_torque_nm: 5.0,
            wheel_acceleration_mps2: 0.0,
            update_rate_hz: 100.0,
            odometry_source: OdometrySource::World,
            publish_wheel_tf: false,
            publish_odom_tf: true,
            publish_wheel_joint_state: false,
            cmd_timeout_s: None,
            line: None,
            plugin: DrivePlugin::GazeboRos,
            linear_limits: None,
            angular_limits: None,
            odometry_rate_hz: None,
            tf_topic: None,
            command_stamped: false,
        }
    }
}

/// Wheels to drive like gazebo_ros_diff_drive, for a robot whose URDF has no drive plugin
/// (`[robot.drive]`, or `--drive LEFT,RIGHT`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// The left wheel's joint.
    pub left_joint: String,
    /// The right wheel's joint.
    pub right_joint: String,
    /// Distance between the wheels (m); default: between the two joints' origins.
    #[serde(default)]
    pub wheel_separation_m: Option<f64>,
    /// Wheel diameter (m); default: from the left wheel's collision cylinder or sphere.
    #[serde(default)]
    pub wheel_diameter_m: Option<f64>,
    /// Motor torque limit (N m); default gazebo_ros_diff_drive's 5.
    #[serde(default)]
    pub wheel_torque_nm: Option<f64>,
    /// Ramp on the commanded wheel rim speed (m/s^2), gazebo_ros_diff_drive's
    /// `wheelAcceleration` (a diff_drive_controller's `linear/x/max_acceleration` does the
    /// same for straight driving); default 0, unlimited.
    #[serde(default)]
    pub wheel_acceleration_mps2: Option<f64>,
}
