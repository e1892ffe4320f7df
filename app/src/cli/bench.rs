//! `rover bench`: physics-only real-time factor on a world (single-threaded), camera frame
//! time, recording overhead and detector stages (beside onnxruntime).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use rover_core::{Perception, RunConfig, run_headless, run_headless_driven, run_headless_observed};
use rover_perception::DetectorConfig;
use rover_sim::{SimOptions, Simulation, Twist};

use super::args::WorldArgs;
use crate::viewer::{ImageOptions, Recorder, RecorderOptions, Viewer};

/// One benchmark measurement.
#[derive(Debug, Clone, Copy)]
pub struct PhysicsBench {
    /// Physics step rate (Hz).
    pub step_hz: f64,
    /// Sim seconds simulated.
    pub sim_s: f64,
    /// Wall seconds it took (best of the repeats).
    pub wall_s: f64,
    /// With an object held: how far it ended from the end effector (m).
    pub held_off_m: Option<f64>,
}

impl PhysicsBench {
    /// Sim seconds per wall second.
    pub fn real_time_factor(&self) -> f64 {
        self.sim_s / self.wall_s
    }

    /// Wall microseconds per physics step.
    pub fn us_per_step(&self) -> f64 {
        self.wall_s * 1e6 / (self.sim_s * self.step_hz)
    }
}

/// Steps the world's physics with the robot driving a figure of eight (forward at
/// [`EIGHT_SPEED_MPS`], a full circle left at [`EIGHT_TURN_RADPS`], then one right) for `sim_s`
/// seconds, `repeats` times; keeps the fastest. The eight closes, so the robot stays within
/// 3.5 m of where it started however long it runs (a 20 m ground holds it).
pub fn physics(
    config: &RunConfig,
    step_hz: Option<f64>,
    (sim_s, repeats): (f64, u32),
    hold: Option<&str>,
) -> Result<PhysicsBench> {
    let (world, robot) = config.load_world_and_robot()?;
    let options = SimOptions {
        step_hz,
        ..config.options.clone()
    };
    let mut best = f64::INFINITY;
    let mut rate = 0.0;
    let mut held_off_m = None;
    for _ in 0..repeats.max(1) {
        let mut sim = Simulation::new(world.clone(), robot.clone(), &options)?;
        rate = 1.0 / sim.dt_s();
        let held = hold.map(|name| grasp(&mut sim, name)).transpose()?;
        let first = sim.step_index();
        let steps = (sim_s / sim.dt_s()).round() as u64;
        let started = Instant::now();
        let mut turning_left = true;
        let lobe_steps = (std::f64::consts::TAU / EIGHT_TURN_RADPS * rate).round() as u64;
        while sim.step_index() - first < steps {
            if (sim.step_index() - first).is_multiple_of(lobe_steps.max(1)) {
                let turn = if turning_left {
                    EIGHT_TURN_RADPS
                } else {
                    -EIGHT_TURN_RADPS
                };
                sim.set_cmd_vel(Twist::new(EIGHT_SPEED_MPS, turn))?;
                turning_left = !turning_left;
            }
            sim.step();
        }
        best = best.min(started.elapsed().as_secs_f64());
        if let Some((object, tool)) = held {
            held_off_m = Some(object_to_link_m(&sim, object, tool));
        }
    }
    Ok(PhysicsBench {
        step_hz: rate,
        sim_s,
        wall_s: best,
        held_off_m,
    })
}

/// The physics benchmark's driving speed (m/s).
const EIGHT_SPEED_MPS: f64 = 0.5;
/// The physics benchmark's turn rate (rad/s): circles of 0.83 m radius.
const EIGHT_TURN_RADPS: f64 = 0.6;

/// Puts world object `name` in the robot's gripper, untimed: the first gripper controller
/// opens, the object goes to the end effector (the world's `[robot] ee_link`), the gripper
/// closes on it with 5 N and settles. Returns the object's index and the end effector.
fn grasp(sim: &mut Simulation, name: &str) -> Result<(usize, rover_sim::LinkId)> {
    let object = sim
        .world()
        .objects
        .iter()
        .position(|o| o.name == name)
        .ok_or_else(|| anyhow::anyhow!("--hold {name}: the world has no object \"{name}\""))?;
    let ee = sim.world().robot.ee_link.clone().ok_or_else(|| {
        anyhow::anyhow!("--hold needs the world's [robot] ee_link (where the object is held)")
    })?;
    let tool = sim
        .robot()
        .link_id(&ee)
        .ok_or_else(|| anyhow::anyhow!("--hold: the robot has no link \"{ee}\" (ee_link)"))?;
    let (controller, joint) = sim
        .robot()
        .controllers
        .as_ref()
        .and_then(|c| c.first_gripper())
        .map(|(name, g)| (name.to_owned(), g.joint.clone()))
        .ok_or_else(|| anyhow::anyhow!("--hold needs a gripper controller"))?;
    let open = sim
        .robot()
        .joint_id(&joint)
        .and_then(|j| sim.robot().joint(j).position_limits())
        .map_or(0.0, |(_, hi)| f64::from(hi));
    sim.command_gripper(&controller, open, 0.0)?;
    let settle = |sim: &mut Simulation, s: f64| {
        let end = sim.sim_time_s() + s;
        while sim.sim_time_s() < end {
            sim.step();
        }
    };
    settle(sim, 1.0);
    let at = sim.world_from_link(tool).translation;
    let at = [f64::from(at.x), f64::from(at.y), f64::from(at.z)];
    sim.place_object(object, at, 0.0)?;
    sim.command_gripper(&controller, 0.0, 5.0)?;
    settle(sim, 1.5);
    let off = object_to_link_m(sim, object, tool);
    anyhow::ensure!(
        off < 0.02,
        "--hold {name}: the gripper did not take it ({off:.3} m from {ee} after closing)"
    );
    Ok((object, tool))
}

