//! The arm's tasks in a session, switched on and off like the follower: **look** (the camera's
//! chain turns so the chosen detection's box centre comes to the image centre) and **reach**
//! (the tool goes to a pre-grasp point short of it, the camera's own chain looking at it when
//! that chain is not the arm's). Both act on detector messages only, with the depth image and
//! the robot's joint states of the image the message came from (kept for the last few images).

use nalgebra::Vector3;
use rover_perception::BoundingBoxes;
use rover_sim::{
    geometry::Pose,
    model::{
        CameraConfig, ChainJoint, EntityIds, IkSolver, IkTarget, KinematicChain, KinematicsError,
        LinkId, isometry_from_pose, link_from_optical,
    },
    physics::{JointCommand, Simulation},
    sensors::CameraFrame,
};

use super::depth::DepthView;
use super::look::{Look, LookConfig};
use super::pick::{Pick, PickConfig, PickState};
use super::reach::{Reach, ReachConfig, ReachState, ReachStep};

/// A tool point whose arm comes this close (m) to anything is refused (touching counts).
const TOOL_CONTACT_M: f32 = 0.001;

/// How many recent images are kept for detections still to come.
const FRAMES: usize = 8;

/// Which links the arm's tasks use and how they behave. The default looks at and reaches for
/// the same class, `sports ball`.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmConfig {
    /// The arm's base link (IK and points are in its frame); `None`: the world's `[robot]
    /// arm_base`, else the robot's root link.
    pub base_link: Option<String>,
    /// The end effector (the tool that reaches); `None`: the world's `[robot] ee_link`, else
    /// no reach.
    pub ee_link: Option<String>,
    /// A MoveIt SRDF whose planning group gives the base and end effector when they are not
    /// given ([`rover_sim::description::load_arm_group`]); `None`: the world's `[robot] srdf`.
    pub srdf: Option<std::path::PathBuf>,
    /// Which SRDF group is the arm (`None`: the world's `[robot] arm_group`, else `arm`, else
    /// the only group).
    pub group: Option<String>,
    /// Look settings (its class is the one looked at).
    pub look: LookConfig,
    /// Reach settings (its class is the one reached for).
    pub reach: ReachConfig,
    /// Pick-and-place settings (its class is the one picked).
    pub pick: PickConfig,
}

/// What the arm is doing on its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ArmMode {
    /// Nothing: it takes commands (keys, scripts, ROS).
    #[default]
    Off,
    /// Looking at the class.
    Look,
    /// Reaching for the class.
    Reach,
    /// Picking the class up and putting it on the place.
    Pick,
}

impl ArmMode {
    /// `off`, `look`, `reach` or `pick`.
    pub fn as_str(self) -> &'static str {
        match self {
            ArmMode::Off => "off",
            ArmMode::Look => "look",
            ArmMode::Reach => "reach",
            ArmMode::Pick => "pick",
        }
    }
}

/// The arm's task as observers see it (HUD, Rerun, ROS).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ArmStatus {
    /// Which task runs.
    pub mode: ArmMode,
    /// What the reach is doing (meaningful in [`ArmMode::Reach`]).
    pub reach: ReachState,
    /// What the pick is doing (meaningful in [`ArmMode::Pick`]).
    pub pick: PickState,
    /// The object point reached for, world frame (m).
    pub object_world_m: Option<[f64; 3]>,
    /// The pre-grasp goal, world frame (m).
    pub goal_world_m: Option<[f64; 3]>,
    /// The tool, world frame (m).
    pub tool_world_m: Option<[f64; 3]>,
    /// The object is hidden by the robot's own links (reach and pick go on with their last
    /// estimate).
    pub hidden: bool,
}

impl Default for ArmConfig {
    fn default() -> Self {
        let reach = ReachConfig::default();
        Self {
            base_link: None,
            ee_link: None,
            srdf: None,
            group: None,
            look: LookConfig {
                class: reach.class.clone(),
                ..LookConfig::default()
            },
            pick: PickConfig {
                class: reach.class.clone(),
                ..PickConfig::default()
            },
            reach,
        }
    }
}

impl ArmConfig {
    /// The config looking at, reaching for and picking `class` (`--arm-class`).
    pub fn with_class(mut self, class: &str) -> Self {
        class.clone_into(&mut self.look.class);
        class.clone_into(&mut self.reach.class);
        class.clone_into(&mut self.pick.class);
        self
    }

