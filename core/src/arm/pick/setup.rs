//! Building a pick, starting it afresh or stopping it, and what it reports (its state, the
//! object, the last plan, what it has to say).

use std::collections::VecDeque;

use nalgebra::{Point3, Vector3};
use rover_sim::{
    model::{
        CameraConfig, CameraInfo, ChainJoint, IkOptions, IkSolver, JointKind, KinematicChain,
        LinkId, isometry_from_pose,
    },
    physics::Simulation,
};

use super::config::PickConfig;
use super::fetch::DriveTo;
use super::state::{Finger, Gripper, Pick, PickState};

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
            taken: None,
            squeeze_n: 0.0,
            stance: None,
            last_seen: None,
            hidden: false,
            unseen: 0,
            state: PickState::Seeking,
            steps: VecDeque::new(),
            running: None,
            object: None,
            planning_s: None,
            path_points: None,
            q: Vec::new(),
            v: Vec::new(),
            said: Vec::new(),
            drive: DriveTo::default(),
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

    /// Whether the object it looks for is hidden by the robot's own links (not detected, the
    /// robot covering where it was last seen): the sightings so far stand.
    pub fn hidden(&self) -> bool {
        self.hidden && matches!(self.state, PickState::Seeking | PickState::Fetching)
    }

    /// Waypoints of the last plan's joint-space paths (to the pre-grasp, the carry, home; 0
    /// for a leg without one): 2 is a straight joint move, more goes round something.
    pub fn path_points(&self) -> Option<[usize; 3]> {
        self.path_points
    }

    /// The settings.
    pub fn config(&self) -> &PickConfig {
        &self.config
    }

    /// Why the pick cannot start in `sim`, if it cannot: a place that is not in the world.
    pub fn check(&self, sim: &Simulation) -> Result<(), String> {
        self.place_under(sim).map(|_| ())
    }

    /// Starts afresh.
    pub fn reset(&mut self) {
        self.sightings.clear();
        self.last_seen = None;
        self.hidden = false;
        self.unseen = 0;
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
        self.stance = None;
    }

    /// What it has to say since the last call: (warning, text).
    pub fn drain_said(&mut self) -> impl Iterator<Item = (bool, String)> + '_ {
        self.said.drain(..)
    }

    /// Stops where it is (the arm holds, the base is left alone), saying `why`.
    pub fn stop(&mut self, why: &str) {
        self.fail(why.to_owned());
    }

    pub(super) fn fail(&mut self, why: String) {
        self.state = PickState::Failed;
        self.steps.clear();
        self.running = None;
        self.leg = None;
        self.base_cmd = None;
        self.said.push((true, format!("pick: {why}")));
    }
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
    let axis = Vector3::new(f64::from(axis.x), f64::from(axis.y), f64::from(axis.z));
    let parent = world_from(finger.parent);
    let tool_from_parent = world_from(tool).inverse() * parent;
    // A sliding finger moves along its axis; a turning one, at the tool point, across the
    // line from its axis to the point.
    let (across_tool, finger) = if matches!(finger.kind, JointKind::Prismatic { .. }) {
        (tool_from_parent.rotation * axis, Finger::Slides)
    } else {
        let origin = finger.parent_from_child.translation;
        let origin = Point3::new(
            f64::from(origin.x),
            f64::from(origin.y),
            f64::from(origin.z),
        );
        let to_tool = tool_from_parent.inverse() * Point3::origin() - origin;
        let arm = to_tool - axis * axis.dot(&to_tool);
        let motion = tool_from_parent.rotation * axis.cross(&arm);
        let lever_m = arm.norm();
        if lever_m < 1e-3 {
            return Err(format!(
                "finger joint \"{}\" turns about the tool point: no squeeze to give",
                spec.1
            ));
        }
        (motion / lever_m, Finger::Turns { lever_m })
    };
    Ok(Gripper {
        controller: spec.0,
        joint,
        open,
        closed,
        across_tool,
        finger,
    })
}
