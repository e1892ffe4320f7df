//! The `rover` command line.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use rover::bench;
use rover::detect::{self, DetectOptions};
use rover::follower::FollowerConfig;
use rover::headless::{self, Perception, RunConfig};
use rover::recorder::{self, ImageOptions, Recorder, RecorderOptions, Viewer};
use rover::script::Script;
use rover::session::{DetectorMode, NoObserver, Observer, Session, SessionOptions};
use rover::trace::TraceWriter;
use rover::window::{self, WindowOptions};
use rover_perception::{DEFAULT_NMS_IOU, DEFAULT_THRESHOLD, DetectorConfig};
use rover_sim::SimOptions;

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
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,

    #[command(flatten)]
    run: RunArgs,
}

const EXAMPLES: &str = "\
Examples:
  rover                                             window + Rerun viewer on the default world
  rover --world worlds/walking.toml --viewer web    a walking person; viewer in the browser
  rover --headless                                  default world and robot for 10 s, print a summary
  rover --headless --record run.rrd                 the same, recorded for `rerun run.rrd`
  rover --headless --script drive.toml --trace out.csv
  rover --headless --world worlds/playground.toml --robot assets/robots/my_robot.urdf --duration 30 --seed 7
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
struct WorldArgs {
    /// World file (TOML, see docs/WORLDS.md) [default: worlds/playground.toml]
    #[arg(long, value_name = "FILE")]
    world: Option<PathBuf>,

    /// Robot URDF [default: the world's [robot] urdf, else assets/robots/my_robot.urdf]
    #[arg(long, value_name = "FILE")]
    robot: Option<PathBuf>,

    /// Physics step rate in Hz, overriding the world's [physics] step_hz
    #[arg(long, value_name = "HZ")]
    physics_hz: Option<f64>,

    /// Seed for everything random; the same seed gives the same run
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Debug, Args)]
struct RunArgs {
    /// Run without a window, as fast as the CPU allows, deterministically (detector in lockstep
    /// on sim time)
    #[arg(long)]
    headless: bool,

    #[command(flatten)]
    world: WorldArgs,

    /// Input script: timed cmd_vel / key / toggle steps on sim time (TOML)
    #[arg(long, value_name = "FILE")]
    script: Option<PathBuf>,

    /// Sim seconds to run [default: last script step + 1 s, or 10 s]
    #[arg(long, value_name = "SECS")]
    duration: Option<f64>,

    /// Write a CSV trace, one row per control update
    #[arg(long, value_name = "FILE")]
    trace: Option<PathBuf>,

    /// Write the robot camera's images as PNG files into DIR (rendered with wgpu: a GPU, or
    /// Mesa's software Vulkan)
    #[arg(long, value_name = "DIR")]
    save_frames: Option<PathBuf>,

    /// With --save-frames: write every Nth camera image
    #[arg(long, default_value_t = 1, value_name = "N")]
    frame_every: u64,

    /// Stop the robot when no cmd_vel arrived for SECS (off by default, like Gazebo; 0 = off)
    #[arg(long, value_name = "SECS")]
    cmd_timeout: Option<f64>,

    #[command(flatten)]
    follow: FollowArgs,

    #[command(flatten)]
    detector: DetectorArgs,

    #[command(flatten)]
    viewer: ViewerArgs,

    #[command(flatten)]
    window: WindowArgs,
}

/// Window options.
#[derive(Debug, Args)]
struct WindowArgs {
    /// Window: sim seconds per wall second
    #[arg(long, default_value_t = 1.0, value_name = "X")]
    rtf: f64,

    /// Window: keep driving after a key is released, like the terminal teleop_twist_keyboard
    /// (default: hold a key to drive, release to stop)
    #[arg(long)]
    latched: bool,

    /// Window: W/A/S/D drive too (teleop's w/x/e/c speed keys are then off; q/z still scale)
    #[arg(long)]
    wasd: bool,

    /// Window: start paused (p resumes, n steps one control update)
    #[arg(long)]
    paused: bool,

    /// Window: write the window's image (camera, boxes, HUD) as PNG when quitting
    #[arg(long, value_name = "FILE.png")]
    screenshot: Option<PathBuf>,
}

