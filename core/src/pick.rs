//! Pick and place: the arm grasps the object of a class the detector sees and puts it on (or
//! in) a place, as a MoveIt pick-and-place node does it with a planning scene.
//!
//! 1. **See.** Each detector message's most confident box of the class becomes the object's
//!    centre and radius in the arm's base frame, from the depth image (as reach estimates it,
//!    [`crate::reach::object_estimate`]). [`PickConfig::sightings`] sightings in a row that agree
//!    within [`PickConfig::agree_m`] are averaged: the object.
//! 2. **Plan** (all of it at once, from the arm's pose now, in the world's planning scene,
//!    [`rover_sim::PlanningScene`]):
//!    - the grasp: the tool at the object's centre, coming in along a direction tilted
//!      [`PickConfig::approach_pitches_deg`] below horizontal (straight down first), the first
//!      that IK reaches and where nothing but the object is within the margin with the fingers
//!      open; the pre-grasp [`PickConfig::approach_m`] back along it;
//!    - the place: the tool over the place's top, the object's bottom
//!      [`PickConfig::drop_height_m`] above it, the object carried in the hand (a sphere on
//!      the tool);
//!    - joint-space paths (RRT-Connect, [`rover_sim::plan_path`]) to the pre-grasp, from the
//!      lift to the place, and home; straight lines by IK for the approach, the lift and the
//!      retreat. A grasp or place no direction reaches, or one that collides, is refused with
//!      the reason.
//! 3. **Run.** The gripper opens, the arm follows the timed paths (each joint at most
//!    [`PickConfig::speed_scale`] of its velocity limit) as a trajectory controller's moving
//!    setpoints, the gripper closes with [`PickConfig::squeeze_n`] until it stalls on the object
//!    (closing all the way means it missed), the arm lifts, carries, the gripper opens over the
//!    place, and the arm retreats and goes back to where it started.

mod fetch;

use std::collections::VecDeque;

use fetch::{BACK_OFF_M, FETCH_FROM_M, MAX_DRIVE_S, SETTLE_BASE_S};

use nalgebra::{
    Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3,
};
use rover_perception::BoundingBoxes;
use rover_sim::{
    CameraConfig, CameraInfo, ChainJoint, GraspMode, IkOptions, IkSolver, IkTarget, JointCommand,
    JointId, KinematicChain, LinkId, Place, PlannerOptions, PlanningScene, Pose, Shape, Simulation,
    TimedPath, Twist, isometry_from_pose, plan_path,
};

use crate::reach::{DepthView, object_estimate};

/// Pick settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PickConfig {
    /// Class to pick (darknet_ros `Class`).
    pub class: String,
    /// Minimum detection probability.
    pub min_probability: f64,
    /// Sightings in a row that must agree before planning.
    pub sightings: u32,
    /// How close (m) sightings must be to agree.
    pub agree_m: f64,
    /// Approach directions tried, degrees below horizontal, in order.
    pub approach_pitches_deg: Vec<f64>,
    /// How far back along the approach the pre-grasp is (m).
    pub approach_m: f64,
    /// How high the object is lifted after the grasp (m).
    pub lift_m: f64,
    /// How far above the place's top the object's bottom is let go (m).
    pub drop_height_m: f64,
    /// The gripper's most effort while closing (N or N m).
    pub squeeze_n: f64,
    /// Each joint's speed as a share of its velocity limit.
    pub speed_scale: f64,
    /// Closer than this (m) to anything is a collision for the planner.
    pub margin_m: f64,
    /// Depth beyond this (m) is not trusted.
    pub max_range_m: f64,
    /// Where to put it (a world object it is dropped on or in, or a point it is set down
    /// at); `None`: the world's `[robot] place`.
    pub place: Option<Place>,
    /// A world object to take by its known pose, no camera needed (as a MoveIt pick node is
    /// given a collision object); `None`: the world's `[robot] pick`, else what the detector
    /// sees of [`Self::class`].
    pub object: Option<String>,
    /// Where (m, x forward and y left in the arm's base frame) the object should be when the
    /// car stops to pick it; set, the pick drives the base to within reach of the object and
    /// then to the place. `None`: the world's `[robot] fetch`, else the base is not moved.
    pub fetch_at: Option<[f64; 2]>,
    /// Planner settings.
    pub planner: PlannerOptions,
}

impl Default for PickConfig {
    fn default() -> Self {
        Self {
            class: "sports ball".into(),
            // darknet_ros's own threshold is 0.3: a small ball at arm's length scores ~0.32.
            min_probability: 0.25,
            sightings: 3,
            agree_m: 0.015,
            approach_pitches_deg: vec![90.0, 75.0, 60.0, 45.0, 30.0, 15.0],
            approach_m: 0.07,
            lift_m: 0.08,
            drop_height_m: 0.07,
            squeeze_n: 5.0,
            speed_scale: 0.5,
            margin_m: 0.01,
            max_range_m: 4.0,
            place: None,
            object: None,
            fetch_at: None,
            planner: PlannerOptions::default(),
        }
    }
}

/// What the pick is doing, as the HUD, Rerun and ROS show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PickState {
    /// Looking for the object.
    #[default]
    Seeking,
    /// Opening, going to the pre-grasp and in.
    Approaching,
    /// Closing on the object.
    Grasping,
    /// Lifting it.
    Lifting,
    /// Carrying it to the place.
    Carrying,
    /// Letting go over the place.
    Releasing,
    /// Backing off and going home.
    Retreating,
    /// Done.
    Done,
    /// Refused or failed (the reason was said).
    Failed,
    /// Driving the base to within reach of the object (`fetch`).
    Fetching,
    /// Driving the base, the object in the hand, to the place (`fetch`).
    Delivering,
}

impl PickState {
    /// Its name in lower case.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Seeking => "seeking",
            Self::Approaching => "approaching",
            Self::Grasping => "grasping",
            Self::Lifting => "lifting",
            Self::Carrying => "carrying",
            Self::Releasing => "releasing",
            Self::Retreating => "retreating",
            Self::Done => "done",
            Self::Failed => "failed",
            Self::Fetching => "fetching",
            Self::Delivering => "delivering",
        }
    }

    /// 0 seeking ... 8 failed, 9 fetching, 10 delivering (for plots).
    pub fn index(self) -> usize {
        self as usize
    }
}

