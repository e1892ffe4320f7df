//! The person follower: turns darknet_ros-style detections (and, when the robot has one, 2D laser
//! scans) into cmd_vel. docs/FOLLOWER.md describes it for users.
//!
//! - **Target**: a person of the configured class, picked as the nearest and then kept: each
//!   detection is placed in the odometry frame (range from the box height, or from where the feet
//!   meet the ground when the box is cut off at the top; the robot's pose at the image's time) and
//!   associated with the target when it falls inside a gate around the target's prediction.
//! - **Estimator**: a constant-velocity Kalman filter ([`TargetFilter`]) on the target's position
//!   and velocity, fed by the camera and by laser returns around the prediction (the laser keeps
//!   a close target whose head the low camera cannot see). Its prediction leads moving targets,
//!   centres the gate and aims the search.
//! - **States** ([`FollowState`]): TRACKING (seen lately: steer to centre it, regulate the range
//!   to the standoff, calm inside a deadband), PURSUING (lost: drive to the standoff from where
//!   the track last was, predicted with its velocity for a bounded time, and look there; a close
//!   standing target the camera cannot see whole is finished on the track), SEARCHING (nothing
//!   there on arrival: turn toward the prediction, then sweep; never drives), STALE (detector
//!   messages stopped: stop), NO DETECTOR, WAITING (nothing heard yet).
//! - **Obstacles**: with a laser, commands whose arcs come near a return are replaced by the best
//!   free arc toward the target ([`AvoidConfig::choose`]). Without a laser the follower cannot see obstacles.
//!
//! Pure library code on sim time: no threads, no clocks, no UI, no allocation per update once
//! the buffers have grown.

mod avoid;
mod filter;

use std::collections::VecDeque;

use nalgebra::Matrix2;
use rover_perception::{BoundingBox, BoundingBoxes};
use rover_sim::{CameraInfo, LaserScan, Odometry, Twist, wrap_angle};

pub use avoid::{AvoidConfig, Avoided};
pub use filter::TargetFilter;
use filter::polar_covariance;

/// Follower settings.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowerConfig {
    /// Class to follow (darknet_ros `Class`).
    pub target_class: String,
    /// Minimum detection probability for a new target.
    pub min_probability: f64,
    /// Minimum detection probability for a detection inside the target's gate to keep it
    /// (a person partly out of view scores lower, and is still the same person).
    pub keep_probability: f64,
    /// Distance to keep from the target (m).
    pub standoff_m: f64,
    /// Assumed real height of the target (m), for range from box height.
    pub target_height_m: f64,
    /// Assumed width of the target's box (m: shoulders and arms), for range from box width
    /// when the box is cut off; each target's own width is learned from its whole boxes.
    pub target_width_m: f64,
    /// Forward speed limit (m/s); backing away from a target that comes too close is limited to
    /// 0.6 times this.
    pub max_speed_mps: f64,
    /// Turn rate limit (rad/s).
    pub max_turn_radps: f64,
    /// Linear acceleration limit (m/s^2).
    pub max_accel_mps2: f64,
    /// Angular acceleration limit (rad/s^2).
    pub max_turn_accel_radps2: f64,
    /// Turn rate while searching for a lost target (rad/s).
    pub search_turn_radps: f64,
    /// Stop when the newest detector message is older than this (s of sim time).
    pub stale_after_s: f64,
    /// TRACKING becomes PURSUING when the target has not been seen for this long (s).
    pub lost_after_s: f64,
    /// PURSUING becomes SEARCHING this long after arriving where the target was expected
    /// without seeing it again (s).
    pub reacquire_s: f64,
    /// ... or this long after arriving when the target is a standing person the camera cannot
    /// see whole from the standoff (s): a low camera sees only legs there and detections
    /// flicker; that is no reason to search.
    pub close_hold_s: f64,
    /// A pursuit that has not arrived after this long gives up and searches (s).
    pub pursue_for_s: f64,
    /// A target not seen by the camera for this long is forgotten: the next person of the class
    /// becomes a new target wherever it is (s).
    pub forget_after_s: f64,
    /// Laser returns keep a target only while the camera confirmed it within this long (s).
    pub laser_confirm_s: f64,
    /// Proportional gain from bearing error (rad) to turn rate (rad/s).
    pub turn_gain: f64,
    /// Proportional gain from range error (m) to speed (m/s).
    pub speed_gain: f64,
    /// Lead moving targets by this long (s): aim where the target will be.
    pub lead_s: f64,
    /// At the standoff: range errors within this band (m) and bearings within
    /// [`FollowerConfig::bearing_deadband_rad`] are left alone once settled (hysteresis: calm).
    pub standoff_band_m: f64,
    /// Bearing deadband at rest (rad).
    pub bearing_deadband_rad: f64,
    /// Obstacle avoidance (used when the robot has a laser).
    pub avoid: AvoidConfig,
}

impl Default for FollowerConfig {
    fn default() -> Self {
        Self {
            target_class: "person".into(),
            min_probability: 0.4,
            keep_probability: 0.3,
            standoff_m: 1.5,
            target_height_m: 1.75,
            target_width_m: 0.55,
            max_speed_mps: 0.8,
            max_turn_radps: 1.2,
            max_accel_mps2: 0.8,
            max_turn_accel_radps2: 3.0,
            search_turn_radps: 0.6,
            stale_after_s: 1.0,
            lost_after_s: 0.6,
            reacquire_s: 2.0,
            close_hold_s: 30.0,
            pursue_for_s: 12.0,
            forget_after_s: 8.0,
            laser_confirm_s: 10.0,
            turn_gain: 1.8,
            speed_gain: 0.8,
            lead_s: 0.5,
            standoff_band_m: 0.25,
            bearing_deadband_rad: 0.1,
            avoid: AvoidConfig::default(),
        }
    }
}
/// Where the camera is and how it projects, as the follower needs it: the robot's own
/// camera_info and mount, so a low, pitched, narrow or offset camera works.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraGeometry {
    /// Focal length (px).
    pub fx: f64,
    /// Focal length (px).
    pub fy: f64,
    /// Principal point (px).
    pub cx: f64,
    /// Principal point (px).
    pub cy: f64,
    /// Image width (px).
    pub width_px: f64,
    /// Image height (px).
    pub height_px: f64,
    /// Camera height above the ground (m).
    pub height_m: f64,
    /// Camera position ahead of the base origin (m).
    pub forward_m: f64,
    /// Camera position left of the base origin (m).
    pub left_m: f64,
    /// Where the optical axis points, counter-clockwise from the base's +x (rad).
    pub yaw_rad: f64,
    /// How far the optical axis looks below the horizon (rad; a TurtleBot3's camera: 0.174).
    pub pitch_down_rad: f64,
}

impl CameraGeometry {
    /// From a CameraInfo and the camera's mounting (height above ground, offset ahead of base),
    /// looking straight ahead and level.
    pub fn new(info: &CameraInfo, height_m: f64, forward_m: f64) -> Self {
        Self {
            fx: info.k[0],
            fy: info.k[4],
            cx: info.k[2],
            cy: info.k[5],
            width_px: f64::from(info.width),
            height_px: f64::from(info.height),
            height_m,
            forward_m,
            left_m: 0.0,
            yaw_rad: 0.0,
            pitch_down_rad: 0.0,
        }
    }

    /// How far below the horizon the ray through image row `v` points (rad; negative above).
    fn dip_rad(&self, v: f64) -> f64 {
        ((v - self.cy) / self.fy).atan() + self.pitch_down_rad
    }

    /// Horizontal distance (m) from the camera at which a standing person of `height_m` just
    /// fills the image from its bottom edge to its top edge: nearer, some of them is cut off.
    pub fn whole_view_range_m(&self, height_m: f64) -> f64 {
        let up = -self.dip_rad(0.0);
        let down = self.dip_rad(self.height_px);
        let from_top = if up > 1e-3 {
            (height_m - self.height_m).max(0.0) / up.tan()
        } else {
            f64::INFINITY
        };
        let from_bottom = if down > 1e-3 {
            self.height_m / down.tan()
        } else {
            f64::INFINITY
        };
        from_top.max(from_bottom)
    }
}

/// What the follower is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FollowState {
    /// No detector message yet: holding still.
    #[default]
    Waiting,
    /// No detector (missing model, failure): holding still.
    NoDetector,
    /// Following a target seen lately.
    Tracking,
    /// Target lost: driving to the standoff from where it was last going, looking there.
    Pursuing,
    /// Target lost: turning toward where it is expected, then sweeping on the spot.
    Searching,
    /// Detections are stale: stopped.
    Stale,
}

impl FollowState {
    /// Lower-case name for logs, traces and the HUD.
    pub fn as_str(self) -> &'static str {
        match self {
            FollowState::Waiting => "waiting",
            FollowState::NoDetector => "no_detector",
            FollowState::Tracking => "tracking",
            FollowState::Pursuing => "pursuing",
            FollowState::Searching => "searching",
            FollowState::Stale => "stale",
        }
    }

    /// Every state, in a stable order (for plots: the index is the state's number).
    pub const ALL: [FollowState; 6] = [
        FollowState::Waiting,
        FollowState::NoDetector,
        FollowState::Tracking,
        FollowState::Pursuing,
        FollowState::Searching,
        FollowState::Stale,
    ];

    /// The state's number in [`FollowState::ALL`].
    pub fn index(self) -> usize {
        FollowState::ALL
            .iter()
            .position(|s| *s == self)
            .unwrap_or(0)
    }
}

/// The followed target, in the odometry frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowTarget {
    /// Track id (increments each time a new target is picked).
    pub id: u32,
    /// Position/velocity estimate.
    pub filter: TargetFilter,
    /// Sim time of the image it was last detected in (s).
    pub camera_s: f64,
    /// Sim time it was last seen by the camera or the laser (s).
    pub seen_s: f64,
    /// Range from the camera at the last detection (m).
    pub range_m: f64,
    /// Bearing at the last detection (rad, positive left).
    pub bearing_rad: f64,
    /// Detection probability.
    pub probability: f64,
    /// Whether it was last seen near, centred and too close for the camera to see whole (at the
    /// standoff a low camera sees legs only and detections flicker).
    pub close_and_centred: bool,
    /// The width of its box in the world (m), learned from its whole boxes: the range of a box
    /// cut off at the top or bottom comes from its width.
    pub width_m: f64,
    /// Sim time of the last update after which its estimate walked (faster than
    /// `MOVING_MPS`); None while it has not, or since it was halted.
    pub walked_s: Option<f64>,
}

impl FollowTarget {
    /// Whether the track was walking when last seen (its estimate's own velocity, not the
    /// prediction's, which runs out when the target is lost: that a prediction stopped does
    /// not mean the person did). A track halted because the person was not where the
    /// prediction walked them (see `Follower::note_missed`) stands.
    ///
    /// A walker's estimate dips below walking speed for a moment now and then (each box's range
    /// wanders with the gait: up to 0.6 s at a time with MakeHuman's walking body): it stays a
    /// walker until it has not walked for [`WALKER_HOLD_S`] of the time it was seen.
    pub fn last_seen_walking(&self) -> bool {
        self.walked_s
            .is_some_and(|walked| self.seen_s - walked <= WALKER_HOLD_S)
    }