    /// The config with the SRDF's planning group (here or in the world's `[robot]`) read into
    /// the base and end effector not given; an error for an SRDF that cannot be read or has no
    /// such group (file and line, the groups it has).
    pub fn resolved(
        &self,
        robot: &rover_sim::model::RobotModel,
        spawn: &rover_sim::model::RobotSpawn,
    ) -> Result<Self, rover_sim::SimError> {
        let mut out = self.clone();
        let Some(srdf) = self.srdf.as_ref().or(spawn.srdf.as_ref()) else {
            return Ok(out);
        };
        let group_name = self.group.as_deref().or(spawn.arm_group.as_deref());
        let group = rover_sim::description::load_arm_group(srdf, robot, group_name)?;
        tracing::info!(
            "arm: SRDF group \"{}\": {} -> {}",
            group.name,
            group.base_link,
            group.tip_link
        );
        let explicit_base = self.base_link.is_some() || spawn.arm_base.is_some();
        let explicit_tip = self.ee_link.is_some() || spawn.ee_link.is_some();
        if !explicit_base {
            out.base_link = Some(group.base_link);
        }
        if !explicit_tip {
            out.ee_link = Some(group.tip_link);
        }
        Ok(out)
    }
}

impl ArmStatus {
    /// The running task's own state (`moving`, `carrying`, ...): reach's or pick's; `None`
    /// for look or off.
    pub fn task_state(&self) -> Option<&'static str> {
        match self.mode {
            ArmMode::Reach => Some(self.reach.as_str()),
            ArmMode::Pick => Some(self.pick.as_str()),
            ArmMode::Off | ArmMode::Look => None,
        }
    }

    /// How far the tool is from the pre-grasp goal (m), once there is one.
    pub fn tool_to_goal_m(&self) -> Option<f64> {
        let (t, g) = (self.tool_world_m?, self.goal_world_m?);
        Some(((t[0] - g[0]).powi(2) + (t[1] - g[1]).powi(2) + (t[2] - g[2]).powi(2)).sqrt())
    }
}

/// One image as the tasks need it later.
#[derive(Debug, Clone)]
struct FrameRecord {
    seq: u64,
    depth_m: Vec<f32>,
    /// Per pixel, whether it shows the robot (empty: the frame had no id image).
    robot_px: Vec<bool>,
    width: u32,
    height: u32,
    /// The optical frame in the arm's base frame.
    base_from_optical: nalgebra::Isometry3<f64>,
    /// The arm's base in the world when the image was taken.
    world_from_base: nalgebra::Isometry3<f64>,
    /// When the image was taken (s of sim time).
    sim_time_s: f64,
    /// Every joint's position (robot joint order; 0 for joints that do not move).
    q: Vec<f64>,
}

/// The session's arm tasks.
#[derive(Debug)]
pub(crate) struct ArmTask {
    mode: ArmMode,
    base_link: LinkId,
    camera_link: LinkId,
    look: Result<Look, String>,
    reach: Result<Reach, String>,
    pick: Result<Pick, String>,
    /// The end effector moved to points (scripts, Cartesian jogging).
    tool: Result<IkSolver, String>,
    /// The planning scene a tool point is checked in (built at the first point).
    tool_scene: Option<rover_sim::planning::PlanningScene>,
    /// In reach mode the camera's chain looks too, when it shares no joint with the arm.
    look_while_reaching: bool,
    frames: Vec<FrameRecord>,
    /// Every joint's position (robot order), and one chain's (chain order): scratch buffers.
    q: Vec<f64>,
    chain_q: Vec<f64>,
    status: ArmStatus,
}

