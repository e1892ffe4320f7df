//! What a pick is and keeps: [`Pick`] and its [`PickState`], and the plan's parts (steps, the
//! gripper, the target, the ways to take hold, the base's legs) the phase files share.

use std::collections::VecDeque;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};
use rover_sim::{
    model::{IkSolver, IkTarget, JointId, LinkId},
    physics::Twist,
    planning::TimedPath,
};

use super::config::PickConfig;
use super::fetch::DriveTo;

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
pub(super) enum Step {
    /// Follow a timed path.
    Move(TimedPath),
    /// Command the gripper; done when it reached its goal or stalled. `grip`: it must stall
    /// on something.
    Gripper { position: f64, grip: bool },
    /// Wait (s); with the grasp assist, until it holds (or the time is up).
    Wait { s: f64, until_held: bool },
}

/// The joint-space paths of a grasp.
#[derive(Debug)]
pub(super) struct Grasp {
    /// From the start to the pre-grasp.
    pub(super) to_pre: Vec<Vec<f64>>,
    /// Straight in, from the pre-grasp to the grasp.
    pub(super) descent: Vec<Vec<f64>>,
    /// Straight up with the object.
    pub(super) lift: Vec<Vec<f64>>,
    /// How the hand holds it.
    pub(super) way: Way,
}

/// The gripper the pick uses.
#[derive(Debug, Clone)]
pub(super) struct Gripper {
    pub(super) controller: String,
    pub(super) joint: JointId,
    pub(super) open: f64,
    pub(super) closed: f64,
    /// The direction the finger joint moves, in the tool's frame (unit): the fingers close
    /// across it.
    pub(super) across_tool: Vector3<f64>,
    /// How its fingers move.
    pub(super) finger: Finger,
}

/// How a gripper's fingers move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Finger {
    /// Along the joint's axis: the joint's position is the finger's distance from the middle.
    Slides,
    /// About the joint's axis, `lever_m` from the tool point (Stretch's): the tool point sits
    /// between the fingers at 0.
    Turns { lever_m: f64 },
}

impl Finger {
    /// How far the finger is from the middle (m) at joint position `q` (m or rad): a turning
    /// one's lever times the sine of its angle.
    pub(super) fn half_width_m(self, q: f64) -> f64 {
        match self {
            Self::Slides => q.abs(),
            Self::Turns { lever_m } => lever_m * q.abs().min(std::f64::consts::FRAC_PI_2).sin(),
        }
    }

    /// How far from 0 the joint is (m or rad) with the finger `half_m` from the middle (a
    /// turning finger at most a right angle).
    pub(super) fn travel(self, half_m: f64) -> f64 {
        match self {
            Self::Slides => half_m.max(0.0),
            Self::Turns { lever_m } => (half_m / lever_m).clamp(0.0, 1.0).asin(),
        }
    }

    /// Effort per newton of squeeze: 1 for a sliding finger, the lever (m) for a turning one
    /// (a squeeze in newtons is then the joint's torque in N m).
    pub(super) fn effort_per_n(self) -> f64 {
        match self {
            Self::Slides => 1.0,
            Self::Turns { lever_m } => lever_m,
        }
    }
}

impl Gripper {
    /// The joint position (m or rad) at which each finger is `half_m` from the middle, on the
    /// side the hand opens to.
    pub(super) fn joint_at(&self, half_m: f64) -> f64 {
        let wide = if self.open.abs() >= self.closed.abs() {
            self.open
        } else {
            self.closed
        };
        self.finger.travel(half_m).copysign(wide)
    }

    /// Each finger's furthest from the middle (m): half the widest the hand opens.
    pub(super) fn widest_m(&self) -> f64 {
        self.finger
            .half_width_m(self.open)
            .max(self.finger.half_width_m(self.closed))
    }
}

/// What is picked, as the plan needs it (arm base frame, m).
#[derive(Debug, Clone, Copy)]
pub(super) struct Target {
    /// Its centre.
    pub(super) centre: Vector3<f64>,
    /// From its centre down to what it rests on.
    pub(super) half_height_m: f64,
    /// A sphere round it: the hand carries it as this.
    pub(super) bound_m: f64,
    /// A box: its orientation (base frame) and half sizes along its axes; the fingers close
    /// across its x or y faces. `None`: round (any turn of the hand will do).
    pub(super) cuboid: Option<(UnitQuaternion<f64>, [f64; 3])>,
    /// An upright cylinder (a can, a bottle, a cup) of this radius (m): taken across its axis
    /// with the fingers level, carried and set down upright.
    pub(super) upright: Option<f64>,
}