/// One thing to do.
#[derive(Debug, Clone)]
enum Step {
    /// Follow a timed path.
    Move(TimedPath),
    /// Command the gripper; done when it reached its goal or stalled. `grip`: it must stall
    /// on something.
    Gripper { position: f64, grip: bool },
    /// Wait (s); with the grasp assist, until it holds (or the time is up).
    Wait { s: f64, until_held: bool },
}

/// Joint-space waypoints (the chain's joints each).
type Waypoints = Vec<Vec<f64>>;

/// The joint-space paths of a grasp.
#[derive(Debug)]
struct Grasp {
    /// From the start to the pre-grasp.
    to_pre: Vec<Vec<f64>>,
    /// Straight in, from the pre-grasp to the grasp.
    descent: Vec<Vec<f64>>,
    /// Straight up with the object.
    lift: Vec<Vec<f64>>,
    /// How the hand holds it.
    way: Way,
}

/// The gripper the pick uses.
#[derive(Debug, Clone)]
struct Gripper {
    controller: String,
    joint: JointId,
    open: f64,
    closed: f64,
    /// The direction the finger joint moves, in the tool's frame (unit): the fingers close
    /// across it.
    across_tool: Vector3<f64>,
}

impl Gripper {
    /// Each finger's furthest from the middle (m or rad): half the widest the hand opens.
    fn widest_m(&self) -> f64 {
        self.open.abs().max(self.closed.abs())
    }
}

/// What is picked, as the plan needs it (arm base frame, m).
#[derive(Debug, Clone, Copy)]
struct Target {
    /// Its centre.
    centre: Vector3<f64>,
    /// From its centre down to what it rests on.
    half_height_m: f64,
    /// A sphere round it: the hand carries it as this.
    bound_m: f64,
    /// A box: its orientation (base frame) and half sizes along its axes; the fingers close
    /// across its x or y faces. `None`: round (any turn of the hand will do).
    cuboid: Option<(UnitQuaternion<f64>, [f64; 3])>,
}

impl Target {
    /// A ball (or anything round) of `radius_m` at `centre`.
    fn round(centre: Vector3<f64>, radius_m: f64) -> Self {
        Self {
            centre,
            half_height_m: radius_m,
            bound_m: radius_m,
            cuboid: None,
        }
    }
}

/// One way of taking hold: the tool's z along `along` (the way in), its turn about it fixed
/// by `turn` or free.
#[derive(Debug, Clone)]
struct Way {
    /// How a refusal names it.
    label: String,
    /// The tool's z axis (base frame, unit).
    along: Vector3<f64>,
    /// The tool's whole orientation (base frame), when its turn matters (across a box's
    /// faces).
    turn: Option<UnitQuaternion<f64>>,
    /// Each finger's position closed on the object (m from the middle).
    grip_m: f64,
}

impl Way {
    /// The IK target for the tool at `point`.
    fn target(&self, point: Vector3<f64>) -> IkTarget {
        match self.turn {
            Some(turn) => IkTarget::pose(&Isometry3::from_parts(Translation3::from(point), turn)),
            None => IkTarget::approach(point, self.along),
        }
    }
}

/// The pick controller for one arm.
#[derive(Debug, Clone)]
pub struct Pick {
    config: PickConfig,
    solver: IkSolver,
    base: LinkId,
    tool: LinkId,
    gripper: Result<Gripper, String>,
    intrinsics: [f64; 4],
    sightings: Vec<(Vector3<f64>, f64)>,
    state: PickState,
    steps: VecDeque<(Step, PickState)>,
    /// The step running and when it started (s of sim time).
    running: Option<(Step, f64)>,
    /// The object's centre (base frame) and radius, once seen.
    object: Option<(Vector3<f64>, f64)>,
    /// Wall-clock seconds the last plan took.
    planning_s: Option<f64>,
    /// Waypoints of the last plan's joint-space paths: to the pre-grasp, the carry, home
    /// (2: a straight joint move; more: it goes round something).
    path_points: Option<[usize; 3]>,
    q: Vec<f64>,
    v: Vec<f64>,
    /// What to say next (a warning when `true`).
    said: Vec<(bool, String)>,
    /// The base's go-to-point controller (`fetch`).
    drive: fetch::DriveTo,
    /// Where the base is driving to, while it is.
    leg: Option<Leg>,
    /// What the base is told this control update (`fetch`: zero while the arm works).
    base_cmd: Option<Twist>,
    /// No sighting from an image taken before this (s of sim time): the base was moving.
    settle_until_s: f64,
    /// The object in the hand, to be placed once the base is at the place (`fetch`).
    held: Option<Held>,
}

impl Pick {
    /// A pick for the chain from `base_link` to `tool_link` of `sim`'s robot, seeing through
    /// `camera` (none: it can only take a named object, [`PickConfig::object`]), with the
    /// robot's first gripper controller.
    pub fn new(
        sim: &Simulation,
        camera: Option<&CameraConfig>,
        base_link: &str,
        tool_link: &str,
        config: PickConfig,
    ) -> Result<Self, String> {
        let robot = sim.robot();
        let chain = KinematicChain::new(robot, base_link, tool_link).map_err(|e| e.to_string())?;
        let (base, tool) = (chain.base(), chain.tip());
        let options = IkOptions {
            tolerance_m: 5e-4,
            tolerance_rad: 5e-3,
            ..IkOptions::default()
        };
        let solver = IkSolver::new(chain, options).map_err(|e| e.to_string())?;
        let intrinsics = camera.map_or([0.0; 4], |camera| {
            let info = CameraInfo::from_config(camera);
            [info.k[0], info.k[4], info.k[2], info.k[5]]
        });
        Ok(Self {
            config,
            solver,
            base,
            tool,
            gripper: find_gripper(sim, tool),
            intrinsics,
            sightings: Vec::new(),
            state: PickState::Seeking,
            steps: VecDeque::new(),
            running: None,
            object: None,
            planning_s: None,
            path_points: None,
            q: Vec::new(),
            v: Vec::new(),
            said: Vec::new(),
            drive: fetch::DriveTo::default(),
            leg: None,
            base_cmd: None,
            settle_until_s: 0.0,
            held: None,
        })
    }

    /// The joints it moves, base to tool.
    pub fn joints(&self) -> &[ChainJoint] {
        self.solver.chain().joints()
    }

    /// What it is doing.
    pub fn state(&self) -> PickState {
        self.state
    }

