//! One run of the robot: simulation, camera, detector, pilot and follower, advanced one physics
//! step at a time. Headless runs and the window use the same [`Session`]; they differ only in
//! who paces it (as fast as possible vs real time) and which detector drives it (lockstep on sim
//! time for determinism vs a worker thread that always takes the newest frame).
//!
//! Data flows one way: world + URDF -> sim -> camera -> detector -> pilot (teleop | follower)
//! -> cmd_vel -> sim. Observers (the Rerun recorder, the window's HUD) only watch.

use std::time::Instant;

use rover_perception::{
    BoundingBoxes, DetectorConfig, FrameStamp, InjectedFault, PerceptionError, WorkerStats,
};
use rover_sim::{
    model::{CameraInfo, LinkId, RobotModel, World},
    physics::{ControlSample, SimOptions, Simulation},
    sensors::{
        BumperSensor, CameraSensor, GpsSensor, GroundTruthBox, ImuSensor, LaserSensor, LidarSensor,
    },
};

use crate::arm::{ArmConfig, ArmMode, ArmTask};
pub use crate::detection::DetectorMode;
use crate::detection::{Detected, Detection};
use crate::error::{CoreError, Result};
use crate::follower::{CameraGeometry, Follower, FollowerConfig, LaserMount};
use crate::input::{Action, JointAction};
use crate::observer::{EventLevel, LoopStats, Observer};
use crate::pilot::{Mode, Pilot};
use crate::sensors::ObservedSensors;

/// Everything a session needs besides the world and the robot.
#[derive(Debug, Clone)]
pub struct SessionOptions {
    /// Simulation options (seed, overrides).
    pub sim: SimOptions,
    /// Whether to render the camera at all.
    pub camera: bool,
    /// Whether every camera image is rendered and shown to the observers (a viewer, a recorder,
    /// saved frames, ROS). When false, only the images the detector takes are rendered; the
    /// others are skipped with the same schedule and frame numbers, so results are the same.
    pub every_frame: bool,
    /// How detection runs (needs the camera).
    pub detector: DetectorMode,
    /// Detector settings (model, input size, thresholds).
    pub detector_config: DetectorConfig,
    /// Make the detector fail on purpose (`--inject-fault`, for tests of the failure policy):
    /// the loaded detector is wrapped in a [`FaultInjector`]; `None` in normal use.
    pub inject_fault: Option<InjectedFault>,
    /// Follower settings.
    pub follower: FollowerConfig,
    /// The arm's look and reach: links and settings.
    pub arm: ArmConfig,
    /// Measure the ground truth of every camera image (rover_sim's id image and silhouettes)
    /// and hand each detection result's observers the ground truth of its image
    /// ([`Observer::detections_truth`]).
    pub ground_truth: bool,
}

/// How many recent images' ground truth is kept for detections still to come (a pipelined
/// result arrives one image later; the worker may lag a few).
const TRUTH_FRAMES: usize = 8;

impl Default for SessionOptions {
    fn default() -> Self {
        Self {
            sim: SimOptions::default(),
            camera: false,
            every_frame: true,
            detector: DetectorMode::Off,
            detector_config: DetectorConfig::default(),
            inject_fault: None,
            follower: FollowerConfig::default(),
            arm: ArmConfig::default(),
            ground_truth: false,
        }
    }
}

/// Sends an event to the observer and to the log.
fn emit(observer: &mut dyn Observer, sim_time_s: f64, level: EventLevel, text: &str) {
    match level {
        EventLevel::Info => tracing::info!("{text}"),
        EventLevel::Warn => tracing::warn!("{text}"),
    }
    observer.event(sim_time_s, level, text);
}

