//! Scenarios: a world, a robot, when the follower is switched on, and what counts as success,
//! in one TOML file (`scenarios/*.toml`, format in docs/FOLLOWER.md). [`run_scenario`] plays
//! one headless and deterministically (lockstep detection on sim time) and measures it with a
//! [`Probe`]; the app's `rover eval` runs many in parallel.
//!
//! ```toml
//! [scenario]
//! description = "A person standing 4 m ahead."
//! duration_s = 25.0
//! target = "alice"          # the person the follower should follow (omit: nobody to follow)
//! # spawn = [-2.0, -0.5, 0.0]  # the robot's start (x m, y m, heading deg), over the world's
//!
//! [criteria]
//! final_range_m = [1.2, 1.8]
//! acquire_within_s = 5.0
//!
//! [world]                   # a world, as in worlds/*.toml (or `world_file = "..."`)
//! name = "ahead"
//! [[world.person]]
//! name = "alice"
//! position_m = [4.0, 0.0]
//! heading_deg = 180.0
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rover_perception::{
    BoundingBoxes, CocoEvaluator, DetectionMetrics, DetectorConfig, GroundTruthObject,
    InjectedFault,
};
use rover_sim::{
    SimError,
    description::WorldFile,
    model::{RobotModel, World},
    physics::{ControlSample, Simulation},
    sensors::GroundTruthBox,
};
use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};
use crate::follower::{FollowState, range_bearing_from};
use crate::headless::{self, RunConfig};
use crate::input::Action;
use crate::observer::{LoopStats, Observer};
use crate::paths;
use crate::pilot::Mode;
use crate::script::{Script, Step};

/// What a scenario must achieve. Every criterion is optional; `never_drive_while_searching` is
/// on unless set to false.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioCriteria {
    /// Range from the robot's base to the target at the end, [min, max] (m).
    pub final_range_m: Option<[f64; 2]>,
    /// The follower first tracks the target within this long after follow mode starts (s).
    pub acquire_within_s: Option<f64>,
    /// After the first TRACKING, the target is never further than this (m).
    pub max_range_after_acquire_m: Option<f64>,
    /// The robot's collision shapes never come closer than this to an obstacle (m).
    pub min_clearance_m: Option<f64>,
    /// The robot's base never comes closer than this to any person's centre (m).
    pub min_person_range_m: Option<f64>,
    /// No forward or backward command while the follower is SEARCHING (default true).
    pub never_drive_while_searching: Option<bool>,
    /// The robot's path is at most this long (m): for "nobody to follow".
    pub max_travel_m: Option<f64>,
    /// For the last this many seconds: |angular cmd| below `calm_turn_radps` and no SEARCHING.
    pub calm_last_s: Option<f64>,
    /// Turn-rate bound for `calm_last_s` (rad/s; default 0.05).
    pub calm_turn_radps: Option<f64>,
    /// After the first TRACKING, the target is never lost (not TRACKING) for longer than this
    /// at a stretch (s): how soon the follower sees a person again after losing them.
    pub max_lost_s: Option<f64>,
    /// At the end the robot faces the target within this angle (deg).
    pub final_facing_deg: Option<f64>,
    /// The detector's recall at IoU 0.5 against the renderer's ground truth, per class with
    /// something to find: the lowest must reach this (0..1).
    pub min_recall: Option<f64>,
    /// The detector's precision at IoU 0.5, per class it reported: the lowest must reach this.
    pub min_precision: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenarioFile {
    scenario: RawScenario,
    #[serde(default)]
    criteria: ScenarioCriteria,
    world: Option<WorldFile>,
    world_file: Option<PathBuf>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScenario {
    name: Option<String>,
    #[serde(default)]
    description: String,
    duration_s: f64,
    #[serde(default = "default_follow_at")]
    follow_at_s: f64,
    target: Option<String>,
    robot: Option<PathBuf>,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    tags: Vec<String>,
    #[serde(default)]
    needs: Vec<Sensor>,
    /// Where the robot starts: x, y (m) and heading (deg), over the world's (an SDF world
    /// says nothing of rover's robot).
    spawn: Option<[f64; 3]>,
}

/// A sensor a scenario needs the robot to have (`needs = ["laser"]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sensor {
    /// A camera (`<sensor type="camera">`): every follower scenario needs one.
    Camera,
    /// A range sensor: a 2D laser (`<sensor type="ray">`), to see obstacles and keep a close
    /// target the camera cannot see whole.
    Laser,
}