    /// The object's centre (base frame, m) and radius (m), once seen.
    pub fn object(&self) -> Option<(Vector3<f64>, f64)> {
        self.object
    }

    /// Wall-clock seconds the plan took, once planned.
    pub fn planning_s(&self) -> Option<f64> {
        self.planning_s
    }

    /// Waypoints of the last plan's joint-space paths (to the pre-grasp, the carry, home; 0
    /// for a leg without one): 2 is a straight joint move, more goes round something.
    pub fn path_points(&self) -> Option<[usize; 3]> {
        self.path_points
    }

    /// Starts afresh.
    pub fn reset(&mut self) {
        self.sightings.clear();
        self.state = PickState::Seeking;
        self.steps.clear();
        self.running = None;
        self.object = None;
        self.planning_s = None;
        self.path_points = None;
        self.drive.reset();
        self.leg = None;
        self.base_cmd = None;
        self.settle_until_s = 0.0;
        self.held = None;
    }

    /// What it has to say since the last call: (warning, text).
    pub fn drain_said(&mut self) -> impl Iterator<Item = (bool, String)> + '_ {
        self.said.drain(..)
    }

    /// A detector message with the depth image it came from, taken at `captured_s` (sim time)
    /// with the arm's base at `world_from_base`: while seeking, a sighting; once the sightings
    /// agree, the plan. With `fetch`, a sighting out of reach sends the base to it, and each
    /// sighting on the way corrects where it goes.
    pub fn observe(
        &mut self,
        boxes: &BoundingBoxes,
        view: &DepthView<'_>,
        (world_from_base, captured_s): (&Isometry3<f64>, f64),
        sim: &Simulation,
    ) {
        // A named object is taken by its pose ([`Self::update`]), not by what is seen.
        let fetching = self.state == PickState::Fetching;
        if !(self.state == PickState::Seeking || fetching) || self.known_object(sim).is_some() {
            return;
        }
        if captured_s < self.settle_until_s {
            return;
        }
        let c = &self.config;
        let seen = boxes
            .bounding_boxes
            .iter()
            .filter(|b| b.class == c.class && b.probability >= c.min_probability)
            .max_by(|a, b| a.probability.total_cmp(&b.probability))
            .and_then(|b| object_estimate(b, view, self.intrinsics, c.max_range_m));
        let Some(seen) = seen else {
            self.sightings.clear();
            return;
        };
        if self.fetch_towards(sim, seen.0, world_from_base) {
            return;
        }
        let c = &self.config;
        if self
            .sightings
            .first()
            .is_some_and(|(p, _)| (p - seen.0).norm() > c.agree_m)
        {
            self.sightings.clear();
        }
        self.sightings.push(seen);
        if self.sightings.len() < c.sightings as usize {
            return;
        }
        let n = self.sightings.len() as f64;
        let centre = self.sightings.iter().map(|(p, _)| p).sum::<Vector3<f64>>() / n;
        let radius = self.sightings.iter().map(|(_, r)| r).sum::<f64>() / n;
        let what = format!("the {}", self.config.class);
        self.plan_for(sim, &what, Target::round(centre, radius));
    }

    /// Plans the whole pick of `target` (called `what`), and starts it or says why not.
    fn plan_for(&mut self, sim: &Simulation, what: &str, target: Target) {
        let centre = target.centre;
        self.object = Some((centre, target.bound_m));
        let started = std::time::Instant::now();
        let planned = self.plan(sim, what, target);
        self.planning_s = Some(started.elapsed().as_secs_f64());
        match planned {
            Ok(steps) => {
                self.steps = steps;
                self.state = PickState::Approaching;
                self.said.push((
                    false,
                    format!(
                        "pick: {what} at ({:.3}, {:.3}, {:.3}) m, {:.3} m across; planned in {:.3} s",
                        centre.x,
                        centre.y,
                        centre.z,
                        2.0 * target.bound_m,
                        self.planning_s.unwrap_or_default()
                    ),
                ));
            }
            Err(why) => self.fail(format!(
                "{what} at ({:.3}, {:.3}, {:.3}) m: {why}",
                centre.x, centre.y, centre.z
            )),
        }
    }

    /// The world object to take by its known pose, if one is named (here or in the world's
    /// `[robot] pick`).
    pub fn known_object<'a>(&'a self, sim: &'a Simulation) -> Option<&'a str> {
        (self.config.object.as_deref()).or(sim.world().robot.pick.as_deref())
    }

    /// Takes the named world object by its pose now (arm base frame): a box by its faces, a
    /// sphere or anything else as round.
    fn seek_known(&mut self, sim: &Simulation, name: &str) {
        let (shape, pose) = match world_object(sim, name, "to pick") {
            Ok(found) => found,
            Err(why) => return self.fail(why),
        };
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let base_from_object = world_from_base.inverse() * isometry_from_pose(&pose);
        let centre = base_from_object.translation.vector;
        if self.fetch_towards(sim, centre, &world_from_base) {
            return;
        }
        let Some(half_height_m) = shape.half_height_m().map(f64::from) else {
            return self.fail(format!(
                "\"{name}\" is a mesh: pick takes boxes, spheres, cylinders and capsules by name"
            ));
        };
        let target = match shape {
            Shape::Box { size_m } => {
                let half = [size_m.x, size_m.y, size_m.z].map(|v| f64::from(v) / 2.0);
                Target {
                    centre,
                    half_height_m,
                    bound_m: half.iter().map(|h| h * h).sum::<f64>().sqrt(),
                    cuboid: Some((base_from_object.rotation, half)),
                }
            }
            Shape::Sphere { radius_m }
            | Shape::Cylinder { radius_m, .. }
            | Shape::Capsule { radius_m, .. } => Target {
                half_height_m,
                ..Target::round(centre, f64::from(*radius_m))
            },
            Shape::Mesh { .. } => return,
        };
        self.plan_for(sim, &format!("\"{name}\""), target);
    }

    /// Stops where it is (the arm holds, the base is left alone), saying `why`.
    pub fn stop(&mut self, why: &str) {
        self.fail(why.to_owned());
    }

    fn fail(&mut self, why: String) {
        self.state = PickState::Failed;
        self.steps.clear();
        self.running = None;
        self.leg = None;
        self.base_cmd = None;
        self.said.push((true, format!("pick: {why}")));
    }

    /// After a control update: runs the plan's steps (joint setpoints and gripper commands to
    /// `sim`).
    pub fn update(&mut self, sim: &mut Simulation) {
        let now = sim.sim_time_s();
        self.base_cmd = None;
        self.drive_base(sim, now);
        if self.state == PickState::Seeking
            && now >= self.settle_until_s
            && let Some(name) = self.known_object(sim).map(str::to_owned)
        {
            self.seek_known(sim, &name);
        }
        self.run_steps(sim, now);
        if self.fetch_at(sim).is_some()
            && !matches!(self.state, PickState::Done | PickState::Failed)
        {
            // A fetch owns the base: it stands still while the arm works.
            self.base_cmd.get_or_insert(Twist::ZERO);
        }
    }

    /// What the base is told this control update: `Some` while a fetch drives it (zero while
    /// the arm works), `None` when the pick leaves the base alone.
    pub fn base_command(&self) -> Option<Twist> {
        self.base_cmd
    }

    /// Runs the plan's steps.
    fn run_steps(&mut self, sim: &mut Simulation, now: f64) {
        if self.running.is_none() {
            let Some((step, state)) = self.steps.pop_front() else {
                if !matches!(
                    self.state,
                    PickState::Seeking | PickState::Done | PickState::Failed | PickState::Fetching
                ) && !self.deliver(sim, now)
                {
                    self.state = PickState::Done;
                    self.said.push((false, "pick: done".to_owned()));
                }
                return;
            };
            self.state = state;
            if let Step::Gripper { position, grip } = &step
                && let Ok(g) = &self.gripper
            {
                let effort = if *grip { self.config.squeeze_n } else { 0.0 };
                if let Err(e) = sim.command_gripper(&g.controller, *position, effort) {
                    self.fail(e.to_string());
                    return;
                }
            }
            self.running = Some((step, now));
        }
        let Some((step, started)) = self.running.take() else {
            return;
        };
        let t = now - started;
        let finished = match &step {
            Step::Move(path) => {
                path.sample(t, &mut self.q, &mut self.v);
                for ((joint, q), v) in self
                    .solver
                    .chain()
                    .joints()
                    .iter()
                    .zip(&self.q)
                    .zip(&self.v)
                {
                    let command = JointCommand::Track {
                        position: *q,
                        velocity: *v,
                    };
                    if let Err(e) = sim.command_joint(&joint.name, command) {
                        tracing::debug!("pick: {e}");
                    }
                }
                let over = t - path.duration_s();
                over >= MAX_SETTLE_S
                    || (over >= SETTLE_S
                        && self.tool_off(sim, path).is_some_and(|off| off <= ARRIVED_M))
            }
            Step::Gripper { grip, .. } => {
                let Ok(g) = &self.gripper else {
                    return;
                };
                match sim.gripper_state(&g.controller) {
                    Some(s) if s.reached_goal && *grip && t > 0.1 => {
                        self.fail(format!(
                            "the gripper closed to {:.4} without touching anything",
                            s.position
                        ));
                        return;
                    }
                    Some(s) if t > 0.1 && (s.reached_goal || s.stalled) => true,
                    _ => t > GRIPPER_TIMEOUT_S,
                }
            }
            Step::Wait { s, until_held } => {
                t >= *s || (*until_held && sim.grasp_assist_holds().is_some())
            }
        };
        if !finished {
            self.running = Some((step, started));
        } else if let Step::Move(path) = &step
            && let Some(off) = self.tool_off(sim, path)
            && off > ARRIVED_M
        {
            self.said.push((
                false,
                format!(
                    "pick: {}: the tool stopped {off:.3} m from its goal (the joints cannot hold it there)",
                    self.state.as_str()
                ),
            ));
        }
    }

    /// How far the tool is from where `path` ends (m).
    fn tool_off(&mut self, sim: &Simulation, path: &TimedPath) -> Option<f64> {
        let goal = path.waypoints().last()?;
        self.q.clear();
        self.q.extend(
            self.solver
                .chain()
                .joints()
                .iter()
                .map(|j| sim.joint_state(j.id).map_or(0.0, |s| s.position)),
        );
        let chain = self.solver.chain();
        let (at, want) = (
            chain.base_from_tip(&self.q).ok()?,
            chain.base_from_tip(goal).ok()?,
        );
        Some((at.translation.vector - want.translation.vector).norm())
    }

    /// The chain's joint positions now.
    fn chain_q(&self, sim: &Simulation) -> Vec<f64> {
        (self.joints().iter())
            .map(|j| sim.joint_state(j.id).map_or(0.0, |s| s.position))
            .collect()
    }

    /// What every plan starts from: the gripper, where the arm's base is, and the planning
    /// scene as the world is now.
    fn planning_start(
        &self,
        sim: &Simulation,
    ) -> Result<(Gripper, Isometry3<f64>, PlanningScene), String> {
        let g = self.gripper.clone()?;
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let scene = sim
            .planning_scene(self.solver.chain(), self.config.margin_m as f32)
            .map_err(|e| e.to_string())?;
        Ok((g, world_from_base, scene))
    }

    /// The whole plan for `target` (called `what`): the grasp, then the place (or, with no
    /// place, holding it up).
    fn plan(
        &mut self,
        sim: &Simulation,
        what: &str,
        target: Target,
    ) -> Result<VecDeque<(Step, PickState)>, String> {
        let (g, world_from_base, mut scene) = self.planning_start(sim)?;
        let w = world_from_base * Point3::from(target.centre);
        let object = scene.object_near([w.x, w.y, w.z], target.bound_m as f32 + 0.02);
        // Over the place: where the carry ends, and how far it then goes straight down.
        let place_under = self.place_under(sim)?;
        let place = place_under.map(|p| over_place(&world_from_base, p, target.half_height_m));
        let q0 = self.chain_q(sim);
        let grasp = self.plan_grasp(&mut scene, what, target, object, &g, &q0)?;
        let assist = sim.world().robot.grasp == GraspMode::Assist;
        let joints = self.joints().to_vec();
        let speed_scale = self.config.speed_scale;
        let timed = |w: Vec<Vec<f64>>, stop: bool| {
            Step::Move(TimedPath::new(w, &joints, speed_scale, RAMP_S, stop))
        };
        let lift_q = grasp.lift.last().cloned().unwrap_or_default();
        self.path_points = Some([grasp.to_pre.len(), 0, 0]);
        let mut steps = VecDeque::from([
            (
                Step::Gripper {
                    position: g.open,
                    grip: false,
                },
                PickState::Approaching,
            ),
            (timed(grasp.to_pre, true), PickState::Approaching),
            (timed(grasp.descent, false), PickState::Approaching),
            (
                Step::Gripper {
                    position: g.closed,
                    grip: true,
                },
                PickState::Grasping,
            ),
            (
                Step::Wait {
                    s: if assist { 2.0 } else { 0.3 },
                    until_held: assist,
                },
                PickState::Grasping,
            ),
            (timed(grasp.lift, false), PickState::Lifting),
        ]);
        let Some((over, lower_m)) = place else {
            // No place: it stays in the hand, held up.
            return Ok(steps);
        };
        if let Some(place) = place_under
            && self.fetch_at(sim).is_some()
        {
            // Fetching: it is held up while the base drives to the place ([`Self::deliver`]).
            self.held = Some(Held {
                target,
                way: grasp.way,
                home_q: q0,
                place,
            });
            return Ok(steps);
        }
        let held = (target, grasp.way);
        steps.extend(self.plan_place(&mut scene, held, &g, (&lift_q, &q0), (over, lower_m))?);
        Ok(steps)
    }

    /// From the lift (`lift_q`) with the object `held` as the hand took it: the carry to over
    /// the place (`over`, base frame), the straight way down `lower_m` (none for a drop), the
    /// release, the retreat and the way home (`home_q`).
    fn plan_place(
        &mut self,
        scene: &mut PlanningScene,
        (target, way_held): (Target, Way),
        g: &Gripper,
        (lift_q, home_q): (&[f64], &[f64]),
        (over, lower_m): (Vector3<f64>, f64),
    ) -> Result<Vec<(Step, PickState)>, String> {
        let joints = self.joints().to_vec();
        let speed_scale = self.config.speed_scale;
        let timed = |w: Vec<Vec<f64>>, stop: bool| {
            Step::Move(TimedPath::new(w, &joints, speed_scale, RAMP_S, stop))
        };
        // Carrying: the object on the tool, as the hand holds it.
        match (target.cuboid, way_held.turn) {
            (Some((r, half)), Some(turn)) => {
                let q = (turn.inverse() * r).into_inner();
                let tool_from_box =
                    glam::Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32);
                scene.attach_box(
                    self.tool,
                    Pose::from_rotation(tool_from_box),
                    half.map(|h| h as f32),
                );
            }
            _ => scene.attach_sphere(Some((self.tool, Pose::IDENTITY, target.bound_m as f32))),
        }
        let ways = self.ways_round(over, g.open);
        let (place_q, _, way) = self
            .reachable(scene, over, lift_q, "the place", None, &ways)
            .map_err(|why| format!("cannot reach over the place: {why}"))?;
        let carry = plan_path(&joints, lift_q, &place_q, &self.config.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("carrying: {e}"))?;
        // Set down: straight down onto the surface, the object (about to touch it) left out.
        scene.attach_sphere(None);
        let set_down = if lower_m > 0.0 {
            self.line_at_least(
                scene,
                &place_q,
                (over, over - Vector3::z() * lower_m),
                Some(&ways[way]),
                1.0,
            )
            .map_err(|e| format!("setting it down: {e}"))?
        } else {
            Vec::new()
        };
        let release_q = set_down.last().cloned().unwrap_or_else(|| place_q.clone());
        // Let go; back up and home, the gripper open.
        scene.set_joint(g.joint, g.open);
        let from = self
            .solver
            .chain()
            .base_from_tip(&release_q)
            .map_err(|e| e.to_string())?
            .translation
            .vector;
        let retreat = self.line_at_least(
            scene,
            &release_q,
            (from, from + Vector3::z() * RETREAT_M.max(lower_m)),
            None,
            0.0,
        )?;
        let retreat_q = retreat.last().cloned().unwrap_or_else(|| release_q.clone());
        let home = plan_path(&joints, &retreat_q, home_q, &self.config.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("going home: {e}"))?;
        self.path_points = Some([
            self.path_points.map_or(0, |p| p[0]),
            carry.len(),
            home.len(),
        ]);
        let mut steps = vec![(timed(carry, true), PickState::Carrying)];
        if set_down.len() > 1 {
            steps.push((timed(set_down, false), PickState::Releasing));
        }
        steps.extend([
            (
                Step::Gripper {
                    position: g.open,
                    grip: false,
                },
                PickState::Releasing,
            ),
            (
                Step::Wait {
                    s: 0.5,
                    until_held: false,
                },
                PickState::Releasing,
            ),
            (timed(retreat, false), PickState::Retreating),
            (timed(home, true), PickState::Retreating),
        ]);
        Ok(steps)
    }

    /// The way to the object and up with it, from `q0`: the path to the pre-grasp (the object
    /// in the scene), the straight way in and the lift (the object left out, the fingers on
    /// it).
    fn plan_grasp(
        &mut self,
        scene: &mut PlanningScene,
        what: &str,
        object: Target,
        target: Option<usize>,
        g: &Gripper,
        q0: &[f64],
    ) -> Result<Grasp, String> {
        let c = self.config.clone();
        let centre = object.centre;
        scene.set_joint(g.joint, g.open);
        if let Some(t) = target {
            scene.ignore_object(t, true);
        }
        let ways = match object.cuboid {
            Some((r, half)) => self.ways_across(
                [(r * Vector3::x(), half[0]), (r * Vector3::y(), half[1])],
                g,
            ),
            None => self.ways_round(centre, object.bound_m),
        };
        if ways.is_empty() {
            return Err(format!(
                "cannot grasp {what}: it is wider than the open gripper ({:.3} m) every way",
                2.0 * g.widest_m()
            ));
        }
        let (grasp_q, mut descent, way) = self
            .reachable(scene, centre, q0, "the grasp", Some(c.approach_m), &ways)
            .map_err(|why| format!("cannot grasp {what}: {why}"))?;
        let pre_q = descent.last().cloned().unwrap_or_else(|| grasp_q.clone());
        descent.reverse();
        if let Some(t) = target {
            scene.ignore_object(t, false);
        }
        let joints = self.joints().to_vec();
        let to_pre = plan_path(&joints, q0, &pre_q, &c.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("to the pre-grasp: {e}"))?;
        if let Some(t) = target {
            scene.ignore_object(t, true);
        }
        let (lo, hi) = (g.closed.min(g.open), g.closed.max(g.open));
        scene.set_joint(g.joint, ways[way].grip_m.clamp(lo, hi));
        // Straight up off what it rests on; the hand may turn on the way (the object turns
        // with it). The arm is checked, the object (touching its support, as far as the
        // estimate knows) only from the lift's top.
        let lift = self.line_at_least(
            scene,
            &grasp_q,
            (centre, centre + Vector3::z() * c.lift_m),
            None,
            0.5,
        )?;
        Ok(Grasp {
            to_pre,
            descent,
            lift,
            way: ways[way].clone(),
        })
    }

    /// The ways to take hold of something round at `point` (base frame): coming in along
    /// [`PickConfig::approach_pitches_deg`] below horizontal, away from the arm's base, the
    /// turn about the way in free; the fingers close to `grip_m`.
    fn ways_round(&self, point: Vector3<f64>, grip_m: f64) -> Vec<Way> {
        let horizontal = Vector3::new(point.x, point.y, 0.0)
            .try_normalize(1e-9)
            .unwrap_or_else(Vector3::x);
        (self.config.approach_pitches_deg.iter())
            .map(|pitch_deg| {
                let pitch = pitch_deg.to_radians();
                Way {
                    label: format!("{pitch_deg:.0} deg down"),
                    along: horizontal * pitch.cos() - Vector3::z() * pitch.sin(),
                    turn: None,
                    grip_m,
                }
            })
            .collect()
    }

    /// The ways to take hold of a box from above: the fingers across one pair of its faces
    /// (the narrower first), either way round; only faces the open gripper fits round (with
    /// 5 mm to spare on each side).
    fn ways_across(&self, mut faces: [(Vector3<f64>, f64); 2], g: &Gripper) -> Vec<Way> {
        faces.sort_by(|a, b| a.1.total_cmp(&b.1));
        let down = -Vector3::z();
        let open = g.widest_m();
        let mut ways = Vec::new();
        for (k, (axis, half)) in faces.iter().enumerate() {
            let across = (axis - down * axis.dot(&down)).try_normalize(1e-6);
            let Some(across) = across.filter(|_| *half + 0.005 <= open) else {
                continue;
            };
            for sign in [1.0, -1.0] {
                if let Some(turn) = turn_taking(g.across_tool, across * sign, down) {
                    ways.push(Way {
                        label: format!(
                            "from above across its {} faces{}",
                            ["narrow", "wide"][k],
                            if sign < 0.0 { ", turned round" } else { "" }
                        ),
                        along: down,
                        turn: Some(turn),
                        grip_m: *half,
                    });
                }
            }
        }
        ways
    }

    /// Joint positions putting the tool at `point` (base frame) the first of `ways` IK
    /// reaches there without a collision (with `back_m`, the straight way back out along it
    /// free too, returned), and which way; else why not each way.
    fn reachable(
        &mut self,
        scene: &mut PlanningScene,
        point: Vector3<f64>,
        seed: &[f64],
        what: &str,
        back_m: Option<f64>,
        ways: &[Way],
    ) -> Result<(Vec<f64>, Waypoints, usize), String> {
        let mut why: Vec<String> = Vec::new();
        for (k, way) in ways.iter().enumerate() {
            let label = &way.label;
            let solution = self
                .solver
                .solve(&way.target(point), seed)
                .map_err(|e| e.to_string())?;
            if !ik_close(solution.position_error_m, solution.orientation_error_rad) {
                why.push(format!(
                    "{label}: out of reach by {:.3} m",
                    solution.position_error_m
                ));
                continue;
            }
            if let Some(hit) = scene.collision(&solution.q) {
                why.push(format!("{label}: {hit}"));
                continue;
            }
            // The straight way in, `back_m` long, must be there too.
            let back = match back_m {
                Some(back_m) => {
                    let to = point - way.along * back_m;
                    match self.line_at_least(scene, &solution.q, (point, to), Some(way), 1.0) {
                        Ok(line) => line,
                        Err(e) => {
                            why.push(format!("{label}: {e}"));
                            continue;
                        }
                    }
                }
                None => Vec::new(),
            };
            return Ok((solution.q, back, k));
        }
        Err(format!("{what}, coming in {}", why.join("; ")))
    }

    /// A straight line of the tool from `from` (at `from_q`) to `to` (base frame), held to
    /// `way`'s direction when given: joint waypoints every centimetre, each by IK from the
    /// last, each free. It may stop short where IK or the scene ends it once `share` of the way
    /// is done (a lift or a retreat at the edge of the arm's reach).
    fn line_at_least(
        &mut self,
        scene: &mut PlanningScene,
        from_q: &[f64],
        (from, to): (Vector3<f64>, Vector3<f64>),
        way: Option<&Way>,
        share: f64,
    ) -> Result<Vec<Vec<f64>>, String> {
        let n = ((to - from).norm() / LINE_STEP_M).ceil().max(1.0) as usize;
        let mut waypoints = vec![from_q.to_vec()];
        for k in 1..=n {
            let p = from + (to - from) * (k as f64 / n as f64);
            let last = waypoints.last().cloned().unwrap_or_default();
            let target = way.map_or(IkTarget::point(p), |w| w.target(p));
            let s = self
                .solver
                .solve(&target, &last)
                .map_err(|e| e.to_string())?;
            let jump =
                s.q.iter()
                    .zip(&last)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
            let done = (k - 1) as f64 / n as f64;
            let blocked = !ik_close(s.position_error_m, s.orientation_error_rad)
                || jump > MAX_LINE_JUMP_RAD
                || scene.collision(&s.q).is_some();
            if blocked && done >= share && k > 1 {
                break;
            }
            if !ik_close(s.position_error_m, s.orientation_error_rad) || jump > MAX_LINE_JUMP_RAD {
                return Err(format!(
                    "no straight move from ({:.3}, {:.3}, {:.3}) to ({:.3}, {:.3}, {:.3}) m: IK {:.3} m off, a {jump:.2} rad jump",
                    from.x, from.y, from.z, to.x, to.y, to.z, s.position_error_m
                ));
            }
            if let Some(hit) = scene.collision(&s.q) {
                return Err(format!("the straight move collides: {hit}"));
            }
            waypoints.push(s.q);
        }
        Ok(waypoints)
    }

    /// Where the object's bottom goes (world frame), how high above that the carry ends, and
    /// how far the hand then goes straight down before letting go (m): over a world object's
    /// top centre, [`PickConfig::drop_height_m`] and no further (dropped into a bin, onto a
    /// tray); at a point, [`PickConfig::approach_m`], then down to [`SET_DOWN_M`] above it (set
    /// down, as MoveIt's place approaches). From the configured place, else the world's
    /// `[robot] place`; none: the object is held up. An error for an object the world lacks.
    fn place_under(&self, sim: &Simulation) -> Result<Option<([f64; 3], f64, f64)>, String> {
        let world = sim.world();
        let name = match self
            .config
            .place
            .clone()
            .or_else(|| world.robot.place.clone())
        {
            None => return Ok(None),
            Some(Place::Point(p)) => {
                let above = self.config.approach_m.max(SET_DOWN_M);
                return Ok(Some((p, above, above - SET_DOWN_M)));
            }
            Some(Place::Object(name)) => name,
        };
        let (shape, pose) = world_object(sim, &name, "to place on")?;
        let t = pose.translation;
        let top = t.z + shape.half_height_m().unwrap_or(0.0);
        Ok(Some((
            [f64::from(t.x), f64::from(t.y), f64::from(top)],
            self.config.drop_height_m,
            0.0,
        )))
    }
}