impl ArmTask {
    /// The tasks for `sim`'s robot seeing through `camera` (the session's camera, if any).
    /// What cannot be built is kept as the reason, said when the task is switched on.
    pub(crate) fn new(sim: &Simulation, camera: Option<&CameraConfig>, config: &ArmConfig) -> Self {
        let robot = sim.robot();
        let spawn = &sim.world().robot;
        let root = &robot.links[robot.root.index()].name;
        let base_name = (config.base_link.as_ref())
            .or(spawn.arm_base.as_ref())
            .unwrap_or(root);
        let ee_link = config.ee_link.as_ref().or(spawn.ee_link.as_ref());
        let base_link = robot.link_id(base_name).unwrap_or(robot.root);
        let camera_link = camera
            .and_then(|c| robot.link_id(&c.link))
            .unwrap_or(robot.root);
        let no_camera = || "the robot has no camera running".to_owned();
        let look = camera.ok_or_else(no_camera).and_then(|c| {
            Look::new(robot, c, base_name, config.look.clone()).map_err(|e| e.to_string())
        });
        let reach = match (camera, ee_link) {
            (None, _) => Err(no_camera()),
            (Some(c), _) if c.depth.is_none() => Err(format!(
                "camera \"{}\" renders no depth (reach needs a <sensor type=\"depth\">)",
                c.name
            )),
            (Some(_), None) => Err(
                "no end effector given (--ee-link LINK, or ee_link in the world's [robot])"
                    .to_owned(),
            ),
            (Some(c), Some(ee)) => {
                Reach::new(robot, c, base_name, ee, config.reach.clone()).map_err(|e| e.to_string())
            }
        };
        // A named object is taken by its known pose: no camera needed.
        let by_name = config.pick.object.is_some() || spawn.pick.is_some();
        let pick = match (camera, ee_link) {
            (_, Some(ee)) if by_name => Pick::new(sim, camera, base_name, ee, config.pick.clone()),
            (Some(c), Some(ee)) if c.depth.is_some() => {
                Pick::new(sim, Some(c), base_name, ee, config.pick.clone())
            }
            _ => Err(reach
                .as_ref()
                .err()
                .cloned()
                .unwrap_or_else(|| "no depth camera or end effector".to_owned())),
        };
        let tool = ee_link
            .ok_or_else(|| {
                "no end effector given (--ee-link LINK, or ee_link in the world's [robot])"
                    .to_owned()
            })
            .and_then(|ee| {
                KinematicChain::new(robot, base_name, ee)
                    .and_then(|chain| IkSolver::new(chain, super::reach::arm_ik_options()))
                    .map_err(|e| e.to_string())
            });
        let look_while_reaching = match (&look, &reach) {
            (Ok(look), Ok(reach)) => look
                .joints()
                .iter()
                .all(|j| reach.joints().iter().all(|r| r.id != j.id)),
            _ => false,
        };
        Self {
            mode: ArmMode::Off,
            base_link,
            camera_link,
            look,
            reach,
            pick,
            tool,
            tool_scene: None,
            look_while_reaching,
            frames: Vec::new(),
            q: Vec::with_capacity(robot.joints.len()),
            chain_q: Vec::with_capacity(robot.joints.len()),
            status: ArmStatus::default(),
        }
    }

    /// The status for observers.
    pub(crate) fn status(&self) -> ArmStatus {
        self.status
    }

    /// Whether the end effector can be moved to points.
    pub(crate) fn has_tool(&self) -> bool {
        self.tool.is_ok()
    }

    /// Moves the end effector to `position_m` (arm base frame), or by it from where the joints'
    /// targets put it (`relative`), by IK from those targets. Why not, when it cannot: no end
    /// effector, a point out of reach (by more than 1 cm), a value that is not finite.
    pub(crate) fn move_tool(
        &mut self,
        position_m: [f64; 3],
        relative: bool,
        sim: &mut Simulation,
    ) -> Result<(), String> {
        let solver = self.tool.as_mut().map_err(|e| format!("no tool: {e}"))?;
        if !position_m.iter().all(|v| v.is_finite()) {
            return Err(format!("tool: {position_m:?} is not a finite point"));
        }
        let q: Vec<f64> = solver
            .chain()
            .joints()
            .iter()
            .map(|j| {
                sim.joint_target(j.id)
                    .or_else(|| sim.joint_state(j.id).map(|s| s.position))
                    .unwrap_or(0.0)
            })
            .collect();
        let [x, y, z] = position_m;
        let mut goal = Vector3::new(x, y, z);
        if relative {
            goal += solver
                .chain()
                .base_from_tip(&q)
                .map_err(|e| e.to_string())?
                .translation
                .vector;
        }
        let solution = solver
            .solve(&IkTarget::point(goal), &q)
            .map_err(|e| e.to_string())?;
        if solution.position_error_m > 0.01 {
            return Err(format!(
                "tool: ({:.3}, {:.3}, {:.3}) m in {} is out of reach by {:.3} m",
                goal.x,
                goal.y,
                goal.z,
                solver.chain().base_name(),
                solution.position_error_m
            ));
        }
        // A point inside something: the arm would have to go through it.
        let scene = match &mut self.tool_scene {
            Some(scene) => {
                sim.refresh_planning_scene(scene);
                scene
            }
            None => self.tool_scene.insert(
                sim.planning_scene(solver.chain(), TOOL_CONTACT_M)
                    .map_err(|e| e.to_string())?,
            ),
        };
        if let Some(hit) = scene.collision(&solution.q) {
            return Err(format!(
                "tool: ({:.3}, {:.3}, {:.3}) m in {} is refused: there, {hit}",
                goal.x,
                goal.y,
                goal.z,
                solver.chain().base_name()
            ));
        }
        command(sim, solver.chain().joints(), &solution.q);
        Ok(())
    }