    /// Notes, after an update at sim time `t_s`, whether the estimate walks.
    fn note_speed(&mut self, t_s: f64) {
        let [vx, vy] = self.filter.velocity_mps();
        if vx.hypot(vy) > MOVING_MPS {
            self.walked_s = Some(self.walked_s.map_or(t_s, |w| w.max(t_s)));
        }
    }

    /// Estimated position now-ish (m, odometry frame): the filter's prediction at `time_s`.
    pub fn position_at(&self, time_s: f64) -> [f64; 2] {
        self.filter
            .predicted_position_m(time_s, PREDICTION_HORIZON_S)
    }
}

/// A walking person is followed at most this much further than the standoff (m).
const MAX_EXTRA_STANDOFF_M: f64 = 1.5;
/// A box edge this close to the image edge (px) is cut off there.
const EDGE_PX: i64 = 2;
/// A box top within this fraction of the image's height of its top border may be cut off
/// there (the detector's edges wander): see `Follower::measure`.
const TOP_EDGE_SLACK: f64 = 0.02;

/// How much less a range from the feet is trusted when the box is cut off at a side of the
/// image (m, 1 sigma): the nearer foot may be the part cut off (with MakeHuman's walking body,
/// a range 0.45 m too far pulled the track off the person).
const SIDE_CUT_FEET_SIGMA_M: f64 = 0.3;
/// How far a walking person's range from one box may be off with their gait (m, 1 sigma):
/// about half a step.
const GAIT_RANGE_SIGMA_M: f64 = 0.15;

/// How quickly a target's learned width follows its whole boxes (fraction per box).
const WIDTH_LEARNING: f64 = 0.2;

/// A person in a detector message, placed in the odometry frame.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    position: [f64; 2],
    /// Bearing from the base's heading (rad, positive left).
    bearing_rad: f64,
    probability: f64,
    seen: Measured,
}

/// What one box says about where a person is.
#[derive(Debug, Clone, Copy)]
struct Measured {
    /// Horizontal range from the camera (m).
    range_m: f64,
    /// Its 1-sigma uncertainty (m): the way it was measured and how far.
    range_sigma_m: f64,
    /// Bearing from the optical axis (rad, positive left).
    bearing_rad: f64,
    /// The box's width in the world (m), when the box is whole.
    width_m: Option<f64>,
}

/// Range (m) and bearing (rad, positive left) of `point` (odometry frame) from a robot at
/// `odom`: where the follower's target or goal is, as the HUD and the scenario probe show it.
pub fn range_bearing_from(odom: Odometry, point: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (point[0] - odom.x_m, point[1] - odom.y_m);
    (dx.hypot(dy), wrap_angle(dy.atan2(dx) - odom.yaw_rad))
}

/// Backing away is limited to this fraction of the forward speed limit.
const REVERSE_FRACTION: f64 = 0.6;
/// A target faster than this is moving (m/s): no calm deadbands, lead it.
const MOVING_MPS: f64 = 0.25;
/// How long after its estimate last walked a track still counts as a walker (s of the time it
/// was seen): see [`FollowTarget::last_seen_walking`].
const WALKER_HOLD_S: f64 = 1.0;
/// A pursuit has arrived when the pursued point is at most this far off the heading (rad) and
/// within the standoff band.
const ARRIVED_BEARING_RAD: f64 = 0.15;
/// How far ahead a lost target's motion is extrapolated (s).
const PREDICTION_HORIZON_S: f64 = 2.0;
/// The detector finds a person reliably while their box is at least this tall (px).
const RELIABLE_BOX_PX: f64 = 100.0;
/// A prediction is in plain view this much beyond where the camera sees a person whole (m) ...
const WHOLE_VIEW_MARGIN_M: f64 = 0.3;
/// ... and this far inside the image's side edges (rad).
const FOV_MARGIN_RAD: f64 = 0.15;
/// Detector messages in a row without a lost target in plain view that halt its track.
const CONTRADICTED_MESSAGES: u32 = 2;
/// Pose history length: enough for a few seconds of control updates at 100 Hz.
const HISTORY: usize = 512;
/// The robot's trail keeps a point every this far (m) ...
const TRAIL_SPACING_M: f64 = 0.05;
/// ... this many of them (20 m of driving).
const TRAIL_POINTS: usize = 400;
/// Backing up without a range sensor needs the ground this far behind the base (m) ...
const REVERSE_LOOK_M: f64 = 0.35;
/// ... to be within this of the trail (m): ground the robot has driven over.
const TRAIL_WIDTH_M: f64 = 0.12;
/// The trail points a camera-only car lines its back up with before backing away: this far
/// from its base (m, nearest and furthest).
const TRAIL_AHEAD_M: [f64; 2] = [0.3, 0.6];
/// Laser returns within this distance of the target's prediction are taken to be the target
/// (m), and returns this close to it are not obstacles.
const LASER_GATE_M: f64 = 0.4;
/// A track the laser picks up again may be this far from the returns (m), at most, and
/// within 3 sigma of its own uncertainty.
const LASER_PICKUP_M: f64 = 2.5;
/// The target's returns are the near surfaces of its legs (the laser sees a skinned person's
/// shins, about 5.5 cm in radius at a scan plane 0.17 m up: docs/WORLDS.md); the centroid of
/// a round leg's visible half is 2r/pi in front of its axis, and the person's centre is between
/// their legs: about this much further than the returns (m).
const BODY_DEPTH_M: f64 = 0.035;
/// Laser returns keep following a target seen this recently (s): a few scans.
const LASER_CONTINUITY_S: f64 = 0.35;
/// Returns further than this from the target's prediction are obstacles (m).
const TARGET_EXCLUSION_M: f64 = 0.6;
/// Obstacles are only considered within this distance of the robot (m).
const OBSTACLE_REACH_M: f64 = 3.0;
/// The way chosen around an obstacle is kept until the avoidance has not steered for this long (s).
const DETOUR_MEMORY_S: f64 = 3.0;
/// Half-width of the line of sight an obstacle must block to hide the target (m).
const OCCLUSION_WIDTH_M: f64 = 0.3;
/// A scan older than this (s) is too old to steer by.
const SCAN_FRESH_S: f64 = 0.5;

/// Where a laser scanner sits on the robot, in the base frame (planar).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LaserMount {
    /// Ahead of the base origin (m).
    pub x_m: f64,
    /// Left of the base origin (m).
    pub y_m: f64,
    /// Yaw of the scan frame relative to the base (rad).
    pub yaw_rad: f64,
}

impl LaserMount {
    /// The planar part of the sensor's pose in the base frame.
    pub fn from_base_from_laser(base_from_laser: rover_sim::Pose) -> Self {
        Self {
            x_m: f64::from(base_from_laser.translation.x),
            y_m: f64::from(base_from_laser.translation.y),
            yaw_rad: wrap_angle(rover_sim::yaw_of(base_from_laser.rotation)),
        }
    }
}

/// The follower. Feed it the robot's odometry every control update ([`Follower::record_pose`]),
/// every detector message ([`Follower::observe`]) and laser scan ([`Follower::observe_scan`]),
/// and ask for a command every control update in follow mode ([`Follower::command`]).
#[derive(Debug, Clone)]
pub struct Follower {
    config: FollowerConfig,
    camera: CameraGeometry,
    laser: Option<LaserMount>,
    target: Option<FollowTarget>,
    next_id: u32,
    last_message_s: Option<f64>,
    last_cmd: Twist,
    last_cmd_s: Option<f64>,
    state: FollowState,
    /// (sim time, odometry) of recent control updates, oldest first.
    poses: VecDeque<(f64, Odometry)>,
    /// Which way to sweep when searching (+1 left, -1 right).
    search_sign: f64,
    /// Whether the search is still turning to face the prediction (before it sweeps).
    search_facing: bool,
    /// Where the robot has been (odometry frame, m): every [`TRAIL_SPACING_M`], the last
    /// [`TRAIL_POINTS`].
    trail: VecDeque<[f64; 2]>,
    /// The newest scan's returns in the odometry frame, and its time.
    returns_odom: Vec<[f64; 2]>,
    scan_s: Option<f64>,
    /// Obstacles in the base frame for this update (scratch, reused).
    obstacles_base: Vec<[f64; 2]>,
    /// Hysteresis at the standoff.
    range_settled: bool,
    heading_settled: bool,
    /// What the avoidance did at the last update.
    avoided: Option<Avoided>,
    /// The way around the current obstacle (+1 left, -1 right, 0 none) and when the avoidance
    /// last steered (s).
    detour_side: f64,
    detour_s: f64,
    /// When the current pursuit started and when it arrived at the pursued point (s).
    pursuit_since_s: f64,
    arrived_s: Option<f64>,
    /// The point driven to at the last command (odometry frame, m).
    goal: Option<[f64; 2]>,
    /// From how far the camera sees a person of the target height whole (m, from the camera).
    whole_view_m: f64,
    /// Up to how far the detector finds a person reliably (m, from the camera): their box is
    /// [`RELIABLE_BOX_PX`] tall there.
    reliable_range_m: f64,
    /// Half the camera's horizontal field of view, on its narrower side (rad).
    half_fov_rad: f64,
    /// Detector messages in a row that did not show a lost target where its prediction put it
    /// in plain view.
    contradictions: u32,
}

impl Follower {
    /// A follower for a camera with this geometry (no laser).
    pub fn new(config: FollowerConfig, camera: CameraGeometry) -> Self {
        let whole_view_m = camera.whole_view_range_m(config.target_height_m);
        let reliable_range_m = camera.fy * config.target_height_m / RELIABLE_BOX_PX;
        let half_fov_rad = (camera.cx.min(camera.width_px - camera.cx) / camera.fx)
            .atan()
            .max(0.0);
        Self {
            config,
            camera,
            laser: None,
            target: None,
            next_id: 0,
            last_message_s: None,
            last_cmd: Twist::ZERO,
            last_cmd_s: None,
            state: FollowState::Waiting,
            poses: VecDeque::with_capacity(HISTORY),
            trail: VecDeque::with_capacity(TRAIL_POINTS),
            search_sign: 1.0,
            search_facing: false,
            returns_odom: Vec::new(),
            scan_s: None,
            obstacles_base: Vec::new(),
            range_settled: false,
            heading_settled: false,
            avoided: None,
            detour_side: 0.0,
            detour_s: f64::NEG_INFINITY,
            pursuit_since_s: 0.0,
            arrived_s: None,
            goal: None,
            whole_view_m,
            reliable_range_m,
            half_fov_rad,
            contradictions: 0,
        }
    }

    /// Uses a laser mounted here: its scans keep the target and steer around obstacles.
    pub fn with_laser(mut self, mount: LaserMount) -> Self {
        self.laser = Some(mount);
        self
    }

    /// The settings.
    pub fn config(&self) -> &FollowerConfig {
        &self.config
    }

    /// What the follower is doing.
    pub fn state(&self) -> FollowState {
        self.state
    }

    /// The current target, if any.
    pub fn target(&self) -> Option<&FollowTarget> {
        self.target.as_ref()
    }