/// A running session.
pub struct Session {
    sim: Simulation,
    camera: Option<CameraSensor>,
    camera_link: LinkId,
    laser: Option<LaserSensor>,
    /// The IMUs, p3d, GPS receivers, 3D lidars and the depth cloud.
    sensors: ObservedSensors,
    detection: Detection,
    labels: Vec<String>,
    every_frame: bool,
    pilot: Pilot,
    /// Whether a fetch commanded the base last control update.
    fetch_drove: bool,
    follower: Follower,
    arm: ArmTask,
    stats: LoopStats,
    last_boxes: Option<BoundingBoxes>,
    detections_done: u64,
    detector_started: Option<Instant>,
    /// With ground truth on: the last [`TRUTH_FRAMES`] images' ground truth, slot `seq %
    /// TRUTH_FRAMES` holding (seq, boxes).
    truth_frames: Vec<(u64, Vec<GroundTruthBox>)>,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("sim", &self.sim)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl Session {
    /// Builds the simulation, and the camera and detector when asked. A detector that cannot
    /// be loaded (no model, bad model) is reported through `observer` as a warning: the session
    /// still runs, manual driving works and the follower holds still. The same policy holds
    /// when the detector fails later (an error or a panic in it), headless or in the window.
    pub fn new(
        world: World,
        robot: RobotModel,
        options: &SessionOptions,
        observer: &mut dyn Observer,
    ) -> Result<Self> {
        let sim = Simulation::new(world, robot, &options.sim)?;
        let wants_camera = options.camera || options.detector != DetectorMode::Off;
        let mut camera = start_camera(&sim, wants_camera, observer)?;
        if options.ground_truth
            && let Some(camera) = camera.as_mut()
        {
            camera
                .enable_ground_truth(&sim)
                .map_err(CoreError::Camera)?;
        }
        let camera_link = sim
            .robot()
            .cameras
            .first()
            .and_then(|c| sim.robot().link_id(&c.link))
            .unwrap_or(sim.robot().root);
        let camera_config = camera.as_ref().and(sim.robot().cameras.first());
        let arm_config = options.arm.resolved(sim.robot(), &sim.world().robot)?;
        let arm = ArmTask::new(&sim, camera_config, &arm_config);
        let laser = start_laser(&sim)?;
        let sensors = ObservedSensors::start(&sim, camera.as_ref().map(|c| c.info()))?;
        let geometry = camera_geometry(&sim, camera.as_ref().map(|c| c.info()), camera_link);
        let mut follower = Follower::new(options.follower.clone(), geometry);
        if let Some(l) = &laser {
            let base_from_laser = sim.world_from_base().inverse() * l.world_from_sensor(&sim);
            follower = follower.with_laser(LaserMount::from_base_from_laser(base_from_laser));
        }
        let (detection, labels) = match (options.detector, camera.is_some()) {
            (DetectorMode::Off, _) | (_, false) => (Detection::Off, Vec::new()),
            (mode, true) => {
                let started =
                    Detection::start(mode, &options.detector_config, options.inject_fault)?;
                started.unwrap_or_else(|e| {
                    emit(
                        observer,
                        0.0,
                        EventLevel::Warn,
                        &format!(
                            "no detector ({e}); manual driving works, the follower holds still"
                        ),
                    );
                    (Detection::Off, Vec::new())
                })
            }
        };
        let stats = LoopStats {
            detector_ok: !detection.is_off(),
            ..LoopStats::default()
        };
        observer.start(&sim, camera.as_ref().map(|c| c.info()), &labels);
        Ok(Self {
            follower,
            arm,
            sim,
            camera,
            camera_link,
            laser,
            sensors,
            detection,
            labels,
            every_frame: options.every_frame,
            pilot: Pilot::default(),
            fetch_drove: false,
            stats,
            last_boxes: None,
            detections_done: 0,
            detector_started: None,
            truth_frames: if options.ground_truth {
                vec![(u64::MAX, Vec::new()); TRUTH_FRAMES]
            } else {
                Vec::new()
            },
        })
    }

    /// The simulation.
    pub fn sim(&self) -> &Simulation {
        &self.sim
    }

    /// Whether the arm's end effector can be moved to points ([`JointAction::Tool`]): an
    /// end effector is given and its chain is sound.
    pub fn has_tool(&self) -> bool {
        self.arm.has_tool()
    }

    /// The arm's reach controller, when the robot has one (an end effector, a depth camera).
    pub fn reach(&self) -> Option<&crate::arm::Reach> {
        self.arm.reach()
    }

    /// The arm's pick controller, when the robot has one (an end effector, a depth camera).
    pub fn pick(&self) -> Option<&crate::arm::Pick> {
        self.arm.pick()
    }

    /// Moves world object `index` (world order) to `position_m` (its centre) with heading
    /// `yaw_rad`, at rest: a scene change from outside the loop (a test, a scripted event).
    pub fn place_object(&mut self, index: usize, position_m: [f64; 3], yaw_rad: f64) -> Result<()> {
        Ok(self.sim.place_object(index, position_m, yaw_rad)?)
    }

    /// Moves SDF model `index` (world order) rigidly so its frame is at `world_from_model`, at
    /// rest: as [`Session::place_object`], for a Gazebo model.
    pub fn place_model(
        &mut self,
        index: usize,
        world_from_model: rover_sim::geometry::Pose,
    ) -> Result<()> {
        Ok(self.sim.place_model(index, world_from_model)?)
    }

    /// The pilot (mode, teleop limits).
    pub fn pilot(&self) -> &Pilot {
        &self.pilot
    }

    /// The follower.
    pub fn follower(&self) -> &Follower {
        &self.follower
    }

    /// The camera's intrinsics, when the camera runs.
    pub fn camera_info(&self) -> Option<&CameraInfo> {
        self.camera.as_ref().map(|c| c.info())
    }

    /// Class names of the detector (empty without one).
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    /// The newest detections.
    pub fn last_boxes(&self) -> Option<&BoundingBoxes> {
        self.last_boxes.as_ref()
    }

    /// Detection results taken so far.
    pub fn detections(&self) -> u64 {
        self.detections_done
    }

    /// Loop figures.
    pub fn stats(&self) -> LoopStats {
        self.stats
    }

    /// Applies a user input (script step, key, gamepad). Manual input while following takes
    /// control back at once.
    pub fn input(&mut self, action: Action, observer: &mut dyn Observer) {
        let arm_mode = match action {
            Action::Joint(joint) => {
                self.joint_input(joint, observer);
                return;
            }
            Action::ToggleLook => Some(self.arm.toggled(ArmMode::Look)),
            Action::ToggleReach => Some(self.arm.toggled(ArmMode::Reach)),
            Action::TogglePick => Some(self.arm.toggled(ArmMode::Pick)),
            Action::Arm(mode) => Some(mode),
            _ => None,
        };
        if let Some(mode) = arm_mode {
            if let Some(why) = self.arm.unknown_class(mode, &self.labels, &self.sim) {
                emit(observer, self.sim.sim_time_s(), EventLevel::Warn, &why);
                return;
            }
            let (level, text) = match self.arm.set(mode, &mut self.sim) {
                Ok(text) => (EventLevel::Info, text),
                Err(why) => (EventLevel::Warn, why),
            };
            emit(observer, self.sim.sim_time_s(), level, &text);
            self.stats.arm = self.arm.status();
            return;
        }
        let before = self.pilot.mode();
        let cmd = self.pilot.apply(&action);
        let after = self.pilot.mode();
        if cmd.is_some() && self.arm.base_command().is_some() {
            // A person (or a ROS node) driving takes the base back from a fetch: their command
            // stands (no stop follows it).
            self.arm
                .stop_fetch("stopped: the base was driven by another input");
            self.fetch_drove = false;
        }
        if before != after {
            self.follower.reset();
            let text = match after {
                Mode::Follow if self.detection.is_off() => {
                    "mode: follow (no detector: holding still)"
                }
                Mode::Follow => "mode: follow",
                Mode::Manual => "mode: manual",
            };
            emit(observer, self.sim.sim_time_s(), EventLevel::Info, text);
        }
        if let Some(cmd) = cmd
            && let Err(e) = self.sim.set_cmd_vel(cmd)
        {
            emit(
                observer,
                self.sim.sim_time_s(),
                EventLevel::Warn,
                &e.to_string(),
            );
        }
        self.stats.mode = after;
    }

    /// A joint input: applied to the simulation; a bad one (an unknown joint or controller,
    /// a number that is not finite, a trajectory that does not fit) is dropped with a warning.
    fn joint_input(&mut self, action: JointAction, observer: &mut dyn Observer) {
        let result = match &action {
            JointAction::Command { joint, command } => self.sim.command_joint(joint, *command),
            JointAction::Controller { name, value } => self.sim.command_controller(name, *value),
            JointAction::Trajectory {
                controller,
                trajectory,
            } => self.sim.follow_trajectory(controller, trajectory),
            JointAction::Gripper {
                controller,
                position,
                max_effort,
            } => self.sim.command_gripper(controller, *position, *max_effort),
            JointAction::Pose(name) => self.sim.go_to_named_pose(name),
            JointAction::Tool {
                position_m,
                relative,
            } => {
                if let Err(why) = self.arm.move_tool(*position_m, *relative, &mut self.sim) {
                    emit(
                        observer,
                        self.sim.sim_time_s(),
                        EventLevel::Warn,
                        &format!("{why}; command dropped"),
                    );
                }
                Ok(())
            }
        };
        if let Err(e) = result {
            emit(
                observer,
                self.sim.sim_time_s(),
                EventLevel::Warn,
                &format!("{e}; command dropped"),
            );
        }
    }

    /// The robot's IMUs (`RobotModel::imus` order).
    pub fn imus(&self) -> &[ImuSensor] {
        self.sensors.imus()
    }

    /// The robot's GPS receivers (`RobotModel::gpss` order).
    pub fn gpss(&self) -> &[GpsSensor] {
        self.sensors.gpss()
    }

    /// The robot's bumpers (`RobotModel::bumpers` order).
    pub fn bumpers(&self) -> &[BumperSensor] {
        self.sensors.bumpers()
    }

    /// The robot's 3D lidars (`RobotModel::lidars` order).
    pub fn lidars(&self) -> &[LidarSensor] {
        self.sensors.lidars()
    }

    /// The laser scanner, when the robot has one.
    pub fn laser(&self) -> Option<&LaserSensor> {
        self.laser.as_ref()
    }
}

// One step of the loop: physics, the arm's task, the camera and its detections.
impl Session {
    /// Advances one physics step: camera and laser (when due), detector, follower, physics.
    /// Returns the control sample when the diff drive's control loop ran.
    pub fn step(&mut self, observer: &mut dyn Observer) -> Result<Option<ControlSample>> {
        self.camera_and_detection(observer)?;
        let sample = self.sim.step();
        let now_s = self.sim.sim_time_s();
        self.sim.drain_controller_events(|text| {
            let level = if text.contains("VIOLATED") {
                EventLevel::Warn
            } else {
                EventLevel::Info
            };
            emit(observer, now_s, level, text);
        });
        if let Some(sample) = &sample {
            // Every mode: detections are placed with the pose at their image's time.
            self.follower
                .record_pose(sample.sim_time_s, sample.odometry);
        }
        // The scan sees the world as this step left it (rapier's scene index is current only
        // after a step).
        if let Some(laser) = self.laser.as_mut()
            && laser.scan_if_due(&self.sim).is_some()
        {
            self.follower.observe_scan(laser.last());
            observer.laser_scan(laser.last(), laser.world_from_sensor(&self.sim));
        }
        self.sensors.update(&self.sim, observer);
        if let Some(sample) = &sample {
            if self.pilot.mode() == Mode::Follow {
                let before = self.follower.state();
                let cmd = self.follower.command(
                    sample.sim_time_s,
                    sample.odometry,
                    self.stats.detector_ok,
                );
                let after = self.follower.state();
                if after != before {
                    emit(
                        observer,
                        sample.sim_time_s,
                        EventLevel::Info,
                        &format!("follower: {} -> {}", before.as_str(), after.as_str()),
                    );
                }
                self.stats.avoiding = self.follower.avoidance().is_some_and(|a| a.steering);
                self.sim.set_cmd_vel(cmd)?;
            } else {
                self.stats.avoiding = false;
            }
            self.stats.mode = self.pilot.mode();
            self.stats.follow_state = self.follower.state();
            let following = self.stats.mode == Mode::Follow;
            self.stats.follow_target_m = self
                .follower
                .target()
                .filter(|_| following)
                .map(|t| t.position_at(sample.sim_time_s));
            self.stats.follow_goal_m = self.follower.goal_m().filter(|_| following);
            self.arm.update(&mut self.sim).map_err(arm_error)?;
            self.fetch_drive()?;
            let now = sample.sim_time_s;
            self.arm.drain_said(|warn, text| {
                let level = if warn {
                    EventLevel::Warn
                } else {
                    EventLevel::Info
                };
                emit(observer, now, level, &text);
            });
            self.arm_events(sample.sim_time_s, observer);
            observer.control(&self.sim, sample, &self.stats);
        }
        Ok(sample)
    }

