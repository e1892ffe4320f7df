//! `rover bench`'s options: the benchmarks ([`BenchKind`]) and their settings.

use std::path::PathBuf;

use clap::{Args, Subcommand};

use super::dataset::DatasetImageFormat;
use super::detector::DetectorArgs;
use super::world::WorldArgs;

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
    /// Sensors: us per reading of each IMU, p3d publisher and GPS of the robot (default: the
    /// playground car's /imu, /ground_truth/state and /fix) while it drives a circle
    Sensors {
        #[command(flatten)]
        world: WorldArgs,

        /// Physics steps to run (each due reading is timed)
        #[arg(long, default_value_t = 4000)]
        steps: usize,
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

    /// Hold this world object or Gazebo model (`[[model]]` name) in the gripper while driving
    /// (before the clock starts: the arm reaches its start pose, the gripper opens, the object
    /// is held at the end effector while the gripper closes on it and, with the world's grasp
    /// assist, until the assist takes it); needs a gripper controller and the world's [robot]
    /// ee_link. Says whether it was still held at the end. E.g. `--world
    /// worlds/arm_car_pick.toml --spawn -3,-3 --hold ball`
    #[arg(long, value_name = "NAME")]
    pub(crate) hold: Option<String>,
}