impl Sensor {
    /// The name used in scenario files and messages.
    pub fn as_str(self) -> &'static str {
        match self {
            Sensor::Camera => "camera",
            Sensor::Laser => "laser",
        }
    }

    /// Whether `robot` carries this kind of sensor.
    pub fn on(self, robot: &RobotModel) -> bool {
        match self {
            Sensor::Camera => !robot.cameras.is_empty(),
            Sensor::Laser => !robot.lasers.is_empty(),
        }
    }
}

fn default_follow_at() -> f64 {
    0.5
}

/// A loaded scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Name (default: the file's stem).
    pub name: String,
    /// The file it came from.
    pub source: PathBuf,
    /// One line for tables.
    pub description: String,
    /// Sim seconds to run.
    pub duration_s: f64,
    /// Sim time at which follow mode is switched on.
    pub follow_at_s: f64,
    /// Index of the target person in the world, if there is one to follow.
    pub target: Option<usize>,
    /// Random seed of the run.
    pub seed: u64,
    /// Free-form labels (e.g. "fast": the subset `cargo test` runs).
    pub tags: Vec<String>,
    /// Sensors the robot must have for the scenario to mean anything (the camera always).
    pub needs: Vec<Sensor>,
    /// What counts as success.
    pub criteria: ScenarioCriteria,
    /// The world.
    pub world: World,
    /// The robot.
    pub robot: RobotModel,
    /// The robot's short name (its file name without `.urdf`/`.xacro`).
    pub robot_name: String,
}

impl Scenario {
    /// Loads and validates a scenario file (world, robot, target, criteria).
    pub fn load(path: &Path) -> Result<Self> {
        Self::load_with_robot(path, None)
    }

    /// [`Scenario::load`], with `robot` (a URDF or xacro file) in place of the robot the
    /// scenario names: the same world, people, spawn pose and criteria for another robot. The
    /// scenario's `xacro_args` and `[robot.drive]` belong to its own robot and are not applied.
    pub fn load_with_robot(path: &Path, robot: Option<&Path>) -> Result<Self> {
        match robot {
            Some(file) => Self::load_with_model(path, Some((file, &Self::load_robot(file)?))),
            None => Self::load_with_model(path, None),
        }
    }

    /// Loads a robot to run scenarios with ([`Scenario::load_with_model`]): once for many
    /// scenarios (`rover eval --robot`), with its xacro defaults.
    pub fn load_robot(file: &Path) -> Result<RobotModel> {
        let options = RunConfig::default().robot_load_options_with(Default::default());
        Ok(RobotModel::load_with(file, &options)?)
    }