    /// Whether the follower has a laser to see obstacles with.
    pub fn has_laser(&self) -> bool {
        self.laser.is_some()
    }

    /// What the obstacle avoidance did at the last command (None without a fresh scan).
    pub fn avoidance(&self) -> Option<Avoided> {
        self.avoided
    }

    /// Forgets the target and the command history (call when follow mode is entered). The pose
    /// history stays: it is recorded in every mode.
    pub fn reset(&mut self) {
        self.target = None;
        self.last_cmd = Twist::ZERO;
        self.last_cmd_s = None;
        self.state = FollowState::Waiting;
        self.range_settled = false;
        self.heading_settled = false;
        self.avoided = None;
        self.detour_side = 0.0;
        self.arrived_s = None;
        self.goal = None;
        self.contradictions = 0;
    }

    /// Records the robot's odometry at a control update. Call it at every control update in
    /// every mode: detections are placed with the pose at their image's time.
    pub fn record_pose(&mut self, now_s: f64, odom: Odometry) {
        if self.poses.back().is_some_and(|(t, _)| *t >= now_s) {
            return;
        }
        if self.poses.len() == HISTORY {
            self.poses.pop_front();
        }
        self.poses.push_back((now_s, odom));
        let here = [odom.x_m, odom.y_m];
        if self
            .trail
            .back()
            .is_none_or(|p| (p[0] - here[0]).hypot(p[1] - here[1]) >= TRAIL_SPACING_M)
        {
            if self.trail.len() == TRAIL_POINTS {
                self.trail.pop_front();
            }
            self.trail.push_back(here);
        }
    }

    /// Whether the ground [`REVERSE_LOOK_M`] behind the base is ground the robot has driven
    /// over (within [`TRAIL_WIDTH_M`] of its trail): the only ground a robot without a range
    /// sensor knows to be free behind it.
    fn driven_behind(&self, odom: Odometry) -> bool {
        let (s, c) = odom.yaw_rad.sin_cos();
        let behind = [odom.x_m - REVERSE_LOOK_M * c, odom.y_m - REVERSE_LOOK_M * s];
        self.trail
            .iter()
            .any(|p| (p[0] - behind[0]).hypot(p[1] - behind[1]) <= TRAIL_WIDTH_M)
    }

    /// Range (m, horizontal, from the camera) and bearing (rad, positive left, from the
    /// camera's optical axis) of a box, for a person of the configured height and width.
    pub fn range_bearing(&self, b: &BoundingBox) -> (f64, f64) {
        let seen = self.measure(b, self.config.target_width_m);
        (seen.range_m, seen.bearing_rad)
    }

    /// Where a box puts a person whose box is `width_m` wide in the world.
    ///
    /// Range: for a whole box, from the person's height between the rays through its top and
    /// bottom (exact for a pitched camera too). For a box cut off at the top or bottom (a low
    /// camera near a person sees the torso or the legs), from where the feet meet the ground
    /// (the camera's height and pitch) when the box's bottom is below the horizon, else from
    /// its width. A box whose bottom is above the horizon (legs hidden) takes its range from
    /// the top of the head.
    fn measure(&self, b: &BoundingBox, width_m: f64) -> Measured {
        let c = &self.camera;
        let u = (b.xmin + b.xmax) as f64 / 2.0;
        let (top, bottom) = (b.ymin as f64, b.ymax as f64);
        // The ray through the box's bottom centre, turned from the optical frame into a level
        // frame: forward is the axis tipped by the pitch.
        let (x_right, y_down) = ((u - c.cx) / c.fx, (bottom - c.cy) / c.fy);
        let (sp, cp) = c.pitch_down_rad.sin_cos();
        let forward = cp - sp * y_down;
        let bearing_rad = (-x_right).atan2(forward.max(1e-6));
        // Rows and columns measure depth along the optical axis: a person off the axis is
        // further than that.
        let off_axis = bearing_rad.cos().max(0.2);
        let up = -c.dip_rad(top);
        let down = c.dip_rad(bottom);
        let span = up.tan() + down.tan();
        let from_height = (span > 1e-6).then(|| self.config.target_height_m / span);
        let clipped_bottom = bottom >= c.height_px - 1.0 - EDGE_PX as f64;
        let clipped_side = b.xmin <= EDGE_PX || b.xmax as f64 >= c.width_px - 1.0 - EDGE_PX as f64;
        let width_px = (b.xmax - b.xmin).max(1) as f64;
        let from_width = (!clipped_side).then(|| c.fx * width_m / width_px);
        let from_feet =
            (!clipped_bottom && down > (1.0 / c.fy).atan()).then(|| c.height_m / down.tan());
        // A detector's box edge at the image's border wanders a few pixels: a top edge near
        // the top border is cut off there when, at the range the feet give, the head would be
        // above the image (taking it for the head put a person 1.6 m away at 3 m).
        let head_out_of_view = from_feet.is_some_and(|d| {
            let head_up = ((self.config.target_height_m - c.height_m) / d).atan();
            head_up > -c.dip_rad(0.0)
        });
        let clipped_top =
            b.ymin <= EDGE_PX || (head_out_of_view && top <= TOP_EDGE_SLACK * c.height_px);
        // A bottom edge above the horizon is not a person's feet (the camera is above the
        // ground): something hides their legs, and the top of their head gives the range.
        let feet_hidden = down <= 0.0 && !clipped_top;
        let from_head = (feet_hidden && up > 1e-3)
            .then(|| (self.config.target_height_m - c.height_m).max(0.1) / up.tan());
        let whole = !clipped_top && !clipped_bottom && !feet_hidden;
        // Each way's 1-sigma error (m) at depth d: a box edge is good to ~2 px; people's
        // heights vary by ~5%, and how wide they look by far more (arms, turned sideways).
        let pixel_rad = 2.0 / c.fy;
        let (depth_m, sigma_m) = match (whole, from_height, from_feet, from_head, from_width) {
            (true, Some(d), ..) => (
                d,
                0.05 + 0.05 * d + d * d * pixel_rad / self.config.target_height_m,
            ),
            // A box's bottom below the horizon is the feet (the hem of a torso box is above a
            // low camera): the feet are exact, the width depends on how the person stands.
            // A box cut off at a side may have lost the nearer foot: the bottom is then the
            // other one's, up to a step further.
            (false, _, Some(d), ..) => (
                d,
                0.05 + d * d * pixel_rad / c.height_m.max(0.05)
                    + if clipped_side {
                        SIDE_CUT_FEET_SIGMA_M
                    } else {
                        0.0
                    },
            ),
            (false, _, None, Some(d), _) => (
                d,
                0.05 + 0.1 * d + d * d * pixel_rad / self.config.target_height_m,
            ),
            (false, _, None, None, Some(d)) => (d, 0.05 + 0.3 * d),
            _ => {
                let d = from_height
                    .unwrap_or(self.config.standoff_m)
                    .min(self.config.standoff_m);
                (d, 0.05 + 0.5 * d)
            }
        };
        let range_m = depth_m / off_axis;
        Measured {
            range_m,
            range_sigma_m: sigma_m / off_axis,
            bearing_rad,
            // The width a whole, uncut box shows, for boxes cut off later.
            width_m: (whole && !clipped_side).then(|| width_px * depth_m / c.fx),
        }
    }

    /// Takes one detector message (possibly with no boxes: darknet_ros' ObjectCount = 0).
    pub fn observe(&mut self, message: &BoundingBoxes) {
        let t_image = message.image_stamp.sim_time_s;
        self.last_message_s = Some(self.last_message_s.map_or(t_image, |t| t.max(t_image)));
        let Some(pose) = self.pose_at(t_image) else {
            return;
        };
        let (sin, cos) = pose.yaw_rad.sin_cos();
        let (ahead, left) = (self.camera.forward_m, self.camera.left_m);
        let camera_x = pose.x_m + cos * ahead - sin * left;
        let camera_y = pose.y_m + sin * ahead + cos * left;
        let camera_yaw = pose.yaw_rad + self.camera.yaw_rad;
        let keep = self
            .target
            .as_ref()
            .filter(|t| t_image - t.camera_s < self.config.forget_after_s);
        // People of the target class in this message, placed in the odometry frame (a kept
        // target's boxes measured with its own learned width). Weaker detections only keep a
        // target.
        let this: &Self = self;
        let width_m = keep.map_or(this.config.target_width_m, |t| t.width_m);
        let floor = if keep.is_some() {
            this.config
                .keep_probability
                .min(this.config.min_probability)
        } else {
            this.config.min_probability
        };
        let candidates = move |floor: f64, width_m: f64| {
            message
                .bounding_boxes
                .iter()
                .filter(move |b| b.class == this.config.target_class && b.probability >= floor)
                .map(move |b| {
                    let seen = this.measure(b, width_m);
                    let heading = camera_yaw + seen.bearing_rad;
                    Candidate {
                        position: [
                            camera_x + seen.range_m * heading.cos(),
                            camera_y + seen.range_m * heading.sin(),
                        ],
                        bearing_rad: wrap_angle(heading - pose.yaw_rad),
                        probability: b.probability,
                        seen,
                    }
                })
        };
        // Best candidate: inside the gate around the target's prediction (nearest to it), or,
        // with no target to keep, the nearest person.
        let mut best: Option<(f64, Candidate)> = None;
        for c in candidates(floor, width_m) {
            let score = match keep {
                Some(t) => {
                    let expected = t.position_at(t_image);
                    let gap = (c.position[0] - expected[0]).hypot(c.position[1] - expected[1]);
                    let unseen_s = (t_image - t.seen_s).max(0.0);
                    // The gate: the person's size, twice the range's uncertainty, and how far
                    // they may have walked unseen.
                    let gate = (0.5 + 2.0 * c.seen.range_sigma_m + 0.5 * unseen_s).min(2.0);
                    if gap > gate {
                        continue;
                    }
                    gap
                }
                None => c.seen.range_m,
            };
            if best.as_ref().is_none_or(|(s, _)| score < *s) {
                best = Some((score, c));
            }
        }
        let mut keeping = keep.is_some();
        if best.is_none()
            && keep.is_some_and(|t| t_image - t.camera_s > self.config.laser_confirm_s)
        {
            // The camera has not confirmed the target for long (the laser alone kept it) and
            // now sees people elsewhere: trust the camera, take the nearest as a new target.
            keeping = false;
            best = candidates(self.config.min_probability, self.config.target_width_m)
                .min_by(|a, b| a.seen.range_m.total_cmp(&b.seen.range_m))
                .map(|c| (c.seen.range_m, c));
        }
        let Some((_, c)) = best else {
            self.note_missed(t_image, [camera_x, camera_y], camera_yaw);
            return;
        };
        self.contradictions = 0;
        self.fold_in(t_image, pose.yaw_rad, keeping, &c);
    }

