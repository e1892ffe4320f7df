//! The world and robot options every simulating command shares ([`WorldArgs`]), with their
//! value parsers.

use std::path::PathBuf;

use clap::Args;
use rover_core::RunConfig;
use rover_sim::physics::SimOptions;

use super::parsers::parse_package_path;

#[derive(Debug, Args)]
pub(crate) struct WorldArgs {
    /// World file: TOML (see docs/WORLDS.md) or a Gazebo SDF world (.world, .sdf)
    /// [default: worlds/playground.toml]
    #[arg(long, value_name = "FILE")]
    pub(crate) world: Option<PathBuf>,

    /// Robot URDF or xacro (.urdf.xacro, .xacro; expanded in-process, no ROS needed)
    /// [default: the world's [robot] urdf, else assets/robots/my_robot.urdf]
    #[arg(long, value_name = "FILE")]
    pub(crate) robot: Option<PathBuf>,

    /// A xacro argument, NAME:=VALUE, for $(arg NAME) in the robot's xacro (repeatable;
    /// overrides the world's [robot] xacro_args)
    #[arg(long = "xacro-arg", value_name = "NAME:=VALUE", value_parser = parse_xacro_arg)]
    pub(crate) xacro_args: Vec<(String, String)>,

    /// Where ROS package NAME is, for package://NAME/... and $(find NAME) (repeatable). Without
    /// it packages are found upward from the robot file (package.xml <name>) and in
    /// ROS_PACKAGE_PATH
    #[arg(long = "package-path", value_name = "NAME=DIR", value_parser = parse_package_path)]
    pub(crate) package_paths: Vec<(String, PathBuf)>,

    /// Where the robot spawns: X,Y in metres and an optional heading in degrees
    /// (counter-clockwise from +x), overriding the world's [robot]
    #[arg(long, value_name = "X,Y[,YAW_DEG]", value_parser = parse_spawn)]
    pub(crate) spawn: Option<[f64; 3]>,

    /// Drive the wheel joints LEFT and RIGHT like gazebo_ros_diff_drive, for a robot whose URDF
    /// names no drive plugin (separation and diameter from the URDF); overrides the world's
    /// [robot.drive]
    #[arg(long, value_name = "LEFT_JOINT,RIGHT_JOINT", value_parser = parse_drive)]
    pub(crate) drive: Option<rover_sim::model::DriveSpec>,

    /// The camera to render when the robot has several: its <sensor name> or cameraName
    /// [default: the first in the file]
    #[arg(long, value_name = "NAME")]
    pub(crate) camera: Option<String>,

    /// A folder of Gazebo models, for model://NAME in SDF worlds (repeatable; searched before
    /// GAZEBO_MODEL_PATH)
    #[arg(long = "model-path", value_name = "DIR")]
    pub(crate) model_paths: Vec<PathBuf>,

    /// Physics step rate in Hz, overriding the world's [physics] step_hz
    #[arg(long, value_name = "HZ")]
    pub(crate) physics_hz: Option<f64>,

    /// How the robot's joints are solved, overriding the world's [physics] joints: impulse
    /// (a constraint per joint, the default) or multibody (reduced coordinates: long arms
    /// with light links, fixed-base arms)
    #[arg(long, value_name = "SOLVER", value_parser = parse_joint_solver)]
    pub(crate) joints: Option<rover_sim::model::JointSolver>,

    /// A ros_control controllers YAML for the robot (overrides the world's [robot]
    /// controllers): joint_state_controller, Joint{Position,Velocity,Effort}Controller and
    /// JointTrajectoryController, gazebo_ros_control/pid_gains, and rover's named_poses.
    /// Without one every actuated joint holds its pose and takes commands by joint name
    #[arg(long, value_name = "FILE.yaml")]
    pub(crate) controllers: Option<PathBuf>,