    /// [`Scenario::load_with_robot`] with the robot already loaded from `file`
    /// ([`Scenario::load_robot`]).
    pub fn load_with_model(path: &Path, robot: Option<(&Path, &RobotModel)>) -> Result<Self> {
        let raw: RawScenarioFile = rover_sim::description::load_toml(path)?;
        let bad = |key: &str, message: String| -> CoreError {
            SimError::invalid(path, None, format!("at `{key}`: {message}")).into()
        };
        let s = raw.scenario;
        if !(s.duration_s.is_finite() && s.duration_s > 0.0 && s.duration_s <= 3600.0) {
            return Err(bad(
                "scenario.duration_s",
                format!("expected sim seconds in (0, 3600], found {}", s.duration_s),
            ));
        }
        if !(s.follow_at_s.is_finite() && (0.0..s.duration_s).contains(&s.follow_at_s)) {
            return Err(bad(
                "scenario.follow_at_s",
                format!(
                    "expected a sim time in [0, duration_s), found {}",
                    s.follow_at_s
                ),
            ));
        }
        check_criteria(&raw.criteria).map_err(|(key, m)| bad(&format!("criteria.{key}"), m))?;
        let world = match (raw.world, raw.world_file) {
            (Some(w), None) => w.into_world(path)?,
            (None, Some(file)) => {
                let file = path.parent().unwrap_or(Path::new(".")).join(file);
                World::load(&file)?
            }
            _ => {
                return Err(bad(
                    "world",
                    "expected either a [world] table or world_file = \"PATH\"".into(),
                ));
            }
        };
        let mut world = world;
        if let Some([x, y, yaw_deg]) = s.spawn {
            if ![x, y, yaw_deg].iter().all(|v| v.is_finite()) {
                return Err(bad(
                    "scenario.spawn",
                    format!(
                        "expected [x_m, y_m, yaw_deg] as finite numbers, found [{x}, {y}, {yaw_deg}]"
                    ),
                ));
            }
            world.robot.position_m = [x, y];
            world.robot.yaw_rad = yaw_deg.to_radians();
        }
        let target = match &s.target {
            Some(name) => Some(
                world
                    .people
                    .iter()
                    .position(|p| &p.name == name)
                    .ok_or_else(|| {
                        let names: Vec<&str> =
                            world.people.iter().map(|p| p.name.as_str()).collect();
                        bad(
                            "scenario.target",
                            format!(
                                "\"{name}\" is not a person in the world; its people: {}",
                                if names.is_empty() {
                                    "none".to_owned()
                                } else {
                                    names.join(", ")
                                }
                            ),
                        )
                    })?,
            ),
            None => None,
        };
        let (robot, robot_path) = match robot {
            Some((file, model)) => (model.clone(), file.to_path_buf()),
            None => {
                let robot_path = s
                    .robot
                    .map(|r| path.parent().unwrap_or(Path::new(".")).join(r))
                    .or_else(|| world.robot.urdf.clone())
                    .unwrap_or_else(paths::default_robot_path);
                let options = RunConfig::default().robot_load_options(&world);
                let mut robot = RobotModel::load_with(&robot_path, &options)?;
                if let Some(spec) = &world.robot.drive {
                    robot.set_drive(spec)?;
                }
                (robot, robot_path)
            }
        };
        let mut needs = s.needs;
        needs.sort_unstable();
        needs.dedup();
        let name = s.name.unwrap_or_else(|| {
            path.file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scenario".into())
        });
        Ok(Self {
            name,
            source: path.to_path_buf(),
            description: s.description,
            duration_s: s.duration_s,
            follow_at_s: s.follow_at_s,
            target,
            seed: s.seed,
            tags: s.tags,
            needs,
            criteria: raw.criteria,
            world,
            robot,
            robot_name: robot_name(&robot_path),
        })
    }

    /// Why this scenario cannot be run with its robot (a sensor it needs is missing), if so.
    pub fn unmet_needs(&self) -> Option<String> {
        let missing: Vec<&str> = std::iter::once(Sensor::Camera)
            .chain(self.needs.iter().copied())
            .filter(|n| !n.on(&self.robot))
            .map(Sensor::as_str)
            .collect();
        (!missing.is_empty()).then(|| {
            format!(
                "needs a {}; {} has none",
                missing.join(" and a "),
                self.robot_name
            )
        })
    }
}

/// A robot's short name: its file name without the `.urdf`, `.xacro` and `.sdf` extensions;
/// a `model.sdf` by its model folder's name.
pub fn robot_name(path: &Path) -> String {
    let mut name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "robot".into());
    for ext in [".xacro", ".urdf", ".sdf"] {
        if let Some(stem) = name.strip_suffix(ext) {
            name = stem.to_owned();
        }
    }
    // A Gazebo model folder's model.sdf is named by its folder (turtlebot3_burger).
    if name == "model"
        && let Some(folder) = path.parent().and_then(Path::file_name)
    {
        name = folder.to_string_lossy().into_owned();
    }
    name
}

fn check_criteria(c: &ScenarioCriteria) -> std::result::Result<(), (String, String)> {
    let positive = |key: &str, v: Option<f64>| match v {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err((
            key.to_owned(),
            format!("expected a finite number >= 0, found {v}"),
        )),
        _ => Ok(()),
    };
    if let Some([lo, hi]) = c.final_range_m
        && !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo <= hi)
    {
        return Err((
            "final_range_m".into(),
            format!("expected [min, max] with 0 <= min <= max, found [{lo}, {hi}]"),
        ));
    }
    positive("acquire_within_s", c.acquire_within_s)?;
    positive("max_range_after_acquire_m", c.max_range_after_acquire_m)?;
    positive("min_clearance_m", c.min_clearance_m)?;
    positive("min_person_range_m", c.min_person_range_m)?;
    positive("max_travel_m", c.max_travel_m)?;
    positive("calm_last_s", c.calm_last_s)?;
    positive("calm_turn_radps", c.calm_turn_radps)?;
    positive("final_facing_deg", c.final_facing_deg)?;
    positive("max_lost_s", c.max_lost_s)?;
    Ok(())
}

