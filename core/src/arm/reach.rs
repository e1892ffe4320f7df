//! Reach: the arm's tool goes to a pre-grasp point short of what the detector sees. From
//! perception only: the boxes, the depth image of the same render, where the camera was on the
//! robot when it took the image (the robot's own joint states, as tf gives them), never the
//! object's true pose.
//!
//! Each detector message:
//! 1. every box of the class, confident enough, becomes a point in the arm's base frame: the
//!    object's centre, estimated along its centre pixel's ray. The median depth of the box's
//!    central part (a box's edges hold background) is the surface the camera sees; the centre
//!    lies one radius beyond it, the radius from the box's size at that depth (exact for a
//!    sphere; for other shapes, an object as deep as it is wide);
//! 2. the point nearest the one reached for last (within [`ReachConfig::gate_m`]) is kept, so
//!    a second object does not take over; after [`ReachConfig::forget_after_s`] without it,
//!    the most confident box will do;
//! 3. when that point has moved more than [`ReachConfig::replan_m`] from the one planned for
//!    (or nothing is planned), a new goal: [`ReachConfig::standoff_m`] short of the point,
//!    horizontally along the line from the arm's base, solved by IK ([`IkSolver`]); the
//!    joints get the solution as targets. A goal IK cannot reach within
//!    [`ReachConfig::max_ik_error_m`] is refused (the arm holds);
//! 4. [`ReachConfig::lost_after`] messages in a row without the object: an arm on its way is
//!    told to stay where it is (hold still); one that has arrived holds its targets. Seen
//!    again where it was, the arm goes on; elsewhere, a new goal (3).
//!
//! The robot's own links are filtered out ([`crate::arm::depth`], MoveIt's self filter): their
//! pixels never enter an estimate; a box the robot partly covers keeps the last estimate (its
//! visible part would shift the centre); an object no longer detected where the robot now
//! covers it is *hidden by the robot*, not lost: the arm goes on to the goal it has.

use nalgebra::Vector3;
use rover_perception::BoundingBoxes;
use rover_sim::model::{
    CameraConfig, CameraInfo, ChainJoint, IkOptions, IkSolver, IkTarget, KinematicChain,
    KinematicsError, RobotModel,
};

use super::depth::{DepthView, PARTLY_HIDDEN_SHARE, hidden_by_robot, object_estimate, robot_share};

/// Reach settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ReachConfig {
    /// Class to reach for (darknet_ros `Class`).
    pub class: String,
    /// Minimum detection probability.
    pub min_probability: f64,
    /// How far short of the object's (estimated) centre the tool stops (m).
    pub standoff_m: f64,
    /// The object must move this far (m) before the goal is planned again.
    pub replan_m: f64,
    /// A point further than this (m) from the object reached for is another object, unless it
    /// was not seen for `forget_after_s`.
    pub gate_m: f64,
    /// After this long without the object (s of sim time), any box of the class will do.
    pub forget_after_s: f64,
    /// Detector messages in a row without the object before the arm holds still.
    pub lost_after: u32,
    /// A goal IK reaches no closer than this (m) is refused.
    pub max_ik_error_m: f64,
    /// The tool within this distance (m) of the goal counts as arrived (and as moving again
    /// beyond twice it).
    pub arrived_m: f64,
    /// Depth beyond this (m) is not trusted (no object is that far within an arm's reach).
    pub max_range_m: f64,
}

impl Default for ReachConfig {
    fn default() -> Self {
        Self {
            class: "sports ball".into(),
            min_probability: 0.4,
            standoff_m: 0.10,
            replan_m: 0.03,
            gate_m: 0.30,
            forget_after_s: 3.0,
            lost_after: 2,
            max_ik_error_m: 0.01,
            arrived_m: 0.02,
            max_range_m: 4.0,
        }
    }
}

/// What the reach is doing, as the HUD, Rerun and ROS show it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ReachState {
    /// On, nothing of the class seen yet.
    #[default]
    Seeking,
    /// Moving the tool to the goal.
    Moving,
    /// The tool is at the goal.
    Arrived,
    /// The object is no longer seen: holding still.
    Lost,
    /// The object is seen but the tool cannot get to the goal: holding.
    Unreachable,
}

impl ReachState {
    /// 0 seeking, 1 moving, 2 arrived, 3 lost, 4 unreachable (for plots).
    pub fn index(self) -> usize {
        self as usize
    }

    /// `seeking`, `moving`, `arrived`, `lost` or `unreachable`.
    pub fn as_str(self) -> &'static str {
        match self {
            ReachState::Seeking => "seeking",
            ReachState::Moving => "moving",
            ReachState::Arrived => "arrived",
            ReachState::Lost => "lost",
            ReachState::Unreachable => "unreachable",
        }
    }
}

