//! Headless runs: a world, a robot and an input script, stepped as fast as the CPU allows.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rover_perception::{DetectorConfig, InjectedFault};
use rover_sim::{
    description::{LoadOptions, ResourcePaths},
    model::{RobotModel, World},
    physics::{ControlSample, SimOptions},
};

use crate::error::{CoreError, Result};
use crate::follower::FollowerConfig;
use crate::input::{InputSource, NoInput};
use crate::observer::{Fanout, NoObserver, Observer};
use crate::paths;
use crate::pilot::Mode;
use crate::run_files::RunFiles;
use crate::script::{Script, ScriptPlayer};
use crate::session::{DetectorMode, Session, SessionOptions};

/// Everything a headless run needs.
#[derive(Debug, Clone, Default)]
pub struct RunConfig {
    /// World file (default: worlds/playground.toml).
    pub world: Option<PathBuf>,
    /// URDF or xacro file (default: the world's `[robot] urdf`, else assets/robots/my_robot.urdf).
    pub robot: Option<PathBuf>,
    /// xacro arguments (over the world's `[robot] xacro_args`) and package folders (over
    /// `ROS_PACKAGE_PATH`) for the robot description.
    pub robot_options: LoadOptions,
    /// Where the robot spawns: x m, y m, yaw deg (overrides the world's `[robot]`).
    pub spawn: Option<[f64; 3]>,
    /// Wheels to drive (overrides the world's `[robot.drive]`).
    pub drive: Option<rover_sim::model::DriveSpec>,
    /// Which camera to render when the robot has several (default: the world's `[robot]
    /// camera`, else the first in the file).
    pub camera: Option<String>,
    /// A ros_control controllers YAML for the robot (overrides the world's `controllers`).
    pub controllers: Option<PathBuf>,
    /// A ros_gz_bridge topic map for the robot's gz topics (overrides the world's
    /// `bridge_config`).
    pub bridge_config: Option<PathBuf>,
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
    /// Camera + detector: `Auto` runs them when the script switches to follow mode or an
    /// observer wants images.
    pub perception: Perception,
    /// Lockstep detection rate on sim time (Hz; default [`DEFAULT_DETECT_HZ`]).
    pub detect_hz: Option<f64>,
    /// Detector settings.
    pub detector: DetectorConfig,
    /// Make the detector fail on purpose ([`SessionOptions::inject_fault`]).
    pub inject_fault: Option<InjectedFault>,
    /// Run the detector on its own thread on the newest frame, as the window does, instead of
    /// in lockstep on sim time: for real-time runs with outside peers (`--ros`), where the loop
    /// must keep pace with the wall clock. Detections then depend on the machine's speed, so
    /// such runs are not deterministic.
    pub detector_thread: bool,
    /// Detect on the loop's own thread, results at once (one core), instead of the default
    /// pipelined detection ([`DetectorMode::Pipelined`]: a second thread, results one
    /// detection period later). Both are deterministic.
    pub serial_detection: bool,
    /// Follower settings.
    pub follower: FollowerConfig,
    /// The arm's look and reach (links, classes).
    pub arm: crate::arm::ArmConfig,
    /// Measure ground truth for every camera image and judge each detection against it
    /// (observers get [`crate::Observer::detections_truth`]).
    pub ground_truth: bool,
    /// Pace the run to this many sim seconds per wall second (None = as fast as the CPU
    /// allows). Pacing never changes the trace: it only waits.
    pub real_time_factor: Option<f64>,
    /// Set from outside (the CLI's SIGINT/SIGTERM handler) to end the run after the current
    /// step; the trace and frames are finished as at a normal end, and
    /// [`RunSummary::interrupted`] says so.
    pub stop: Option<Arc<AtomicBool>>,
}

/// Whether a headless run renders the camera and runs the detector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Perception {
    /// When the script toggles follow mode, look or reach, or something watches the camera.
    #[default]
    Auto,
    /// Always.
    On,
    /// Never (the follower holds still).
    Off,
}