/// Where the base is driving to.
#[derive(Debug, Clone, Copy)]
struct Leg {
    /// The point brought to the fetch point (world frame, m): the object's centre, or the
    /// place's point under the object.
    goal: Vector3<f64>,
    /// To the place, the object in the hand (else to the object).
    to_place: bool,
    /// When the drive started (s of sim time).
    started_s: f64,
    /// Backing away first, from where the base was (world x, y, m).
    back_from: Option<Vector2<f64>>,
}

/// The object in the hand while the base drives to the place.
#[derive(Debug, Clone)]
struct Held {
    /// What it is, as it was taken.
    target: Target,
    /// How the hand holds it.
    way: Way,
    /// Where the arm goes back to after the place.
    home_q: Vec<f64>,
    /// The place ([`Pick::place_under`]): the point under the object (world, m), how high above
    /// it the carry ends, how far the hand then goes straight down.
    place: ([f64; 3], f64, f64),
}

impl Pick {
    /// Where the object should be when the base stops to pick it (arm base frame, m), when
    /// the pick drives the base.
    fn fetch_at(&self, sim: &Simulation) -> Option<Vector2<f64>> {
        (self.config.fetch_at)
            .or(sim.world().robot.fetch)
            .map(|[x, y]| Vector2::new(x, y))
    }