/// What the arm should do after a detector message.
#[derive(Debug, Clone, PartialEq)]
pub enum ReachStep {
    /// Nothing new: the joints go on to their targets.
    Keep,
    /// New joint targets ([`Reach::joints`] order).
    Move(Vec<f64>),
    /// Stay where the joints are now.
    Hold,
}

/// A goal planned for an object.
#[derive(Debug, Clone, PartialEq)]
struct Goal {
    /// The object point it was planned for (base frame, m).
    object_m: Vector3<f64>,
    /// The pre-grasp point (base frame, m).
    pregrasp_m: Vector3<f64>,
}

/// The reach controller for one arm and one depth camera.
#[derive(Debug, Clone)]
pub struct Reach {
    config: ReachConfig,
    solver: IkSolver,
    /// fx, fy, cx, cy (px).
    intrinsics: [f64; 4],
    /// The object reached for (base frame, m) and when its image was taken (s).
    object: Option<(Vector3<f64>, f64)>,
    /// The object's radius as last estimated (m).
    radius_m: f64,
    /// The object is not detected and the robot's own links cover where it was.
    hidden: bool,
    goal: Option<Goal>,
    missed: u32,
    state: ReachState,
    /// Stopped on its way when the object was lost: seen again, the goal is solved anew.
    stopped: bool,
}

impl Reach {
    /// A reach controller moving the joints between `base_link` and `tool_link` of `robot`,
    /// seeing through `camera` (which must render depth to be of use).
    pub fn new(
        robot: &RobotModel,
        camera: &CameraConfig,
        base_link: &str,
        tool_link: &str,
        config: ReachConfig,
    ) -> Result<Self, KinematicsError> {
        let chain = KinematicChain::new(robot, base_link, tool_link)?;
        let info = CameraInfo::from_config(camera);
        Ok(Self {
            config,
            solver: IkSolver::new(chain, arm_ik_options())?,
            intrinsics: [info.k[0], info.k[4], info.k[2], info.k[5]],
            object: None,
            radius_m: 0.0,
            hidden: false,
            goal: None,
            missed: 0,
            state: ReachState::Seeking,
            stopped: false,
        })
    }

    /// The settings.
    pub fn config(&self) -> &ReachConfig {
        &self.config
    }

    /// The joints it moves, base to tool.
    pub fn joints(&self) -> &[ChainJoint] {
        self.solver.chain().joints()
    }

    /// The arm's chain.
    pub fn chain(&self) -> &KinematicChain {
        self.solver.chain()
    }

    /// What it is doing.
    pub fn state(&self) -> ReachState {
        self.state
    }

    /// Whether the object is hidden by the robot's own links (not detected, the robot covering
    /// where it was): the arm goes on with its last estimate.
    pub fn hidden(&self) -> bool {
        self.hidden
    }

    /// The object point reached for (base frame, m), once seen.
    pub fn object_m(&self) -> Option<Vector3<f64>> {
        self.object.map(|(p, _)| p)
    }

    /// The pre-grasp point the tool is sent to (base frame, m), once planned.
    pub fn goal_m(&self) -> Option<Vector3<f64>> {
        self.goal.as_ref().map(|g| g.pregrasp_m)
    }

    /// Starts afresh (nothing seen, nothing planned).
    pub fn reset(&mut self) {
        self.object = None;
        self.hidden = false;
        self.goal = None;
        self.missed = 0;
        self.state = ReachState::Seeking;
        self.stopped = false;
    }

    /// Notes where the tool is now (the arm's joint positions, [`Reach::joints`] order): a
    /// moving reach within [`ReachConfig::arrived_m`] of its goal has arrived. Returns the
    /// tool's position (base frame, m).
    pub fn update_tool(&mut self, q: &[f64]) -> Result<Vector3<f64>, KinematicsError> {
        let tool = self.solver.chain().base_from_tip(q)?.translation.vector;
        if let Some(goal) = &self.goal {
            // Arrived within `arrived_m`, moving again only beyond twice that: a tool that
            // settles right at the edge does not flicker between the two.
            let d = (tool - goal.pregrasp_m).norm();
            self.state = match self.state {
                ReachState::Moving if d <= self.config.arrived_m => ReachState::Arrived,
                ReachState::Arrived if d > 2.0 * self.config.arrived_m => ReachState::Moving,
                state => state,
            };
        }
        Ok(tool)
    }