/// An object this close to the end effector (m) is still in the hand.
const HELD_WITHIN_M: f64 = 0.05;

/// How far world object `object` is from link `link` (m).
fn object_to_link_m(sim: &Simulation, object: usize, link: rover_sim::LinkId) -> f64 {
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    let o = poses.get(object).map(|p| p.translation).unwrap_or_default();
    f64::from((o - sim.world_from_link(link).translation).length())
}

/// Result of the detector benchmark.
#[derive(Debug, Clone)]
pub struct DetectorBench {
    /// Model input size (width, height).
    pub input_size: (usize, usize),
    /// Median letterbox + normalisation (ms).
    pub preprocess_ms: f64,
    /// The runtime measured (`tract` or `onnxruntime`).
    pub runtime: &'static str,
    /// Median inference (ms).
    pub inference_ms: f64,
    /// Median decode + NMS (ms).
    pub decode_ms: f64,
    /// Median end to end (ms).
    pub total_ms: f64,
    /// onnxruntime's median (Python, as many threads) on the same graph and input, when it
    /// could run.
    pub onnxruntime_ms: Result<f64, String>,
}

pub(crate) fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Times the detector (`config.threads` threads, `runs` frames after one warm-up) on `image`,
/// then onnxruntime (Python, scripts/ort_reference.py) on exactly the same graph and input
/// tensor with as many intra-op threads.
pub fn detector(
    config: rover_perception::DetectorConfig,
    image: &std::path::Path,
    runs: usize,
) -> Result<DetectorBench> {
    use rover_perception::{Detector, FrameStamp, RgbView, load_rgb};

    let mut detector = Detector::load(config)?;
    let (w, h, pixels) = load_rgb(image)?;
    let view = RgbView::new(w, h, &pixels)?;
    detector.detect(view, FrameStamp::default())?;
    let (mut pre, mut inf, mut dec, mut total) = (vec![], vec![], vec![], vec![]);
    for frame in 0..runs.max(1) {
        let r = detector.detect(
            view,
            FrameStamp {
                sim_time_s: 0.0,
                frame: frame as u64,
            },
        )?;
        let t = detector.last_times();
        pre.push(t.preprocess_ms);
        inf.push(t.inference_ms);
        dec.push(t.decode_ms);
        total.push(r.latency_ms);
    }
    let input_size = detector.input_size();
    let onnxruntime_ms = onnxruntime_median(&mut detector, view, runs);
    Ok(DetectorBench {
        runtime: detector.config().runtime.name(),
        input_size,
        preprocess_ms: median(&mut pre),
        inference_ms: median(&mut inf),
        decode_ms: median(&mut dec),
        total_ms: median(&mut total),
        onnxruntime_ms,
    })
}