    /// The object is at `centre` (base frame, the base at `world_from_base`): with fetch, when
    /// it is out of the arm's spot (or already being driven to), the base drives to it.
    /// Returns whether it does.
    fn fetch_towards(
        &mut self,
        sim: &Simulation,
        centre: Vector3<f64>,
        world_from_base: &Isometry3<f64>,
    ) -> bool {
        let Some(at) = self.fetch_at(sim) else {
            return false;
        };
        let driving = self.state == PickState::Fetching;
        if !driving && (centre.xy() - at).norm() < FETCH_FROM_M {
            return false;
        }
        let goal = (world_from_base * Point3::from(centre)).coords;
        let started_s = match self.leg {
            Some(leg) if driving => leg.started_s,
            _ => {
                self.drive.reset();
                self.said.push((
                    false,
                    format!(
                        "pick: fetch: driving to the object at ({:.2}, {:.2}) m",
                        goal.x, goal.y
                    ),
                ));
                sim.sim_time_s()
            }
        };
        self.sightings.clear();
        self.state = PickState::Fetching;
        self.leg = Some(Leg {
            goal,
            to_place: false,
            started_s,
            back_from: None,
        });
        true
    }

    /// One control update of a drive: the base's command, and what comes after it gets there
    /// (a fresh look at the object, or the place's plan once the base has settled).
    fn drive_base(&mut self, sim: &Simulation, now: f64) {
        let Some(leg) = self.leg else {
            return;
        };
        let Some(at) = self.fetch_at(sim) else {
            self.leg = None;
            return;
        };
        if now - leg.started_s > MAX_DRIVE_S {
            self.leg = None;
            return self.fail(format!(
                "fetch: the base did not get there in {MAX_DRIVE_S:.0} s"
            ));
        }
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        if let Some(from) = leg.back_from {
            if (world_from_base.translation.vector.xy() - from).norm() < BACK_OFF_M {
                self.base_cmd = Some(self.drive.back(now));
                return;
            }
            self.leg = Some(Leg {
                back_from: None,
                ..leg
            });
        }
        let point = world_from_base.inverse() * Point3::from(leg.goal);
        let (cmd, there) = self.drive.command(now, point.coords.xy(), at);
        self.base_cmd = Some(cmd);
        if !there {
            return;
        }
        self.leg = None;
        self.settle_until_s = now + SETTLE_BASE_S;
        let (x, y) = (point.x, point.y);
        if leg.to_place {
            self.said.push((
                false,
                format!("pick: fetch: at the place ({x:.3}, {y:.3}) m from the arm's base"),
            ));
        } else {
            self.state = PickState::Seeking;
            self.said.push((
                false,
                format!(
                    "pick: fetch: the object should be at ({x:.3}, {y:.3}) m from the arm's base; looking again"
                ),
            ));
        }
    }

