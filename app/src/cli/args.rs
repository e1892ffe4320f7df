//! The command line: every option and subcommand, with their checks.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use rover_core::{FollowerConfig, Perception, RunConfig};
use rover_perception::{
    DEFAULT_NMS_IOU, DEFAULT_THRESHOLD, DetectorConfig, FaultKind, InjectedFault, Runtime,
};
use rover_sim::SimOptions;

use crate::viewer::{ImageOptions, RecorderOptions, Viewer};

/// rover: a desktop robot simulator for learning robot perception.
///
/// A URDF differential-drive car with a camera, in a world from worlds/, stepped with rapier3d
/// physics and driven like Gazebo's diff_drive plugin (cmd_vel: linear.x m/s, angular.z rad/s;
/// REP-103 frames: x forward, y left, z up).
///
/// Without a subcommand rover opens the driver's station: a window with the car's camera, boxes
/// and a HUD; drive with teleop_twist_keyboard's keys (hold to drive) or a gamepad, press `f` to
/// let the follower drive toward the person, and watch everything in the Rerun viewer. With
/// --headless it runs as fast as the CPU allows from a script of timed inputs, deterministically.
#[derive(Debug, Parser)]
#[command(version, about, long_about, after_help = EXAMPLES)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Option<Command>,

    #[command(flatten)]
    pub(crate) run: RunArgs,
}