/// Per-op profile: tract's plan node by node beside onnxruntime's profiler, grouped by the
/// ONNX op type, on the same graph and input tensor (one thread each).
fn profile_detector(
    config: rover_perception::DetectorConfig,
    image: &std::path::Path,
    runs: usize,
) -> Result<()> {
    use rover_perception::{Detector, FrameStamp, RgbView, load_rgb};
    let mut detector = Detector::load(config)?;
    let (w, h, pixels) = load_rgb(image)?;
    let view = RgbView::new(w, h, &pixels)?;
    detector.detect(view, FrameStamp::default())?;
    detector.preprocess(view)?;
    let tract = detector.profile_ops(runs)?;
    let model = std::env::temp_dir().join(format!("rover-profile-{}.onnx", std::process::id()));
    let (iw, ih) = detector.input_size();
    let ort = detector
        .export_onnx(&model)
        .map_err(anyhow::Error::from)
        .and_then(|()| {
            let (input, _) = detector.preprocess(view)?;
            Ok(rover_perception::onnxruntime_reference_profiled(
                &model,
                input,
                &[1, 3, ih, iw],
                runs.max(1),
            )?)
        });
    let _ = std::fs::remove_file(&model);
    let ort_ops = match ort {
        Ok(run) => run.ops,
        Err(e) => {
            say!("onnxruntime: not profiled ({e:#})");
            Vec::new()
        }
    };
    let tract_total: f64 = tract.iter().map(|g| g.ms).sum();
    let ort_total: f64 = ort_ops.iter().map(|(_, ms)| ms).sum();
    say!("per-op profile, ms per run (sum of node times), one thread, {runs} runs:");
    say!(
        "{:<20} {:>6} {:>9} {:>9} {:>7}   tract's ops (ms)",
        "ONNX op",
        "nodes",
        "tract",
        "ort",
        "ratio"
    );
    for g in &tract {
        let ort_ms = ort_ops
            .iter()
            .find(|(op, _)| *op == g.onnx_op)
            .map(|(_, ms)| *ms);
        let top: Vec<String> = g
            .tract_ops
            .iter()
            .take(3)
            .map(|(op, ms)| format!("{op} {ms:.1}"))
            .collect();
        say!(
            "{:<20} {:>6} {:>9.2} {:>9} {:>7}   {}",
            g.onnx_op,
            g.nodes,
            g.ms,
            ort_ms.map_or_else(|| "-".to_owned(), |m| format!("{m:.2}")),
            ort_ms.map_or_else(|| "-".to_owned(), |m| format!("{:.2}x", g.ms / m)),
            top.join(", ")
        );
    }
    for (op, ms) in &ort_ops {
        if !tract.iter().any(|g| g.onnx_op == *op) {
            say!("{op:<20} {:>6} {:>9} {ms:>9.2}", "-", "-");
        }
    }
    say!(
        "{:<20} {:>6} {:>9.2} {:>9.2} {:>7.2}x",
        "total",
        "",
        tract_total,
        ort_total,
        tract_total / ort_total
    );
    say!();
    Ok(())
}

fn onnxruntime_median(
    detector: &mut rover_perception::Detector,
    view: rover_perception::RgbView<'_>,
    runs: usize,
) -> Result<f64, String> {
    let model = std::env::temp_dir().join(format!("rover-bench-{}.onnx", std::process::id()));
    let (w, h) = detector.input_size();
    let threads = detector.config().threads;
    let result = detector
        .export_onnx(&model)
        .map_err(|e| e.to_string())
        .and_then(|()| {
            let (input, _) = detector.preprocess(view).map_err(|e| e.to_string())?;
            rover_perception::onnxruntime_reference(
                &model,
                input,
                &[1, 3, h, w],
                threads,
                runs.max(1) + 1,
            )
            .map(|r| r.median_ms)
            .map_err(|e| format!("{e:#}"))
        });
    let _ = std::fs::remove_file(&model);
    result
}

/// Result of the camera benchmark.
#[derive(Debug, Clone)]
pub struct CameraBench {
    /// Graphics adapter used.
    pub adapter: String,
    /// Image size (px).
    pub size: (u32, u32),
    /// Median render + readback (ms).
    pub median_ms: f64,
    /// Fastest frame (ms).
    pub best_ms: f64,
    /// Median with ground truth on: id image and silhouettes read back, boxes measured (ms).
    pub truth_median_ms: f64,
    /// Median ms per image with the depth image read back too.
    pub depth_median_ms: f64,
    /// Labelled things in the world.
    pub labelled: usize,
}