/// What a run measured (ground truth, not what the robot believed).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ScenarioMetrics {
    /// Sim time run (s).
    pub sim_s: f64,
    /// Sim time of the first TRACKING after follow mode started (s).
    pub acquired_at_s: Option<f64>,
    /// Range from the base to the target at the end (m).
    pub final_range_m: Option<f64>,
    /// Largest range to the target after the first TRACKING (m).
    pub max_range_after_acquire_m: Option<f64>,
    /// Smallest gap between the robot and an obstacle (m; capped at 1).
    pub min_clearance_m: f64,
    /// Smallest range from the base to any person's centre (m).
    pub min_person_range_m: Option<f64>,
    /// Sim seconds with a nonzero linear command while SEARCHING.
    pub drove_while_searching_s: f64,
    /// Length of the robot's path (m).
    pub travel_m: f64,
    /// Largest |angular cmd| over the calm window (rad/s).
    pub calm_max_turn_radps: Option<f64>,
    /// Whether the follower searched during the calm window.
    pub calm_searched: Option<bool>,
    /// How far the robot's heading is from facing the target at the end (deg).
    pub final_facing_deg: Option<f64>,
    /// Sim seconds spent in each follower state while following.
    pub state_s: BTreeMap<String, f64>,
    /// Follower state changes while following.
    pub transitions: u32,
    /// Follower state at the end.
    pub final_state: String,
    /// Sim seconds steering around an obstacle.
    pub avoiding_s: f64,
    /// Longest stretch without TRACKING after the first TRACKING (s): from losing the target to
    /// seeing it again (or to the end).
    #[serde(default)]
    pub longest_lost_s: f64,
    /// The detector judged against the renderer's ground truth of the images it took, with
    /// COCO's rules (AP50, AP50:95, per-class precision, recall, mean IoU); `None` when it
    /// took no image.
    #[serde(default)]
    pub detector: Option<DetectionMetrics>,
}

/// One criterion's verdict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioCheck {
    /// The criterion's key.
    pub name: String,
    /// What was required.
    pub limit: String,
    /// What was measured.
    pub value: String,
    /// Whether it held.
    pub passed: bool,
}

/// The result of one scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioResult {
    /// Scenario name.
    pub name: String,
    /// The robot's short name ([`robot_name`]).
    #[serde(default)]
    pub robot: String,
    /// Its file, as given.
    pub file: String,
    /// Its description.
    pub description: String,
    /// Every criterion held and the run finished.
    pub passed: bool,
    /// The verdicts.
    pub checks: Vec<ScenarioCheck>,
    /// What was measured.
    pub metrics: ScenarioMetrics,
    /// Why the run could not be done, if it could not.
    pub error: Option<String>,
    /// Why the scenario was not run with this robot (a sensor it needs is missing): neither
    /// passed nor failed.
    #[serde(default)]
    pub skipped: Option<String>,
    /// Wall-clock seconds the run took (the one field that differs between identical runs).
    pub wall_s: f64,
}

impl ScenarioResult {
    /// A result for a scenario that could not be loaded or run.
    pub fn failed(name: &str, robot: &str, file: &str, error: String) -> Self {
        Self {
            name: name.to_owned(),
            robot: robot.to_owned(),
            file: file.to_owned(),
            description: String::new(),
            passed: false,
            checks: Vec::new(),
            metrics: ScenarioMetrics::default(),
            error: Some(error),
            skipped: None,
            wall_s: 0.0,
        }
    }

    /// A result for a scenario not run with this robot, and why.
    pub fn skipped(scenario: &Scenario, reason: String) -> Self {
        Self {
            description: scenario.description.clone(),
            error: None,
            skipped: Some(reason),
            ..Self::failed(
                &scenario.name,
                &scenario.robot_name,
                &scenario.source.display().to_string(),
                String::new(),
            )
        }
    }
}