    /// A detector message without the target. A walking target last estimated nearer than
    /// the camera sees a person whole (a low camera's blind zone), whose prediction has walked
    /// them out to where the camera would see them whole and in view, did not go there: they
    /// stopped or turned in the blind zone. After [`CONTRADICTED_MESSAGES`] such messages in a
    /// row the track halts at its last estimate (the nearer choice), so a pursuit does not
    /// drive past a person who stopped.
    fn note_missed(&mut self, t_image: f64, camera_xy: [f64; 2], camera_yaw_rad: f64) {
        let Some(t) = self.target.as_mut() else {
            return;
        };
        let [vx, vy] = t
            .filter
            .predicted_velocity_mps(t_image, PREDICTION_HORIZON_S);
        let from_camera = |p: [f64; 2]| {
            let (dx, dy) = (p[0] - camera_xy[0], p[1] - camera_xy[1]);
            (dx.hypot(dy), wrap_angle(dy.atan2(dx) - camera_yaw_rad))
        };
        let (last_m, _) = from_camera(t.filter.position_m());
        let (range_m, bearing_rad) = from_camera(t.position_at(t_image));
        let in_plain_view = range_m >= self.whole_view_m + WHOLE_VIEW_MARGIN_M
            && range_m <= self.reliable_range_m
            && bearing_rad.abs() <= self.half_fov_rad - FOV_MARGIN_RAD;
        if vx.hypot(vy) > MOVING_MPS && last_m < self.whole_view_m && in_plain_view {
            self.contradictions += 1;
        } else {
            self.contradictions = 0;
        }
        if self.contradictions >= CONTRADICTED_MESSAGES {
            t.filter.halt(t_image);
            t.walked_s = None;
            self.contradictions = 0;
        }
    }

    /// Folds a chosen detection into the target (`keeping`), or makes it a new target.
    fn fold_in(&mut self, t_image: f64, yaw_rad: f64, keeping: bool, c: &Candidate) {
        let (position, range_m, bearing_rad) = (c.position, c.seen.range_m, c.bearing_rad);
        let heading = yaw_rad + bearing_rad;
        // A walking person's feet are up to half a step either side of their centre, and the
        // box's bottom is the nearer foot's: the range wanders with the gait.
        let walking = keeping
            && self
                .target
                .as_ref()
                .is_some_and(FollowTarget::last_seen_walking);
        let range_sigma_m = if walking {
            c.seen.range_sigma_m.hypot(GAIT_RANGE_SIGMA_M)
        } else {
            c.seen.range_sigma_m
        };
        let cov = polar_covariance(heading, range_sigma_m, 0.05 + 0.02 * range_m);
        let near_m = (self.config.standoff_m + 0.8).max(self.whole_view_m + 0.3);
        let close_and_centred = range_m < near_m && bearing_rad.abs() < 0.3;
        // Only confident whole boxes teach the width.
        let learned_width = c
            .seen
            .width_m
            .filter(|_| c.probability >= self.config.min_probability);
        match (keeping, self.target.as_mut()) {
            (true, Some(t)) => {
                t.filter.update(t_image, position, &cov);
                t.note_speed(t_image);
                if (bearing_rad - t.bearing_rad).abs() > 1e-3 {
                    self.search_sign = (bearing_rad - t.bearing_rad).signum();
                }
                t.camera_s = t.camera_s.max(t_image);
                t.seen_s = t.seen_s.max(t_image);
                t.range_m = range_m;
                t.bearing_rad = bearing_rad;
                t.probability = c.probability;
                t.close_and_centred = close_and_centred;
                if let Some(w) = learned_width {
                    t.width_m += WIDTH_LEARNING * (w - t.width_m);
                }
            }
            _ => {
                self.next_id += 1;
                self.target = Some(FollowTarget {
                    id: self.next_id,
                    filter: TargetFilter::new(t_image, position, cov),
                    camera_s: t_image,
                    seen_s: t_image,
                    range_m,
                    bearing_rad,
                    probability: c.probability,
                    close_and_centred,
                    width_m: learned_width.unwrap_or(self.config.target_width_m),
                    walked_s: None,
                });
            }
        }
        if bearing_rad.abs() > 0.2 {
            self.search_sign = bearing_rad.signum();
        }
    }

    /// Takes one laser scan: its returns become the obstacles the next commands avoid, and the
    /// returns around the target's prediction (while the camera confirmed it lately) update the
    /// target. Ignored when the follower has no laser mount.
    pub fn observe_scan(&mut self, scan: &LaserScan) {
        let Some(mount) = self.laser else {
            return;
        };
        let Some(pose) = self.pose_at(scan.stamp_s) else {
            return;
        };
        let (sin, cos) = pose.yaw_rad.sin_cos();
        let laser_x = pose.x_m + cos * mount.x_m - sin * mount.y_m;
        let laser_y = pose.y_m + sin * mount.x_m + cos * mount.y_m;
        let laser_yaw = pose.yaw_rad + mount.yaw_rad;
        self.returns_odom.clear();
        for (i, &r) in scan.ranges_m.iter().enumerate() {
            if !r.is_finite() {
                continue;
            }
            let a = laser_yaw + f64::from(scan.angle_rad(i));
            let r = f64::from(r);
            self.returns_odom
                .push([laser_x + r * a.cos(), laser_y + r * a.sin()]);
        }
        self.scan_s = Some(scan.stamp_s);
        let Some(t) = self.target.as_mut() else {
            return;
        };
        // The laser keeps a target the camera confirmed lately, or one it has been following
        // scan after scan (a person at the standoff, whose head the camera cannot see).
        let continuous = scan.stamp_s - t.seen_s <= LASER_CONTINUITY_S;
        if scan.stamp_s - t.camera_s > self.config.laser_confirm_s && !continuous {
            return;
        }
        let expected = t.position_at(scan.stamp_s);
        // A track the laser follows scan after scan moves little between scans: a tight gate.
        // A track the laser picks up (the camera lost the person on the way in, the pursuit
        // brought them into range) may be off by its own uncertainty: the gate is 3 sigma of
        // the track's covariance (Mahalanobis), long along the camera's line of sight, where
        // its range is weakest (a low camera's foot point moves a few pixels over metres), and
        // narrow across it. Only a compact cluster (a person, not a wall) is taken.
        let picking_up = scan.stamp_s - t.seen_s > LASER_CONTINUITY_S;
        let distance = |p: &[f64; 2]| (p[0] - expected[0]).hypot(p[1] - expected[1]);
        let gate = if picking_up {
            let cov =
                t.filter.position_covariance() + Matrix2::identity() * (LASER_GATE_M / 3.0).powi(2);
            cov.try_inverse()
        } else {
            None
        };
        let sigmas = |p: &[f64; 2]| {
            gate.map_or(f64::INFINITY, |inverse| {
                let d = nalgebra::Vector2::new(p[0] - expected[0], p[1] - expected[1]);
                (d.transpose() * inverse * d)[(0, 0)].max(0.0).sqrt()
            })
        };
        let inside = |p: &[f64; 2]| {
            if picking_up {
                distance(p) <= LASER_PICKUP_M && sigmas(p) <= 3.0
            } else {
                distance(p) <= LASER_GATE_M
            }
        };
        let Some(seed) = self
            .returns_odom
            .iter()
            .filter(|p| inside(p))
            .min_by(|a, b| {
                if picking_up {
                    sigmas(a).total_cmp(&sigmas(b))
                } else {
                    distance(a).total_cmp(&distance(b))
                }
            })
            .copied()
        else {
            return;
        };
        let around = if picking_up { seed } else { expected };
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
        let mut spread_m: f64 = 0.0;
        for p in &self.returns_odom {
            let gap = (p[0] - around[0]).hypot(p[1] - around[1]);
            if gap <= LASER_GATE_M {
                sx += p[0];
                sy += p[1];
                n += 1;
            }
            if gap <= LASER_GATE_M + 0.2 {
                spread_m = spread_m.max(gap);
            }
        }
        if n < 2 || (picking_up && spread_m > LASER_GATE_M) {
            return;
        }
        let (cx, cy) = (sx / n as f64, sy / n as f64);
        let away = (cy - laser_y).atan2(cx - laser_x);
        let centre = [
            cx + BODY_DEPTH_M * away.cos(),
            cy + BODY_DEPTH_M * away.sin(),
        ];
        let cov = Matrix2::identity() * 0.08f64.powi(2);
        t.filter.update(scan.stamp_s, centre, &cov);
        t.note_speed(scan.stamp_s);
        t.seen_s = t.seen_s.max(scan.stamp_s);
    }

    /// The command for this control update at sim time `now_s`, given the robot's odometry
    /// now. `detector_ok` is false when there is no detector (missing model, failure): the
    /// follower then stops.
    pub fn command(&mut self, now_s: f64, odom: Odometry, detector_ok: bool) -> Twist {
        self.record_pose(now_s, odom);
        let dt = self.last_cmd_s.map_or(0.0, |t| (now_s - t).clamp(0.0, 0.1));
        let fresh = self
            .last_message_s
            .is_some_and(|t| now_s - t <= self.config.stale_after_s);
        self.avoided = None;
        let state = if !detector_ok {
            FollowState::NoDetector
        } else if self.last_message_s.is_none() {
            FollowState::Waiting
        } else if !fresh {
            FollowState::Stale
        } else {
            self.follow_state(now_s, odom)
        };
        if state == FollowState::Pursuing && self.state != FollowState::Pursuing {
            self.pursuit_since_s = now_s;
            self.arrived_s = None;
        }
        if state == FollowState::Searching && self.state != FollowState::Searching {
            self.aim_search(now_s, odom);
        }
        self.state = state;
        self.goal = None;
        let wanted = match state {
            FollowState::Tracking | FollowState::Pursuing => self.pursue(now_s, odom, state),
            FollowState::Searching => self.search(now_s, odom),
            _ => Twist::ZERO,
        };
        let cmd = if matches!(state, FollowState::Tracking | FollowState::Pursuing) {
            self.limit(wanted, dt)
        } else if state == FollowState::Searching {
            // Searching never drives: the forward command drops to zero at once.
            Twist::new(0.0, self.limit(wanted, dt).angular_radps)
        } else {
            // Stale or no detector: stop now, no ramp (the wheels' own ramp still applies).
            Twist::ZERO
        };
        self.last_cmd = cmd;
        self.last_cmd_s = Some(now_s);
        cmd
    }

    /// The point the follower is driving to (odometry frame, m): where it aims at the target
    /// while TRACKING, the pursued point while PURSUING; None otherwise.
    pub fn goal_m(&self) -> Option<[f64; 2]> {
        self.goal
    }

    /// TRACKING while the target is seen; once lost, PURSUING until the pursuit arrived and
    /// looked for `reacquire_s` (longer for a close standing target the camera cannot see
    /// whole) or ran out of time; then SEARCHING until it is seen again.
    fn follow_state(&self, now_s: f64, odom: Odometry) -> FollowState {
        let c = &self.config;
        let Some(t) = &self.target else {
            return FollowState::Searching;
        };
        if now_s - t.seen_s <= c.lost_after_s {
            return FollowState::Tracking;
        }
        match self.state {
            FollowState::Searching => FollowState::Searching,
            FollowState::Pursuing => {
                // A close standing target is held on the track; a walker whose prediction
                // ran out is not known to stand: it is looked for briefly, then searched.
                let standing = !t.last_seen_walking();
                let look_s = if t.close_and_centred && standing {
                    c.close_hold_s
                } else {
                    c.reacquire_s
                };
                let done = match self.arrived_s {
                    Some(arrived) => now_s - arrived > look_s,
                    // Behind an obstacle the laser sees: keep going round it until forgotten.
                    None if self.occluded(t.position_at(now_s), now_s, odom) => {
                        now_s - t.seen_s > c.forget_after_s
                    }
                    None => now_s - self.pursuit_since_s > c.pursue_for_s,
                };
                if done {
                    FollowState::Searching
                } else {
                    FollowState::Pursuing
                }
            }
            _ => FollowState::Pursuing,
        }
    }