/// Renders `frames` camera images of the world from the robot's camera while it drives a
/// circle (render + readback + post-processing per frame, after one warm-up), interleaving a
/// camera without and one with ground truth so both see the same machine load.
pub fn camera(config: &RunConfig, frames: usize) -> Result<CameraBench> {
    let (world, robot) = config.load_world_and_robot()?;
    let mut sim = Simulation::new(world, robot, &config.options)?;
    // The colour image alone, then with ground truth, then with a depth image.
    let mut sensor = rover_sim::CameraSensor::new(&sim)?;
    sensor.disable_depth();
    let mut truth = rover_sim::CameraSensor::new(&sim)?;
    truth.disable_depth();
    truth.enable_ground_truth(&sim)?;
    let mut depth = rover_sim::CameraSensor::new(&sim)?;
    depth.enable_depth();
    depth.capture(&sim)?;
    sim.set_cmd_vel(Twist::new(0.3, 0.4))?;
    sensor.capture(&sim)?;
    truth.capture(&sim)?;
    let mut times = Vec::with_capacity(frames);
    let mut truth_times = Vec::with_capacity(frames);
    let mut depth_times = Vec::with_capacity(frames);
    for _ in 0..frames.max(1) {
        for _ in 0..5 {
            sim.step();
        }
        let start = Instant::now();
        sensor.capture(&sim)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        truth.capture(&sim)?;
        truth_times.push(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        depth.capture(&sim)?;
        depth_times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    let best_ms = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(CameraBench {
        adapter: sensor.renderer().adapter().to_owned(),
        size: (sensor.info().width, sensor.info().height),
        median_ms: median(&mut times),
        best_ms,
        truth_median_ms: median(&mut truth_times),
        depth_median_ms: median(&mut depth_times),
        labelled: rover_sim::EntityIds::new(sim.world()).len(),
    })
}

/// Laser benchmark figures.
#[derive(Debug, Clone)]
pub struct LaserBench {
    /// Rays per scan.
    pub rays: u32,
    /// Scans per sim second.
    pub rate_hz: f64,
    /// Median wall time of one scan (ms).
    pub median_ms: f64,
    /// Fastest scan (ms).
    pub best_ms: f64,
    /// Median wall time of one follower command with the scan's obstacles (us).
    pub follower_us: f64,
    /// Median wall time of the avoidance's full window search over the scan's returns, with
    /// the way ahead blocked (the worst case, us).
    pub window_search_us: f64,
}

/// Laser: time per scan (ray casts against the physics scene) and the follower's command with
/// that scan's obstacles, in the configured world with its robot (default: the playground and
/// the tutorial car with its laser).
pub fn laser(config: &RunConfig, scans: usize) -> Result<LaserBench> {
    let (world, robot) = config.load_world_and_robot()?;
    anyhow::ensure!(
        !robot.lasers.is_empty(),
        "{}: the robot has no <sensor type=\"ray\">; try --robot assets/robots/my_robot_laser.urdf.xacro",
        robot.source.display()
    );
    let mut sim = Simulation::new(world, robot, &config.options)?;
    let mut sensor = rover_sim::LaserSensor::new(&sim, 0)?;
    let mount = rover_core::LaserMount::from_base_from_laser(
        sim.world_from_base().inverse() * sensor.world_from_sensor(&sim),
    );
    // The camera's geometry does not matter here: no detections are fed.
    let geometry = rover_core::CameraGeometry {
        fx: 381.0,
        fy: 381.0,
        cx: 320.5,
        cy: 240.5,
        width_px: 640.0,
        height_px: 480.0,
        height_m: 0.18,
        forward_m: 0.15,
        left_m: 0.0,
        yaw_rad: 0.0,
        pitch_down_rad: 0.0,
    };
    let mut follower = rover_core::Follower::new(rover_core::FollowerConfig::default(), geometry)
        .with_laser(mount);
    sim.set_cmd_vel(Twist::new(0.3, 0.4))?;
    sensor.scan_now(&sim);
    let mut times = Vec::with_capacity(scans);
    let mut follower_times = Vec::with_capacity(scans);
    let mut window_times = Vec::with_capacity(scans);
    let mut points: Vec<[f64; 2]> = Vec::new();
    let avoid = rover_core::AvoidConfig::default();
    for _ in 0..scans.max(1) {
        for _ in 0..5 {
            if let Some(sample) = sim.step() {
                follower.record_pose(sample.sim_time_s, sample.odometry);
            }
        }
        let start = Instant::now();
        let scan = sensor.scan_now(&sim);
        times.push(start.elapsed().as_secs_f64() * 1e3);
        points.clear();
        points.extend(
            scan.points()
                .map(|[x, y]| [f64::from(x) + mount.x_m, f64::from(y) + mount.y_m]),
        );
        points.push([0.5, 0.0]);
        follower.observe_scan(scan);
        let start = Instant::now();
        let _ = follower.command(sim.sim_time_s(), sim.odometry(), true);
        follower_times.push(start.elapsed().as_secs_f64() * 1e6);
        let start = Instant::now();
        let out = avoid.choose(Twist::new(0.8, 0.0), [4.0, 0.0], &points, 0.8, 1.2, 0.0);
        window_times.push(start.elapsed().as_secs_f64() * 1e6);
        std::hint::black_box(out);
    }
    let best_ms = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(LaserBench {
        rays: sensor.config().samples,
        rate_hz: sensor.config().update_rate_hz,
        median_ms: median(&mut times),
        best_ms,
        follower_us: median(&mut follower_times),
        window_search_us: median(&mut window_times),
    })
}

pub(crate) fn bench_laser(world: WorldArgs, scans: usize) -> Result<()> {
    let config = world.run_config(None);
    let b = laser(&config, scans)?;
    say!(
        "laser benchmark: {} rays at {} Hz, {scans} scans: median {:.3} ms, best {:.3} ms per scan ({:.2}% of a core at {} Hz); follower command {:.1} us; avoidance window search (worst case, every return) {:.0} us",
        b.rays,
        b.rate_hz,
        b.median_ms,
        b.best_ms,
        b.median_ms * b.rate_hz / 10.0,
        b.rate_hz,
        b.follower_us,
        b.window_search_us
    );
    Ok(())
}

/// Recording overhead: the same headless run (camera and lockstep detector on) without and
/// with `--record`.
#[derive(Debug, Clone)]
pub struct RecordBench {
    /// Wall seconds without recording (best of the repeats).
    pub plain_s: f64,
    /// Wall seconds with recording to an .rrd file (best of the repeats).
    pub recorded_s: f64,
    /// Size of the recording (bytes).
    pub rrd_bytes: u64,
}

impl RecordBench {
    /// recorded / plain.
    pub fn ratio(&self) -> f64 {
        self.recorded_s / self.plain_s
    }
}

/// Runs `config` `repeats` times each without and with a recorder writing into `dir`.
pub fn record(
    config: &RunConfig,
    images: ImageOptions,
    repeats: u32,
    dir: &std::path::Path,
) -> Result<RecordBench> {
    let config = RunConfig {
        perception: Perception::On,
        ..config.clone()
    };
    let mut plain = f64::INFINITY;
    let mut recorded = f64::INFINITY;
    let mut rrd_bytes = 0;
    for i in 0..repeats.max(1) {
        let started = Instant::now();
        run_headless(&config)?;
        plain = plain.min(started.elapsed().as_secs_f64());
        let path = dir.join(format!("bench-{i}.rrd"));
        let started = Instant::now();
        let options = RecorderOptions {
            viewer: Viewer::Save(path.clone()),
            images,
            ..RecorderOptions::default()
        };
        let mut rec = Recorder::start(&options)?
            .ok_or_else(|| anyhow::anyhow!("the recorder did not start"))?;
        run_headless_observed(&config, &mut rec, true)?;
        if let Err(e) = rec.finish() {
            tracing::warn!("the recording was not written in full: {e}");
        }
        drop(rec);
        recorded = recorded.min(started.elapsed().as_secs_f64());
        rrd_bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        let _ = std::fs::remove_file(&path);
    }
    Ok(RecordBench {
        plain_s: plain,
        recorded_s: recorded,
        rrd_bytes,
    })
}

pub(crate) fn bench_cmd(world: WorldArgs, args: super::args::PhysicsBenchArgs) -> Result<()> {
    let (sim_seconds, repeats, rates) = (args.sim_seconds, args.repeats, args.rates);
    anyhow::ensure!(
        sim_seconds.is_finite() && sim_seconds > 0.0,
        "--sim-seconds must be positive, found {sim_seconds}"
    );
    let config = world.run_config(None);
    let mut plan: Vec<Option<f64>> = vec![world.physics_hz];
    plan.extend(rates.into_iter().map(Some));
    say!("physics-only benchmark: {sim_seconds} sim s per run, best of {repeats}, one thread");
    say!(
        "{:>10} {:>12} {:>12} {:>14}",
        "step_hz",
        "wall_s",
        "us/step",
        "real-time x"
    );
    for step_hz in plan {
        let b = physics(
            &config,
            step_hz,
            (sim_seconds, repeats),
            args.hold.as_deref(),
        )?;
        say!(
            "{:>10.0} {:>12.3} {:>12.1} {:>14.0}",
            b.step_hz,
            b.wall_s,
            b.us_per_step(),
            b.real_time_factor()
        );
        if let (Some(name), Some(off)) = (&args.hold, b.held_off_m) {
            let verdict = if off < HELD_WITHIN_M {
                "still in the hand"
            } else {
                "dropped"
            };
            say!("  {name}: {verdict}, {off:.3} m from the end effector at the end");
        }
    }
    Ok(())
}

pub(crate) fn bench_record(
    world: WorldArgs,
    duration: f64,
    repeats: u32,
    jpeg: Option<u8>,
) -> Result<()> {
    let config = RunConfig {
        duration_s: Some(duration),
        ..world.run_config(None)
    };
    let dir = std::env::temp_dir().join(format!("rover-bench-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    say!(
        "recording overhead: {duration} sim s headless, camera + lockstep detector on, best of {repeats}"
    );
    let b = record(
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
    say!("without --record: {:.2} s wall", b.plain_s);
    say!(
        "with --record:    {:.2} s wall ({:.1} MB .rrd)",
        b.recorded_s,
        b.rrd_bytes as f64 / 1e6
    );
    say!("ratio: {:.2}x (goal <= 1.3x)", b.ratio());
    Ok(())
}

/// What the ROS bridge costs the loop.
#[derive(Debug, Clone, Copy)]
pub struct RosBench {
    /// Wall seconds without the bridge (best of the repeats).
    pub plain_s: f64,
    /// Wall seconds with the bridge and its subscribers (best of the repeats).
    pub bridged_s: f64,
    /// Messages the subscribers received in the fastest bridged run, per topic (image, /odom,
    /// /tf).
    pub received: [u64; 3],
    /// Wall seconds the bridge itself spent on the loop thread in that run.
    pub bridge_loop_s: f64,
}

/// The same headless run (camera + lockstep detector, unpaced) without and with the ROS
/// bridge, while an in-process node subscribes to the camera image, /odom and /tf (raw bytes,
/// like `rostopic hz`).
pub fn ros(config: &RunConfig, repeats: u32) -> Result<RosBench> {
    use rover_ros1::{Node, NodeOptions};
    let master = NodeOptions::from_env("rover_bench")?;
    rover_ros1::ros_call(
        &master.master_uri,
        "getPid",
        &[rover_ros1::Value::from("/rover_bench")],
        std::time::Duration::from_secs(2),
    )
    .map_err(|e| {
        anyhow::anyhow!(
            "no ROS master at {} ({e}): start roscore (or `rosmaster --core`) first",
            master.master_uri
        )
    })?;
    let config = RunConfig {
        perception: Perception::On,
        real_time_factor: None,
        ..config.clone()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let plan = crate::ros::RosPlan::for_robot(&robot);
    let image_topic = plan
        .image_topic
        .clone()
        .ok_or_else(|| anyhow::anyhow!("the robot has no camera"))?;
    let listener = Node::start(master)?;
    let mut subs = vec![
        listener.subscribe_raw(&image_topic, "sensor_msgs/Image", 4)?,
        listener.subscribe_raw(&plan.odom_topic, "nav_msgs/Odometry", 1000)?,
        listener.subscribe_raw("/tf", "tf2_msgs/TFMessage", 1000)?,
    ];
    let options = crate::ros::RosOptions {
        name: "rover".into(),
        sim_time: false,
        ground_truth: false,
    };
    let mut plain = f64::INFINITY;
    let mut bridged = f64::INFINITY;
    let mut received = [0; 3];
    let mut bridge_loop_s = 0.0;
    for _ in 0..repeats.max(1) {
        let started = Instant::now();
        run_headless(&config)?;
        plain = plain.min(started.elapsed().as_secs_f64());

        let (mut bridge, mut cmd_vel) = crate::ros::RosBridge::start(&options, &robot)?;
        // The subscribers connect before the clock starts.
        let wait = Instant::now();
        while !listener.is_registered() && wait.elapsed().as_secs_f64() < 10.0 {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        std::thread::sleep(std::time::Duration::from_secs(2));
        for s in &subs {
            while s.try_recv().is_some() {}
        }
        let counting = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
        let flag = counting.clone();
        let owned = std::mem::take(&mut subs);
        let counter = std::thread::spawn(move || {
            let mut n = [0u64; 3];
            while flag.load(std::sync::atomic::Ordering::Relaxed) {
                let mut any = false;
                for (i, s) in owned.iter().enumerate() {
                    while s.try_recv().is_some() {
                        n[i] += 1;
                        any = true;
                    }
                }
                if !any {
                    std::thread::sleep(std::time::Duration::from_millis(2));
                }
            }
            (n, owned)
        });
        let started = Instant::now();
        let run = run_headless_driven(
            &config,
            world.clone(),
            robot.clone(),
            &mut bridge,
            true,
            &mut cmd_vel,
        );
        let wall = started.elapsed().as_secs_f64();
        bridge.finish();
        std::thread::sleep(std::time::Duration::from_millis(500));
        counting.store(false, std::sync::atomic::Ordering::Relaxed);
        let (n, owned) = counter
            .join()
            .map_err(|_| anyhow::anyhow!("the counting thread panicked"))?;
        subs = owned;
        run?;
        if wall < bridged {
            bridged = wall;
            received = n;
            bridge_loop_s = bridge.loop_time().as_secs_f64();
        }
    }
    Ok(RosBench {
        plain_s: plain,
        bridged_s: bridged,
        received,
        bridge_loop_s,
    })
}

pub(crate) fn bench_ros(world: WorldArgs, duration: f64, repeats: u32) -> Result<()> {
    let config = RunConfig {
        duration_s: Some(duration),
        ..world.run_config(None)
    };
    say!(
        "ROS bridge cost: {duration} sim s headless, camera + lockstep detector on, unpaced, best of {repeats}"
    );
    let b = ros(&config, repeats)?;
    say!("without --ros: {:.2} s wall", b.plain_s);
    say!(
        "with --ros and 3 subscribers: {:.2} s wall (received {} images, {} odom, {} tf)",
        b.bridged_s,
        b.received[0],
        b.received[1],
        b.received[2]
    );
    say!(
        "ratio: {:.3}x; {:+.2} ms per sim second",
        b.bridged_s / b.plain_s,
        (b.bridged_s - b.plain_s) * 1e3 / duration
    );
    say!(
        "the bridge on the loop thread: {:.2} ms per sim second ({:.3}% of real time)",
        b.bridge_loop_s * 1e3 / duration,
        b.bridge_loop_s * 100.0 / duration
    );
    Ok(())
}

pub(crate) fn bench_camera(world: WorldArgs, frames: usize) -> Result<()> {
    let config = world.run_config(None);
    let b = camera(&config, frames)?;
    say!(
        "camera benchmark: {}x{} on {}, {frames} frames: median {:.2} ms, best {:.2} ms per frame (render + readback)",
        b.size.0,
        b.size.1,
        b.adapter,
        b.median_ms,
        b.best_ms
    );
    say!(
        "with ground truth ({} labelled things: id image, silhouettes, boxes): median {:.2} ms, +{:.2} ms",
        b.labelled,
        b.truth_median_ms,
        b.truth_median_ms - b.median_ms
    );
    say!(
        "with a depth image (the depth buffer read back as metres): median {:.2} ms, +{:.2} ms",
        b.depth_median_ms,
        b.depth_median_ms - b.median_ms
    );
    Ok(())
}

pub(crate) fn bench_detect(
    config: DetectorConfig,
    image: Option<PathBuf>,
    runs: usize,
    profile: bool,
) -> Result<()> {
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
    say!(
        "detector benchmark on {}: {runs} runs after a warm-up, {} thread(s) for both runtimes (--detect-threads)",
        image.display(),
        config.threads
    );
    if profile {
        // Node by node, one thread: the times add up to the run.
        profile_detector(
            DetectorConfig {
                threads: 1,
                runtime: rover_perception::Runtime::Tract,
                ..config.clone()
            },
            &image,
            runs,
        )?;
    }
    let b = detector(config, &image, runs)?;
    say!("input {}x{}", b.input_size.0, b.input_size.1);
    say!("{:<28} {:>10}", "stage (median)", "ms");
    say!("{:<28} {:>10.1}", "preprocess (letterbox)", b.preprocess_ms);
    say!(
        "{:<28} {:>10.1}",
        format!("{} inference", b.runtime),
        b.inference_ms
    );
    say!("{:<28} {:>10.1}", "decode + NMS", b.decode_ms);
    say!(
        "{:<28} {:>10.1}   ({:.1} Hz)",
        "end to end",
        b.total_ms,
        1000.0 / b.total_ms
    );
    match b.onnxruntime_ms {
        Ok(ort) => {
            say!("{:<28} {:>10.1}", "onnxruntime inference", ort);
            say!(
                "{:<28} {:>10.2}x",
                format!("{} / onnxruntime (Python)", b.runtime),
                b.inference_ms / ort
            );
        }
        Err(e) => say!("onnxruntime: not measured ({e}); pip install onnxruntime"),
    }
    Ok(())
}

/// `rover bench people`: the sweep table per body and posture, and the cost of posing a body.
pub(crate) fn bench_people(args: super::args::PeopleBenchArgs) -> Result<()> {
    use super::args::{PeopleBenchArgs, SweepBody, SweepPostureArg};
    let PeopleBenchArgs {
        world,
        detector,
        bodies,
        postures,
        save,
    } = args;
    let config = detector.tool_config(super::args::spare_detect_threads())?;
    use rover_core::{SWEEP_DISTANCES_M, SWEEP_HEADINGS_DEG, SWEEP_POSTURES, SweepPosture};
    let mut run = world.run_config(None);
    if run.world.is_none() {
        run.world = Some(rover_core::bundled_path("worlds/people.toml"));
    }
    let mut detector = rover_perception::Detector::load(config)?;
    let wants = |p: &SweepPosture| {
        postures.is_empty()
            || postures.iter().any(|w| {
                matches!(
                    (w, p),
                    (SweepPostureArg::Standing, SweepPosture::Standing)
                        | (SweepPostureArg::Walk, SweepPosture::Walking(_))
                )
            })
    };
    say!(
        "people sweep on {}: 8 headings x {} distances per posture, IoU >= 0.5 against ground truth; cells: detection confidence, `-` missed",
        run.world
            .as_deref()
            .unwrap_or(std::path::Path::new("?"))
            .display(),
        SWEEP_DISTANCES_M.len()
    );
    for body in &bodies {
        let (name, shape) = match body {
            SweepBody::Makehuman => {
                if rover_sim::human::shared().is_none() {
                    say!("makehuman: not available (see the warning above); skipped");
                    continue;
                }
                ("makehuman", Some(rover_sim::human::BodyShape::default()))
            }
            SweepBody::Figure => ("figure", None),
        };
        let dir = match &save {
            Some(d) => {
                let dir = d.join(name);
                std::fs::create_dir_all(&dir)?;
                Some(dir)
            }
            None => None,
        };
        let (mut all_found, mut all, mut near_found, mut near) = (0, 0, 0, 0);
        for posture in SWEEP_POSTURES.iter().filter(|p| wants(p)) {
            let views = rover_core::sweep(&run, &mut detector, shape, *posture, dir.as_deref())?;
            say!("");
            say!("{name}, {posture}:");
            let mut header = format!("{:>8}", "m \\ deg");
            for h in SWEEP_HEADINGS_DEG {
                header.push_str(&format!("{h:>6.0}"));
            }
            say!("{header}   found");
            for d in SWEEP_DISTANCES_M {
                let row: Vec<_> = views.iter().filter(|v| v.distance_m == d).collect();
                let mut line = format!("{d:>8.1}");
                for v in &row {
                    if v.found {
                        line.push_str(&format!("{:>6.2}", v.confidence));
                    } else {
                        line.push_str(&format!("{:>6}", "-"));
                    }
                }
                let found = row.iter().filter(|v| v.found).count();
                say!("{line}   {found}/{}", row.len());
            }
            let found = views.iter().filter(|v| v.found).count();
            let at_near: Vec<_> = views
                .iter()
                .filter(|v| v.distance_m == SWEEP_DISTANCES_M[0])
                .collect();
            let near_hits = at_near.iter().filter(|v| v.found).count();
            say!(
                "{name}, {posture}: {found}/{} views found, {near_hits}/{} at {} m",
                views.len(),
                at_near.len(),
                SWEEP_DISTANCES_M[0]
            );
            (all_found, all, near_found, near) = (
                all_found + found,
                all + views.len(),
                near_found + near_hits,
                near + at_near.len(),
            );
        }
        say!("");
        say!(
            "{name} in all: {all_found}/{all} views found, {near_found}/{near} at {} m",
            SWEEP_DISTANCES_M[0]
        );
    }
    time_posing()?;
    time_frames(&run)
}

/// Median camera frame time (ms; render + readback, posing included) with `count` people of
/// `shape` (`None`: the figure) walking side by side 3-7 m ahead of the robot.
fn frame_ms(
    run: &RunConfig,
    count: usize,
    shape: Option<rover_sim::human::BodyShape>,
) -> Result<f64> {
    let (mut world, robot) = run.load_world_and_robot()?;
    let template = world.people.first().cloned();
    world.people.clear();
    let [rx, ry] = world.robot.position_m;
    for i in 0..count {
        let Some(mut p) = template.clone() else {
            anyhow::bail!("the frame cost needs a world with a person to copy");
        };
        let x = rx + 3.0 + (i % 3) as f64 * 1.5;
        let y = ry + (i as f64 - (count as f64 - 1.0) / 2.0) * 0.7;
        p.name = format!("p{i}");
        p.position_m = [x, y];
        p.shape = shape;
        p.walk = Some(rover_sim::Walk {
            waypoints_m: vec![[x + 1.0, y]],
            speed_mps: 0.8,
            repeat: true,
            start_after_s: 0.0,
        });
        world.people.push(p);
    }
    let mut sim = Simulation::new(world, robot, &run.options)?;
    let mut camera = rover_sim::CameraSensor::new(&sim)?;
    camera.disable_depth();
    camera.capture(&sim)?;
    let mut times = Vec::new();
    for _ in 0..60 {
        for _ in 0..5 {
            sim.step();
        }
        let start = Instant::now();
        camera.capture(&sim)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(&mut times))
}

/// What walking people add to a 640x480 camera frame: 0, 1 and 10 of them, MakeHuman's body
/// beside the figure.
fn time_frames(run: &RunConfig) -> Result<()> {
    let none = frame_ms(run, 0, None)?;
    say!("");
    say!("camera frame (median of 60, posing + render + readback): {none:.2} ms with nobody");
    let mut bodies = vec![("figure", None)];
    if rover_sim::human::shared().is_some() {
        bodies.insert(
            0,
            ("makehuman", Some(rover_sim::human::BodyShape::default())),
        );
    }
    for (name, shape) in bodies {
        for count in [1, 10] {
            let ms = frame_ms(run, count, shape)?;
            say!(
                "{name}: {count:>2} walking 3-7 m ahead: {ms:.2} ms, +{:.2} ms",
                ms - none
            );
        }
    }
    Ok(())
}

/// Times posing (skinning) the default MakeHuman body through a walk.
fn time_posing() -> Result<()> {
    if let Some(human) = rover_sim::human::shared() {
        let body = human.body(
            rover_sim::human::BodyShape::default(),
            1.75,
            rover_sim::human::Outfit::default(),
        )?;
        let mut posed = rover_sim::human::PosedBody::default();
        let mut times = Vec::new();
        for k in 0..200 {
            let posture = rover_sim::human::Posture::Walking {
                phase_rad: 0.05 * f64::from(k + 1),
                stride_m: 1.2,
            };
            let start = Instant::now();
            body.pose(posture, &mut posed);
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        say!(
            "posing one body ({} vertices, linear-blend skinning on the CPU): median {:.3} ms",
            body.vertex_count(),
            median(&mut times)
        );
    }
    Ok(())
}