/// Measures a scenario run from the session's control updates (an observer: it never
/// influences the run).
#[derive(Debug)]
struct Probe {
    target: Option<usize>,
    last_t: Option<f64>,
    last_xy: Option<[f64; 2]>,
    last_state: FollowState,
    last_state_following: bool,
    calm_from_s: Option<f64>,
    /// When the target was last lost after the first TRACKING (s).
    lost_since_s: Option<f64>,
    metrics: ScenarioMetrics,
    /// Every detection result against the ground truth of its image.
    evaluator: CocoEvaluator,
    /// Reused per result.
    truth: Vec<GroundTruthObject>,
    found: Vec<rover_perception::Detection>,
}

/// Clearances are measured up to this distance (m).
const CLEARANCE_CAP_M: f32 = 1.0;

impl Probe {
    /// A probe for `target` (index into the world's people); `calm_from_s` starts the calm
    /// window.
    pub fn new(target: Option<usize>, calm_from_s: Option<f64>) -> Self {
        Self {
            target,
            last_t: None,
            last_xy: None,
            last_state: FollowState::Waiting,
            last_state_following: false,
            calm_from_s,
            lost_since_s: None,
            metrics: ScenarioMetrics {
                min_clearance_m: f64::from(CLEARANCE_CAP_M),
                ..ScenarioMetrics::default()
            },
            evaluator: CocoEvaluator::default(),
            truth: Vec::new(),
            found: Vec::new(),
        }
    }

    /// What was measured so far, the detector's metrics included.
    pub fn metrics(&self) -> ScenarioMetrics {
        let mut m = self.metrics.clone();
        if self.evaluator.images() > 0 {
            m.detector = Some(self.evaluator.summary());
        }
        m
    }
}

impl Observer for Probe {
    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        crate::judge::eval_objects(boxes, truth, &mut self.truth, &mut self.found);
        self.evaluator.add_image(&self.truth, &self.found);
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        let t = sample.sim_time_s;
        // The first update counts for one control period of the tutorial car (100 Hz).
        let dt = self.last_t.map_or(0.01, |l| (t - l).max(0.0));
        self.last_t = Some(t);
        let m = &mut self.metrics;
        m.sim_s = t;
        let g = sample.ground_truth;
        if let Some([x, y]) = self.last_xy {
            m.travel_m += (g.x_m - x).hypot(g.y_m - y);
        }
        self.last_xy = Some([g.x_m, g.y_m]);
        m.min_clearance_m = m
            .min_clearance_m
            .min(f64::from(sim.obstacle_clearance_m(CLEARANCE_CAP_M)));
        for (i, p) in sim.world().people.iter().enumerate() {
            let (px, py, _) = p.pose_at(t);
            let (range, bearing) = range_bearing_from(g, [px, py]);
            m.min_person_range_m = Some(m.min_person_range_m.map_or(range, |r| r.min(range)));
            if Some(i) == self.target {
                m.final_range_m = Some(range);
                m.final_facing_deg = Some(bearing.to_degrees().abs());
                if m.acquired_at_s.is_some() {
                    m.max_range_after_acquire_m =
                        Some(m.max_range_after_acquire_m.map_or(range, |r| r.max(range)));
                }
            }
        }
        let following = stats.mode == Mode::Follow;
        let state = stats.follow_state;
        // The command in force now was decided at the previous update, in the previous state.
        if self.last_state_following
            && self.last_state == FollowState::Searching
            && sample.cmd.linear_mps.abs() > 1e-6
        {
            m.drove_while_searching_s += dt;
        }
        if following {
            *m.state_s.entry(state.as_str().to_owned()).or_default() += dt;
            if self.last_state_following && state != self.last_state {
                m.transitions += 1;
            }
            if state == FollowState::Tracking && m.acquired_at_s.is_none() {
                m.acquired_at_s = Some(t);
                if let Some(i) = self.target {
                    let (px, py, _) = sim.world().people[i].pose_at(t);
                    m.max_range_after_acquire_m = Some((px - g.x_m).hypot(py - g.y_m));
                }
            }
            if stats.avoiding {
                m.avoiding_s += dt;
            }
            if m.acquired_at_s.is_some() {
                if state == FollowState::Tracking {
                    self.lost_since_s = None;
                } else {
                    let since = *self.lost_since_s.get_or_insert(t);
                    m.longest_lost_s = m.longest_lost_s.max(t - since);
                }
            }
        }
        if self.calm_from_s.is_some_and(|from| t >= from) {
            let turn = sample.cmd.angular_radps.abs();
            m.calm_max_turn_radps = Some(m.calm_max_turn_radps.map_or(turn, |v| v.max(turn)));
            let searched = m.calm_searched.unwrap_or(false) || state == FollowState::Searching;
            m.calm_searched = Some(searched);
        }
        m.final_state = state.as_str().to_owned();
        self.last_state = state;
        self.last_state_following = following;
    }
}