const EXAMPLES: &str = "\
Examples:
  rover                                             window + Rerun viewer on the default world
  rover --world worlds/walking.toml --viewer web    a walking person; viewer in the browser
  rover --headless                                  default world and robot for 10 s, print a summary
  rover --headless --record run.rrd                 the same, recorded for `rerun run.rrd`
  rover --headless --script drive.toml --trace out.csv
  rover --headless --world worlds/playground.toml --robot assets/robots/my_robot.urdf --duration 30 --seed 7
  roscore & rover --ros --headless                  join a ROS 1 graph: /cmd_vel in; /odom, /tf, camera, darknet_ros boxes out
  rover bench                                       physics-only real-time factor
  rover detect photo.jpg --out boxes.png            YOLO boxes on an image (the model's quick check)

Window keys (teleop_twist_keyboard layout; hold to drive, release to stop; --latched to keep going):
  u i o / j k l / m , .   drive       k, space  stop      q/z w/x e/c  speed/turn x1.1 / x0.9
  arrows                  drive       f  follow on/off    p  pause, n  single step    Esc  quit
Gamepad: hold LB (deadman) + left stick forward/back, right stick turn; A toggles follow.

Script format (TOML, times in sim seconds):
  steps = [
    { at = 0.0, cmd_vel = [0.5, 0.0] },   # linear.x m/s, angular.z rad/s
    { at = 2.0, key = \"j\" },              # teleop_twist_keyboard key: u i o j k l m , . q z w x e c space
    { at = 3.0, toggle = \"follow\" },      # flip manual/follow
  ]

Trace CSV columns (one row per diff-drive control update):
  sim_time_s,x_m,y_m,yaw_rad,odom_x_m,odom_y_m,odom_yaw_rad,cmd_linear_mps,cmd_angular_radps,mode";

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
    pub(crate) drive: Option<rover_sim::DriveSpec>,

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
    pub(crate) joints: Option<rover_sim::JointSolver>,

    /// A ros_control controllers YAML for the robot (overrides the world's [robot]
    /// controllers): joint_state_controller, Joint{Position,Velocity,Effort}Controller and
    /// JointTrajectoryController, gazebo_ros_control/pid_gains, and rover's named_poses.
    /// Without one every actuated joint holds its pose and takes commands by joint name
    #[arg(long, value_name = "FILE.yaml")]
    pub(crate) controllers: Option<PathBuf>,

    /// Seed for everything random; the same seed gives the same run
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
}

#[derive(Debug, Args)]
pub(crate) struct RunArgs {
    /// Run without a window, as fast as the CPU allows, deterministically (detector in lockstep
    /// on sim time)
    #[arg(long)]
    pub(crate) headless: bool,

    #[command(flatten)]
    pub(crate) world: WorldArgs,

    /// Input script: timed cmd_vel / key / toggle steps on sim time (TOML)
    #[arg(long, value_name = "FILE")]
    pub(crate) script: Option<PathBuf>,

    /// Sim seconds to run [default: last script step + 1 s, or 10 s]
    #[arg(long, value_name = "SECS")]
    pub(crate) duration: Option<f64>,

    /// Write a CSV trace, one row per control update
    #[arg(long, value_name = "FILE")]
    pub(crate) trace: Option<PathBuf>,

    /// Write the robot camera's images as PNG files into DIR (rendered with wgpu: a GPU, or
    /// Mesa's software Vulkan)
    #[arg(long, value_name = "DIR")]
    pub(crate) save_frames: Option<PathBuf>,

    /// With --save-frames: write every Nth camera image
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub(crate) frame_every: u64,

    /// Stop the robot when no cmd_vel arrived for SECS (off by default, like Gazebo; 0 = off)
    #[arg(long, value_name = "SECS")]
    pub(crate) cmd_timeout: Option<f64>,

    #[command(flatten)]
    pub(crate) follow: FollowArgs,

    #[command(flatten)]
    pub(crate) arm: ArmArgs,

    #[command(flatten)]
    pub(crate) detector: DetectorArgs,

    #[command(flatten)]
    pub(crate) viewer: ViewerArgs,

    #[command(flatten)]
    pub(crate) window: WindowArgs,

    #[command(flatten)]
    pub(crate) ros: RosArgs,
}

/// ROS 1 bridge options.
#[derive(Debug, Args)]
pub(crate) struct RosArgs {
    /// Join a ROS 1 graph (start `roscore` first; ROS_MASTER_URI, ROS_IP, ROS_HOSTNAME are
    /// honoured): /cmd_vel drives the car, and rover publishes what Gazebo and darknet_ros would
    /// (/odom, /tf, /tf_static, /joint_states, /clock, the camera's image and camera_info,
    /// /darknet_ros/bounding_boxes, found_object, detection_image, the laser's scan) and sets
    /// /robot_description. Headless runs then default to --rtf 1. See docs/ROS.md
    #[arg(long)]
    pub(crate) ros: bool,

    /// Join ROS 2 over DDS (RTPS, as rmw_cyclonedds and rmw_fastrtps speak it; ROS_DOMAIN_ID
    /// is honoured; no ROS install needed): rt/cmd_vel drives the car, and rover publishes
    /// what the ROS 1 bridge does with ROS 2's types (/clock, /odom, /tf, /tf_static,
    /// /joint_states, the camera's image and camera_info, /darknet_ros/bounding_boxes and
    /// found_object, the laser's scan). Can run beside --ros. Headless runs then default to
    /// --rtf 1. See docs/ROS2.md
    #[arg(long)]
    pub(crate) ros2: bool,

    /// Record the ROS 2 topics (those --ros2 publishes, with or without --ros2) into an MCAP
    /// file: CDR messages and their ROS 2 definitions, as `ros2 bag record -s mcap` writes
    /// them, for `ros2 bag play FILE`, Foxglove, rosbags or Rerun. Stamps are sim time;
    /// nothing is dropped (the run waits for the disk if it must). Does not change the pace
    #[arg(long, value_name = "FILE.mcap")]
    pub(crate) record_mcap: Option<PathBuf>,

    /// With --ros or --ros2: the node's name (ROS 2's tools list it, with `ros2 node list`,
    /// as `/NAME`)
    #[arg(long, value_name = "NAME", default_value = "rover")]
    pub(crate) ros_name: String,

    /// With --ros2: the ROS 2 distribution the peers run, for what differs on the wire
    /// (`ros_discovery_info`'s ids: 24 bytes on Humble, 16 from Iron on). Default:
    /// `ROS_DISTRO` when it names one of these, else lyrical (the newest LTS)
    #[arg(long, value_name = "DISTRO", value_parser = ros_distro_parser())]
    pub(crate) ros_distro: Option<crate::ros2::RosDistro>,

    /// With --ros: also set /use_sim_time so ROS nodes follow rover's /clock
    #[arg(long, requires = "ros")]
    pub(crate) ros_sim_time: bool,
}

impl RosArgs {
    /// Whether a ROS peer may be listening (--ros or --ros2): headless runs then keep real
    /// time.
    pub(crate) fn any(&self) -> bool {
        self.ros || self.ros2
    }

    /// Whether a bridge runs: a ROS peer, or the MCAP recording.
    pub(crate) fn bridges(&self) -> bool {
        self.any() || self.record_mcap.is_some()
    }

    /// The ROS 2 bridge's settings (--ros2 and/or --record-mcap), `None` when it is off.
    pub(crate) fn ros2_options(&self) -> anyhow::Result<Option<crate::ros2::Ros2Options>> {
        crate::ros2::Ros2Options::new(
            self.ros2,
            self.record_mcap.as_deref(),
            &self.ros_name,
            self.ros_distro,
        )
    }

    /// The bridge's settings, when --ros is on; `ground_truth`: the run measures it
    /// (`--ground-truth`), the bridge publishes it.
    pub(crate) fn options(&self, ground_truth: bool) -> Option<crate::ros::RosOptions> {
        self.ros.then(|| crate::ros::RosOptions {
            name: self.ros_name.clone(),
            sim_time: self.ros_sim_time,
            ground_truth,
        })
    }
}

/// Window options.
#[derive(Debug, Args)]
pub(crate) struct WindowArgs {
    /// Sim seconds per wall second [default: 1 in the window; headless runs go as fast as the
    /// CPU allows unless given, e.g. --rtf 1 for a live viewer or ROS peers]
    #[arg(long, value_name = "X")]
    pub(crate) rtf: Option<f64>,

    /// Window: keep driving after a key is released, like the terminal teleop_twist_keyboard
    /// (default: hold a key to drive, release to stop)
    #[arg(long)]
    pub(crate) latched: bool,

    /// Window: W/A/S/D drive too (teleop's w/x/e/c speed keys are then off; q/z still scale)
    #[arg(long)]
    pub(crate) wasd: bool,

    /// Window: start paused (p resumes, n steps one control update)
    #[arg(long)]
    pub(crate) paused: bool,

    /// Window: write the window's image (camera, boxes, HUD) as PNG when quitting
    #[arg(long, value_name = "FILE.png")]
    pub(crate) screenshot: Option<PathBuf>,
}

/// Rerun viewer and recording options.
#[derive(Debug, Args)]
pub(crate) struct ViewerArgs {
    /// Rerun viewer: `spawn` (native viewer, `pip install rerun-sdk==0.36.3`), `connect [URL]`
    /// (a running viewer, default rerun+http://127.0.0.1:9876/proxy), `web` (rover serves the
    /// web viewer and prints its URL), `save FILE.rrd`, or `none` [default: none when headless;
    /// in the window: spawn when a matching `rerun` is on PATH, else web]
    #[arg(long, num_args = 1..=2, value_names = ["MODE", "ARG"])]
    pub(crate) viewer: Vec<String>,

    /// Also record the run to this .rrd file (works with any --viewer)
    #[arg(long, value_name = "FILE.rrd")]
    pub(crate) record: Option<PathBuf>,

    /// Write the .rrd without its footer (the chunk index rerun keeps in memory until the end,
    /// ~MB per hour of recording): memory stays flat on runs of many hours. The file is still
    /// valid; `rerun rrd optimize` adds the index later
    #[arg(long, requires = "record")]
    pub(crate) record_no_footer: bool,

    /// Camera images sent to Rerun per sim second [default: every camera frame]
    #[arg(long, value_name = "HZ")]
    pub(crate) image_hz: Option<f64>,

    /// Send camera images to Rerun at 1/N of their width and height (long runs)
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub(crate) image_downscale: u32,

    /// Send camera images to Rerun as JPEG of this quality (1-100) instead of raw RGB
    #[arg(long, value_name = "Q", value_parser = clap::value_parser!(u8).range(1..=100))]
    pub(crate) image_jpeg: Option<u8>,

    /// Port of the web viewer (`--viewer web`)
    #[arg(long, default_value_t = 9090, value_name = "PORT")]
    pub(crate) web_port: u16,

    /// Port of the Rerun data server behind the web viewer (`--viewer web`)
    #[arg(long, default_value_t = 9876, value_name = "PORT")]
    pub(crate) grpc_port: u16,
}

impl ViewerArgs {
    pub(crate) fn options(&self, interactive: bool) -> Result<RecorderOptions> {
        let viewer = if self.viewer.is_empty() {
            if interactive {
                let (viewer, why) = crate::viewer::default_viewer();
                tracing::info!("viewer: {why}");
                viewer
            } else {
                Viewer::None
            }
        } else {
            Viewer::parse(&self.viewer)?
        };
        if let Some(hz) = self.image_hz {
            anyhow::ensure!(
                hz.is_finite() && hz > 0.0,
                "--image-hz must be positive, found {hz}"
            );
        }
        anyhow::ensure!(
            (1..=16).contains(&self.image_downscale),
            "--image-downscale must be 1..=16, found {}",
            self.image_downscale
        );
        Ok(RecorderOptions {
            viewer,
            record: self.record.clone(),
            footer: !self.record_no_footer,
            images: ImageOptions {
                rate_hz: self.image_hz,
                downscale: self.image_downscale,
                jpeg_quality: self.image_jpeg,
            },
            web_port: self.web_port,
            grpc_port: self.grpc_port,
        })
    }
}

/// Camera, detector and follower options of a run.
#[derive(Debug, Args)]
pub(crate) struct FollowArgs {
    /// Headless: run the camera and detector even when the script never switches to follow
    /// (they always run when it does)
    #[arg(long, conflicts_with = "no_detector")]
    pub(crate) detect: bool,

    /// Never run the detector (the follower then holds still)
    #[arg(long)]
    pub(crate) no_detector: bool,

    /// Headless: detections per sim second, in lockstep with the simulation (deterministic)
    #[arg(long, value_name = "HZ", default_value_t = rover_core::DEFAULT_DETECT_HZ)]
    pub(crate) detect_hz: f64,

    /// Headless: detect on the loop's own thread with results at once, instead of pipelined on
    /// a second thread with results one detection period (1 / --detect-hz) after their image.
    /// Both are deterministic; pipelined uses two cores
    #[arg(long)]
    pub(crate) serial_detect: bool,

    /// Ground truth: measure every camera image's labelled things from the renderer (people,
    /// `class = "..."` objects, known Gazebo models) and judge each detection against its own
    /// image at IoU 0.5: Rerun shows the ground-truth boxes beside the detections, misses and
    /// false positives marked, and per-class precision, recall and IoU over time; the HUD
    /// says it in one line; --trace gets truth_* columns (docs/GROUND_TRUTH.md)
    #[arg(long)]
    pub(crate) ground_truth: bool,

    /// Follower: class to follow (a darknet_ros `Class`, e.g. person, dog)
    #[arg(long, default_value = "person", value_name = "CLASS")]
    pub(crate) target_class: String,

    /// Follower: distance to keep from the target (m)
    #[arg(long, default_value_t = 1.5, value_name = "M")]
    pub(crate) standoff: f64,

    /// Follower: speed limit (m/s; the follower's default, enough to keep up with a person
    /// walking at 0.6 m/s)
    #[arg(long, default_value_t = 0.8, value_name = "MPS")]
    pub(crate) follow_speed: f64,
}

impl FollowArgs {
    pub(crate) fn follower(&self) -> anyhow::Result<FollowerConfig> {
        anyhow::ensure!(
            self.standoff.is_finite() && self.standoff > 0.3,
            "--standoff must be more than 0.3 m, found {}",
            self.standoff
        );
        anyhow::ensure!(
            self.follow_speed.is_finite() && self.follow_speed > 0.0,
            "--follow-speed must be a positive speed in m/s, found {}",
            self.follow_speed
        );
        Ok(FollowerConfig {
            target_class: self.target_class.clone(),
            standoff_m: self.standoff,
            max_speed_mps: self.follow_speed,
            ..FollowerConfig::default()
        })
    }

    pub(crate) fn perception(&self) -> Perception {
        match (self.detect, self.no_detector) {
            (_, true) => Perception::Off,
            (true, _) => Perception::On,
            _ => Perception::Auto,
        }
    }
}

/// The arm's look, reach and pick (docs/ARM.md): switched on by `toggle = "look"` / `"reach"` /
/// `"pick"` in a script, the station's keys, or ROS.
#[derive(Debug, Args)]
pub(crate) struct ArmArgs {
    /// Arm: the end effector that reaches (e.g. TIAGo's arm_tool_link) [default: the world's
    /// [robot] ee_link]
    #[arg(long, value_name = "LINK")]
    pub(crate) ee_link: Option<String>,

    /// Arm: the link look and reach work from; IK moves the joints between it and --ee-link
    /// (e.g. TIAGo's torso_lift_link, so the head looks while the arm reaches) [default: the
    /// world's [robot] arm_base, else the robot's root link]
    #[arg(long, value_name = "LINK")]
    pub(crate) arm_base: Option<String>,

    /// Arm: a MoveIt SRDF whose planning group (--arm-group) gives --arm-base and --ee-link
    /// when they are not given [default: the world's [robot] srdf]
    #[arg(long, value_name = "FILE")]
    pub(crate) srdf: Option<PathBuf>,

    /// Arm: the SRDF's planning group that is the arm [default: the world's [robot] arm_group,
    /// else `arm`, else the only group]
    #[arg(long, value_name = "NAME")]
    pub(crate) arm_group: Option<String>,

    /// Arm: the class look turns to and reach goes for (a darknet_ros `Class`)
    #[arg(long, default_value = "sports ball", value_name = "CLASS")]
    pub(crate) arm_class: String,

    /// Arm: how far short of the object's centre (estimated from its box and the depth image)
    /// the tool stops (m)
    #[arg(long, default_value_t = 0.10, value_name = "M")]
    pub(crate) reach_standoff: f64,

    /// Pick: where pick puts what it picked: a world object's name (e.g. worlds/
    /// arm_car_pick.toml's `bin`; dropped on or in it) or a point X,Y,Z in the world frame (m;
    /// set down there) [default: the world's [robot] place]
    #[arg(long, value_name = "NAME|X,Y,Z", allow_hyphen_values = true)]
    pub(crate) place: Option<String>,

    /// Pick: take this world object by its known pose (as a MoveIt node adds the object to
    /// its planning scene), no camera or detector needed [default: the world's [robot] pick,
    /// else what the detector sees of --arm-class]
    #[arg(long, value_name = "NAME")]
    pub(crate) pick_object: Option<String>,

    /// Pick: fetch: the car drives to within reach of the object (until it is at X,Y, m, x
    /// forward and y left in the arm's base frame: where the arm takes it best), picks it,
    /// backs off and drives to the --place, and puts it there (e.g. worlds/
    /// arm_car_fetch.toml) [default: the world's [robot] fetch, else the base stays put]
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true)]
    pub(crate) fetch: Option<String>,
}