impl Target {
    /// A ball (or anything round) of `radius_m` at `centre`.
    pub(super) fn round(centre: Vector3<f64>, radius_m: f64) -> Self {
        Self {
            centre,
            half_height_m: radius_m,
            bound_m: radius_m,
            cuboid: None,
            upright: None,
        }
    }

    /// An upright cylinder of `radius_m`, `half_height_m` above and below `centre`.
    pub(super) fn upright(centre: Vector3<f64>, radius_m: f64, half_height_m: f64) -> Self {
        Self {
            centre,
            half_height_m,
            bound_m: radius_m.hypot(half_height_m),
            cuboid: None,
            upright: Some(radius_m),
        }
    }

    /// The mean of `seen` (not empty): upright when every one of them is.
    pub(super) fn mean(seen: &[Target]) -> Self {
        let n = seen.len().max(1) as f64;
        let centre = seen.iter().map(|t| t.centre).sum::<Vector3<f64>>() / n;
        let across = seen.iter().map(Target::across_m).sum::<f64>() / n;
        if seen.iter().all(|t| t.upright.is_some()) {
            let half_height_m = seen.iter().map(|t| t.half_height_m).sum::<f64>() / n;
            Self::upright(centre, across, half_height_m)
        } else {
            Self::round(centre, across)
        }
    }

    /// Its size as messages say it: "0.067 m across", or "upright, 0.066 m across, 0.124 m
    /// tall".
    pub(super) fn size_text(&self) -> String {
        match self.upright {
            Some(r) => format!(
                "upright, {:.3} m across, {:.3} m tall",
                2.0 * r,
                2.0 * self.half_height_m
            ),
            None => format!("{:.3} m across", 2.0 * self.bound_m),
        }
    }

    /// Its radius across the fingers for a round or upright object (a box: its bound).
    pub(super) fn across_m(&self) -> f64 {
        self.upright.unwrap_or(self.bound_m)
    }
}

/// One way of taking hold: the tool's z along `along` (the way in), its turn about it fixed
/// by `turn` or free.
#[derive(Debug, Clone)]
pub(super) struct Way {
    /// How a refusal names it.
    pub(super) label: String,
    /// The tool's z axis (base frame, unit).
    pub(super) along: Vector3<f64>,
    /// The tool's whole orientation (base frame), when its turn matters (across a box's
    /// faces).
    pub(super) turn: Option<UnitQuaternion<f64>>,
    /// Each finger's position closed on the object (m from the middle).
    pub(super) grip_m: f64,
    /// Where the tool is from the object's centre (base frame, m): zero but for an upright
    /// object taken from above (near its top, the hand clear of it).
    pub(super) offset: Vector3<f64>,
    /// The hand's turn is the arm's to give, not the plan's: an arm that holds it level
    /// whatever it does (Stretch's lift, telescope and wrist yaw) is given only the point;
    /// `along` and `turn` are what it reached there with ([`Pick::reachable`]).
    pub(super) free: bool,
}

impl Way {
    /// The way of an arm that holds the hand level (see [`Way::free`]): the tool `offset`
    /// from the object's centre, the fingers closing to `grip_m`.
    pub(super) fn level(grip_m: f64, offset: Vector3<f64>) -> Self {
        Self {
            label: "level, turned as the arm reaches".into(),
            along: Vector3::zeros(),
            turn: None,
            grip_m,
            offset,
            free: true,
        }
    }

    /// The IK target for the tool at `point`.
    pub(super) fn target(&self, point: Vector3<f64>) -> IkTarget {
        match self.turn {
            _ if self.free => IkTarget::point(point),
            Some(turn) => IkTarget::pose(&Isometry3::from_parts(Translation3::from(point), turn)),
            None => IkTarget::approach(point, self.along),
        }
    }
}