/// Judges a run's metrics against `scenario`'s criteria (what [`run_scenario`] does at the
/// end; also for re-judging saved metrics against other bounds).
pub fn judge_scenario(scenario: &Scenario, m: &ScenarioMetrics) -> Vec<ScenarioCheck> {
    let (criteria, follow_at_s) = (&scenario.criteria, scenario.follow_at_s);
    let mut checks = Vec::new();
    let mut check = |name: &str, limit: String, value: String, passed: bool| {
        checks.push(ScenarioCheck {
            name: name.to_owned(),
            limit,
            value,
            passed,
        });
    };
    let show =
        |v: Option<f64>, unit: &str| v.map_or("none".to_owned(), |v| format!("{v:.2} {unit}"));
    if let Some([lo, hi]) = criteria.final_range_m {
        let ok = m.final_range_m.is_some_and(|r| (lo..=hi).contains(&r));
        check(
            "final_range_m",
            format!("{lo:.2}-{hi:.2} m"),
            show(m.final_range_m, "m"),
            ok,
        );
    }
    if let Some(limit) = criteria.acquire_within_s {
        let after = m.acquired_at_s.map(|t| t - follow_at_s);
        check(
            "acquire_within_s",
            format!("<= {limit:.1} s"),
            show(after, "s"),
            after.is_some_and(|a| a <= limit),
        );
    }
    if let Some(limit) = criteria.max_range_after_acquire_m {
        check(
            "max_range_after_acquire_m",
            format!("<= {limit:.2} m"),
            show(m.max_range_after_acquire_m, "m"),
            m.max_range_after_acquire_m.is_some_and(|r| r <= limit),
        );
    }
    if let Some(limit) = criteria.min_clearance_m {
        check(
            "min_clearance_m",
            format!("> {limit:.2} m"),
            format!("{:.3} m", m.min_clearance_m),
            m.min_clearance_m > limit,
        );
    }
    if let Some(limit) = criteria.min_person_range_m {
        check(
            "min_person_range_m",
            format!(">= {limit:.2} m"),
            show(m.min_person_range_m, "m"),
            m.min_person_range_m.is_none_or(|r| r >= limit),
        );
    }
    if criteria.never_drive_while_searching.unwrap_or(true) {
        check(
            "never_drive_while_searching",
            "0 s".into(),
            format!("{:.2} s", m.drove_while_searching_s),
            m.drove_while_searching_s == 0.0,
        );
    }
    if let Some(limit) = criteria.max_travel_m {
        check(
            "max_travel_m",
            format!("<= {limit:.2} m"),
            format!("{:.2} m", m.travel_m),
            m.travel_m <= limit,
        );
    }
    if let Some(window) = criteria.calm_last_s {
        let bound = criteria.calm_turn_radps.unwrap_or(0.05);
        let ok = m.calm_max_turn_radps.is_some_and(|w| w < bound) && m.calm_searched == Some(false);
        check(
            "calm_last_s",
            format!("last {window:.0} s: |w| < {bound:.2} rad/s, no searching"),
            format!(
                "max |w| {}, searched {}",
                show(m.calm_max_turn_radps, "rad/s"),
                m.calm_searched
                    .map_or("?", |s| if s { "yes" } else { "no" })
            ),
            ok,
        );
    }
    if let Some(limit) = criteria.max_lost_s {
        check(
            "max_lost_s",
            format!("<= {limit:.1} s"),
            format!("{:.2} s", m.longest_lost_s),
            m.longest_lost_s <= limit,
        );
    }
    detector_checks(criteria, m, &mut check);
    if let Some(limit) = criteria.final_facing_deg {
        check(
            "final_facing_deg",
            format!("<= {limit:.0} deg"),
            show(m.final_facing_deg, "deg"),
            m.final_facing_deg.is_some_and(|f| f <= limit),
        );
    }
    checks
}