/// Default lockstep detection rate of headless runs (Hz of sim time): about what the default
/// model reaches on two CPU cores in real time.
pub const DEFAULT_DETECT_HZ: f64 = 5.0;

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
    /// Camera images written by `save_frames`.
    pub frames_written: u64,
    /// The last control sample.
    pub last: Option<ControlSample>,
    /// Mode at the end.
    pub mode: Mode,
    /// The run was ended early through [`RunConfig::stop`].
    pub interrupted: bool,
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

impl RunConfig {
    /// Whether [`RunConfig::stop`] asks the run to end.
    pub fn stop_requested(&self) -> bool {
        self.stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// Loads the world and robot this config names, with its spawn, drive and camera choices
    /// applied.
    pub fn load_world_and_robot(&self) -> Result<(World, RobotModel)> {
        let world_path = self.world.clone().unwrap_or_else(paths::default_world);
        let mut world = World::load_with(&world_path, &self.resource_paths())?;
        // `--srdf` stands for the world's: the planner reads its collision pairs from there.
        if let Some(srdf) = &self.arm.srdf {
            world.robot.srdf = Some(srdf.clone());
        }
        if let Some([x, y, yaw_deg]) = self.spawn {
            world.robot.position_m = [x, y];
            world.robot.yaw_rad = yaw_deg.to_radians();
        }
        let robot_path = self
            .robot
            .clone()
            .or_else(|| world.robot.urdf.clone())
            .unwrap_or_else(paths::default_robot_path);
        let mut robot = RobotModel::load_with(&robot_path, &self.robot_load_options(&world))?;
        if let Some(spec) = self.drive.as_ref().or(world.robot.drive.as_ref()) {
            robot.set_drive(spec)?;
        }
        if let Some(path) = self
            .controllers
            .as_ref()
            .or(world.robot.controllers.as_ref())
        {
            robot.load_controllers(path)?;
        }
        if let Some(path) = self
            .bridge_config
            .as_ref()
            .or(world.robot.bridge_config.as_ref())
        {
            let map = rover_sim::description::TopicMap::load(path)?;
            robot.bridge_topics(&map)?;
        }
        if let Some(name) = self.camera.as_ref().or(world.robot.camera.as_ref()) {
            robot.select_camera(name)?;
        } else if robot.cameras.len() > 1 {
            tracing::info!(
                "{}: {} cameras; rendering \"{}\" (choose with --camera NAME)",
                robot.name,
                robot.cameras.len(),
                robot.cameras[0].name
            );
        }
        Ok((world, robot))
    }

    /// Loads the script this config names (an empty one without).
    pub fn load_script(&self) -> Result<Script> {
        match &self.script {
            Some(path) => Script::load(path),
            None => Ok(Script::default()),
        }
    }

    /// Where packages and models are found: the config's folders first, then
    /// `ROS_PACKAGE_PATH` and `GAZEBO_MODEL_PATH`.
    fn resource_paths(&self) -> ResourcePaths {
        let mine = &self.robot_options.resources;
        let mut paths = ResourcePaths::from_env();
        paths.packages.extend(mine.packages.clone());
        paths
            .package_search
            .splice(0..0, mine.package_search.iter().cloned());
        paths
            .model_search
            .splice(0..0, mine.model_search.iter().cloned());
        paths
    }

    /// How the robot is read: the config's resource paths, and xacro arguments from the
    /// world's `[robot]`, then the config's.
    pub(crate) fn robot_load_options(&self, world: &World) -> LoadOptions {
        self.robot_load_options_with(world.robot.xacro_args.clone())
    }

    /// [`RunConfig::robot_load_options`] with these xacro arguments in place of a world's.
    pub(crate) fn robot_load_options_with(
        &self,
        mut xacro_args: std::collections::BTreeMap<String, String>,
    ) -> LoadOptions {
        xacro_args.extend(self.robot_options.xacro_args.clone());
        LoadOptions {
            xacro_args,
            resources: self.resource_paths(),
        }
    }
}

/// Runs headless and writes the trace, if asked. Deterministic: the same world, robot, script
/// and seed give a byte-identical trace (detection runs in lockstep on sim time).
pub fn run_headless(config: &RunConfig) -> Result<RunSummary> {
    run_headless_observed(config, &mut NoObserver, false)
}

/// [`run_headless`] with an observer (the Rerun recorder). `observer_wants_camera` turns the
/// camera and detector on under [`Perception::Auto`].
pub fn run_headless_observed(
    config: &RunConfig,
    observer: &mut dyn Observer,
    observer_wants_camera: bool,
) -> Result<RunSummary> {
    let (world, robot) = config.load_world_and_robot()?;
    let script = config.load_script()?;
    run_loaded(
        config,
        world,
        robot,
        script,
        observer,
        observer_wants_camera,
    )
}

/// [`run_headless_observed`] with the world and robot already loaded (the config's paths for
/// them are not read; its spawn, drive and camera choices are not applied) and input from
/// outside (the ROS bridge's `/cmd_vel`), polled before every physics step after the script's
/// due steps. Such runs are only as deterministic as their input's timing.
pub fn run_headless_driven(
    config: &RunConfig,
    world: World,
    robot: RobotModel,
    observer: &mut dyn Observer,
    observer_wants_camera: bool,
    inputs: &mut dyn InputSource,
) -> Result<RunSummary> {
    let script = config.load_script()?;
    run_inner(
        config,
        world,
        robot,
        script,
        observer,
        observer_wants_camera,
        inputs,
    )
}

/// [`run_headless_observed`] with the world, robot and script already loaded (the config's
/// paths for them are not read; its spawn, drive and camera choices are not applied): for
/// scenario files, built in memory.
pub(crate) fn run_loaded(
    config: &RunConfig,
    world: World,
    robot: RobotModel,
    script: Script,
    observer: &mut dyn Observer,
    observer_wants_camera: bool,
) -> Result<RunSummary> {
    run_inner(
        config,
        world,
        robot,
        script,
        observer,
        observer_wants_camera,
        &mut NoInput,
    )
}

fn run_inner(
    config: &RunConfig,
    world: World,
    robot: RobotModel,
    script: Script,
    observer: &mut dyn Observer,
    observer_wants_camera: bool,
    inputs: &mut dyn InputSource,
) -> Result<RunSummary> {
    let limits = RunLimits::check(config, &script)?;
    let mut player = ScriptPlayer::new(script);
    let perceive = match config.perception {
        Perception::On => true,
        Perception::Off => false,
        Perception::Auto => player.toggles_perception() || observer_wants_camera,
    };
    let mut files = RunFiles::open(
        config.trace.as_deref(),
        config.save_frames.as_deref(),
        config.frame_every,
        config.ground_truth,
    )?;
    let world_name = world.name.clone();
    let robot_name = robot.name.clone();
    let saves_frames = files.frames.is_some();
    let options = SessionOptions {
        sim: config.options.clone(),
        // The observers (ROS, a recorder) get the camera with the detector off too.
        camera: perceive || saves_frames || observer_wants_camera,
        every_frame: observer_wants_camera || saves_frames,
        detector: detector_mode(config, perceive, limits.detect_hz),
        detector_config: config.detector.clone(),
        inject_fault: config.inject_fault,
        follower: config.follower.clone(),
        arm: config.arm.clone(),
        ground_truth: config.ground_truth,
    };
    let mut fan = Fanout::default();
    fan.push(&mut files);
    fan.push(observer);
    let mut session = Session::new(world, robot, &options, &mut fan)?;
    let stepped = step_to_end(
        config,
        limits.duration_s,
        &mut session,
        &mut player,
        inputs,
        &mut fan,
    )?;
    drop(fan);
    let written = files.finish()?;
    Ok(RunSummary {
        world: world_name,
        robot: robot_name,
        sim_time_s: session.sim().sim_time_s(),
        steps: session.sim().step_index(),
        wall_s: stepped.wall_s,
        rows: written.rows,
        frames_written: written.frames,
        last: stepped.last,
        mode: session.pilot().mode(),
        interrupted: stepped.interrupted,
    })
}

/// A run's length and detection rate, checked along with its pacing.
struct RunLimits {
    /// Sim seconds to run.
    duration_s: f64,
    /// Detections per sim second.
    detect_hz: f64,
}

impl RunLimits {
    /// The config's duration (default: the script's last step + 1 s, or 10 s without a
    /// script), detection rate and real-time factor, each refused when out of range.
    fn check(config: &RunConfig, script: &Script) -> Result<Self> {
        let duration_s = match config.duration_s {
            Some(d) if d.is_finite() && d >= 0.0 => d,
            Some(d) => {
                return Err(CoreError::Option(format!(
                    "--duration must be a number of seconds >= 0, found {d}"
                )));
            }
            None if config.script.is_some() || !script.steps.is_empty() => script.end_s() + 1.0,
            None => 10.0,
        };
        let detect_hz = config.detect_hz.unwrap_or(DEFAULT_DETECT_HZ);
        if !(detect_hz.is_finite() && detect_hz > 0.0) {
            return Err(CoreError::Option(format!(
                "--detect-hz must be a positive number, found {detect_hz}"
            )));
        }
        if let Some(rtf) = config.real_time_factor
            && !(rtf.is_finite() && rtf > 0.0)
        {
            return Err(CoreError::Option(format!(
                "--rtf must be a positive factor, found {rtf}"
            )));
        }
        Ok(Self {
            duration_s,
            detect_hz,
        })
    }
}

/// How a headless run detects: not at all without perception; else on a worker thread
/// (`detector_thread`), serially on the loop's thread (`serial_detection`), or pipelined.
fn detector_mode(config: &RunConfig, perceive: bool, detect_hz: f64) -> DetectorMode {
    if perceive && config.detector_thread {
        DetectorMode::Worker
    } else if perceive && config.serial_detection {
        DetectorMode::Lockstep { rate_hz: detect_hz }
    } else if perceive {
        DetectorMode::Pipelined { rate_hz: detect_hz }
    } else {
        DetectorMode::Off
    }
}

/// What the stepping loop did.
struct Stepped {
    /// The last control sample.
    last: Option<ControlSample>,
    /// Wall time of the loop (s).
    wall_s: f64,
    /// Ended early through [`RunConfig::stop`].
    interrupted: bool,
}

/// A duration that means "until stopped" (Ctrl-C, or the stop flag): 1e9 s of sim time, some
/// 32 years; progress lines then say so instead of counting toward it.
pub const UNTIL_STOPPED_S: f64 = 1e9;

/// Steps the session until `duration_s` of sim time or a stop request: script steps and
/// outside inputs first, then physics; paced to the real-time factor and reporting progress
/// when the config asks. An observer's failure ends the run with its error.
fn step_to_end(
    config: &RunConfig,
    duration_s: f64,
    session: &mut Session,
    player: &mut ScriptPlayer,
    inputs: &mut dyn InputSource,
    fan: &mut Fanout<'_>,
) -> Result<Stepped> {
    let total_steps = (duration_s / session.sim().dt_s()).round() as u64;
    let mut last = None;
    let started = Instant::now();
    let mut last_report = started;
    let mut interrupted = false;
    while session.sim().step_index() < total_steps {
        if config.stop_requested() {
            interrupted = true;
            break;
        }
        player.play(session, fan);
        while let Some(action) = inputs.poll() {
            session.input(action, fan);
        }
        if let Some(sample) = session.step(fan)? {
            last = Some(sample);
        }
        if let Some(failure) = fan.failure() {
            return Err(failure);
        }
        if let Some(rtf) = config.real_time_factor {
            // Ahead of the wall clock: wait (in steps of a few ms, so sleeping stays coarse).
            let ahead_s = session.sim().sim_time_s() / rtf - started.elapsed().as_secs_f64();
            if ahead_s > 0.005 {
                std::thread::sleep(Duration::from_secs_f64(ahead_s));
            }
        }
        if let Some(every) = config.progress_every
            && last_report.elapsed() >= every
        {
            last_report = Instant::now();
            let rtf = session.sim().sim_time_s() / started.elapsed().as_secs_f64();
            if duration_s >= UNTIL_STOPPED_S {
                tracing::info!(
                    "sim time {:.1} s ({rtf:.1}x real time; until stopped)",
                    session.sim().sim_time_s()
                );
            } else {
                tracing::info!(
                    "sim time {:.1} / {duration_s:.1} s ({rtf:.1}x real time)",
                    session.sim().sim_time_s()
                );
            }
        }
    }
    Ok(Stepped {
        last,
        wall_s: started.elapsed().as_secs_f64(),
        interrupted,
    })
}