/// `--fetch X,Y`: two finite numbers (m).
fn parse_fetch(text: &str) -> anyhow::Result<[f64; 2]> {
    let numbers: Result<Vec<f64>, _> = text.split(',').map(|p| p.trim().parse::<f64>()).collect();
    match numbers.as_deref() {
        Ok(&[x, y]) if x.is_finite() && y.is_finite() => Ok([x, y]),
        _ => anyhow::bail!(
            "--fetch {text}: expected X,Y: where the object should be when the car stops to pick it (two finite numbers, m, in the arm's base frame)"
        ),
    }
}

/// `--place`: three comma-separated finite numbers are a point, anything else an object's name.
fn parse_place(text: &str) -> anyhow::Result<rover_sim::Place> {
    let numbers: Result<Vec<f64>, _> = text.split(',').map(|p| p.trim().parse::<f64>()).collect();
    if let Ok(point) = numbers
        && let [x, y, z] = point[..]
    {
        anyhow::ensure!(
            point.iter().all(|v| v.is_finite()),
            "--place {text}: a point must be three finite numbers X,Y,Z (m)"
        );
        return Ok(rover_sim::Place::Point([x, y, z]));
    }
    anyhow::ensure!(
        !text.trim().is_empty(),
        "--place: expected a world object's name or a point X,Y,Z (m), found nothing"
    );
    Ok(rover_sim::Place::Object(text.to_owned()))
}