    /// Whether the laser shows an obstacle on the line of sight from the robot to `target`
    /// (odometry frame): the camera cannot see the target, and the robot should go around.
    fn occluded(&self, target: [f64; 2], now_s: f64, odom: Odometry) -> bool {
        if self.laser.is_none() || self.scan_s.is_none_or(|t| now_s - t > SCAN_FRESH_S) {
            return false;
        }
        let (dx, dy) = (target[0] - odom.x_m, target[1] - odom.y_m);
        let range = dx.hypot(dy);
        if range < 1e-6 {
            return false;
        }
        let (ux, uy) = (dx / range, dy / range);
        self.returns_odom.iter().any(|p| {
            let (px, py) = (p[0] - odom.x_m, p[1] - odom.y_m);
            let along = px * ux + py * uy;
            let across = (py * ux - px * uy).abs();
            along > 0.2 && along < range - TARGET_EXCLUSION_M && across < OCCLUSION_WIDTH_M
        })
    }

    /// TRACKING and PURSUING: face the target (leading it when it moves and is seen) and
    /// regulate the range to the standoff; calm inside the deadbands; around obstacles. While
    /// PURSUING the goal is the track's prediction (bounded in time) and the car backs away
    /// only from a person predicted to walk closer: once at the standoff from it and facing
    /// it, it has arrived and looks.
    fn pursue(&mut self, now_s: f64, odom: Odometry, state: FollowState) -> Twist {
        let Some(t) = &self.target else {
            return Twist::ZERO;
        };
        let c = &self.config;
        let here = t.position_at(now_s);
        let [vx, vy] = t.filter.predicted_velocity_mps(now_s, PREDICTION_HORIZON_S);
        let moving = vx.hypot(vy) > MOVING_MPS;
        let walker = moving || t.last_seen_walking();
        let tracking = state == FollowState::Tracking;
        let lead = if tracking && moving { c.lead_s } else { 0.0 };
        let aim = [here[0] + vx * lead, here[1] + vy * lead];
        self.goal = Some(aim);
        let (range, _) = range_bearing_from(odom, here);
        let (_, bearing) = range_bearing_from(odom, aim);
        let range_error = range - self.keep_range_m(walker);
        if !tracking
            && self.arrived_s.is_none()
            && range_error < c.standoff_band_m
            && bearing.abs() < ARRIVED_BEARING_RAD
        {
            self.arrived_s = Some(now_s);
        }
        // Hysteresis: once centred and at the standoff, stay still until the error is clear.
        if bearing.abs() < 0.03 {
            self.heading_settled = true;
        } else if bearing.abs() > c.bearing_deadband_rad || moving {
            self.heading_settled = false;
        }
        // A walking target's range never settles: its speed is fed forward below, and a
        // car that stops each time the error crosses zero falls behind at every crossing.
        if range_error.abs() < 0.05 && !moving {
            self.range_settled = true;
        } else if range_error.abs() > c.standoff_band_m || moving {
            self.range_settled = false;
        }
        let angular = if self.heading_settled {
            0.0
        } else {
            (c.turn_gain * bearing).clamp(-c.max_turn_radps, c.max_turn_radps)
        };
        let mut speed_cap = 0.0;
        let linear = if !self.range_settled {
            // The target's speed along the line of sight, fed forward: keep up with people
            // walking away, give way to people walking closer (also when the camera lost them
            // close by: the prediction still walks on for a bounded time).
            let (dx, dy) = (here[0] - odom.x_m, here[1] - odom.y_m);
            let radial = if moving && range > 1e-6 {
                (vx * dx + vy * dy) / range
            } else {
                0.0
            };
            // Backing away is for a person who comes too close, not for a standing lost one.
            let reverse = if tracking || moving {
                c.max_speed_mps * REVERSE_FRACTION
            } else {
                0.0
            };
            let law = (c.speed_gain * range_error + radial).clamp(-reverse, c.max_speed_mps);
            speed_cap = law.max(0.0);
            if law >= 0.0 {
                // Drive only while the target is roughly ahead; full speed when centred.
                law * (1.0 - bearing.abs() / 0.8).clamp(0.0, 1.0)
            } else {
                // Back away from a target that comes too close, as far as backing up helps.
                law * bearing.cos().max(0.0)
            }
        } else {
            0.0
        };
        // Without a range sensor, backing up is blind: only over ground already driven.
        let (linear, angular) = if linear < 0.0 && self.laser.is_none() {
            self.give_way_over_trail(odom, linear, angular, bearing)
        } else {
            (linear, angular)
        };
        let preferred = Twist::new(linear, angular);
        self.avoid(preferred, here, speed_cap, now_s, odom)
    }

    /// A camera-only car that should back away from a person coming too close backs only
    /// over ground it has driven over (nothing tells it what else is behind). When its trail
    /// is not straight behind it, it turns toward the heading that puts the trail behind —
    /// as far as keeps the target inside the camera's view — and backs once it is.
    /// `linear` (< 0) and `angular` are what it would do with a free way back; `bearing` is
    /// the target's from the base's heading.
    fn give_way_over_trail(
        &self,
        odom: Odometry,
        linear: f64,
        angular: f64,
        bearing: f64,
    ) -> (f64, f64) {
        let c = &self.config;
        let linear = if self.driven_behind(odom) {
            linear
        } else {
            0.0
        };
        let Some(back_yaw) = self.trail_behind_yaw(odom) else {
            return (linear, angular);
        };
        let target_yaw = odom.yaw_rad + bearing;
        // Turned as far as the target's centre stays in view: a walking person is seen on
        // the image's edge (measured: 20 degrees short of the edge, the walking world's
        // walker came round to 0.56 m before the trail was behind the car). A target lost
        // from view is kept where the camera would see them whole, to find them again
        // (at the edge, Gazebo's actor was lost for 7.6 s on its loop, 2.8 s so).
        let reach = if self.state == FollowState::Tracking {
            self.half_fov_rad
        } else {
            let range_m = self.target.as_ref().map_or(c.standoff_m, |t| t.range_m);
            self.half_fov_rad - (0.5 * c.target_width_m / range_m.max(0.5)).atan()
        };
        let wanted_yaw = target_yaw + wrap_angle(back_yaw - target_yaw).clamp(-reach, reach);
        let turn = wrap_angle(wanted_yaw - odom.yaw_rad);
        let angular = (c.turn_gain * turn).clamp(-c.max_turn_radps, c.max_turn_radps);
        (linear, angular)
    }

    /// The heading (odometry frame, rad) that would put the robot's trail straight behind
    /// it: toward the base from the trail point [`TRAIL_AHEAD_M`] away that lies most nearly
    /// behind it. None when no trail point lies that far away.
    fn trail_behind_yaw(&self, odom: Odometry) -> Option<f64> {
        let rear_yaw = odom.yaw_rad + std::f64::consts::PI;
        self.trail
            .iter()
            .filter_map(|p| {
                let (dx, dy) = (p[0] - odom.x_m, p[1] - odom.y_m);
                let d = dx.hypot(dy);
                (TRAIL_AHEAD_M[0]..=TRAIL_AHEAD_M[1])
                    .contains(&d)
                    .then(|| dy.atan2(dx))
            })
            .min_by(|a, b| {
                wrap_angle(a - rear_yaw)
                    .abs()
                    .total_cmp(&wrap_angle(b - rear_yaw).abs())
            })
            .map(|toward_trail| wrap_angle(toward_trail + std::f64::consts::PI))
    }

    /// The range to keep from the target (m, from the base). A walking person is kept where
    /// the camera sees them whole, unless a laser keeps them at the standoff: a low camera
    /// that closes in on a walking person loses them at every step, and one who walks toward
    /// the car walks into its blind zone unless it gives way. Once they stand, the car closes
    /// in to the standoff.
    fn keep_range_m(&self, moving: bool) -> f64 {
        let c = &self.config;
        if !moving || self.laser.is_some() {
            return c.standoff_m;
        }
        (self.whole_view_m + self.camera.forward_m)
            .clamp(c.standoff_m, c.standoff_m + MAX_EXTRA_STANDOFF_M)
    }

    /// Replaces `preferred` by a free arc when the laser shows an obstacle in its way.
    fn avoid(
        &mut self,
        preferred: Twist,
        target: [f64; 2],
        speed_cap_mps: f64,
        now_s: f64,
        odom: Odometry,
    ) -> Twist {
        let Some(scan_s) = self.scan_s else {
            return preferred;
        };
        if self.laser.is_none() || now_s - scan_s > SCAN_FRESH_S {
            return preferred;
        }
        let (sin, cos) = odom.yaw_rad.sin_cos();
        self.obstacles_base.clear();
        for p in &self.returns_odom {
            if (p[0] - target[0]).hypot(p[1] - target[1]) < TARGET_EXCLUSION_M {
                continue;
            }
            let (dx, dy) = (p[0] - odom.x_m, p[1] - odom.y_m);
            if dx.hypot(dy) > OBSTACLE_REACH_M {
                continue;
            }
            self.obstacles_base
                .push([cos * dx + sin * dy, -sin * dx + cos * dy]);
        }
        let (dx, dy) = (target[0] - odom.x_m, target[1] - odom.y_m);
        let goal = [cos * dx + sin * dy, -sin * dx + cos * dy];
        if now_s - self.detour_s > DETOUR_MEMORY_S {
            self.detour_side = 0.0;
        }
        let out = self.config.avoid.choose(
            preferred,
            goal,
            &self.obstacles_base,
            speed_cap_mps.min(self.config.max_speed_mps),
            self.config.max_turn_radps,
            self.detour_side,
        );
        if out.steering {
            self.detour_s = now_s;
            if self.detour_side == 0.0 && out.cmd.angular_radps.abs() > 0.05 {
                self.detour_side = out.cmd.angular_radps.signum();
            }
        }
        self.avoided = Some(out);
        out.cmd
    }

    /// Sets the sweep direction when a search starts: the way the target was moving around
    /// the robot, else the side it was last seen on.
    fn aim_search(&mut self, now_s: f64, odom: Odometry) {
        self.search_facing = true;
        if let Some(t) = &self.target {
            let here = t.position_at(now_s);
            let [vx, vy] = t.filter.velocity_mps();
            let (dx, dy) = (here[0] - odom.x_m, here[1] - odom.y_m);
            let around = dx * vy - dy * vx;
            if vx.hypot(vy) > 0.2 && around.abs() > 1e-6 {
                self.search_sign = around.signum();
            }
        }
    }

