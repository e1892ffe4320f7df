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

use std::collections::VecDeque;

use nalgebra::{Point3, Vector3};
use rover_perception::BoundingBoxes;
use rover_sim::{
    CameraConfig, CameraInfo, ChainJoint, GraspMode, IkOptions, IkSolver, IkTarget, JointCommand,
    JointId, KinematicChain, LinkId, PlannerOptions, PlanningScene, Pose, Shape, Simulation,
    TimedPath, isometry_from_pose, plan_path,
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
    /// The world object to put it on (by name); `None`: the world's `[robot] place`.
    pub place: Option<String>,
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
        }
    }

    /// 0 seeking ... 8 failed (for plots).
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
}

/// The gripper the pick uses.
#[derive(Debug, Clone)]
struct Gripper {
    controller: String,
    joint: JointId,
    open: f64,
    closed: f64,
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
}

impl Pick {
    /// A pick for the chain from `base_link` to `tool_link` of `sim`'s robot, seeing through
    /// `camera`, with the robot's first gripper controller.
    pub fn new(
        sim: &Simulation,
        camera: &CameraConfig,
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
        let info = CameraInfo::from_config(camera);
        Ok(Self {
            config,
            solver,
            base,
            tool,
            gripper: find_gripper(sim),
            intrinsics: [info.k[0], info.k[4], info.k[2], info.k[5]],
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
    }

    /// What it has to say since the last call: (warning, text).
    pub fn drain_said(&mut self) -> impl Iterator<Item = (bool, String)> + '_ {
        self.said.drain(..)
    }

    /// A detector message with the depth image it came from: while seeking, a sighting; once
    /// the sightings agree, the plan.
    pub fn observe(&mut self, boxes: &BoundingBoxes, view: &DepthView<'_>, sim: &Simulation) {
        if self.state != PickState::Seeking {
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
        self.object = Some((centre, radius));
        let started = std::time::Instant::now();
        let planned = self.plan(sim, centre, radius);
        self.planning_s = Some(started.elapsed().as_secs_f64());
        match planned {
            Ok(steps) => {
                self.steps = steps;
                self.state = PickState::Approaching;
                self.said.push((
                    false,
                    format!(
                        "pick: {} at ({:.3}, {:.3}, {:.3}) m, radius {:.3} m; planned in {:.3} s",
                        self.config.class,
                        centre.x,
                        centre.y,
                        centre.z,
                        radius,
                        self.planning_s.unwrap_or_default()
                    ),
                ));
            }
            Err(why) => self.fail(why),
        }
    }

    fn fail(&mut self, why: String) {
        self.state = PickState::Failed;
        self.steps.clear();
        self.running = None;
        self.said.push((true, format!("pick: {why}")));
    }

    /// After a control update: runs the plan's steps (joint setpoints and gripper commands to
    /// `sim`).
    pub fn update(&mut self, sim: &mut Simulation) {
        let now = sim.sim_time_s();
        if self.running.is_none() {
            let Some((step, state)) = self.steps.pop_front() else {
                if !matches!(
                    self.state,
                    PickState::Seeking | PickState::Done | PickState::Failed
                ) {
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

    /// The whole plan for an object at `centre` (base frame) of `radius`: the grasp, then the
    /// place (or, with no place, holding it up).
    fn plan(
        &mut self,
        sim: &Simulation,
        centre: Vector3<f64>,
        radius: f64,
    ) -> Result<VecDeque<(Step, PickState)>, String> {
        let g = self.gripper.clone()?;
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let mut scene = sim
            .planning_scene(self.solver.chain(), self.config.margin_m as f32)
            .map_err(|e| e.to_string())?;
        let w = world_from_base * Point3::from(centre);
        let target = scene.object_near([w.x, w.y, w.z], radius as f32 + 0.02);
        let place = self.place_top(sim)?.map(|top| {
            let over = world_from_base.inverse()
                * Point3::new(top[0], top[1], top[2] + self.config.drop_height_m + radius);
            over.coords
        });
        let q0: Vec<f64> = self
            .joints()
            .iter()
            .map(|j| sim.joint_state(j.id).map_or(0.0, |s| s.position))
            .collect();
        let grasp = self.plan_grasp(&mut scene, (centre, radius), target, &g, &q0)?;
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
        let Some(over) = place else {
            // No place: it stays in the hand, held up.
            return Ok(steps);
        };
        // Carrying: the object on the tool.
        scene.attach_sphere(Some((self.tool, Pose::IDENTITY, radius as f32)));
        let (place_q, _) = self
            .reachable(&mut scene, over, &lift_q, "the place", None)
            .map_err(|why| format!("cannot reach over the place: {why}"))?;
        let carry = plan_path(&joints, &lift_q, &place_q, &self.config.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("carrying: {e}"))?;
        // Let go; back up and home, the gripper open.
        scene.attach_sphere(None);
        scene.set_joint(g.joint, g.open);
        let from = self
            .solver
            .chain()
            .base_from_tip(&place_q)
            .map_err(|e| e.to_string())?
            .translation
            .vector;
        let retreat = self.line_at_least(
            &mut scene,
            &place_q,
            (from, from + Vector3::z() * RETREAT_M),
            None,
            0.0,
        )?;
        let retreat_q = retreat.last().cloned().unwrap_or_else(|| place_q.clone());
        let home = plan_path(&joints, &retreat_q, &q0, &self.config.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("going home: {e}"))?;
        self.path_points = Some([
            self.path_points.map_or(0, |p| p[0]),
            carry.len(),
            home.len(),
        ]);
        steps.extend([
            (timed(carry, true), PickState::Carrying),
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
        (centre, radius): (Vector3<f64>, f64),
        target: Option<usize>,
        g: &Gripper,
        q0: &[f64],
    ) -> Result<Grasp, String> {
        let c = self.config.clone();
        scene.set_joint(g.joint, g.open);
        if let Some(t) = target {
            scene.ignore_object(t, true);
        }
        let (grasp_q, mut descent) = self
            .reachable(scene, centre, q0, "the grasp", Some(c.approach_m))
            .map_err(|why| format!("cannot grasp the {}: {why}", c.class))?;
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
        scene.set_joint(g.joint, radius.clamp(lo, hi));
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
        })
    }

    /// Joint positions putting the tool at `point` (base frame) coming in along the first of
    /// the approach pitches IK reaches there without a collision (with `back_m`, the straight
    /// way back out along it free too, returned), else why not at each pitch.
    fn reachable(
        &mut self,
        scene: &mut PlanningScene,
        point: Vector3<f64>,
        seed: &[f64],
        what: &str,
        back_m: Option<f64>,
    ) -> Result<(Vec<f64>, Waypoints), String> {
        let horizontal = Vector3::new(point.x, point.y, 0.0)
            .try_normalize(1e-9)
            .unwrap_or_else(Vector3::x);
        let mut why: Vec<String> = Vec::new();
        for pitch_deg in self.config.approach_pitches_deg.clone() {
            let pitch = pitch_deg.to_radians();
            let approach = horizontal * pitch.cos() - Vector3::z() * pitch.sin();
            let solution = self
                .solver
                .solve(&IkTarget::approach(point, approach), seed)
                .map_err(|e| e.to_string())?;
            if !ik_close(solution.position_error_m, solution.orientation_error_rad) {
                why.push(format!(
                    "{pitch_deg:.0} deg down: out of reach by {:.3} m",
                    solution.position_error_m
                ));
                continue;
            }
            if let Some(hit) = scene.collision(&solution.q) {
                why.push(format!("{pitch_deg:.0} deg down: {hit}"));
                continue;
            }
            // The straight way in, `back_m` long, must be there too.
            let back = match back_m {
                Some(back_m) => {
                    match self.line(
                        scene,
                        &solution.q,
                        point,
                        point - approach * back_m,
                        Some(approach),
                    ) {
                        Ok(line) => line,
                        Err(e) => {
                            why.push(format!("{pitch_deg:.0} deg down: {e}"));
                            continue;
                        }
                    }
                }
                None => Vec::new(),
            };
            return Ok((solution.q, back));
        }
        Err(format!("{what}, coming in {}", why.join("; ")))
    }

    /// A straight line of the tool from `from` (at `from_q`) to `to` (base frame), its z along
    /// `approach` when given: joint waypoints every centimetre, each by IK from the last, each
    /// free.
    fn line(
        &mut self,
        scene: &mut PlanningScene,
        from_q: &[f64],
        from: Vector3<f64>,
        to: Vector3<f64>,
        approach: Option<Vector3<f64>>,
    ) -> Result<Vec<Vec<f64>>, String> {
        self.line_at_least(scene, from_q, (from, to), approach, 1.0)
    }

    /// [`Self::line`] that may stop short where IK or the scene ends it, once `share` of the
    /// way is done (a lift or a retreat at the edge of the arm's reach).
    fn line_at_least(
        &mut self,
        scene: &mut PlanningScene,
        from_q: &[f64],
        (from, to): (Vector3<f64>, Vector3<f64>),
        approach: Option<Vector3<f64>>,
        share: f64,
    ) -> Result<Vec<Vec<f64>>, String> {
        let n = ((to - from).norm() / LINE_STEP_M).ceil().max(1.0) as usize;
        let mut waypoints = vec![from_q.to_vec()];
        for k in 1..=n {
            let p = from + (to - from) * (k as f64 / n as f64);
            let last = waypoints.last().cloned().unwrap_or_default();
            let target = approach.map_or(IkTarget::point(p), |d| IkTarget::approach(p, d));
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

    /// The top centre of the place (world frame): the configured place, else the world's
    /// `[robot] place`, else none (the object is held up). An error for a name the world
    /// lacks.
    fn place_top(&self, sim: &Simulation) -> Result<Option<[f64; 3]>, String> {
        let world = sim.world();
        let Some(name) = self
            .config
            .place
            .clone()
            .or_else(|| world.robot.place.clone())
        else {
            return Ok(None);
        };
        let index = world
            .objects
            .iter()
            .position(|o| o.name == name)
            .ok_or_else(|| {
                let names: Vec<&str> = world
                    .objects
                    .iter()
                    .map(|o| o.name.as_str())
                    .filter(|n| !n.is_empty())
                    .collect();
                format!(
                    "no world object \"{name}\" to place on; the world's objects: {}",
                    names.join(", ")
                )
            })?;
        let mut poses = Vec::new();
        sim.object_poses_into(&mut poses);
        let pose = poses.get(index).copied().unwrap_or(Pose::IDENTITY);
        let half_height = match world.objects[index].shape {
            Shape::Box { size_m } => size_m.z / 2.0,
            Shape::Sphere { radius_m } => radius_m,
            Shape::Cylinder { length_m, .. } => length_m / 2.0,
            Shape::Capsule {
                radius_m, length_m, ..
            } => radius_m + length_m / 2.0,
            Shape::Mesh { .. } => 0.0,
        };
        let t = pose.translation;
        Ok(Some([
            f64::from(t.x),
            f64::from(t.y),
            f64::from(t.z + half_height),
        ]))
    }
}

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
/// limit, as Franka's and the arm car's fingers are).
fn find_gripper(sim: &Simulation) -> Result<Gripper, String> {
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
    Ok(Gripper {
        controller: spec.0,
        joint,
        open,
        closed,
    })
}