impl ArmArgs {
    pub(crate) fn arm(&self) -> anyhow::Result<rover_core::ArmConfig> {
        anyhow::ensure!(
            self.reach_standoff.is_finite() && self.reach_standoff >= 0.0,
            "--reach-standoff must be a distance of 0 m or more, found {}",
            self.reach_standoff
        );
        Ok(rover_core::ArmConfig {
            base_link: self.arm_base.clone(),
            ee_link: self.ee_link.clone(),
            srdf: self.srdf.clone(),
            group: self.arm_group.clone(),
            look: rover_core::LookConfig {
                class: self.arm_class.clone(),
                ..rover_core::LookConfig::default()
            },
            reach: rover_core::ReachConfig {
                class: self.arm_class.clone(),
                standoff_m: self.reach_standoff,
                ..rover_core::ReachConfig::default()
            },
            pick: rover_core::PickConfig {
                class: self.arm_class.clone(),
                place: self.place.as_deref().map(parse_place).transpose()?,
                object: self.pick_object.clone(),
                fetch_at: self.fetch.as_deref().map(parse_fetch).transpose()?,
                ..rover_core::PickConfig::default()
            },
        })
    }
}

/// Detector options shared by the commands that run YOLO.
#[derive(Debug, Args)]
pub(crate) struct DetectorArgs {
    /// YOLO ONNX model [default: YOLOv12n from the crates.io package easy-yolo 0.1.3, fetched
    /// into ~/.cache/rover on first use; its weights are AGPL-3.0]. Heads: YOLOv5 [1,N,5+C],
    /// YOLOv8/11/12 [1,4+C,N], YOLOv10 [1,K,6]
    #[arg(long, value_name = "FILE")]
    pub(crate) model: Option<PathBuf>,

    /// Class names, one per line (darknet's coco.names format) [default: the model's `names`
    /// metadata, else COCO's 80]
    #[arg(long, value_name = "FILE")]
    pub(crate) labels: Option<PathBuf>,

    /// Confidence threshold (darknet_ros's default)
    #[arg(long, default_value_t = DEFAULT_THRESHOLD, value_name = "T")]
    pub(crate) threshold: f32,

    /// Class-wise NMS IoU threshold (darknet_ros's default)
    #[arg(long, default_value_t = DEFAULT_NMS_IOU, value_name = "IOU")]
    pub(crate) nms: f32,

    /// Network input size WIDTHxHEIGHT, multiples of 32 [default: 512x384 for the default model
    /// (the camera's 4:3 aspect), the model's own size otherwise]
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub(crate) input_size: Option<(usize, usize)>,

    /// Make the detector fail on purpose after N detections, to see (or test) how a run
    /// copes: KIND@N with KIND `panic` or `error`, e.g. `panic@10`
    #[arg(long, value_name = "KIND@N", value_parser = parse_fault)]
    pub(crate) inject_fault: Option<InjectedFault>,

    /// Threads for one detection: tract splits the network's matrix products across them, and
    /// the boxes are bit-identical whatever the count [default: 2 (1 on a one-core machine);
    /// 1 in `rover eval`'s workers, which already fill the cores]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=64))]
    pub(crate) detect_threads: Option<u16>,

    /// The network's runtime: `tract` (pure Rust, built in) or `onnxruntime`, the
    /// libonnxruntime.so of a `pip install onnxruntime` (found in $VIRTUAL_ENV, rover's
    /// ~/.cache/rover/venv, ~/.local or the system's Python; or set ORT_DYLIB_PATH), loaded at
    /// run time. Same graph, same boxes within float rounding; onnxruntime is ~1.6x faster here
    #[arg(long, value_enum, default_value_t = RuntimeArg::Tract, value_name = "RUNTIME")]
    pub(crate) runtime: RuntimeArg,
}

fn parse_fault(text: &str) -> Result<InjectedFault, String> {
    let (kind, n) = text
        .split_once('@')
        .ok_or_else(|| format!("expected KIND@N like panic@10, found '{text}'"))?;
    let kind = match kind {
        "panic" => FaultKind::Panic,
        "error" => FaultKind::Error,
        other => return Err(format!("'{other}' is not a fault: expected panic or error")),
    };
    let after_detections = n
        .parse()
        .map_err(|_| format!("'{n}' is not a whole number of detections"))?;
    Ok(InjectedFault {
        after_detections,
        kind,
    })
}

fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT like 640x480, found '{text}'"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{v}' is not a whole number of pixels"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// `--runtime`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum RuntimeArg {
    /// tract-onnx (default)
    Tract,
    /// onnxruntime's shared library from a pip install
    Onnxruntime,
}

impl From<RuntimeArg> for Runtime {
    fn from(arg: RuntimeArg) -> Self {
        match arg {
            RuntimeArg::Tract => Runtime::Tract,
            RuntimeArg::Onnxruntime => Runtime::OnnxRuntime,
        }
    }
}

/// The machine's CPU cores: the default of `--jobs` (eval, dataset).
pub(crate) fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Detector threads where the loop leaves a core free for them: 2, or 1 on a one-core machine.
/// Two measured here (2 vCPU, 512x384): one detection 76 -> 49 ms, the same boxes.
pub(crate) fn spare_detect_threads() -> usize {
    cores().min(2)
}

impl DetectorArgs {
    /// The same options as command-line arguments (to hand them to a child process).
    pub(crate) fn to_args(&self) -> Vec<std::ffi::OsString> {
        let mut args: Vec<std::ffi::OsString> = Vec::new();
        if let Some(m) = &self.model {
            args.push("--model".into());
            args.push(m.into());
        }
        if let Some(l) = &self.labels {
            args.push("--labels".into());
            args.push(l.into());
        }
        args.push(format!("--threshold={}", self.threshold).into());
        args.push(format!("--nms={}", self.nms).into());
        if let Some((w, h)) = self.input_size {
            args.push(format!("--input-size={w}x{h}").into());
        }
        if let Some(f) = self.inject_fault {
            let kind = match f.kind {
                FaultKind::Panic => "panic",
                FaultKind::Error => "error",
            };
            args.push(format!("--inject-fault={kind}@{}", f.after_detections).into());
        }
        if let Some(n) = self.detect_threads {
            args.push(format!("--detect-threads={n}").into());
        }
        if self.runtime != RuntimeArg::Tract {
            args.push(format!("--runtime={}", Runtime::from(self.runtime).name()).into());
        }
        args
    }

    /// The detector's settings for a command that runs no session (`rover detect`, `rover
    /// bench detect`), where `--inject-fault` has nothing to act on and is refused.
    pub(crate) fn tool_config(&self, default_threads: usize) -> anyhow::Result<DetectorConfig> {
        anyhow::ensure!(
            self.inject_fault.is_none(),
            "--inject-fault applies to runs (headless, the window, eval), not to this command"
        );
        self.config(default_threads)
    }

    /// The detector's settings; `default_threads` where `--detect-threads` was not given (see
    /// [`spare_detect_threads`]). `--inject-fault` is not among them: runs hand
    /// [`DetectorArgs::inject_fault`] to the session, which wraps the detector.
    pub(crate) fn config(&self, default_threads: usize) -> anyhow::Result<DetectorConfig> {
        anyhow::ensure!(
            (0.0..=1.0).contains(&self.threshold),
            "--threshold must be between 0 and 1, found {}",
            self.threshold
        );
        anyhow::ensure!(
            (0.0..=1.0).contains(&self.nms),
            "--nms must be between 0 and 1, found {}",
            self.nms
        );
        Ok(DetectorConfig {
            model: self.model.clone(),
            labels: self.labels.clone(),
            input_size: self.input_size,
            threshold: self.threshold,
            nms_iou: self.nms,
            threads: self.detect_threads.map_or(default_threads, usize::from),
            runtime: self.runtime.into(),
            ..DetectorConfig::default()
        })
    }
}

#[derive(Debug, Subcommand)]
pub(crate) enum BenchKind {
    /// Physics-only real-time factor (what plain `rover bench` measures): the robot drives a
    /// figure of eight while its arm, if it has one, holds its pose
    Physics {
        #[command(flatten)]
        world: WorldArgs,

        #[command(flatten)]
        physics: PhysicsBenchArgs,
    },
    /// Rerun recording overhead: the same headless run (camera + detector) without and with
    /// --record
    Record {
        #[command(flatten)]
        world: WorldArgs,

        /// Sim seconds per run
        #[arg(long, default_value_t = 10.0, value_name = "SECS")]
        duration: f64,

        /// Repeats (the fastest of each counts)
        #[arg(long, default_value_t = 2)]
        repeats: u32,

        /// Send camera images as JPEG of this quality instead of raw RGB
        #[arg(long, value_name = "Q")]
        image_jpeg: Option<u8>,
    },
    /// ROS bridge cost: the same headless run (camera + lockstep detector) without and with
    /// --ros and in-process subscribers to the image, /odom and /tf. Needs a master
    /// (`roscore`; ROS_MASTER_URI)
    Ros {
        #[command(flatten)]
        world: WorldArgs,

        /// Sim seconds per run
        #[arg(long, default_value_t = 10.0, value_name = "SECS")]
        duration: f64,

        /// Repeats (the fastest of each counts)
        #[arg(long, default_value_t = 2)]
        repeats: u32,
    },
    /// Camera: ms per image (render + readback) on this machine's GPU or software Vulkan
    Camera {
        #[command(flatten)]
        world: WorldArgs,

        /// Frames to time (after one warm-up)
        #[arg(long, default_value_t = 60)]
        frames: usize,
    },
    /// Laser: ms per scan (ray casts against the physics scene) and the follower's command cost
    /// with a scan's obstacles
    Laser {
        #[command(flatten)]
        world: WorldArgs,

        /// Scans to time (after one warm-up)
        #[arg(long, default_value_t = 200)]
        scans: usize,
    },
    /// Dataset: labelled 640x480 images per second (layout, render + ground truth, encode and
    /// write), written into a temporary folder
    Dataset {
        #[command(flatten)]
        world: WorldArgs,

        /// Images to make (after one warm-up)
        #[arg(long, default_value_t = 100)]
        images: u64,

        /// Image files: png or jpg
        #[arg(long, default_value = "png", value_name = "png|jpg")]
        image_format: DatasetImageFormat,

        /// Images made at once, as `rover dataset --jobs` [default: the number of CPU cores]
        #[arg(long, short = 'j', value_name = "N")]
        jobs: Option<usize>,
    },
    /// Inverse kinematics: ms per solve (damped least squares) to targets made by forward
    /// kinematics from seeded random in-limit poses of the chain, solved from its rest pose;
    /// e.g. `rover bench ik --robot tiago_no_hand.urdf --base torso_lift_link --ee-link
    /// arm_tool_link`
    Ik {
        #[command(flatten)]
        world: WorldArgs,

        /// The chain's base link [default: the robot's root link]
        #[arg(long, value_name = "LINK")]
        base: Option<String>,

        /// The end effector: the chain's tip link
        #[arg(long, value_name = "LINK")]
        ee_link: String,

        /// Targets to solve
        #[arg(long, default_value_t = 200)]
        targets: usize,

        /// Also match the tip's orientation (full pose targets), not only its position
        #[arg(long)]
        pose: bool,
    },
    /// People: is a person a `person` to the detector from every side? The world's first
    /// person (default world: worlds/people.toml, the tutorial's camera car) seen from 8
    /// headings at 1.5, 2, 3, 5 and 8 m, standing and at 4 phases of the walk, one image each,
    /// found when a detection matches the ground truth at IoU >= 0.5; MakeHuman's body and
    /// rover's figure side by side. Also times posing (skinning) a body
    People(PeopleBenchArgs),
    /// Detector latency: tract (rover) vs onnxruntime on the same graph, input and thread count
    Detect {
        #[command(flatten)]
        detector: DetectorArgs,

        /// Image to detect on [default: darknet's person.jpg if installed, else a test pattern]
        #[arg(long, value_name = "FILE")]
        image: Option<PathBuf>,

        /// Timed runs (after one warm-up)
        #[arg(long, default_value_t = 15)]
        runs: usize,

        /// Also time every node: tract's plan beside onnxruntime's profiler, by ONNX op type
        #[arg(long)]
        profile: bool,
    },
}