    /// SEARCHING: first face where the target is expected; once facing it (and still nothing),
    /// sweep the way it was going, without turning back. Never drives.
    fn search(&mut self, now_s: f64, odom: Odometry) -> Twist {
        let c = &self.config;
        if self.search_facing
            && let Some(t) = &self.target
        {
            let (_, bearing) = range_bearing_from(odom, t.position_at(now_s));
            if bearing.abs() > 0.15 && now_s - t.seen_s < c.forget_after_s {
                let angular = (c.turn_gain * bearing).clamp(-c.max_turn_radps, c.max_turn_radps);
                return Twist::new(0.0, angular);
            }
        }
        // Facing where it was expected (or nowhere to face): sweep from here on.
        self.search_facing = false;
        Twist::new(0.0, self.search_sign * c.search_turn_radps)
    }

    fn limit(&self, wanted: Twist, dt: f64) -> Twist {
        let c = &self.config;
        // Slowing down (toward zero) may be twice as quick as speeding up: braking for an
        // obstacle must not wait for the ramp.
        // Steering around an obstacle needs the arc it chose, not a slow blend toward it.
        let steering = self.avoided.is_some_and(|a| a.steering);
        let step = |from: f64, to: f64, rate: f64| {
            let slowing = to.abs() < from.abs() && to * from >= 0.0;
            let rate = if slowing || steering {
                2.0 * rate
            } else {
                rate
            };
            from + (to - from).clamp(-rate * dt, rate * dt)
        };
        Twist::new(
            step(
                self.last_cmd.linear_mps,
                wanted.linear_mps,
                c.max_accel_mps2,
            ),
            step(
                self.last_cmd.angular_radps,
                wanted.angular_radps,
                c.max_turn_accel_radps2,
            ),
        )
    }

    /// Odometry at sim time `t` (nearest recorded control update at or before it).
    fn pose_at(&self, t: f64) -> Option<Odometry> {
        let mut found = self.poses.front().map(|(_, o)| *o);
        for (time, odom) in self.poses.iter().rev() {
            if *time <= t + 1e-9 {
                found = Some(*odom);
                break;
            }
        }
        found
    }
}

#[cfg(test)]
#[allow(clippy::expect_used)]
mod tests {
    use super::*;
    use rover_perception::FrameStamp;

    fn camera() -> CameraGeometry {
        CameraGeometry {
            fx: 381.36,
            fy: 381.36,
            cx: 320.5,
            cy: 240.5,
            width_px: 640.0,
            height_px: 480.0,
            height_m: 0.18,
            forward_m: 0.15,
            left_m: 0.0,
            yaw_rad: 0.0,
            pitch_down_rad: 0.0,
        }
    }

    fn person_box(range_m: f64, bearing_rad: f64) -> BoundingBox {
        let c = camera();
        let along = range_m * bearing_rad.cos();
        let u = c.cx - c.fx * bearing_rad.tan();
        let h = c.fy * 1.75 / along;
        let feet = c.cy + c.fy * 0.18 / along;
        BoundingBox {
            class: "person".into(),
            probability: 0.8,
            xmin: (u - h * 0.15) as i64,
            ymin: (feet - h) as i64,
            xmax: (u + h * 0.15) as i64,
            ymax: feet as i64,
            id: 0,
        }
    }

    fn message(t: f64, boxes: Vec<BoundingBox>) -> BoundingBoxes {
        BoundingBoxes {
            image_stamp: FrameStamp {
                sim_time_s: t,
                frame: (t * 30.0) as u64,
            },
            frame_id: "camera_link_optical".into(),
            bounding_boxes: boxes,
            latency_ms: 0.0,
        }
    }

    #[test]
    fn range_and_bearing_come_back_from_a_projected_box() {
        let f = Follower::new(FollowerConfig::default(), camera());
        for (range, bearing) in [(3.0, 0.0), (5.0, 0.3), (2.0, -0.4)] {
            let (r, b) = f.range_bearing(&person_box(range, bearing));
            assert!((r - range).abs() < 0.05 * range, "{r} vs {range}");
            assert!((b - bearing).abs() < 0.01, "{b} vs {bearing}");
        }
        // Cut off at the top: the feet give the range.
        let mut clipped = person_box(1.5, 0.0);
        clipped.ymin = 0;
        let (r, _) = f.range_bearing(&clipped);
        assert!((r - 1.5).abs() < 0.1, "{r}");
    }

    #[test]
    fn range_from_the_feet_honours_a_pitched_camera() {
        // A TurtleBot3-like camera: 0.15 m up, looking 0.174 rad down. Feet at 2 m dip
        // atan(0.15 / 2) below the horizon, so atan(0.15 / 2) - 0.174 below the optical axis.
        let pitched = CameraGeometry {
            height_m: 0.15,
            pitch_down_rad: 0.174,
            ..camera()
        };
        let f = Follower::new(FollowerConfig::default(), pitched);
        for range in [1.5f64, 2.0, 3.0] {
            let dip = (0.15 / range).atan() - 0.174;
            let feet = pitched.cy + pitched.fy * dip.tan();
            let clipped = BoundingBox {
                class: "person".into(),
                probability: 0.8,
                xmin: 300,
                ymin: 0,
                xmax: 340,
                ymax: feet.round() as i64,
                id: 0,
            };
            let (r, _) = f.range_bearing(&clipped);
            assert!((r - range).abs() < 0.1 * range, "{r} vs {range}");
        }
    }

