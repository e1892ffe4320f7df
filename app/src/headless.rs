//! Headless runs: a world, a robot and an input script, stepped as fast as the CPU allows.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rover_sim::{CameraSensor, ControlSample, RobotModel, SimOptions, Simulation, World};

use crate::paths;
use crate::pilot::{Mode, Pilot};
use crate::script::Script;
use crate::trace::TraceWriter;

/// Everything a headless run needs.
#[derive(Debug, Clone, Default)]
pub struct RunConfig {
    /// World file (default: worlds/playground.toml).
    pub world: Option<PathBuf>,
    /// URDF file (default: the world's `[robot] urdf`, else assets/robots/my_robot.urdf).
    pub robot: Option<PathBuf>,
    /// Input script.
    pub script: Option<PathBuf>,
    /// Sim seconds to run (default: the script's last step + 1 s, or 10 s without a script).
    pub duration_s: Option<f64>,
    /// Where to write the trace CSV.
    pub trace: Option<PathBuf>,
    /// Simulation options (seed, overrides).
    pub options: SimOptions,
    /// Log progress to stderr about every this many wall seconds (None = quiet).
    pub progress_every: Option<Duration>,
    /// Write camera images as PNG into this folder.
    pub save_frames: Option<PathBuf>,
    /// Write every Nth camera image (1 = all).
    pub frame_every: u64,
}

/// What a headless run did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    /// World name.
    pub world: String,
    /// Robot name.
    pub robot: String,
    /// Sim time reached (s).
    pub sim_time_s: f64,
    /// Physics steps taken.
    pub steps: u64,
    /// Wall time of the stepping loop (s).
    pub wall_s: f64,
    /// Trace rows written (= control updates).
    pub rows: u64,
    /// The last control sample.
    pub last: Option<ControlSample>,
    /// Mode at the end.
    pub mode: Mode,
}

impl RunSummary {
    /// Sim seconds per wall second.
    pub fn real_time_factor(&self) -> f64 {
        if self.wall_s > 0.0 {
            self.sim_time_s / self.wall_s
        } else {
            f64::INFINITY
        }
    }
}

/// Loads the world and robot a [`RunConfig`] names.
pub fn load(config: &RunConfig) -> Result<(World, RobotModel)> {
    let world_path = config.world.clone().unwrap_or_else(paths::default_world);
    let world = World::load(&world_path)?;
    let robot_path = config
        .robot
        .clone()
        .or_else(|| world.robot.urdf.clone())
        .unwrap_or_else(paths::default_robot);
    let robot = RobotModel::load(&robot_path)?;
    Ok((world, robot))
}

/// Runs headless and writes the trace, if asked. Deterministic: the same world, robot, script
/// and seed give a byte-identical trace.
pub fn run(config: &RunConfig) -> Result<RunSummary> {
    let (world, robot) = load(config)?;
    let script = match &config.script {
        Some(path) => Script::load(path)?,
        None => Script::default(),
    };
    let duration_s = match config.duration_s {
        Some(d) if d.is_finite() && d >= 0.0 => d,
        Some(d) => anyhow::bail!("--duration must be a number of seconds >= 0, found {d}"),
        None if config.script.is_some() => script.end_s() + 1.0,
        None => 10.0,
    };
    let mut trace = match &config.trace {
        Some(path) => {
            let file = File::create(path)
                .with_context(|| format!("cannot create trace file {}", path.display()))?;
            Some(TraceWriter::new(BufWriter::new(file))?)
        }
        None => None,
    };

    let world_name = world.name.clone();
    let robot_name = robot.name.clone();
    let mut sim = Simulation::new(world, robot, &config.options)?;
    let mut camera = match &config.save_frames {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
            let sensor = CameraSensor::new(&sim)?;
            tracing::info!(
                "camera: {}x{} at {} Hz, rendering on {}",
                sensor.info().width,
                sensor.info().height,
                sim.robot()
                    .cameras
                    .first()
                    .map_or(0.0, |c| c.update_rate_hz),
                sensor.renderer().adapter()
            );
            Some((sensor, dir.clone()))
        }
        None => None,
    };
    let frame_every = config.frame_every.max(1);
    let mut frames_written = 0u64;
    let mut pilot = Pilot::default();
    let mut next_step = 0;
    let total_steps = (duration_s / sim.dt_s()).round() as u64;
    let mut last = None;
    let started = Instant::now();
    let mut last_report = started;

    while sim.step_index() < total_steps {
        let now = sim.sim_time_s();
        while let Some(step) = script.steps.get(next_step) {
            // Half a physics step of tolerance: a step applies at the first physics step at or
            // after its time.
            if step.at_s > now + sim.dt_s() / 2.0 {
                break;
            }
            if let Some(cmd) = pilot.apply(step.action)
                && let Err(e) = sim.set_cmd_vel(cmd)
            {
                tracing::warn!("script step at {} s: {e}", step.at_s);
            }
            next_step += 1;
        }
        if let Some((sensor, dir)) = camera.as_mut()
            && let Some(frame) = sensor.capture_if_due(&sim)?
            && frame.seq % frame_every == 0
        {
            let path = dir.join(format!("frame_{:06}.png", frame.seq));
            image::save_buffer(
                &path,
                frame.rgb,
                frame.width,
                frame.height,
                image::ExtendedColorType::Rgb8,
            )
            .with_context(|| format!("cannot write {}", path.display()))?;
            frames_written += 1;
        }
        if let Some(sample) = sim.step() {
            if let Some(t) = trace.as_mut() {
                t.row(&sample, pilot.mode())?;
            }
            last = Some(sample);
        }
        if let Some(every) = config.progress_every
            && last_report.elapsed() >= every
        {
            last_report = Instant::now();
            tracing::info!(
                "sim time {:.1} / {:.1} s ({:.0}x real time)",
                sim.sim_time_s(),
                duration_s,
                sim.sim_time_s() / started.elapsed().as_secs_f64()
            );
        }
    }
    let wall_s = started.elapsed().as_secs_f64();
    let rows = match trace {
        Some(t) => {
            let rows = t.rows();
            t.finish()?;
            rows
        }
        None => 0,
    };
    if let Some((_, dir)) = &camera {
        tracing::info!("wrote {frames_written} camera frames to {}", dir.display());
    }
    Ok(RunSummary {
        world: world_name,
        robot: robot_name,
        sim_time_s: sim.sim_time_s(),
        steps: sim.step_index(),
        wall_s,
        rows,
        last,
        mode: pilot.mode(),
    })
}