    /// The arm's status after a control update, and its changes as events: the reach's and
    /// the pick's states, and the object hidden by the robot or in view again.
    fn arm_events(&mut self, now_s: f64, observer: &mut dyn Observer) {
        let before = self.stats.arm;
        self.stats.arm = self.arm.status();
        let now = self.stats.arm;
        if before.mode != now.mode {
            return;
        }
        if let (Some(was), Some(is)) = (before.task_state(), now.task_state())
            && was != is
        {
            let text = format!("{}: {was} -> {is}", now.mode.as_str());
            emit(observer, now_s, EventLevel::Info, &text);
        }
        if before.hidden != now.hidden {
            let text = if now.hidden {
                "the object is hidden by the robot's own links: going on with its last estimate"
            } else {
                "the object is in view again"
            };
            let text = format!("{}: {text}", now.mode.as_str());
            emit(observer, now_s, EventLevel::Info, &text);
        }
    }

    /// A fetch's base command (pick driving the base) goes to the drive; a stop once it lets
    /// go. The follower keeps the base while it drives.
    fn fetch_drive(&mut self) -> Result<()> {
        let cmd = self.arm.base_command();
        match cmd {
            Some(cmd) if self.pilot.mode() == Mode::Manual => self.sim.set_cmd_vel(cmd)?,
            None if self.fetch_drove && self.pilot.mode() == Mode::Manual => {
                self.sim.set_cmd_vel(rover_sim::physics::Twist::ZERO)?;
            }
            _ => {}
        }
        self.fetch_drove = cmd.is_some();
        Ok(())
    }

