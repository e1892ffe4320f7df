//! The command line: every option and subcommand, with their checks. This file holds the
//! top-level [`Cli`] and its [`Command`]s; their options live in the files beside it, by topic.

mod arm;
mod bench;
mod dataset;
mod detector;
mod eval;
mod launch;
mod parsers;
mod ros;
mod run;
mod world;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

pub(crate) use bench::{BenchKind, PeopleBenchArgs, PhysicsBenchArgs, SweepBody, SweepPostureArg};
pub(crate) use dataset::{DatasetArgs, DatasetFormat, DatasetImageFormat, Randomize};
pub(crate) use detector::{DetectorArgs, cores, spare_detect_threads};
pub(crate) use eval::EvalArgs;
pub(crate) use launch::{LaunchArgs, XacroArgs};
pub(crate) use ros::RosArgs;
pub(crate) use run::RunArgs;
pub(crate) use world::WorldArgs;

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