/// Rerun viewer and recording options.
#[derive(Debug, Args)]
struct ViewerArgs {
    /// Rerun viewer: `spawn` (native viewer, `pip install rerun-sdk==0.36.3`), `connect [URL]`
    /// (a running viewer, default rerun+http://127.0.0.1:9876/proxy), `web` (rover serves the
    /// web viewer and prints its URL), `save FILE.rrd`, or `none` [default: none when headless;
    /// in the window: spawn when a matching `rerun` is on PATH, else web]
    #[arg(long, num_args = 1..=2, value_names = ["MODE", "ARG"])]
    viewer: Vec<String>,

    /// Also record the run to this .rrd file (works with any --viewer)
    #[arg(long, value_name = "FILE.rrd")]
    record: Option<PathBuf>,

    /// Camera images sent to Rerun per sim second [default: every camera frame]
    #[arg(long, value_name = "HZ")]
    image_hz: Option<f64>,

    /// Send camera images to Rerun at 1/N of their width and height (long runs)
    #[arg(long, default_value_t = 1, value_name = "N")]
    image_downscale: u32,

    /// Send camera images to Rerun as JPEG of this quality (1-100) instead of raw RGB
    #[arg(long, value_name = "Q", value_parser = clap::value_parser!(u8).range(1..=100))]
    image_jpeg: Option<u8>,

    /// Port of the web viewer (`--viewer web`)
    #[arg(long, default_value_t = 9090, value_name = "PORT")]
    web_port: u16,

    /// Port of the Rerun data server behind the web viewer (`--viewer web`)
    #[arg(long, default_value_t = 9876, value_name = "PORT")]
    grpc_port: u16,
}