    fn camera_and_detection(&mut self, observer: &mut dyn Observer) -> Result<()> {
        // Results from the worker thread arrive whenever they are ready.
        if let Some((result, stats)) = self.detection.latest() {
            match result {
                Ok(boxes) => self.accept(boxes, Some(stats), observer),
                Err(e) => self.detector_failed(&e, observer),
            }
        }
        // A pipelined result is taken when its sim time comes, waiting for it if need be; but
        // first this step's image, when one is due, goes to the detector's queue, so the thread
        // starts on it the moment the owed result is done (nothing in the image depends on that
        // result: the follower acts on it at the next control update, as before).
        let now_s = self.sim.sim_time_s();
        let mut owed = self.detection.take_owed(now_s);
        let detected = self.camera_step(observer, &mut owed)?;
        if let Some(result) = detected {
            self.take(result, observer);
        }
        if owed && let Some(result) = self.detection.wait_owed() {
            self.take(result, observer);
        }
        Ok(())
    }

    /// Renders the camera image when due (or skips it when nobody would look at it), shows it to
    /// the observers and hands it to the detector. `owed`: a pipelined result is due this step;
    /// when an image is submitted here, that result is waited for right after (and `owed`
    /// cleared) and returned.
    fn camera_step(
        &mut self,
        observer: &mut dyn Observer,
        owed: &mut bool,
    ) -> Result<Option<Detected>> {
        let Some(camera) = self.camera.as_mut() else {
            return Ok(None);
        };
        if !self.every_frame && camera.due(&self.sim) {
            // Nobody looks at this image unless the detector takes it.
            let wanted = self.detection.wants_image(self.sim.sim_time_s());
            if !wanted {
                camera.skip_if_due(&self.sim);
                return Ok(None);
            }
        }
        if self.arm.wants_robot_pixels() {
            // The self filter's robot pixels (allocated once, on the first reach or pick).
            camera.enable_id_image();
        }
        let world_from_camera = self.sim.world_from_link(self.camera_link);
        let Some(frame) = camera
            .capture_if_due(&self.sim)
            .map_err(CoreError::Camera)?
        else {
            return Ok(None);
        };
        self.stats.frames += 1;
        observer.camera_frame(&frame, world_from_camera);
        self.sensors
            .camera_frame(&frame, world_from_camera, observer);
        self.arm.capture(&frame, &self.sim);
        if let Some(slot) = self.truth_frames.get_mut(frame.seq as usize % TRUTH_FRAMES) {
            slot.0 = frame.seq;
            rover_sim::sensors::copy_boxes(&mut slot.1, frame.ground_truth);
        }
        let stamp = FrameStamp {
            sim_time_s: frame.sim_time_s,
            frame: frame.seq,
        };
        let detected = self
            .detection
            .submit(&frame, stamp, owed, &mut self.detector_started);
        Ok(detected)
    }