    /// Takes one detector message, the depth image it came from and the arm's joint positions
    /// now ([`Reach::joints`] order): what the joints should do.
    pub fn observe(
        &mut self,
        boxes: &BoundingBoxes,
        view: &DepthView<'_>,
        q: &[f64],
    ) -> Result<ReachStep, KinematicsError> {
        let t = boxes.image_stamp.sim_time_s;
        let Some((point, radius_m)) = self.pick(boxes, view, t) else {
            if let Some((last, _)) = self.object
                && hidden_by_robot(view, self.intrinsics, last, self.radius_m)
            {
                // Behind the arm, not gone: go on to the goal there is.
                self.hidden = true;
                self.missed = 0;
                return Ok(ReachStep::Keep);
            }
            self.hidden = false;
            self.missed = self.missed.saturating_add(1);
            if self.missed == self.config.lost_after && self.state != ReachState::Seeking {
                // An arm on its way stops where it is; one that arrived (or was refused a
                // goal) is holding its targets already.
                self.stopped = self.state == ReachState::Moving;
                self.state = ReachState::Lost;
                if self.stopped {
                    return Ok(ReachStep::Hold);
                }
            }
            return Ok(ReachStep::Keep);
        };
        self.missed = 0;
        self.hidden = false;
        self.object = Some((point, t));
        self.radius_m = radius_m;
        let moved = self
            .goal
            .as_ref()
            .is_none_or(|g| (g.object_m - point).norm() > self.config.replan_m);
        if !moved {
            if self.state == ReachState::Lost {
                // update_tool says whether it is there.
                self.state = ReachState::Moving;
                if std::mem::take(&mut self.stopped) {
                    return Ok(ReachStep::Move(self.solve_current(q)?));
                }
            }
            return Ok(ReachStep::Keep);
        }
        self.stopped = false;
        let pregrasp_m = pregrasp(point, self.config.standoff_m);
        let solution = self.solver.solve(&IkTarget::point(pregrasp_m), q)?;
        self.goal = Some(Goal {
            object_m: point,
            pregrasp_m,
        });
        if solution.position_error_m > self.config.max_ik_error_m {
            tracing::debug!(
                "reach: goal {pregrasp_m:?} out of reach by {:.3} m",
                solution.position_error_m
            );
            self.state = ReachState::Unreachable;
            return Ok(ReachStep::Hold);
        }
        self.state = ReachState::Moving;
        Ok(ReachStep::Move(solution.q))
    }

    /// The current goal solved again from `q` (after holding still).
    fn solve_current(&mut self, q: &[f64]) -> Result<Vec<f64>, KinematicsError> {
        match &self.goal {
            Some(goal) => Ok(self.solver.solve(&IkTarget::point(goal.pregrasp_m), q)?.q),
            None => Ok(q.to_vec()),
        }
    }

    /// The object point and radius of the box to reach for in this message, if any. A box the
    /// robot partly covers gives the last estimate (when it is that object) rather than its
    /// own.
    fn pick(
        &self,
        boxes: &BoundingBoxes,
        view: &DepthView<'_>,
        t: f64,
    ) -> Option<(Vector3<f64>, f64)> {
        let c = &self.config;
        let keep = self
            .object
            .filter(|(_, seen_s)| t - seen_s <= c.forget_after_s)
            .map(|(p, _)| p);
        boxes
            .bounding_boxes
            .iter()
            .filter(|b| b.class == c.class && b.probability >= c.min_probability)
            .filter_map(|b| {
                let (p, r) = object_estimate(b, view, self.intrinsics, c.max_range_m)?;
                match keep {
                    Some(last) => {
                        let gap = (p - last).norm();
                        let partly = robot_share(b, view) >= PARTLY_HIDDEN_SHARE;
                        let seen = if partly {
                            (last, self.radius_m)
                        } else {
                            (p, r)
                        };
                        (gap <= c.gate_m).then_some((seen, -gap))
                    }
                    None => Some(((p, r), b.probability)),
                }
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(seen, _)| seen)
    }
}

/// IK settings for an arm moved by perception or by hand: 1 mm is close enough, so a solve from
/// the arm's own pose that gets there is kept rather than restarted from random poses (which
/// could swing the arm into a far-off configuration for a slightly smaller error).
pub(crate) fn arm_ik_options() -> IkOptions {
    IkOptions {
        tolerance_m: 1e-3,
        ..IkOptions::default()
    }
}

/// The pre-grasp point for an object point (base frame): `standoff_m` short of it, along the
/// horizontal line from the base's origin (straight down the base's -x when the object is
/// right above it).
pub fn pregrasp(object_m: Vector3<f64>, standoff_m: f64) -> Vector3<f64> {
    let horizontal = Vector3::new(object_m.x, object_m.y, 0.0);
    let approach = horizontal.try_normalize(1e-9).unwrap_or_else(Vector3::x);
    object_m - standoff_m * approach
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pregrasp_point_is_short_of_the_object_along_the_line_from_the_base() {
        let p = pregrasp(Vector3::new(0.6, 0.8, 0.3), 0.1);
        assert!((p - Vector3::new(0.54, 0.72, 0.3)).norm() < 1e-12, "{p:?}");
        let above = pregrasp(Vector3::new(0.0, 0.0, 0.4), 0.1);
        assert!((above - Vector3::new(-0.1, 0.0, 0.4)).norm() < 1e-12);
    }
}