    /// After the grasp's steps, with the object held for a fetch: the drive to the place,
    /// then (the base settled) the place's plan. Returns whether it took over (`false`:
    /// nothing is held for it, the pick is done).
    fn deliver(&mut self, sim: &Simulation, now: f64) -> bool {
        let Some(held) = &self.held else {
            return false;
        };
        if self.state != PickState::Delivering {
            let [x, y, z] = held.place.0;
            let base = sim.world_from_link(self.base).translation;
            self.leg = Some(Leg {
                goal: Vector3::new(x, y, z),
                to_place: true,
                started_s: now,
                back_from: Some(Vector2::new(f64::from(base.x), f64::from(base.y))),
            });
            self.drive.reset();
            self.state = PickState::Delivering;
            self.said.push((
                false,
                format!("pick: fetch: driving to the place at ({x:.2}, {y:.2}) m"),
            ));
            return true;
        }
        if self.leg.is_some() || now < self.settle_until_s {
            return true;
        }
        let Some(held) = self.held.take() else {
            return false;
        };
        match self.plan_delivery(sim, held) {
            Ok(steps) => self.steps = VecDeque::from(steps),
            Err(why) => self.fail(format!("fetch: at the place: {why}")),
        }
        true
    }

    /// The place's plan from where the arm is now, the object held as it was taken.
    fn plan_delivery(
        &mut self,
        sim: &Simulation,
        held: Held,
    ) -> Result<Vec<(Step, PickState)>, String> {
        let (g, world_from_base, mut scene) = self.planning_start(sim)?;
        let q = self.chain_q(sim);
        // The object in the hand is carried, not avoided.
        let tool = self
            .solver
            .chain()
            .base_from_tip(&q)
            .map_err(|e| e.to_string())?;
        let in_hand = world_from_base * Point3::from(tool.translation.vector);
        if let Some(i) = scene.object_near(
            [in_hand.x, in_hand.y, in_hand.z],
            held.target.bound_m as f32 + 0.02,
        ) {
            scene.ignore_object(i, true);
        }
        let over = over_place(&world_from_base, held.place, held.target.half_height_m);
        self.plan_place(
            &mut scene,
            (held.target, held.way),
            &g,
            (&q, &held.home_q),
            over,
        )
    }
}