    /// A lockstep or pipelined result: its boxes, or the detector's failure.
    fn take(&mut self, result: Detected, observer: &mut dyn Observer) {
        match result {
            Ok(boxes) => self.accept(boxes, None, observer),
            Err(e) => self.detector_failed(&e, observer),
        }
    }

    /// One policy for a detector that fails mid-run, headless or in the window: say so (log,
    /// observers, HUD), turn detection off, keep manual driving; the follower holds still.
    fn detector_failed(&mut self, error: &PerceptionError, observer: &mut dyn Observer) {
        emit(
            observer,
            self.sim.sim_time_s(),
            EventLevel::Warn,
            &format!("detector failed: {error}; manual driving works, the follower holds still"),
        );
        self.detection = Detection::Off;
        self.stats.detector_ok = false;
        self.stats.detector_failed = true;
    }

    fn accept(
        &mut self,
        boxes: BoundingBoxes,
        worker: Option<WorkerStats>,
        observer: &mut dyn Observer,
    ) {
        self.detections_done += 1;
        self.stats.detector_latency_ms = boxes.latency_ms;
        match worker {
            Some(w) => {
                self.stats.frames_dropped = w.dropped;
                let wall = self
                    .detector_started
                    .map_or(0.0, |t| t.elapsed().as_secs_f64());
                if wall > 0.0 {
                    self.stats.detector_hz = w.processed as f64 / wall;
                }
            }
            None => {
                let t = self.sim.sim_time_s();
                if t > 0.0 {
                    self.stats.detector_hz = self.detections_done as f64 / t;
                }
            }
        }
        self.follower.observe(&boxes);
        if let Err(e) = self.arm.observe(&boxes, &mut self.sim) {
            emit(
                observer,
                self.sim.sim_time_s(),
                EventLevel::Warn,
                &format!("arm: {e}"),
            );
        }
        observer.detections(&boxes, &self.labels);
        let seq = boxes.image_stamp.frame;
        if let Some((_, truth)) = self
            .truth_frames
            .get(seq as usize % TRUTH_FRAMES)
            .filter(|(s, _)| *s == seq)
        {
            observer.detections_truth(&boxes, truth);
        }
        self.last_boxes = Some(boxes);
    }
}

/// The robot's first camera when one is wanted; a robot without a camera is a warning to
/// `observer`, not an error.
fn start_camera(
    sim: &Simulation,
    wanted: bool,
    observer: &mut dyn Observer,
) -> Result<Option<CameraSensor>> {
    if !wanted {
        return Ok(None);
    }
    if sim.robot().cameras.is_empty() {
        emit(
            observer,
            0.0,
            EventLevel::Warn,
            "the robot has no camera: no images, no detections, the follower holds still",
        );
        return Ok(None);
    }
    let sensor = CameraSensor::new(sim).map_err(CoreError::Camera)?;
    tracing::info!(
        "camera: {}x{}, rendering on {}",
        sensor.info().width,
        sensor.info().height,
        sensor.renderer().adapter()
    );
    Ok(Some(sensor))
}

/// The robot's first laser, if any: always on (casting a scan is cheap), for the follower's
/// obstacles and target and for observers.
fn start_laser(sim: &Simulation) -> Result<Option<LaserSensor>> {
    let Some(config) = sim.robot().lasers.first() else {
        return Ok(None);
    };
    let sensor = LaserSensor::new(sim, 0)?;
    tracing::info!(
        "laser: {} rays, {:.1}-{:.1} m at {} Hz",
        config.samples,
        config.range_min_m,
        config.range_max_m,
        config.update_rate_hz
    );
    Ok(Some(sensor))
}

/// The follower's view of the camera: intrinsics, and where the camera sits on the robot as
/// it rests at the start. Without a camera the follower never sees anything, so any geometry
/// will do.
fn camera_geometry(
    sim: &Simulation,
    info: Option<&CameraInfo>,
    camera_link: LinkId,
) -> CameraGeometry {
    let world_from_camera = sim.world_from_link(camera_link);
    let base_from_camera = sim.world_from_base().inverse() * world_from_camera;
    let height_m = f64::from(world_from_camera.translation.z);
    let forward_m = f64::from(base_from_camera.translation.x);
    let left_m = f64::from(base_from_camera.translation.y);
    // Gazebo cameras look along their link's +x.
    let look_world = world_from_camera.rotation * glam::Vec3::X;
    let pitch_down_rad = f64::from((-look_world.z).clamp(-1.0, 1.0).asin());
    let look_base = base_from_camera.rotation * glam::Vec3::X;
    let yaw_rad = f64::from(look_base.y.atan2(look_base.x));
    match info {
        Some(info) => CameraGeometry {
            left_m,
            yaw_rad,
            pitch_down_rad,
            ..CameraGeometry::new(info, height_m, forward_m)
        },
        None => CameraGeometry {
            fx: 1.0,
            fy: 1.0,
            cx: 0.0,
            cy: 0.0,
            width_px: 1.0,
            height_px: 1.0,
            height_m,
            forward_m,
            left_m,
            yaw_rad,
            pitch_down_rad,
        },
    }
}

/// A chain error from the arm's tasks (a chain built from this robot does not produce one).
fn arm_error(e: rover_sim::model::KinematicsError) -> CoreError {
    CoreError::Option(format!("arm: {e}"))
}