/// `rover bench people`'s options.
#[derive(Debug, Args)]
pub(crate) struct PeopleBenchArgs {
    #[command(flatten)]
    pub(crate) world: WorldArgs,

    #[command(flatten)]
    pub(crate) detector: DetectorArgs,

    /// Bodies to sweep: makehuman (MakeHuman's body) and/or figure (rover's
    /// own figure of primitives)
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "makehuman,figure",
        value_name = "BODY,..."
    )]
    pub(crate) bodies: Vec<SweepBody>,

    /// Only these postures: standing, walk (4 phases) [default: both]
    #[arg(long, value_delimiter = ',', value_name = "POSTURE,...")]
    pub(crate) postures: Vec<SweepPostureArg>,

    /// Save every image into this folder (BODY/POSTURE_HEADING_DISTANCE.png)
    #[arg(long, value_name = "DIR")]
    pub(crate) save: Option<PathBuf>,
}

/// A body `rover bench people` sweeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum SweepBody {
    /// MakeHuman's body.
    Makehuman,
    /// rover's own figure of primitives.
    Figure,
}

/// Postures `rover bench people` shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum SweepPostureArg {
    /// Standing still.
    Standing,
    /// Walking, at 0, 25, 50 and 75 % of the gait cycle.
    Walk,
}

/// `rover dataset`'s options.
#[derive(Debug, Args)]
pub(crate) struct DatasetArgs {
    #[command(flatten)]
    pub(crate) world: WorldArgs,

    /// The dataset's folder (new, empty, or one this command made before: it resumes)
    #[arg(long, value_name = "DIR")]
    pub(crate) out: PathBuf,

    /// How many images
    #[arg(long, default_value_t = 100, value_name = "N")]
    pub(crate) images: u64,

    /// Fraction of images in the validation split
    #[arg(long, default_value_t = 0.1, value_name = "FRACTION")]
    pub(crate) val: f64,

    /// Output formats: yolo (Ultralytics layout, data.yaml), coco (COCO JSON), or both
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "yolo,coco",
        value_name = "FORMAT,..."
    )]
    pub(crate) format: Vec<DatasetFormat>,

    /// Image files: png (lossless) or jpg (quality 95)
    #[arg(long, default_value = "png", value_name = "png|jpg")]
    pub(crate) image_format: DatasetImageFormat,

    /// What to randomize: robot, things (people's and labelled things' poses), clothes,
    /// bodies (people's shapes, heights, skin, hair, gait phase), light, noise; `none` for none
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "robot,things,clothes,bodies,light,noise",
        value_name = "WHAT,..."
    )]
    pub(crate) randomize: Vec<Randomize>,

    /// Distances from the robot to the thing it faces (m)
    #[arg(long, default_value = "1.5,8", value_name = "MIN,MAX", value_parser = parse_range)]
    pub(crate) distance: [f64; 2],

    /// Fraction of background images (the robot anywhere, facing anywhere)
    #[arg(long, default_value_t = 0.05, value_name = "FRACTION")]
    pub(crate) background: f64,

    /// How far people and labelled things move from where the world puts them (m, in x and y)
    #[arg(long, default_value_t = 0.5, value_name = "M")]
    pub(crate) move_m: f64,

    /// How far labelled objects and models turn (deg, either way); people face any way
    #[arg(long, default_value_t = 180.0, value_name = "DEG")]
    pub(crate) turn_deg: f64,

    /// Largest camera noise standard deviation (0..1 of full scale)
    #[arg(long, default_value_t = 0.02, value_name = "STDDEV")]
    pub(crate) noise_max: f64,

    /// Also run the detector on every image: its boxes in the records, COCO results in
    /// OUT/detections/, and its COCO metrics (AP50, AP50:95, per class) in OUT/metrics.json
    #[arg(long)]
    pub(crate) detect: bool,

    /// Images to make at once, each on a thread of its own with its own simulation, camera
    /// and detector; the files do not depend on it [default: the number of CPU cores]
    #[arg(long, short = 'j', value_name = "N")]
    pub(crate) jobs: Option<usize>,

    /// Make only shard I of N (counted from 0), e.g. one Slurm array task: the images whose
    /// number modulo N is I, into OUT/shard-I-of-N/ (resumable like any dataset). Merge the N
    /// folders with --merge once all are finished (docs/SCALE.md)
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    pub(crate) shard: Option<(usize, usize)>,

    /// Merge the folders of finished shards (OUT/shard-I-of-N/ of --shard) into the dataset
    /// folder OUT, with one COCO JSON and data.yaml, instead of making images. Refuses an
    /// incomplete set (naming the missing shards) or shards made differently (naming the field)
    #[arg(long, value_name = "SHARD_DIR", num_args = 1.., conflicts_with_all = ["shard", "detect", "images", "world", "robot"])]
    pub(crate) merge: Vec<PathBuf>,

    #[command(flatten)]
    pub(crate) detector: DetectorArgs,
}