/// Where the carry ends over a place ([`Pick::place_under`]: the point under the object, how
/// high above it the carry ends, how far the hand then goes down), in the arm's base frame for
/// an object `half_height_m` tall above its centre, and how far it goes down.
fn over_place(
    world_from_base: &Isometry3<f64>,
    ([x, y, z], above_m, lower_m): ([f64; 3], f64, f64),
    half_height_m: f64,
) -> (Vector3<f64>, f64) {
    let over = world_from_base.inverse() * Point3::new(x, y, z + above_m + half_height_m);
    (over.coords, lower_m)
}

/// World object `name`'s shape and pose now; else an error saying what it was wanted for
/// (`"to pick"`) and listing the world's objects.
fn world_object<'w>(
    sim: &'w Simulation,
    name: &str,
    wanted: &str,
) -> Result<(&'w Shape, Pose), String> {
    let world = sim.world();
    let index = (world.objects.iter())
        .position(|o| o.name == name)
        .ok_or_else(|| {
            format!(
                "no world object \"{name}\" {wanted}; the world's objects: {}",
                object_names(sim)
            )
        })?;
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    let pose = poses.get(index).copied().unwrap_or(Pose::IDENTITY);
    Ok((&world.objects[index].shape, pose))
}

/// The world's named objects, comma-separated (for errors).
fn object_names(sim: &Simulation) -> String {
    let names: Vec<&str> = (sim.world().objects.iter())
        .map(|o| o.name.as_str())
        .filter(|n| !n.is_empty())
        .collect();
    names.join(", ")
}