/// `min_recall` and `min_precision`: the worst class must reach the bound.
fn detector_checks(
    criteria: &ScenarioCriteria,
    m: &ScenarioMetrics,
    check: &mut impl FnMut(&str, String, String, bool),
) {
    let classes = m
        .detector
        .as_ref()
        .map(|d| d.classes.as_slice())
        .unwrap_or(&[]);
    let worst = |value: fn(&rover_perception::ClassMetrics) -> Option<f64>| {
        classes
            .iter()
            .filter_map(|c| value(c).map(|v| (v, c.class.as_str())))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    };
    for (name, limit, found) in [
        ("min_recall", criteria.min_recall, worst(|c| c.recall)),
        (
            "min_precision",
            criteria.min_precision,
            worst(|c| c.precision),
        ),
    ] {
        let Some(limit) = limit else {
            continue;
        };
        check(
            name,
            format!(">= {limit:.2}"),
            found.map_or("nothing judged".to_owned(), |(v, class)| {
                format!("{v:.3} ({class})")
            }),
            found.is_some_and(|(v, _)| v >= limit),
        );
    }
}

/// How [`run_scenario`] runs a scenario besides what the file says.
#[derive(Debug, Clone, Default)]
pub struct ScenarioOptions {
    /// Detector settings (model, input size).
    pub detector: DetectorConfig,
    /// Make the detector fail on purpose ([`crate::SessionOptions::inject_fault`]).
    pub inject_fault: Option<InjectedFault>,
    /// Write the run's trace CSV here.
    pub trace: Option<PathBuf>,
}

/// Runs a scenario headless (deterministic) and judges it. `extra` watches the run too (the
/// app's Rerun recorder); it never influences it.
pub fn run_scenario(
    scenario: &Scenario,
    options: &ScenarioOptions,
    extra: &mut dyn Observer,
) -> Result<ScenarioResult> {
    let config = RunConfig {
        duration_s: Some(scenario.duration_s),
        trace: options.trace.clone(),
        detector: options.detector.clone(),
        inject_fault: options.inject_fault,
        options: rover_sim::physics::SimOptions {
            seed: scenario.seed,
            ..rover_sim::physics::SimOptions::default()
        },
        ground_truth: true,
        ..RunConfig::default()
    };
    let script = Script {
        steps: vec![Step {
            at_s: scenario.follow_at_s,
            action: Action::ToggleFollow,
        }],
    };
    let calm_from = scenario
        .criteria
        .calm_last_s
        .map(|w| (scenario.duration_s - w).max(0.0));
    let mut probe = Probe::new(scenario.target, calm_from);
    let started = std::time::Instant::now();
    {
        let mut both = (&mut probe, extra);
        headless::run_loaded(
            &config,
            scenario.world.clone(),
            scenario.robot.clone(),
            script,
            &mut both,
            false,
        )?;
    }
    let wall_s = started.elapsed().as_secs_f64();
    let metrics = probe.metrics();
    let checks = judge_scenario(scenario, &metrics);
    Ok(ScenarioResult {
        name: scenario.name.clone(),
        robot: scenario.robot_name.clone(),
        file: scenario.source.display().to_string(),
        description: scenario.description.clone(),
        passed: checks.iter().all(|c| c.passed),
        checks,
        metrics,
        error: None,
        skipped: None,
        wall_s,
    })
}

/// The scenario files a list of paths names: files as given, folders' `*.toml` in name order.
pub fn collect_scenario_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|source| SimError::Io {
                    path: p.clone(),
                    source,
                })?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.extension().is_some_and(|e| e == "toml"))
                .collect();
            found.sort();
            files.extend(found);
        } else if p.is_file() {
            files.push(p.clone());
        } else {
            return Err(SimError::Io {
                path: p.clone(),
                source: std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "no such scenario file or folder",
                ),
            }
            .into());
        }
    }
    Ok(files)
}
