//! The follower's tuning: the constants its measuring, tracking and control share.

/// A walking person is followed at most this much further than the standoff (m).
pub(super) const MAX_EXTRA_STANDOFF_M: f64 = 1.5;
/// A box edge this close to the image edge (px) is cut off there.
pub(super) const EDGE_PX: i64 = 2;
/// A box top within this fraction of the image's height of its top border may be cut off
/// there (the detector's edges wander): see `Follower::measure`.
pub(super) const TOP_EDGE_SLACK: f64 = 0.02;

/// How much less a range from the feet is trusted when the box is cut off at a side of the
/// image (m, 1 sigma): the nearer foot may be the part cut off (with MakeHuman's walking body,
/// a range 0.45 m too far pulled the track off the person).
pub(super) const SIDE_CUT_FEET_SIGMA_M: f64 = 0.3;
/// How far a walking person's range from one box may be off with their gait (m, 1 sigma):
/// about half a step.
pub(super) const GAIT_RANGE_SIGMA_M: f64 = 0.15;

/// How quickly a target's learned width follows its whole boxes (fraction per box).
pub(super) const WIDTH_LEARNING: f64 = 0.2;
/// Backing away is limited to this fraction of the forward speed limit.
pub(super) const REVERSE_FRACTION: f64 = 0.6;
/// A target faster than this is moving (m/s): no calm deadbands, lead it.
pub(super) const MOVING_MPS: f64 = 0.25;
/// How long after its estimate last walked a track still counts as a walker (s of the time it
/// was seen): see [`FollowTarget::last_seen_walking`].
pub(super) const WALKER_HOLD_S: f64 = 1.0;
/// A pursuit has arrived when the pursued point is at most this far off the heading (rad) and
/// within the standoff band.
pub(super) const ARRIVED_BEARING_RAD: f64 = 0.15;
/// How far ahead a lost target's motion is extrapolated (s).
pub(super) const PREDICTION_HORIZON_S: f64 = 2.0;
/// The detector finds a person reliably while their box is at least this tall (px).
pub(super) const RELIABLE_BOX_PX: f64 = 100.0;
/// A prediction is in plain view this much beyond where the camera sees a person whole (m) ...
pub(super) const WHOLE_VIEW_MARGIN_M: f64 = 0.3;
/// ... and this far inside the image's side edges (rad).
pub(super) const FOV_MARGIN_RAD: f64 = 0.15;
/// Detector messages in a row without a lost target in plain view that halt its track.
pub(super) const CONTRADICTED_MESSAGES: u32 = 2;
/// Pose history length: enough for a few seconds of control updates at 100 Hz.
pub(super) const HISTORY: usize = 512;
/// The robot's trail keeps a point every this far (m) ...
pub(super) const TRAIL_SPACING_M: f64 = 0.05;
/// ... this many of them (20 m of driving).
pub(super) const TRAIL_POINTS: usize = 400;
/// Backing up without a range sensor needs the ground this far behind the base (m) ...
pub(super) const REVERSE_LOOK_M: f64 = 0.35;
/// ... to be within this of the trail (m): ground the robot has driven over.
pub(super) const TRAIL_WIDTH_M: f64 = 0.12;
/// The trail points a camera-only car lines its back up with before backing away: this far
/// from its base (m, nearest and furthest).
pub(super) const TRAIL_AHEAD_M: [f64; 2] = [0.3, 0.6];
/// Laser returns within this distance of the target's prediction are taken to be the target
/// (m), and returns this close to it are not obstacles.
pub(super) const LASER_GATE_M: f64 = 0.4;
/// A track the laser picks up again may be this far from the returns (m), at most, and
/// within 3 sigma of its own uncertainty.
pub(super) const LASER_PICKUP_M: f64 = 2.5;
/// The target's returns are the near surfaces of its legs (the laser sees a skinned person's
/// shins, about 5.5 cm in radius at a scan plane 0.17 m up: docs/WORLDS.md); the centroid of
/// a round leg's visible half is 2r/pi in front of its axis, and the person's centre is between
/// their legs: about this much further than the returns (m).
pub(super) const BODY_DEPTH_M: f64 = 0.035;
/// Laser returns keep following a target seen this recently (s): a few scans.
pub(super) const LASER_CONTINUITY_S: f64 = 0.35;
/// Returns further than this from the target's prediction are obstacles (m).
pub(super) const TARGET_EXCLUSION_M: f64 = 0.6;
/// Obstacles are only considered within this distance of the robot (m).
pub(super) const OBSTACLE_REACH_M: f64 = 3.0;
/// The way chosen around an obstacle is kept until the avoidance has not steered for this long (s).
pub(super) const DETOUR_MEMORY_S: f64 = 3.0;
/// Half-width of the line of sight an obstacle must block to hide the target (m).
pub(super) const OCCLUSION_WIDTH_M: f64 = 0.3;
/// A scan older than this (s) is too old to steer by.
pub(super) const SCAN_FRESH_S: f64 = 0.5;