/// The tool's orientation (base frame) whose z is `along` and whose finger direction
/// (`across_tool`, in the tool's frame) is `across`; `None` when either pair is parallel.
fn turn_taking(
    across_tool: Vector3<f64>,
    across: Vector3<f64>,
    along: Vector3<f64>,
) -> Option<UnitQuaternion<f64>> {
    let frame = |x: Vector3<f64>, z: Vector3<f64>| -> Option<Matrix3<f64>> {
        let z = z.try_normalize(1e-9)?;
        let x = (x - z * x.dot(&z)).try_normalize(1e-6)?;
        Some(Matrix3::from_columns(&[x, z.cross(&x), z]))
    };
    let in_tool = frame(across_tool, Vector3::z())?;
    let in_base = frame(across, along)?;
    let rotation = Rotation3::from_matrix_unchecked(in_base * in_tool.transpose());
    Some(UnitQuaternion::from_rotation_matrix(&rotation))
}

/// How far above a place point the object's bottom is let go (m): set down, not dropped.
const SET_DOWN_M: f64 = 0.005;

/// Seconds after a path's end before the next step (the joints settle on their setpoints).
const SETTLE_S: f64 = 0.3;
/// How far the tool backs up after letting go (m).
const RETREAT_M: f64 = 0.05;
/// The tool this close to a path's end (m) has arrived.
const ARRIVED_M: f64 = 0.004;
/// The most seconds to wait after a path's end for the tool to arrive.
const MAX_SETTLE_S: f64 = 3.0;
/// Seconds a gripper command may take.
const GRIPPER_TIMEOUT_S: f64 = 3.0;
/// Seconds to full speed on a timed path.
const RAMP_S: f64 = 0.3;
/// Spacing of a straight move's waypoints (m).
const LINE_STEP_M: f64 = 0.01;
/// The most one joint may change between a straight move's waypoints (rad): more is IK
/// jumping to another branch.
const MAX_LINE_JUMP_RAD: f64 = 0.3;

/// Whether an IK solution is close enough to use: 3 mm and about 2 degrees.
fn ik_close(position_m: f64, orientation_rad: f64) -> bool {
    position_m <= 0.003 && orientation_rad <= 0.035
}

/// The robot's first gripper controller: its name, finger joint and limits (open at the upper
/// limit, as Franka's and the arm car's fingers are), and the way its finger moves seen from
/// `tool` (rigidly on the finger joint's parent, as a tool point on a hand is).
fn find_gripper(sim: &Simulation, tool: LinkId) -> Result<Gripper, String> {
    let robot = sim.robot();
    let spec = robot
        .controllers
        .as_ref()
        .and_then(|c| c.first_gripper())
        .map(|(name, g)| (name.to_owned(), g.joint.clone()))
        .ok_or_else(|| {
            "the robot has no gripper controller (a GripperActionController in its controllers file)"
                .to_owned()
        })?;
    let joint = robot
        .joint_id(&spec.1)
        .ok_or_else(|| format!("no finger joint \"{}\"", spec.1))?;
    let (closed, open) = robot
        .joint(joint)
        .position_limits()
        .map(|(lo, hi)| (f64::from(lo), f64::from(hi)))
        .ok_or_else(|| format!("finger joint \"{}\" has no limits", spec.1))?;
    let finger = robot.joint(joint);
    let world_from = |link| isometry_from_pose(&sim.world_from_link(link));
    let axis = finger.parent_from_child.rotation * finger.axis;
    let across_tool = (world_from(tool).rotation.inverse() * world_from(finger.parent).rotation)
        * Vector3::new(f64::from(axis.x), f64::from(axis.y), f64::from(axis.z));
    Ok(Gripper {
        controller: spec.0,
        joint,
        open,
        closed,
        across_tool,
    })
}