    /// The reach controller, when the robot has one.
    pub(crate) fn reach(&self) -> Option<&Reach> {
        self.reach.as_ref().ok()
    }

    /// The mode a toggle of `mode` leads to: `mode`, or off when it runs.
    pub(crate) fn toggled(&self, mode: ArmMode) -> ArmMode {
        if self.mode == mode {
            ArmMode::Off
        } else {
            mode
        }
    }
}

// Switching tasks, and what each image, detector message and control update does for them.
impl ArmTask {
    /// Switches to `next` (the arm stops where it is); the text for the event log, or why it
    /// cannot run (a warning; nothing changes). Setting the mode that runs starts it afresh.
    pub(crate) fn set(&mut self, next: ArmMode, sim: &mut Simulation) -> Result<String, String> {
        match next {
            ArmMode::Look => {
                self.look.as_ref().map_err(|e| format!("no look: {e}"))?;
            }
            ArmMode::Reach => {
                self.reach.as_ref().map_err(|e| format!("no reach: {e}"))?;
            }
            ArmMode::Pick => {
                let pick = self.pick.as_ref().map_err(|e| format!("no pick: {e}"))?;
                pick.check(sim).map_err(|e| format!("no pick: {e}"))?;
            }
            ArmMode::Off => {}
        }
        // Whatever was going on stops where it is.
        self.hold(sim);
        if let Ok(reach) = self.reach.as_mut() {
            reach.reset();
        }
        if let Ok(pick) = self.pick.as_mut() {
            pick.reset();
        }
        self.mode = next;
        self.status = ArmStatus {
            mode: next,
            ..ArmStatus::default()
        };
        if self.frames.is_empty() && next != ArmMode::Off {
            self.frames = vec![
                FrameRecord {
                    seq: u64::MAX,
                    depth_m: Vec::new(),
                    robot_px: Vec::new(),
                    width: 0,
                    height: 0,
                    base_from_optical: nalgebra::Isometry3::identity(),
                    world_from_base: nalgebra::Isometry3::identity(),
                    sim_time_s: 0.0,
                    q: Vec::new(),
                };
                FRAMES
            ];
        }
        Ok(format!("arm: {}", next.as_str()))
    }

    /// Why `mode` cannot run with a detector that knows `labels` (empty: none runs, nothing
    /// to check): its class is not one of them. The message names the nearest classes.
    pub(crate) fn unknown_class(
        &self,
        mode: ArmMode,
        labels: &[String],
        sim: &Simulation,
    ) -> Option<String> {
        // A task that cannot be built says so when switched on ([`Self::set`]).
        let class = match mode {
            ArmMode::Off => return None,
            ArmMode::Look => &self.look.as_ref().ok()?.config().class,
            ArmMode::Reach => &self.reach.as_ref().ok()?.config().class,
            ArmMode::Pick => {
                let pick = self.pick.as_ref().ok()?;
                if pick.known_object(sim).is_some() {
                    return None;
                }
                &pick.config().class
            }
        };
        if labels.is_empty() || labels.iter().any(|l| l == class) {
            return None;
        }
        let mut near: Vec<(f64, &String)> = labels
            .iter()
            .map(|l| {
                let shared = l.split(' ').any(|w| class.split(' ').any(|c| c == w));
                let score = strsim::jaro_winkler(l, class) + if shared { 1.0 } else { 0.0 };
                (score, l)
            })
            .collect();
        near.sort_by(|a, b| b.0.total_cmp(&a.0));
        // Those sharing a word with it, else the three most alike.
        let sharing = near.iter().filter(|(score, _)| *score >= 1.0).count();
        let shown = if sharing > 0 { sharing.min(3) } else { 3 };
        let nearest: Vec<String> = (near.iter().take(shown))
            .map(|(_, l)| format!("\"{l}\""))
            .collect();
        Some(format!(
            "arm: {} stays off: \"{class}\" is not a class the detector knows ({} classes); the nearest: {}",
            mode.as_str(),
            labels.len(),
            nearest.join(", ")
        ))
    }