    /// A ros_gz_bridge topic map (the YAML parameter_bridge takes as config_file) naming the
    /// robot's gz-sim topics on ROS 1 and ROS 2: each entry's gz_topic_name is published as its
    /// ros_topic_name and ros_type_name (cmd_vel as geometry_msgs/msg/TwistStamped where it
    /// says so). Overrides the world's [robot] bridge_config. Without one, a gz topic's ROS
    /// name is the gz name itself
    #[arg(long = "bridge-config", value_name = "FILE.yaml")]
    pub(crate) bridge_config: Option<PathBuf>,

    /// Seed for everything random; the same seed gives the same run
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
}

/// `NAME:=VALUE` (xacro's own spelling; `NAME=VALUE` is accepted too).
fn parse_xacro_arg(s: &str) -> Result<(String, String), String> {
    let (name, value) = s
        .split_once(":=")
        .or_else(|| s.split_once('='))
        .ok_or_else(|| format!("expected NAME:=VALUE, found \"{s}\""))?;
    if name.is_empty() {
        return Err(format!(
            "expected NAME:=VALUE with a non-empty NAME, found \"{s}\""
        ));
    }
    Ok((name.to_owned(), value.to_owned()))
}

/// `LEFT_JOINT,RIGHT_JOINT`.
fn parse_drive(s: &str) -> Result<rover_sim::model::DriveSpec, String> {
    match s.split(',').map(str::trim).collect::<Vec<_>>().as_slice() {
        [left, right] if !left.is_empty() && !right.is_empty() => Ok(rover_sim::model::DriveSpec {
            left_joint: (*left).to_owned(),
            right_joint: (*right).to_owned(),
            wheel_separation_m: None,
            wheel_diameter_m: None,
            wheel_torque_nm: None,
            wheel_acceleration_mps2: None,
        }),
        _ => Err(format!("expected LEFT_JOINT,RIGHT_JOINT, found \"{s}\"")),
    }
}

/// `X,Y` or `X,Y,YAW_DEG`.
fn parse_spawn(s: &str) -> Result<[f64; 3], String> {
    let values: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("expected X,Y[,YAW_DEG] as finite numbers, found \"{s}\""))?;
    match values.as_slice() {
        [x, y] => Ok([*x, *y, 0.0]),
        [x, y, yaw] => Ok([*x, *y, *yaw]),
        _ => Err(format!("expected X,Y[,YAW_DEG], found \"{s}\"")),
    }
}

impl WorldArgs {
    /// The robot-loading options these arguments give.
    pub(crate) fn robot_options(&self) -> rover_sim::description::LoadOptions {
        let mut options = rover_sim::description::LoadOptions::default();
        options.xacro_args.extend(self.xacro_args.iter().cloned());
        options
            .resources
            .packages
            .extend(self.package_paths.iter().cloned());
        options
            .resources
            .model_search
            .extend(self.model_paths.iter().cloned());
        options
    }

    /// A run of this world and robot; the rest at its defaults.
    pub(crate) fn run_config(&self, cmd_timeout_s: Option<f64>) -> RunConfig {
        RunConfig {
            world: self.world.clone(),
            robot: self.robot.clone(),
            robot_options: self.robot_options(),
            spawn: self.spawn,
            drive: self.drive.clone(),
            camera: self.camera.clone(),
            controllers: self.controllers.clone(),
            bridge_config: self.bridge_config.clone(),
            options: SimOptions {
                seed: self.seed,
                cmd_timeout_s,
                step_hz: self.physics_hz,
                joints: self.joints,
            },
            ..RunConfig::default()
        }
    }
}

fn parse_joint_solver(text: &str) -> Result<rover_sim::model::JointSolver, String> {
    match text {
        "multibody" => Ok(rover_sim::model::JointSolver::Multibody),
        "impulse" => Ok(rover_sim::model::JointSolver::Impulse),
        other => Err(format!("expected multibody or impulse, found '{other}'")),
    }
}
