//! A run's options ([`RunArgs`]: the window or headless), with the window's, the Rerun
//! viewer's and the follower's.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use rover_core::{FollowerConfig, Perception};

use super::arm::ArmArgs;
use super::detector::DetectorArgs;
use super::ros::RosArgs;
use super::world::WorldArgs;
use crate::viewer::{ImageOptions, RecorderOptions, Viewer};

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