impl ViewerArgs {
    fn options(&self, interactive: bool) -> Result<RecorderOptions> {
        let viewer = if self.viewer.is_empty() {
            if interactive {
                let (viewer, why) = recorder::default_viewer();
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
struct FollowArgs {
    /// Headless: run the camera and detector even when the script never switches to follow
    /// (they always run when it does)
    #[arg(long, conflicts_with = "no_detector")]
    detect: bool,

    /// Never run the detector (the follower then holds still)
    #[arg(long)]
    no_detector: bool,

    /// Headless: detections per sim second, in lockstep with the simulation (deterministic)
    #[arg(long, value_name = "HZ", default_value_t = headless::DEFAULT_DETECT_HZ)]
    detect_hz: f64,

    /// Follower: class to follow (a darknet_ros `Class`, e.g. person, dog)
    #[arg(long, default_value = "person", value_name = "CLASS")]
    target_class: String,

    /// Follower: distance to keep from the target (m)
    #[arg(long, default_value_t = 1.5, value_name = "M")]
    standoff: f64,

    /// Follower: speed limit (m/s)
    #[arg(long, default_value_t = 0.5, value_name = "MPS")]
    follow_speed: f64,
}

impl FollowArgs {
    fn follower(&self) -> anyhow::Result<FollowerConfig> {
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

    fn perception(&self) -> Perception {
        match (self.detect, self.no_detector) {
            (_, true) => Perception::Off,
            (true, _) => Perception::On,
            _ => Perception::Auto,
        }
    }
}

/// Detector options shared by the commands that run YOLO.
#[derive(Debug, Args)]
struct DetectorArgs {
    /// YOLO ONNX model [default: YOLOv12n from the crates.io package easy-yolo 0.1.3, fetched
    /// into ~/.cache/rover on first use; its weights are AGPL-3.0]. Heads: YOLOv5 [1,N,5+C],
    /// YOLOv8/11/12 [1,4+C,N], YOLOv10 [1,K,6]
    #[arg(long, value_name = "FILE")]
    model: Option<PathBuf>,

    /// Class names, one per line (darknet's coco.names format) [default: the model's `names`
    /// metadata, else COCO's 80]
    #[arg(long, value_name = "FILE")]
    labels: Option<PathBuf>,

    /// Confidence threshold (darknet_ros's default)
    #[arg(long, default_value_t = DEFAULT_THRESHOLD, value_name = "T")]
    threshold: f32,

    /// Class-wise NMS IoU threshold (darknet_ros's default)
    #[arg(long, default_value_t = DEFAULT_NMS_IOU, value_name = "IOU")]
    nms: f32,

    /// Network input size WIDTHxHEIGHT, multiples of 32 [default: 512x384 for the default model
    /// (the camera's 4:3 aspect), the model's own size otherwise]
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    input_size: Option<(usize, usize)>,
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

impl DetectorArgs {
    fn config(&self) -> anyhow::Result<DetectorConfig> {
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
            ..DetectorConfig::default()
        })
    }
}

#[derive(Debug, Subcommand)]
enum BenchKind {
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
    /// Camera: ms per image (render + readback) on this machine's GPU or software Vulkan
    Camera {
        #[command(flatten)]
        world: WorldArgs,

        /// Frames to time (after one warm-up)
        #[arg(long, default_value_t = 60)]
        frames: usize,
    },
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
    },
}

#[derive(Debug, Subcommand)]
enum Command {
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

    /// Benchmarks: physics-only real-time factor (default), or `bench detect`
    Bench {
        #[command(subcommand)]
        kind: Option<BenchKind>,

        #[command(flatten)]
        world: WorldArgs,

        /// Sim seconds per measurement
        #[arg(long, default_value_t = 60.0, value_name = "SECS")]
        sim_seconds: f64,

        /// Repeats per measurement (the fastest counts)
        #[arg(long, default_value_t = 3)]
        repeats: u32,

        /// Also measure at these step rates (Hz), e.g. --rates 250,500,1000
        #[arg(long, value_delimiter = ',', value_name = "HZ,...")]
        rates: Vec<f64>,
    },
}

impl WorldArgs {
    /// A run of this world and robot; the rest at its defaults.
    fn run_config(&self, cmd_timeout_s: Option<f64>) -> RunConfig {
        RunConfig {
            world: self.world.clone(),
            robot: self.robot.clone(),
            options: SimOptions {
                seed: self.seed,
                cmd_timeout_s,
                step_hz: self.physics_hz,
            },
            ..RunConfig::default()
        }
    }
}

fn run(args: RunArgs) -> Result<()> {
    if !args.headless {
        return run_window(args);
    }
    let config = RunConfig {
        script: args.script,
        duration_s: args.duration,
        trace: args.trace.clone(),
        progress_every: Some(Duration::from_secs(5)),
        save_frames: args.save_frames,
        frame_every: args.frame_every,
        perception: args.follow.perception(),
        detect_hz: Some(args.follow.detect_hz),
        detector: args.detector.config()?,
        follower: args.follow.follower()?,
        ..args.world.run_config(args.cmd_timeout)
    };
    let recorder_options = args.viewer.options(false)?;
    let summary = match Recorder::start(&recorder_options)? {
        Some(mut rec) => {
            if let Some(url) = &rec.web_url {
                println!("Rerun web viewer: {url}");
            }
            let summary = headless::run_observed(&config, &mut rec, true);
            rec.finish();
            if let Some(path) = &recorder_options.record {
                println!("recording: {}", recorder::describe_file(path));
            }
            if let (Some(url), Ok(_)) = (&rec.web_url, &summary) {
                println!("run finished; still serving the web viewer at {url} (Ctrl-C to quit)");
                loop {
                    std::thread::sleep(Duration::from_secs(3600));
                }
            }
            summary?
        }
        None => headless::run(&config)?,
    };
    println!(
        "rover: world \"{}\", robot \"{}\": {:.2} s sim time in {} physics steps, {:.3} s wall ({:.0}x real time)",
        summary.world,
        summary.robot,
        summary.sim_time_s,
        summary.steps,
        summary.wall_s,
        summary.real_time_factor()
    );
    if let Some(last) = summary.last {
        let g = last.ground_truth;
        let o = last.odometry;
        println!(
            "final pose: x {:.3} m, y {:.3} m, yaw {:.1} deg (odometry: x {:.3} m, y {:.3} m, yaw {:.1} deg); mode {}",
            g.x_m,
            g.y_m,
            g.yaw_rad.to_degrees(),
            o.x_m,
            o.y_m,
            o.yaw_rad.to_degrees(),
            summary.mode.as_str()
        );
    }
    if let Some(path) = &args.trace {
        println!("trace: {} ({} rows)", path.display(), summary.rows);
    }
    Ok(())
}

fn run_window(args: RunArgs) -> Result<()> {
    window::check_display()?;
    anyhow::ensure!(
        args.window.rtf.is_finite() && args.window.rtf > 0.0,
        "--rtf must be a positive factor, found {}",
        args.window.rtf
    );
    let config = args.world.run_config(args.cmd_timeout);
    let (world, robot) = headless::load(&config)?;
    let script = match &args.script {
        Some(path) => Script::load(path)?,
        None => Script::default(),
    };
    let recorder_options = args.viewer.options(true)?;
    let mut recorder = match Recorder::start(&recorder_options) {
        Ok(r) => r,
        Err(e) => {
            tracing::warn!("{e:#}; going on without a viewer");
            None
        }
    };
    if let Some(url) = recorder.as_ref().and_then(|r| r.web_url.clone()) {
        println!("Rerun web viewer: {url}");
    }
    let mut none = NoObserver;
    let observer: &mut dyn Observer = match recorder.as_mut() {
        Some(r) => r,
        None => &mut none,
    };
    let options = SessionOptions {
        sim: config.options.clone(),
        camera: true,
        detector: if args.follow.no_detector {
            DetectorMode::Off
        } else {
            DetectorMode::Worker
        },
        detector_config: args.detector.config()?,
        follower: args.follow.follower()?,
        save_frames: args.save_frames.clone(),
        frame_every: args.frame_every,
    };
    let session = Session::new(world, robot, &options, observer)?;
    let trace = match &args.trace {
        Some(path) => {
            let file = std::fs::File::create(path)
                .with_context(|| format!("cannot create trace file {}", path.display()))?;
            Some(TraceWriter::new(std::io::BufWriter::new(file))?)
        }
        None => None,
    };
    let summary = window::run(
        session,
        observer,
        WindowOptions {
            real_time_factor: args.window.rtf,
            latched: args.window.latched,
            wasd: args.window.wasd,
            duration_s: args.duration,
            paused: args.window.paused,
            script,
            screenshot: args.window.screenshot.clone(),
        },
        trace,
    )?;
    if let Some(r) = recorder.as_mut() {
        r.finish();
    }
    println!(
        "rover: {:.1} s sim time in {:.1} s wall; mode {}",
        summary.sim_time_s,
        summary.wall_s,
        summary.mode.as_str()
    );
    if let Some(path) = &recorder_options.record {
        println!("recording: {}", recorder::describe_file(path));
    }
    Ok(())
}

fn bench_cmd(world: WorldArgs, sim_seconds: f64, repeats: u32, rates: Vec<f64>) -> Result<()> {
    anyhow::ensure!(
        sim_seconds.is_finite() && sim_seconds > 0.0,
        "--sim-seconds must be positive, found {sim_seconds}"
    );
    let config = world.run_config(None);
    let mut plan: Vec<Option<f64>> = vec![world.physics_hz];
    plan.extend(rates.into_iter().map(Some));
    println!("physics-only benchmark: {sim_seconds} sim s per run, best of {repeats}, one thread");
    println!(
        "{:>10} {:>12} {:>12} {:>14}",
        "step_hz", "wall_s", "us/step", "real-time x"
    );
    for step_hz in plan {
        let b = bench::physics(&config, step_hz, sim_seconds, repeats)?;
        println!(
            "{:>10.0} {:>12.3} {:>12.1} {:>14.0}",
            b.step_hz,
            b.wall_s,
            b.us_per_step(),
            b.real_time_factor()
        );
    }
    Ok(())
}

fn bench_record(world: WorldArgs, duration: f64, repeats: u32, jpeg: Option<u8>) -> Result<()> {
    let config = RunConfig {
        duration_s: Some(duration),
        ..world.run_config(None)
    };
    let dir = std::env::temp_dir().join(format!("rover-bench-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    println!(
        "recording overhead: {duration} sim s headless, camera + lockstep detector on, best of {repeats}"
    );
    let b = bench::record(
        &config,
        ImageOptions {
            jpeg_quality: jpeg,
            ..ImageOptions::default()
        },
        repeats,
        &dir,
    );
    let _ = std::fs::remove_dir_all(&dir);
    let b = b?;
    println!("without --record: {:.2} s wall", b.plain_s);
    println!(
        "with --record:    {:.2} s wall ({:.1} MB .rrd)",
        b.recorded_s,
        b.rrd_bytes as f64 / 1e6
    );
    println!("ratio: {:.2}x (goal <= 1.3x)", b.ratio());
    Ok(())
}

fn bench_camera(world: WorldArgs, frames: usize) -> Result<()> {
    let config = world.run_config(None);
    let b = bench::camera(&config, frames)?;
    println!(
        "camera benchmark: {}x{} on {}, {frames} frames: median {:.2} ms, best {:.2} ms per frame (render + readback)",
        b.size.0, b.size.1, b.adapter, b.median_ms, b.best_ms
    );
    Ok(())
}

fn bench_detect(config: DetectorConfig, image: Option<PathBuf>, runs: usize) -> Result<()> {
    let image = match image {
        Some(path) => path,
        None => {
            let darknet = PathBuf::from("/usr/share/darknet/data/person.jpg");
            if darknet.is_file() {
                darknet
            } else {
                let path = std::env::temp_dir().join("rover-bench-pattern.png");
                let pattern = image::RgbImage::from_fn(640, 480, |x, y| {
                    image::Rgb([(x % 256) as u8, (y % 256) as u8, ((x + y) % 256) as u8])
                });
                pattern.save(&path)?;
                path
            }
        }
    };
    println!(
        "detector benchmark on {}: {runs} runs after a warm-up, one thread",
        image.display()
    );
    let b = bench::detector(config, &image, runs)?;
    println!("input {}x{}", b.input_size.0, b.input_size.1);
    println!("{:<28} {:>10}", "stage (median)", "ms");
    println!("{:<28} {:>10.1}", "preprocess (letterbox)", b.preprocess_ms);
    println!("{:<28} {:>10.1}", "tract inference", b.inference_ms);
    println!("{:<28} {:>10.1}", "decode + NMS", b.decode_ms);
    println!(
        "{:<28} {:>10.1}   ({:.1} Hz)",
        "end to end",
        b.total_ms,
        1000.0 / b.total_ms
    );
    match b.onnxruntime_ms {
        Ok(ort) => {
            println!("{:<28} {:>10.1}", "onnxruntime inference", ort);
            println!(
                "{:<28} {:>10.2}x",
                "tract / onnxruntime",
                b.inference_ms / ort
            );
        }
        Err(e) => println!("onnxruntime: not measured ({e}); pip install onnxruntime"),
    }
    Ok(())
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| {
                tracing_subscriber::EnvFilter::new(
                    "info,tract_onnx=error,tract_hir=error,tract_core=error",
                )
            }),
        )
        .with_writer(std::io::stderr)
        .with_target(false)
        .init();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Bench {
            kind:
                Some(BenchKind::Detect {
                    detector,
                    image,
                    runs,
                }),
            ..
        }) => detector
            .config()
            .and_then(|config| bench_detect(config, image, runs)),
        Some(Command::Bench {
            kind: Some(BenchKind::Camera { world, frames }),
            ..
        }) => bench_camera(world, frames),
        Some(Command::Bench {
            kind:
                Some(BenchKind::Record {
                    world,
                    duration,
                    repeats,
                    image_jpeg,
                }),
            ..
        }) => bench_record(world, duration, repeats, image_jpeg),
        Some(Command::Bench {
            kind: None,
            world,
            sim_seconds,
            repeats,
            rates,
        }) => bench_cmd(world, sim_seconds, repeats, rates),
        Some(Command::Detect {
            images,
            detector,
            json,
            out,
        }) => detector.config().and_then(|config| {
            detect::run(&DetectOptions {
                images,
                detector: config,
                json,
                out,
            })
        }),
        None => run(cli.run),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rover: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