/// The pick controller for one arm.
#[derive(Debug, Clone)]
pub struct Pick {
    pub(super) config: PickConfig,
    pub(super) solver: IkSolver,
    pub(super) base: LinkId,
    pub(super) tool: LinkId,
    pub(super) gripper: Result<Gripper, String>,
    pub(super) intrinsics: [f64; 4],
    pub(super) sightings: Vec<Target>,
    /// The last sighting taken (centre, world frame, and radius, m).
    pub(super) last_seen: Option<(Vector3<f64>, f64)>,
    /// The object is not detected and the robot's own links cover where it was last seen.
    pub(super) hidden: bool,
    /// Detector messages in a row without the object (since the base last stopped).
    pub(super) unseen: u32,
    pub(super) state: PickState,
    pub(super) steps: VecDeque<(Step, PickState)>,
    /// The step running and when it started (s of sim time).
    pub(super) running: Option<(Step, f64)>,
    /// The object's centre (base frame) and radius, once seen.
    pub(super) object: Option<(Vector3<f64>, f64)>,
    /// Wall-clock seconds the last plan took.
    pub(super) planning_s: Option<f64>,
    /// How the last plan takes hold of the object ([`Way::label`]).
    pub(super) taken: Option<String>,
    /// The gripper's effort closing on it (N or N m): [`PickConfig::squeeze_n`], or
    /// [`PickConfig::squeeze_upright_n`] for an upright object; set by each plan.
    pub(super) squeeze_n: f64,
    /// Waypoints of the last plan's joint-space paths: to the pre-grasp, the carry, home
    /// (2: a straight joint move; more: it goes round something).
    pub(super) path_points: Option<[usize; 3]>,
    pub(super) q: Vec<f64>,
    pub(super) v: Vec<f64>,
    /// What to say next (a warning when `true`).
    pub(super) said: Vec<(bool, String)>,
    /// The base's go-to-point controller (`fetch`).
    pub(super) drive: DriveTo,
    /// Where the base is driving to, while it is.
    pub(super) leg: Option<Leg>,
    /// What the base is told this control update (`fetch`: zero while the arm works).
    pub(super) base_cmd: Option<Twist>,
    /// No sighting from an image taken before this (s of sim time): the base was moving.
    pub(super) settle_until_s: f64,
    /// The object in the hand, to be placed once the base is at the place (`fetch`).
    pub(super) held: Option<Held>,
    /// With no `fetch` point, where the base stands for the leg under way (arm base frame,
    /// x and y, m): chosen from the arm's reachability when the object or the place is out of
    /// reach.
    pub(super) stance: Option<Vector2<f64>>,
}

/// Where the base is driving to.
#[derive(Debug, Clone)]
pub(super) struct Leg {
    /// The point brought to the fetch point (world frame, m): the object's centre, or the
    /// place's point under the object.
    pub(super) goal: Vector3<f64>,
    /// To the place, the object in the hand (else to the object).
    pub(super) to_place: bool,
    /// When the drive started (s of sim time).
    pub(super) started_s: f64,
    /// Backing away first, from where the base was (world x, y, m).
    pub(super) back_from: Option<Vector2<f64>>,
    /// Corners to drive through first, round what stands between (world x, y, m).
    pub(super) via: Vec<Vector2<f64>>,
    /// The heading (world, rad) the base ends at when the stance puts the object beside it
    /// ([`super::ground::beside`]): the base drives to that pose. `None`: the point's range
    /// and bearing from the base decide the drive.
    pub(super) yaw_rad: Option<f64>,
    /// When the drive last asked whether the arm reaches the place from where the base is
    /// (s of sim time): a pose drive to the place stops as soon as it does.
    pub(super) reach_checked_s: f64,
}

/// The object in the hand while the base drives to the place.
#[derive(Debug, Clone)]
pub(super) struct Held {
    /// What it is, as it was taken.
    pub(super) target: Target,
    /// How the hand holds it.
    pub(super) way: Way,
    /// Where the arm goes back to after the place.
    pub(super) home_q: Vec<f64>,
    /// The place ([`Pick::place_under`]): the point under the object (world, m), how high above
    /// it the carry ends, how far the hand then goes straight down.
    pub(super) place: ([f64; 3], f64, f64),
    /// Where on the place it may go (world, m; [`Pick::place_spots`]): the place's point
    /// first. The base need not stop exactly where it was sent: the place's plan takes the
    /// first spot the arm reaches from where it stopped.
    pub(super) spots: Vec<[f64; 3]>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sliding_fingers_width_is_its_position_a_turning_ones_its_levers_sine() {
        let sliding = Finger::Slides;
        assert_eq!(sliding.half_width_m(-0.04), 0.04);
        assert_eq!(sliding.travel(0.03), 0.03);
        assert_eq!(sliding.effort_per_n(), 1.0);
        // Stretch's fingers: 0.6 rad on a 0.1 m lever is 56 mm from the middle, not 0.6 m.
        let turning = Finger::Turns { lever_m: 0.1 };
        assert!((turning.half_width_m(-0.6) - 0.1 * 0.6f64.sin()).abs() < 1e-12);
        let q = turning.travel(0.033);
        assert!((turning.half_width_m(q) - 0.033).abs() < 1e-12, "{q}");
        assert!(q > 0.0 && q < 0.6);
        // Wider than the lever: as far as the finger turns across (a right angle).
        assert!((turning.travel(0.5) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(turning.effort_per_n(), 0.1);
    }
}