    #[test]
    fn approaches_a_centred_target_and_stops_at_the_standoff() {
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(4.0, 0.0)]));
        let mut cmd = Twist::ZERO;
        for i in 1..200 {
            cmd = f.command(i as f64 * 0.01, odom, true);
            f.observe(&message(i as f64 * 0.01, vec![person_box(4.0, 0.0)]));
        }
        assert_eq!(f.state(), FollowState::Tracking);
        assert!(
            (cmd.linear_mps - FollowerConfig::default().max_speed_mps).abs() < 0.01,
            "{cmd:?}"
        );
        assert!(cmd.angular_radps.abs() < 0.01, "{cmd:?}");
        // At the standoff it holds still.
        let mut f = Follower::new(FollowerConfig::default(), camera());
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(1.5 - 0.15, 0.0)]));
        let cmd = f.command(0.01, odom, true);
        assert!(cmd.linear_mps.abs() < 0.01, "{cmd:?}");
    }

    #[test]
    fn acceleration_is_limited() {
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(6.0, 0.5)]));
        let cmd = f.command(0.01, odom, true);
        assert!(cmd.linear_mps <= FollowerConfig::default().max_accel_mps2 * 0.01 + 1e-9);
        assert!(cmd.angular_radps <= 3.0 * 0.01 + 1e-9 && cmd.angular_radps > 0.0);
    }

    #[test]
    fn keeps_the_same_target_among_several_people() {
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        // The nearer one is picked first...
        f.observe(&message(
            0.0,
            vec![person_box(5.0, 0.3), person_box(3.0, -0.3)],
        ));
        let first = f.target().expect("target").clone();
        assert!(first.bearing_rad < 0.0);
        // ...and kept when the other comes a little nearer.
        f.command(0.1, odom, true);
        f.observe(&message(
            0.1,
            vec![person_box(2.9, 0.3), person_box(3.05, -0.3)],
        ));
        let t = f.target().expect("target");
        assert_eq!(t.id, first.id);
        assert!(t.bearing_rad < 0.0);
    }

    #[test]
    fn searches_toward_where_the_target_went_and_stops_when_stale() {
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let mut odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(3.0, -0.5)]));
        // Lost: empty messages keep coming (past the pursuit and the look around).
        let mut cmd = Twist::ZERO;
        for i in 1..=1000 {
            let t = i as f64 * 0.01;
            f.observe(&message(t, vec![]));
            cmd = f.command(t, odom, true);
            drive(&mut odom, cmd, 0.01);
        }
        assert_eq!(f.state(), FollowState::Searching);
        assert!(
            cmd.angular_radps < 0.0,
            "sweeps right, the way it went: {cmd:?}"
        );
        assert!(cmd.linear_mps.abs() < 1e-9, "never drives while searching");
        // No messages for more than a second: stop.
        let cmd = f.command(10.0 + 1.01, odom, true);
        assert_eq!(f.state(), FollowState::Stale);
        assert_eq!(cmd, Twist::ZERO);
        // No detector: stop.
        let cmd = f.command(11.1, odom, false);
        assert_eq!(cmd, Twist::ZERO);
        assert_eq!(f.state(), FollowState::NoDetector);
    }

    #[test]
    fn uses_the_pose_at_image_time() {
        // The robot turned 0.3 rad left after the image was taken: the target, dead ahead in
        // the image, is now 0.3 rad to the right.
        let mut f = Follower::new(FollowerConfig::default(), camera());
        f.command(0.0, Odometry::default(), true);
        let turned = Odometry {
            yaw_rad: 0.3,
            ..Odometry::default()
        };
        f.command(0.2, turned, true);
        f.observe(&message(0.0, vec![person_box(4.0, 0.0)]));
        let here = f.target().expect("target").position_at(0.2);
        let (_, bearing) = range_bearing_from(turned, here);
        assert!((bearing + 0.3).abs() < 0.05, "{bearing}");
    }

    #[test]
    fn a_detection_after_follow_off_drive_on_is_placed_with_the_current_pose() {
        // Review fix: poses are recorded in every mode. Follow on, off, drive 2 m forward by
        // hand (the session records poses but asks for no command), on again: a person seen
        // 3 m ahead is 5 m from the start, not 3 m (a phantom at the old pose).
        let mut f = Follower::new(FollowerConfig::default(), camera());
        f.command(0.0, Odometry::default(), true);
        f.reset();
        for i in 1..=200 {
            let t = f64::from(i) * 0.01;
            let odom = Odometry {
                x_m: t,
                ..Odometry::default()
            };
            f.record_pose(t, odom);
        }
        f.reset();
        let now = Odometry {
            x_m: 2.0,
            ..Odometry::default()
        };
        f.observe(&message(2.0, vec![person_box(3.0, 0.0)]));
        let here = f.target().expect("target").position_at(2.0);
        let expected_x = 2.0 + camera().forward_m + 3.0;
        assert!((here[0] - expected_x).abs() < 0.2, "{here:?}");
        f.command(2.01, now, true);
        let cmd = f.command(2.02, now, true);
        assert_eq!(f.state(), FollowState::Tracking);
        assert!(cmd.linear_mps > 0.0, "{cmd:?}");
    }

    #[test]
    fn a_close_centred_target_that_flickers_is_held_not_searched_for() {
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        // At the standoff (1.5 m from the base: the camera is 0.15 m ahead of it), dead ahead,
        // seen once, then only empty messages for 20 s: the pursuit has arrived at once, and
        // a standing person the camera cannot see whole from here is looked at, not searched.
        f.observe(&message(0.0, vec![person_box(1.5 - 0.15, 0.0)]));
        for i in 1..=2000 {
            let t = f64::from(i) * 0.01;
            f.observe(&message(t, vec![]));
            let cmd = f.command(t, odom, true);
            if t > 0.7 {
                assert_eq!(f.state(), FollowState::Pursuing, "at {t}");
            }
            assert!(cmd.angular_radps.abs() < 0.05, "{cmd:?} at {t}");
            assert!(cmd.linear_mps.abs() < 1e-9, "{cmd:?} at {t}");
        }
    }

    /// Moves `odom` by `cmd` for `dt` (a unicycle): the follower's commands take effect.
    fn drive(odom: &mut Odometry, cmd: Twist, dt: f64) {
        odom.yaw_rad += cmd.angular_radps * dt;
        odom.x_m += cmd.linear_mps * odom.yaw_rad.cos() * dt;
        odom.y_m += cmd.linear_mps * odom.yaw_rad.sin() * dt;
    }

    #[test]
    fn a_lost_target_is_pursued_to_where_it_was_then_searched_for() {
        // Seen once 5 m ahead, 0.3 rad left, then never again (hidden): the car drives to the
        // standoff from where it was, looks for `reacquire_s`, and only then searches.
        let config = FollowerConfig::default();
        let mut f = Follower::new(config.clone(), camera());
        let mut odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(5.0, 0.3)]));
        let seen_at = f.target().expect("target").position_at(0.0);
        let mut arrived = None;
        let mut searched_at = None;
        for i in 1..=2000 {
            let t = f64::from(i) * 0.01;
            f.observe(&message(t, vec![]));
            let cmd = f.command(t, odom, true);
            drive(&mut odom, cmd, 0.01);
            match f.state() {
                FollowState::Pursuing => {
                    assert_eq!(f.goal_m(), Some(seen_at), "the pursued point at {t}");
                    let range = (seen_at[0] - odom.x_m).hypot(seen_at[1] - odom.y_m);
                    if arrived.is_none() && range < config.standoff_m + config.standoff_band_m {
                        arrived = Some(t);
                    }
                }
                FollowState::Searching => {
                    searched_at.get_or_insert(t);
                    assert!(cmd.linear_mps.abs() < 1e-9, "never drives while searching");
                }
                other => assert!(t < config.lost_after_s + 0.02, "{other:?} at {t}"),
            }
        }
        let arrived = arrived.expect("the pursuit reaches the standoff");
        let searched_at = searched_at.expect("then it searches");
        let range = (seen_at[0] - odom.x_m).hypot(seen_at[1] - odom.y_m);
        assert!(
            (range - config.standoff_m).abs() < config.standoff_band_m + 0.05,
            "stopped {range} m from where the target was"
        );
        assert!(
            searched_at > arrived && searched_at < arrived + config.reacquire_s + 1.0,
            "arrived at {arrived} s, searched at {searched_at} s"
        );
    }

    #[test]
    fn a_second_person_does_not_take_over_while_the_target_is_lost() {
        // The target (4 m ahead) is lost; 1 s later a second person shows up 2.2 m from where
        // it was, nearer the car: the follower keeps pursuing its own target.
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(4.0, 0.0)]));
        let id = f.target().expect("target").id;
        for i in 1..=200 {
            let t = f64::from(i) * 0.01;
            let boxes = if t > 1.0 {
                vec![person_box(2.5, 0.5)]
            } else {
                vec![]
            };
            f.observe(&message(t, boxes));
            f.command(t, odom, true);
        }
        let t = f.target().expect("target");
        assert_eq!(t.id, id, "a new person took over");
        assert_eq!(f.state(), FollowState::Pursuing);
        assert!(
            t.position_at(2.0)[1].abs() < 0.1,
            "{:?}",
            t.position_at(2.0)
        );
    }

    #[test]
    fn boxes_cut_off_or_hidden_still_give_the_range() {
        let f = Follower::new(FollowerConfig::default(), camera());
        let c = camera();
        // A person 1.3 m away seen by the low camera: the box runs from the image's top edge
        // down to the torso (the legs are not detected), 0.55 m wide: range from the width.
        let depth = 1.3;
        let torso = BoundingBox {
            class: "person".into(),
            probability: 0.5,
            xmin: (c.cx - c.fx * 0.275 / depth) as i64,
            ymin: 0,
            xmax: (c.cx + c.fx * 0.275 / depth) as i64,
            ymax: (c.cy - c.fy * (0.85 - c.height_m) / depth) as i64,
            id: 0,
        };
        let (r, _) = f.range_bearing(&torso);
        assert!((r - depth).abs() < 0.1, "torso box: {r} m");
        // A person 4.5 m away behind a crate: the box ends above the horizon (no feet), so
        // its top (the head) gives the range, not its short height (which said 11 m).
        let depth = 4.5;
        let hidden = BoundingBox {
            ymax: (c.cy - c.fy * (0.5 - c.height_m) / depth) as i64,
            ..person_box(depth, 0.0)
        };
        let (r, _) = f.range_bearing(&hidden);
        assert!((r - depth).abs() < 0.3, "legs hidden: {r} m");
    }

    fn scan_with_person_at(range_m: f32, bearing_rad: f32, t: f64) -> LaserScan {
        // 360 rays; the person's 0.13 m body hides a few of them.
        let mut ranges = vec![f32::INFINITY; 360];
        for (i, r) in ranges.iter_mut().enumerate() {
            let a = (i as f32).to_radians();
            let off = rover_sim::wrap_angle(f64::from(a - bearing_rad)) as f32;
            if (off * range_m).abs() < 0.13 {
                *r = range_m - 0.1;
            }
        }
        LaserScan {
            stamp_s: t,
            seq: 0,
            frame_id: "base_scan".into(),
            angle_min_rad: 0.0,
            angle_max_rad: 359f32.to_radians(),
            angle_increment_rad: 1f32.to_radians(),
            time_increment_s: 0.0,
            scan_time_s: 0.1,
            range_min_m: 0.12,
            range_max_m: 3.5,
            ranges_m: ranges,
        }
    }

    #[test]
    fn laser_returns_keep_a_target_the_camera_no_longer_sees() {
        let mut f =
            Follower::new(FollowerConfig::default(), camera()).with_laser(LaserMount::default());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(2.0, 0.0)]));
        // The person steps 0.5 m to the left over 2 s; only the laser sees it.
        for i in 1..=200 {
            let t = f64::from(i) * 0.01;
            f.observe(&message(t, vec![]));
            if i % 10 == 0 {
                let y = 0.5 * (t / 2.0);
                let range = (2.15f64.powi(2) + y * y).sqrt() as f32;
                let bearing = (y / 2.15).atan() as f32;
                f.observe_scan(&scan_with_person_at(range, bearing, t));
            }
            f.command(t, odom, true);
        }
        assert_eq!(f.state(), FollowState::Tracking);
        let here = f.target().expect("target").position_at(2.0);
        assert!((here[1] - 0.5).abs() < 0.15, "{here:?}");
    }

    #[test]
    fn the_laser_picks_up_a_lost_track_along_the_cameras_line_of_sight() {
        // A track from a far camera box: long along the line of sight (1.1 m sigma), narrow
        // across it (0.14 m). Lost a second ago, it is predicted at `expected`; one compact
        // laser cluster shows a person at `person`.
        let pick_up = |expected: [f64; 2], person: [f64; 2]| {
            let mut f = Follower::new(FollowerConfig::default(), camera())
                .with_laser(LaserMount::default());
            let odom = Odometry::default();
            f.command(0.0, odom, true);
            f.observe(&message(0.0, vec![person_box(2.0, 0.0)]));
            let t = f.target.as_mut().expect("target");
            let cov = Matrix2::new(1.2, 0.0, 0.0, 0.02);
            t.filter = TargetFilter::new(0.0, expected, cov);
            f.observe(&message(1.0, vec![]));
            let range = person[0].hypot(person[1]);
            let bearing = person[1].atan2(person[0]);
            f.observe_scan(&scan_with_person_at(range as f32, bearing as f32, 1.0));
            f.target().expect("target").position_at(1.0)
        };
        // 1.5 m short of the prediction, straight ahead: the camera's range was long. Taken.
        let here = pick_up([4.0, 0.0], [2.5, 0.0]);
        assert!(
            (here[0] - 2.5).abs() < 0.3 && here[1].abs() < 0.1,
            "{here:?}"
        );
        // 1.2 m to the side of the prediction, where the track is certain: not taken.
        let here = pick_up([3.0, 0.0], [3.0, 1.2]);
        assert!(
            (here[0] - 3.0).abs() < 0.1 && here[1].abs() < 0.1,
            "{here:?}"
        );
    }

    /// The box the test camera sees of a person standing at `person` (odometry frame) from a
    /// robot at `odom`, cut off at the image's top edge as a low camera sees a near person.
    fn seen_box(odom: Odometry, person: [f64; 2]) -> BoundingBox {
        let (s, c) = odom.yaw_rad.sin_cos();
        let camera_xy = [
            odom.x_m + c * camera().forward_m,
            odom.y_m + s * camera().forward_m,
        ];
        let (dx, dy) = (person[0] - camera_xy[0], person[1] - camera_xy[1]);
        let mut b = person_box(dx.hypot(dy), wrap_angle(dy.atan2(dx) - odom.yaw_rad));
        b.ymin = b.ymin.max(0);
        b
    }

    #[test]
    fn a_walker_lost_in_the_blind_zone_who_does_not_walk_out_of_it_has_stopped() {
        // The camera sees the person whole from 2.49 m. They walk away at 0.5 m/s from 1.6 m to
        // 2.2 m in front of the camera, seen at 5 Hz, then stop there and are never detected
        // again (a detector's blind spot): their prediction would carry them on into plain view
        // (0.8 m further), where the camera sees nobody. The track stops where it was last.
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        let forward = camera().forward_m;
        for i in 0..=6 {
            let t = f64::from(i) * 0.2;
            f.observe(&message(
                t,
                vec![seen_box(odom, [forward + 1.6 + 0.5 * t, 0.0])],
            ));
            f.command(t + 0.01, odom, true);
        }
        let [vx, _] = f.target().expect("target").filter.velocity_mps();
        assert!(vx > 0.3, "walking away: {vx} m/s");
        for i in 7..=40 {
            let t = f64::from(i) * 0.2;
            f.observe(&message(t, vec![]));
            f.command(t + 0.01, odom, true);
        }
        let t = f.target().expect("target");
        let here = t.position_at(8.0);
        assert!(
            (here[0] - (forward + 2.2)).abs() < 0.25 && here[1].abs() < 0.1,
            "the track should stop near where the person was last seen: {here:?}"
        );
        let [vx, vy] = t.filter.predicted_velocity_mps(8.0, PREDICTION_HORIZON_S);
        assert!(vx.hypot(vy) < 1e-9);

        // A walker lost in plain view (hidden, or gone out of the side) is not taken to have
        // stopped: the prediction walks on for its horizon.
        let mut f = Follower::new(FollowerConfig::default(), camera());
        f.command(0.0, odom, true);
        for i in 0..=6 {
            let t = f64::from(i) * 0.2;
            f.observe(&message(
                t,
                vec![seen_box(odom, [forward + 3.0 + 0.5 * t, 0.0])],
            ));
            f.command(t + 0.01, odom, true);
        }
        for i in 7..=40 {
            let t = f64::from(i) * 0.2;
            f.observe(&message(t, vec![]));
            f.command(t + 0.01, odom, true);
        }
        let here = f.target().expect("target").position_at(8.0);
        assert!(here[0] > forward + 3.6 + 0.5, "{here:?}");
    }

    #[test]
    fn a_walker_at_the_kept_range_is_followed_without_stopping() {
        // A person walks away at 0.4 m/s; the car drives as commanded. Once it has caught up
        // to the range it keeps, the range error crosses zero again and again: the walker's
        // speed must stay fed forward. (The range used to settle at each crossing and the car
        // slowed, here to 0.33 m/s; in the walk_away scenario it stopped and fell 3.01 m
        // behind.)
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let mut odom = Odometry::default();
        let forward = camera().forward_m;
        let mut slowest_mps = f64::INFINITY;
        let (mut nearest_m, mut furthest_m) = (f64::INFINITY, 0.0f64);
        for i in 0..1500 {
            let t = f64::from(i) * 0.02;
            let person = [forward + 3.0 + 0.4 * t, 0.0];
            if i % 10 == 0 {
                f.observe(&message(t, vec![seen_box(odom, person)]));
            }
            let cmd = f.command(t + 0.001, odom, true);
            odom.x_m += cmd.linear_mps * 0.02;
            if t > 10.0 {
                slowest_mps = slowest_mps.min(cmd.linear_mps);
                nearest_m = nearest_m.min(person[0] - odom.x_m);
                furthest_m = furthest_m.max(person[0] - odom.x_m);
            }
        }
        // The speed wanders with the boxes' pixel rounding (5 Hz), the range barely.
        assert!(slowest_mps > 0.3, "it slowed to {slowest_mps} m/s");
        assert!(
            furthest_m - nearest_m < 0.05,
            "the range wandered {nearest_m}..{furthest_m} m"
        );
        // A receding walker is followed at the walking distance.
        let walking_m = camera().whole_view_range_m(1.75) + forward;
        assert!(
            (nearest_m - walking_m).abs() < 0.1,
            "followed at {nearest_m} m, not {walking_m} m"
        );
    }

    #[test]
    fn a_box_top_at_the_border_is_cut_off_when_the_feet_put_the_head_out_of_view() {
        // A person 1.6 m away: the 18 cm camera sees them from the chest down, but a detector's
        // box top wanders a few pixels below the border. Taken for the head, that box put
        // them at ~3 m; the feet say 1.6 m and that the head is out of view.
        let f = Follower::new(FollowerConfig::default(), camera());
        let mut b = person_box(1.6, 0.0);
        assert!(b.ymin < 0, "the head is out of view at 1.6 m");
        b.ymin = 3;
        let (range_m, _) = f.range_bearing(&b);
        assert!((range_m - 1.6).abs() < 0.1, "range {range_m} m");
        // A person just far enough to be seen whole, their head a few pixels below the border,
        // is still ranged from their height.
        let whole_m = camera().whole_view_range_m(1.75);
        let b = person_box(whole_m + 0.05, 0.0);
        assert!(
            b.ymin > 0 && f64::from(b.ymin as i32) < 0.02 * 480.0,
            "top {}",
            b.ymin
        );
        let (range_m, _) = f.range_bearing(&b);
        assert!(
            (range_m - (whole_m + 0.05)).abs() < 0.1,
            "range {range_m} m"
        );
    }

    #[test]
    fn a_camera_only_car_turns_its_back_to_its_trail_to_give_way() {
        // The car drove 3 m along +x, then turned 0.5 rad left to face a person who now walks
        // straight at it. Its trail is not behind it, so it may not back up as it stands: it
        // turns toward the heading that puts the trail behind (keeping them in view) and backs.
        let config = FollowerConfig::default();
        let mut f = Follower::new(config, camera());
        for i in 0..=100 {
            let pose = Odometry {
                x_m: -3.0 * (1.0 - f64::from(i) / 100.0),
                ..Odometry::default()
            };
            f.record_pose(-1.0 + f64::from(i) * 0.01, pose);
        }
        let mut odom = Odometry {
            yaw_rad: 0.5,
            ..Odometry::default()
        };
        let start = [2.2 * 0.5f64.cos(), 2.2 * 0.5f64.sin()];
        let (mut widest_rad, mut nearest_m) = (0.0f64, f64::INFINITY);
        for i in 0..=600 {
            let t = f64::from(i) * 0.01;
            let walked = (0.4 * t).min(1.4);
            let person = [
                start[0] * (1.0 - walked / 2.2),
                start[1] * (1.0 - walked / 2.2),
            ];
            let (range_m, bearing_rad) = range_bearing_from(odom, person);
            if i % 20 == 0 {
                f.observe(&message(t, vec![seen_box(odom, person)]));
                widest_rad = widest_rad.max(bearing_rad.abs());
            }
            nearest_m = nearest_m.min(range_m);
            let cmd = f.command(t, odom, true);
            drive(&mut odom, cmd, 0.01);
        }
        assert!(odom.x_m < -0.5, "backed to x = {} m", odom.x_m);
        assert!(odom.y_m.abs() < 0.15, "left its trail: y = {} m", odom.y_m);
        assert!(
            widest_rad < 0.5,
            "turned them to {widest_rad} rad off the axis"
        );
        assert!(nearest_m > 1.2, "let them within {nearest_m} m");
    }

    #[test]
    fn a_walker_whose_estimate_dips_below_walking_speed_stays_a_walker_for_a_while() {
        // A person walking across 4 m ahead, then standing still where they are. The car
        // stands: only the estimate moves. (A walking body's boxes make the estimate dip below
        // walking speed for a moment now and then; that must not make the car close in to
        // the standoff and back off again at each dip.)
        let mut f = Follower::new(FollowerConfig::default(), camera());
        let odom = Odometry::default();
        let person = |t: f64| [4.0, -1.0 + 0.6 * t.min(3.0)];
        let mut walked = false;
        let mut first_slow: Option<(f64, bool)> = None;
        for i in 0..=300 {
            let t = f64::from(i) * 0.02;
            f.record_pose(t, odom);
            if i % 10 == 0 {
                f.observe(&message(t, vec![seen_box(odom, person(t))]));
            }
            let Some(target) = f.target() else { continue };
            let [vx, vy] = target.filter.velocity_mps();
            let fast = vx.hypot(vy) > MOVING_MPS;
            walked |= fast && target.last_seen_walking();
            if walked && !fast && first_slow.is_none() {
                first_slow = Some((t, target.last_seen_walking()));
            }
        }
        assert!(walked, "the walk was never seen as walking");
        let Some((slow_s, still_walker)) = first_slow else {
            panic!("the estimate never slowed down");
        };
        assert!(
            still_walker,
            "let go as soon as the estimate slowed ({slow_s} s)"
        );
        // Three seconds of standing: they stand.
        let standing = f.target().map(|t| !t.last_seen_walking());
        assert_eq!(standing, Some(true), "still a walker after 3 s of standing");
    }

    #[test]
    fn a_camera_only_car_pursues_a_lost_walker_to_the_walking_distance() {
        // A person walking away 4.5 m ahead is lost from view at 1 s (hidden), long before the
        // car is near. The prediction walks them on and stops; that it stopped does not mean
        // they did: the camera-only car ends where its camera would see them whole, not at
        // the standoff, and then looks for them.
        let config = FollowerConfig::default();
        let whole_m = camera().whole_view_range_m(config.target_height_m) + camera().forward_m;
        let mut f = Follower::new(config.clone(), camera());
        let mut odom = Odometry::default();
        for i in 0..=1000 {
            let t = f64::from(i) * 0.01;
            if i % 20 == 0 {
                let person = [4.5 + 0.5 * t, 0.0];
                let boxes = if t <= 1.0 {
                    vec![seen_box(odom, person)]
                } else {
                    vec![]
                };
                f.observe(&message(t, boxes));
            }
            let cmd = f.command(t, odom, true);
            drive(&mut odom, cmd, 0.01);
        }
        let target = f.target().expect("the target is kept");
        let (range_m, _) = range_bearing_from(odom, target.position_at(10.0));
        assert!(target.last_seen_walking());
        assert!(
            range_m > whole_m - config.standoff_band_m - 0.1,
            "closed in to {range_m} m of a walker it lost (walking distance {whole_m} m)"
        );
    }

    #[test]
    fn a_camera_only_car_gives_way_to_a_walker_coming_closer() {
        // A person walks straight at the car at 0.4 m/s from 4 m. Without a laser, the car keeps
        // them where its camera sees them whole (2.49 m from the camera): it backs away instead
        // of letting them walk into its blind zone, over the 3 m it drove to get here; where it
        // has not driven it does not back up blind.
        let config = FollowerConfig::default();
        let whole_m = camera().whole_view_range_m(config.target_height_m) + camera().forward_m;
        let run = |came_from_m: f64| {
            let mut f = Follower::new(config.clone(), camera());
            for i in 0..=100 {
                let x = -came_from_m * (1.0 - f64::from(i) / 100.0);
                let pose = Odometry {
                    x_m: x,
                    ..Odometry::default()
                };
                f.record_pose(-1.0 + f64::from(i) * 0.01, pose);
            }
            let mut odom = Odometry::default();
            f.command(0.0, odom, true);
            let (mut nearest_m, mut backed_m) = (f64::INFINITY, 0.0f64);
            for i in 1..=1200 {
                let t = f64::from(i) * 0.01;
                let person = [4.0 - 0.4 * t, 0.0];
                if i % 20 == 0 && person[0] - odom.x_m > 1.0 {
                    f.observe(&message(t, vec![seen_box(odom, person)]));
                }
                let cmd = f.command(t, odom, true);
                drive(&mut odom, cmd, 0.01);
                backed_m = backed_m.min(odom.x_m);
                // While its trail lasts (it ends 3 m back, reached after ~10 s).
                if t > 4.0 && t <= 9.0 {
                    nearest_m = nearest_m.min(person[0] - odom.x_m);
                }
            }
            (backed_m, nearest_m)
        };
        let (backed_m, nearest_m) = run(3.0);
        assert!(backed_m < -2.0, "backed away {backed_m} m");
        assert!(
            backed_m > -3.0 - REVERSE_LOOK_M,
            "backed off its trail: {backed_m} m"
        );
        assert!(
            nearest_m > whole_m - 0.5,
            "let the person within {nearest_m} m (sees them whole from {whole_m} m)"
        );
        let (blind_m, _) = run(0.0);
        assert!(
            blind_m > -0.05,
            "backed {blind_m} m over ground it never drove"
        );
        // With a laser the standoff is kept instead: the laser sees them at any range.
        let mut f = Follower::new(config.clone(), camera()).with_laser(LaserMount::default());
        let mut odom = Odometry::default();
        f.command(0.0, odom, true);
        for i in 1..=300 {
            let t = f64::from(i) * 0.01;
            if i % 20 == 0 {
                f.observe(&message(t, vec![seen_box(odom, [4.0 - 0.4 * t, 0.0])]));
            }
            let cmd = f.command(t, odom, true);
            drive(&mut odom, cmd, 0.01);
        }
        assert!(
            odom.x_m > 0.0,
            "the laser car drove toward them: {}",
            odom.x_m
        );
    }
}