/// A dataset output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DatasetFormat {
    /// Ultralytics YOLO: images/, labels/, data.yaml
    Yolo,
    /// COCO JSON: annotations/instances_{train,val}.json
    Coco,
}

/// A dataset image format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DatasetImageFormat {
    /// Lossless PNG
    Png,
    /// JPEG, quality 95
    Jpg,
}

/// Something `rover dataset` can randomize.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Randomize {
    /// Where the robot (its camera) stands and looks
    Robot,
    /// Where people and labelled things stand and face
    Things,
    /// People's shirt and trousers colours
    Clothes,
    /// People's bodies (shape sliders, height, children too), skin tones, hair colours and
    /// styles, trousers or skirts, and half of them caught mid-stride
    Bodies,
    /// The sun's direction and strength, the sky's light
    Light,
    /// The camera's noise
    Noise,
    /// Nothing
    None,
}

fn parse_range(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [lo, hi] = parts.as_slice() else {
        return Err(format!("expected MIN,MAX, found '{text}'"));
    };
    let number = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("expected a number, found '{t}'"))
    };
    Ok([number(lo)?, number(hi)?])
}

/// `rover eval`'s options.
#[derive(Debug, Args)]
pub(crate) struct EvalArgs {
    /// Scenario files, or folders of them (their *.toml in name order) [default: scenarios/]
    #[arg(value_name = "PATH")]
    pub(crate) paths: Vec<PathBuf>,

    /// Scenarios run at once, each in its own process [default: the number of CPU cores]
    #[arg(long, short = 'j', value_name = "N")]
    pub(crate) jobs: Option<usize>,

    /// Folder for eval.json and eval.csv (and per-scenario .rrd/.csv files)
    #[arg(long, default_value = "eval-out", value_name = "DIR")]
    pub(crate) out: PathBuf,

    /// Also record every scenario to OUT/NAME.rrd, for inspection in Rerun
    #[arg(long)]
    pub(crate) rrd: bool,

    /// Also write every scenario's trace to OUT/NAME.csv
    #[arg(long)]
    pub(crate) traces: bool,

    /// Run only shard I of N: the scenarios (in name order) whose index modulo N is I; the
    /// results go to OUT/eval-shard-I-of-N.json for `--merge` (see docs/FOLLOWER.md)
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    pub(crate) shard: Option<(usize, usize)>,

    /// Merge shards' result files into OUT/eval.json and eval.csv instead of running anything
    #[arg(long, value_name = "JSON", num_args = 1.., conflicts_with_all = ["jobs", "rrd", "shard", "paths", "robot"])]
    pub(crate) merge: Vec<PathBuf>,

    /// Run only scenarios with this tag (repeatable), e.g. --tag fast
    #[arg(long, value_name = "TAG")]
    pub(crate) tag: Vec<String>,

    /// Run every scenario with this robot (URDF or xacro) instead of the one it names
    /// (repeatable: every scenario for every robot, and a robots x scenarios table). A scenario
    /// whose `needs` the robot lacks (e.g. a laser for obstacles) is skipped with the reason
    #[arg(long, value_name = "FILE")]
    pub(crate) robot: Vec<PathBuf>,

    #[command(flatten)]
    pub(crate) detector: DetectorArgs,

    /// Internal: run the one scenario given in this process and write its result to this file
    #[arg(long, hide = true, value_name = "RESULT.json")]
    pub(crate) worker: Option<PathBuf>,
}

fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let parsed = text.split_once('/').and_then(|(i, n)| {
        Some((
            i.trim().parse::<usize>().ok()?,
            n.trim().parse::<usize>().ok()?,
        ))
    });
    match parsed {
        Some((i, n)) if n > 0 && i < n => Ok((i, n)),
        _ => Err(format!(
            "expected I/N with 0 <= I < N (shard I of N, counted from 0), found '{text}'"
        )),
    }
}

#[derive(Debug, Subcommand)]
#[allow(
    clippy::large_enum_variant,
    reason = "parsed once per process: the variants' size difference costs nothing worth boxing for"
)]
pub(crate) enum Command {
    /// Run a catkin package's roslaunch file: rover in Gazebo's and darknet_ros' place, the
    /// other nodes started against a ROS master
    ///
    /// `rover launch PKG FILE.launch [name:=value ...]` (or a path to the file) reads the file as
    /// roslaunch does (args, includes, groups, params, rosparam, nodes, remaps, env,
    /// substitutions). gazebo_ros' world and spawn_model, robot_state_publisher,
    /// joint_state_publisher, controller spawners and darknet_ros become rover's world, robot,
    /// /tf, /joint_states, controllers and detector; every other node is started as a process
    /// (output prefixed with its name), after the launch's parameters are set on the ROS master
    /// at ROS_MASTER_URI, which rover starts (rosmaster) when none answers. Ctrl-C stops the
    /// nodes, rover and that master. Run options (--headless, --duration, --trace, ...) apply
    /// as in a plain run; --world/--robot override the launch's. See docs/ROS.md.
    Launch(LaunchArgs),

    /// Expand a xacro file and print the URDF (as ROS' `xacro FILE [name:=value ...]` does)
    Xacro(XacroArgs),

    /// Run the YOLO detector on image files and print the boxes
    ///
    /// One line per box: `class probability xmin ymin xmax ymax` (source-image pixels), or with
    /// --json one darknet_ros-shaped object per image.
    Detect {
        /// Image files (PNG, JPEG)
        #[arg(required = true, value_name = "IMAGE")]
        images: Vec<PathBuf>,

        #[command(flatten)]
        detector: DetectorArgs,

        /// Print darknet_ros-shaped JSON, one object per image per line
        #[arg(long)]
        json: bool,

        /// Write the image with boxes drawn (a folder when several images are given)
        #[arg(long, value_name = "PATH")]
        out: Option<PathBuf>,
    },