    /// Whether a task runs that needs the camera's id image (the robot's own pixels).
    pub(crate) fn wants_robot_pixels(&self) -> bool {
        matches!(self.mode, ArmMode::Reach | ArmMode::Pick)
    }

    /// Keeps what a camera image's detections will need: its depth, which pixels are the
    /// robot's, where the camera was and the joints' positions (only while a task runs).
    pub(crate) fn capture(&mut self, frame: &CameraFrame<'_>, sim: &Simulation) {
        if self.mode == ArmMode::Off {
            return;
        }
        let Some(slot) = self.frames.get_mut(frame.seq as usize % FRAMES) else {
            return;
        };
        slot.seq = frame.seq;
        slot.width = frame.width;
        slot.height = frame.height;
        slot.depth_m.clear();
        slot.depth_m
            .extend_from_slice(frame.depth_m.unwrap_or_default());
        slot.robot_px.clear();
        if let Some(image) = frame.entities {
            // The depth image is the ideal pinhole one: so are the robot's pixels.
            let ids = if image.distorted {
                &image.ideal_ids
            } else {
                &image.ids
            };
            (slot.robot_px).extend(ids.iter().map(|&id| id == EntityIds::ROBOT));
        }
        let base_from_camera =
            sim.world_from_link(self.base_link).inverse() * sim.world_from_link(self.camera_link);
        slot.base_from_optical =
            isometry_from_pose(&(base_from_camera * Pose::from_rotation(link_from_optical())));
        slot.world_from_base = isometry_from_pose(&sim.world_from_link(self.base_link));
        slot.sim_time_s = sim.sim_time_s();
        joint_positions(sim, &mut slot.q);
    }

    /// A detector message: the tasks' joint targets go to the simulation. Errors are the
    /// chain's (they cannot happen for a chain built from this robot).
    pub(crate) fn observe(
        &mut self,
        boxes: &BoundingBoxes,
        sim: &mut Simulation,
    ) -> Result<(), KinematicsError> {
        if self.mode == ArmMode::Off {
            return Ok(());
        }
        let seq = boxes.image_stamp.frame;
        let Some(record) = self
            .frames
            .get(seq as usize % FRAMES)
            .filter(|r| r.seq == seq)
        else {
            return Ok(());
        };
        let looking = self.mode == ArmMode::Look || self.look_while_reaching;
        if looking && let Ok(look) = self.look.as_mut() {
            chain_positions(look.joints(), &record.q, &mut self.chain_q);
            if let Some(targets) = look.observe(boxes, &self.chain_q)? {
                command(sim, look.joints(), &targets);
            }
        }
        if self.mode == ArmMode::Pick
            && let Ok(pick) = self.pick.as_mut()
        {
            let view = DepthView {
                depth_m: &record.depth_m,
                width: record.width,
                height: record.height,
                base_from_optical: record.base_from_optical,
                robot_px: &record.robot_px,
            };
            pick.observe(
                boxes,
                &view,
                (&record.world_from_base, record.sim_time_s),
                sim,
            );
        }
        if self.mode == ArmMode::Reach
            && let Ok(reach) = self.reach.as_mut()
        {
            joint_positions(sim, &mut self.q);
            chain_positions(reach.joints(), &self.q, &mut self.chain_q);
            let view = DepthView {
                depth_m: &record.depth_m,
                width: record.width,
                height: record.height,
                base_from_optical: record.base_from_optical,
                robot_px: &record.robot_px,
            };
            match reach.observe(boxes, &view, &self.chain_q)? {
                ReachStep::Keep => {}
                ReachStep::Move(targets) => command(sim, reach.joints(), &targets),
                ReachStep::Hold => command(sim, reach.joints(), &self.chain_q),
            }
        }
        Ok(())
    }

    /// After a control update: the pick's steps, the reach's arrival and the status's world
    /// points.
    pub(crate) fn update(&mut self, sim: &mut Simulation) -> Result<(), KinematicsError> {
        if self.mode == ArmMode::Pick {
            return self.update_pick(sim);
        }
        if self.mode != ArmMode::Reach {
            return Ok(());
        }
        let Ok(reach) = self.reach.as_mut() else {
            return Ok(());
        };
        joint_positions(sim, &mut self.q);
        chain_positions(reach.joints(), &self.q, &mut self.chain_q);
        let tool = reach.update_tool(&self.chain_q)?;
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base_link));
        let world = |p: Vector3<f64>| {
            let w = world_from_base * nalgebra::Point3::from(p);
            [w.x, w.y, w.z]
        };
        self.status = ArmStatus {
            mode: self.mode,
            reach: reach.state(),
            object_world_m: reach.object_m().map(world),
            goal_world_m: reach.goal_m().map(world),
            tool_world_m: Some(world(tool)),
            hidden: reach.hidden(),
            ..ArmStatus::default()
        };
        Ok(())
    }

    /// The pick's step and status.
    fn update_pick(&mut self, sim: &mut Simulation) -> Result<(), KinematicsError> {
        let Ok(pick) = self.pick.as_mut() else {
            return Ok(());
        };
        pick.update(sim);
        joint_positions(sim, &mut self.q);
        chain_positions(pick.joints(), &self.q, &mut self.chain_q);
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base_link));
        let world = |p: Vector3<f64>| {
            let w = world_from_base * nalgebra::Point3::from(p);
            [w.x, w.y, w.z]
        };
        let tool = self
            .tool
            .as_ref()
            .ok()
            .map(|t| t.chain().base_from_tip(&self.chain_q))
            .transpose()?
            .map(|p| world(p.translation.vector));
        self.status = ArmStatus {
            mode: self.mode,
            pick: pick.state(),
            object_world_m: pick.object().map(|(p, _)| world(p)),
            tool_world_m: tool,
            hidden: pick.hidden(),
            ..ArmStatus::default()
        };
        Ok(())
    }

    /// What the pick has to say since the last call: (warning, text).
    pub(crate) fn drain_said(&mut self, mut f: impl FnMut(bool, String)) {
        if let Ok(pick) = self.pick.as_mut() {
            for (warn, text) in pick.drain_said() {
                f(warn, text);
            }
        }
    }

    /// What the pick tells the base this control update (`fetch`), while pick is on.
    pub(crate) fn base_command(&self) -> Option<rover_sim::physics::Twist> {
        if self.mode != ArmMode::Pick {
            return None;
        }
        self.pick.as_ref().ok().and_then(Pick::base_command)
    }

    /// Stops a fetch's pick, saying `why`.
    pub(crate) fn stop_fetch(&mut self, why: &str) {
        if let Ok(pick) = self.pick.as_mut() {
            pick.stop(why);
        }
    }

    /// The pick controller, when the robot has one.
    pub(crate) fn pick(&self) -> Option<&Pick> {
        self.pick.as_ref().ok()
    }

    /// Tells the tasks' joints to stay where they are.
    fn hold(&mut self, sim: &mut Simulation) {
        joint_positions(sim, &mut self.q);
        let joints = match self.mode {
            ArmMode::Off => return,
            ArmMode::Look => self.look.as_ref().map(|l| l.joints()).unwrap_or_default(),
            ArmMode::Reach => self.reach.as_ref().map(|r| r.joints()).unwrap_or_default(),
            ArmMode::Pick => self.pick.as_ref().map(|p| p.joints()).unwrap_or_default(),
        };
        chain_positions(joints, &self.q, &mut self.chain_q);
        command(sim, joints, &self.chain_q);
    }
}

/// Every joint's position now (robot joint order; 0 for a joint that does not move).
fn joint_positions(sim: &Simulation, out: &mut Vec<f64>) {
    out.clear();
    out.extend(
        sim.robot()
            .joint_ids()
            .map(|(id, _)| sim.joint_state(id).map_or(0.0, |s| s.position)),
    );
}

/// A chain's joints' positions (chain order) out of every joint's (robot order), into `out`.
fn chain_positions(joints: &[ChainJoint], all: &[f64], out: &mut Vec<f64>) {
    out.clear();
    out.extend(
        joints
            .iter()
            .map(|j| all.get(j.id.index()).copied().unwrap_or(0.0)),
    );
}

/// Position commands to a chain's `joints`; a joint without an actuator is skipped (logged at
/// debug level: the chain's passive joints follow the others).
fn command(sim: &mut Simulation, joints: &[ChainJoint], targets: &[f64]) {
    for (joint, q) in joints.iter().zip(targets) {
        if let Err(e) = sim.command_joint(&joint.name, JointCommand::Position(*q)) {
            tracing::debug!("arm: {e}");
        }
    }
}