    /// Run follower scenarios (world + robot + success criteria) headless in parallel and judge
    /// them
    ///
    /// Each scenario file (scenarios/*.toml; format in docs/FOLLOWER.md) runs deterministically
    /// in its own process, --jobs at a time. Prints a table, writes OUT/eval.json and
    /// OUT/eval.csv, and exits 1 when a scenario fails. --robot (repeatable) runs the suite on
    /// other robots; --shard and --merge split a suite over machines.
    Eval(EvalArgs),

    /// Write a labelled dataset from a world: images with YOLO labels and/or COCO JSON
    ///
    /// Every image is a scene laid out anew from --seed and the image's number: the robot
    /// faces a labelled thing (a person, an object with class = "...", a Gazebo model of a
    /// known class) from 1.5-8 m, people and labelled things move and turn, people change
    /// clothes and bodies, the sun moves, the camera's noise varies (--randomize chooses). The labels are
    /// the renderer's own ground truth: visible (tight) boxes, ignore regions for things too
    /// small or hidden (COCO iscrowd; left out of YOLO labels). Layout: OUT/data.yaml,
    /// OUT/images/{train,val}, OUT/labels/{train,val} (Ultralytics), OUT/annotations/
    /// instances_{train,val}.json (COCO), OUT/ground_truth/ (rover's record per image: full and
    /// visible boxes, visibility, layout). The same command on the same folder resumes a
    /// stopped run; a folder made with other settings is refused. docs/GROUND_TRUTH.md.
    Dataset(DatasetArgs),

    /// Benchmarks: physics-only real-time factor (default), or `bench detect`
    Bench {
        #[command(subcommand)]
        kind: Option<BenchKind>,

        #[command(flatten)]
        world: WorldArgs,

        #[command(flatten)]
        physics: PhysicsBenchArgs,
    },
}

/// The physics benchmark's settings (`rover bench`, `rover bench physics`).
#[derive(Debug, Args)]
pub(crate) struct PhysicsBenchArgs {
    /// Sim seconds per measurement
    #[arg(long, default_value_t = 60.0, value_name = "SECS")]
    pub(crate) sim_seconds: f64,

    /// Repeats per measurement (the fastest counts)
    #[arg(long, default_value_t = 3)]
    pub(crate) repeats: u32,

    /// Also measure at these step rates (Hz), e.g. --rates 250,500,1000
    #[arg(long, value_delimiter = ',', value_name = "HZ,...")]
    pub(crate) rates: Vec<f64>,

    /// Hold this world object in the gripper while driving (before the clock starts: the
    /// gripper opens, the object is put at the end effector, the gripper closes on it);
    /// needs a gripper controller and the world's [robot] ee_link. Says whether it was still
    /// held at the end. E.g. `--world worlds/arm_car_pick.toml --spawn -3,-3 --hold ball`
    #[arg(long, value_name = "NAME")]
    pub(crate) hold: Option<String>,
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
fn parse_drive(s: &str) -> Result<rover_sim::DriveSpec, String> {
    match s.split(',').map(str::trim).collect::<Vec<_>>().as_slice() {
        [left, right] if !left.is_empty() && !right.is_empty() => Ok(rover_sim::DriveSpec {
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

/// `NAME=DIR` for a ROS package folder.
fn parse_package_path(s: &str) -> Result<(String, PathBuf), String> {
    let (name, dir) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=DIR, found \"{s}\""))?;
    let dir = PathBuf::from(dir);
    if name.is_empty() || !dir.is_dir() {
        return Err(format!(
            "expected NAME=DIR naming an existing folder, found \"{s}\""
        ));
    }
    Ok((name.to_owned(), dir))
}

impl WorldArgs {
    /// The robot-loading options these arguments give.
    pub(crate) fn robot_options(&self) -> rover_sim::LoadOptions {
        let mut options = rover_sim::LoadOptions::default();
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

fn parse_joint_solver(text: &str) -> Result<rover_sim::JointSolver, String> {
    match text {
        "multibody" => Ok(rover_sim::JointSolver::Multibody),
        "impulse" => Ok(rover_sim::JointSolver::Impulse),
        other => Err(format!("expected multibody or impulse, found '{other}'")),
    }
}

/// `rover launch` arguments: the launch file, roslaunch's query options, and rover's run
/// options (--headless, --duration, --trace, --record-mcap, ...).
#[derive(Debug, Args)]
pub(crate) struct LaunchArgs {
    /// `PKG FILE.launch` (FILE found in ROS package PKG, as `roslaunch PKG FILE` finds it) or
    /// `PATH.launch`, then `name:=value` args for the file
    #[arg(required = true, num_args = 1.., value_name = "PKG FILE | PATH")]
    pub(crate) launch: Vec<String>,

    /// Print the parameters the launch sets (YAML, as `roslaunch --dump-params`) and exit
    #[arg(long)]
    pub(crate) dump_params: bool,

    /// Print the nodes' names (as `roslaunch --nodes`) and exit
    #[arg(long)]
    pub(crate) nodes: bool,

    /// Print the command line NODE would be started with, environment first (as
    /// `roslaunch --args NODE`), and exit
    #[arg(long = "args", value_name = "NODE")]
    pub(crate) node_args: Option<String>,

    /// Print the launch files read (as `roslaunch --files`) and exit
    #[arg(long)]
    pub(crate) files: bool,

    #[command(flatten)]
    pub(crate) run: RunArgs,
}

/// `rover xacro` arguments.
#[derive(Debug, Args)]
pub(crate) struct XacroArgs {
    /// The xacro file
    pub(crate) file: PathBuf,

    /// `name:=value` args (`$(arg name)`)
    #[arg(value_name = "ARG")]
    pub(crate) args: Vec<String>,

    /// Where ROS package NAME is, for $(find NAME) (repeatable)
    #[arg(long = "package-path", value_name = "NAME=DIR", value_parser = parse_package_path)]
    pub(crate) package_paths: Vec<(String, PathBuf)>,
}

/// `--ros-distro`: one of the distributions rover-ros2 knows, listed in `--help` and in the
/// error for any other name.
fn ros_distro_parser() -> impl clap::builder::TypedValueParser<Value = crate::ros2::RosDistro> {
    use crate::ros2::RosDistro;
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(RosDistro::ALL.map(RosDistro::as_str)).try_map(
        |name| RosDistro::from_name(&name).ok_or_else(|| format!("no ROS 2 distribution {name}")),
    )
}
