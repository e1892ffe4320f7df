//! The person follower: turns darknet_ros-style detections into cmd_vel.
//!
//! Better than the tutorials' "person seen -> 0.1 m/s forward":
//! - picks a target of the configured class and keeps the same one across frames (a small
//!   tracker: the detection nearest to where the target is expected, within a gate);
//! - estimates its range from the box height (pinhole model and an assumed person height), or
//!   from where its feet meet the ground when the box is cut off by the top of the image;
//! - remembers the target's position in the odometry frame, so the command uses the robot's
//!   current pose rather than the pose at the (older) image time;
//! - steers to centre it and regulates the range to a standoff, under speed and acceleration
//!   limits, slowing down while the target is far off-centre;
//! - when the target is lost, turns toward where it was last seen and keeps searching on the
//!   spot (it never drives blind);
//! - stops when detections are stale (no detector message for longer than `stale_after_s`) or the
//!   detector is unavailable.
//!
//! Pure library code on sim time: no threads, no clocks, no UI.

use std::collections::VecDeque;

use rover_perception::{BoundingBox, BoundingBoxes};
use rover_sim::wrap_angle;
use rover_sim::{CameraInfo, Odometry, Twist};

/// Follower settings.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowerConfig {
    /// Class to follow (darknet_ros `Class`).
    pub target_class: String,
    /// Minimum detection probability for a target.
    pub min_probability: f64,
    /// Distance to keep from the target (m).
    pub standoff_m: f64,
    /// Assumed real height of the target (m), for range from box height.
    pub target_height_m: f64,
    /// Forward speed limit (m/s); reversing is limited to a third of it.
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
    /// The target counts as lost when not seen for this long (s).
    pub lost_after_s: f64,
    /// Proportional gain from bearing error (rad) to turn rate (rad/s).
    pub turn_gain: f64,
    /// Proportional gain from range error (m) to speed (m/s).
    pub speed_gain: f64,
}

impl Default for FollowerConfig {
    fn default() -> Self {
        Self {
            target_class: "person".into(),
            min_probability: 0.4,
            standoff_m: 1.5,
            target_height_m: 1.75,
            max_speed_mps: 0.5,
            max_turn_radps: 1.0,
            max_accel_mps2: 0.6,
            max_turn_accel_radps2: 3.0,
            search_turn_radps: 0.6,
            stale_after_s: 1.0,
            lost_after_s: 0.6,
            turn_gain: 1.8,
            speed_gain: 0.8,
        }
    }
}

/// Where the camera is and how it projects, as the follower needs it.
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
    /// Image height (px).
    pub height_px: f64,
    /// Camera height above the ground (m).
    pub height_m: f64,
    /// Camera position ahead of the base origin (m).
    pub forward_m: f64,
    /// How far the optical axis looks below the horizon (rad; a TurtleBot3's camera: 0.174).
    pub pitch_down_rad: f64,
}

impl CameraGeometry {
    /// From a CameraInfo and the camera's mounting (height above ground, offset ahead of base).
    pub fn new(info: &CameraInfo, height_m: f64, forward_m: f64) -> Self {
        Self {
            fx: info.k[0],
            fy: info.k[4],
            cx: info.k[2],
            cy: info.k[5],
            height_px: f64::from(info.height),
            height_m,
            forward_m,
            pitch_down_rad: 0.0,
        }
    }
}

/// What the follower is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FollowState {
    /// No detector, or no detections yet: holding still.
    #[default]
    Waiting,
    /// Following a target.
    Tracking,
    /// Target lost: turning toward where it was last seen, then searching.
    Searching,
    /// Detections are stale: stopped.
    Stale,
}

impl FollowState {
    /// Lower-case name for logs and the HUD.
    pub fn as_str(self) -> &'static str {
        match self {
            FollowState::Waiting => "waiting",
            FollowState::Tracking => "tracking",
            FollowState::Searching => "searching",
            FollowState::Stale => "stale",
        }
    }
}

/// The followed target, in the odometry frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Target {
    /// Track id (increments each time a new target is picked).
    pub id: u32,
    /// Position (m, odometry frame).
    pub x_m: f64,
    /// Position (m, odometry frame).
    pub y_m: f64,
    /// Sim time of the image it was last seen in (s).
    pub seen_s: f64,
    /// Range at that time (m).
    pub range_m: f64,
    /// Bearing at that time (rad, positive left).
    pub bearing_rad: f64,
    /// Detection probability.
    pub probability: f64,
}

/// Pose history length: enough for a few seconds of control updates at 100 Hz.
const HISTORY: usize = 512;

/// The follower. Feed it every detector message with [`Follower::observe`] and ask for a
/// command every control update with [`Follower::command`].
#[derive(Debug, Clone)]
pub struct Follower {
    config: FollowerConfig,
    camera: CameraGeometry,
    target: Option<Target>,
    next_id: u32,
    last_message_s: Option<f64>,
    last_cmd: Twist,
    last_cmd_s: Option<f64>,
    state: FollowState,
    /// (sim time, odometry) of recent control updates, oldest first.
    poses: VecDeque<(f64, Odometry)>,
    /// Which way the target was last moving across the image (+1 left, -1 right).
    search_sign: f64,
}

impl Follower {
    /// A follower for a camera with this geometry.
    pub fn new(config: FollowerConfig, camera: CameraGeometry) -> Self {
        Self {
            config,
            camera,
            target: None,
            next_id: 0,
            last_message_s: None,
            last_cmd: Twist::ZERO,
            last_cmd_s: None,
            state: FollowState::Waiting,
            poses: VecDeque::with_capacity(HISTORY),
            search_sign: 1.0,
        }
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
    pub fn target(&self) -> Option<&Target> {
        self.target.as_ref()
    }

    /// Forgets the target and the command history (call when follow mode is entered).
    pub fn reset(&mut self) {
        self.target = None;
        self.last_cmd = Twist::ZERO;
        self.last_cmd_s = None;
        self.state = FollowState::Waiting;
    }

    /// Range (m) and bearing (rad, positive left) of a box, seen from the camera.
    pub fn range_bearing(&self, b: &BoundingBox) -> (f64, f64) {
        let c = &self.camera;
        let u = (b.xmin + b.xmax) as f64 / 2.0;
        let bearing = ((c.cx - u) / c.fx).atan();
        let height_px = (b.ymax - b.ymin).max(1) as f64;
        let from_height = c.fy * self.config.target_height_m / height_px;
        // A box cut off at the top underestimates the height (overestimates the range): use
        // where the feet meet the ground instead, when they are below the horizon.
        let clipped_top = b.ymin <= 2;
        // The feet's ray dips below the horizon by the camera's pitch plus its angle below the
        // optical axis.
        let feet_dip_rad = ((b.ymax as f64 - c.cy) / c.fy).atan() + c.pitch_down_rad;
        let from_feet = (feet_dip_rad > (1.0 / c.fy).atan() && (b.ymax as f64) < c.height_px - 2.0)
            .then(|| c.height_m / feet_dip_rad.tan());
        let along_axis = match (clipped_top, from_feet) {
            (true, Some(d)) => d,
            (true, None) => from_height.min(self.config.standoff_m),
            (false, _) => from_height,
        };
        (along_axis / bearing.cos(), bearing)
    }

    /// Takes one detector message (possibly with no boxes: darknet_ros' ObjectCount = 0).
    pub fn observe(&mut self, message: &BoundingBoxes) {
        let t_image = message.image_stamp.sim_time_s;
        self.last_message_s = Some(self.last_message_s.map_or(t_image, |t| t.max(t_image)));
        let Some(pose) = self.pose_at(t_image) else {
            return;
        };
        let (sin, cos) = pose.yaw_rad.sin_cos();
        let camera_x = pose.x_m + cos * self.camera.forward_m;
        let camera_y = pose.y_m + sin * self.camera.forward_m;
        let mut best: Option<(f64, Target)> = None;
        for b in &message.bounding_boxes {
            if b.class != self.config.target_class || b.probability < self.config.min_probability {
                continue;
            }
            let (range_m, bearing_rad) = self.range_bearing(b);
            let heading = pose.yaw_rad + bearing_rad;
            let candidate = Target {
                id: 0,
                x_m: camera_x + range_m * heading.cos(),
                y_m: camera_y + range_m * heading.sin(),
                seen_s: t_image,
                range_m,
                bearing_rad,
                probability: b.probability,
            };
            // Keep the current target: the candidate nearest to it within a gate that grows
            // with the time since it was seen (people walk ~1.5 m/s). Otherwise, the nearest.
            let score = match &self.target {
                Some(t) => {
                    let gap = (candidate.x_m - t.x_m).hypot(candidate.y_m - t.y_m);
                    let gate = 0.8 + 1.5 * (t_image - t.seen_s).max(0.0) + 0.15 * t.range_m;
                    if gap > gate && t_image - t.seen_s < self.config.lost_after_s {
                        continue;
                    }
                    gap
                }
                None => range_m,
            };
            if best.as_ref().is_none_or(|(s, _)| score < *s) {
                best = Some((score, candidate));
            }
        }
        if let Some((_, mut seen)) = best {
            seen.id = match &self.target {
                Some(t) if t_image - t.seen_s < self.config.lost_after_s => t.id,
                _ => {
                    self.next_id += 1;
                    self.next_id
                }
            };
            if let Some(t) = &self.target
                && (seen.bearing_rad - t.bearing_rad).abs() > 1e-3
            {
                self.search_sign = (seen.bearing_rad - t.bearing_rad).signum();
            }
            if seen.bearing_rad.abs() > 0.2 {
                self.search_sign = seen.bearing_rad.signum();
            }
            self.target = Some(seen);
        }
    }

    /// The command for this control update at sim time `now_s`, given the robot's odometry
    /// now. `detector_ok` is false when there is no detector (missing model, failure): the
    /// follower then stops.
    pub fn command(&mut self, now_s: f64, odom: Odometry, detector_ok: bool) -> Twist {
        if self.poses.len() == HISTORY {
            self.poses.pop_front();
        }
        self.poses.push_back((now_s, odom));
        let dt = self.last_cmd_s.map_or(0.0, |t| (now_s - t).clamp(0.0, 0.1));
        let fresh = self
            .last_message_s
            .is_some_and(|t| now_s - t <= self.config.stale_after_s);
        let (wanted, state) = if !detector_ok || self.last_message_s.is_none() {
            (Twist::ZERO, FollowState::Waiting)
        } else if !fresh {
            (Twist::ZERO, FollowState::Stale)
        } else {
            match self.target {
                Some(t) if now_s - t.seen_s <= self.config.lost_after_s => {
                    (self.track(&t, odom), FollowState::Tracking)
                }
                Some(t) => (self.search(Some(&t), odom), FollowState::Searching),
                None => (self.search(None, odom), FollowState::Searching),
            }
        };
        self.state = state;
        let cmd = if matches!(state, FollowState::Tracking | FollowState::Searching) {
            self.limit(wanted, dt)
        } else {
            // Stale or no detector: stop now, no ramp (the wheels' own ramp still applies).
            Twist::ZERO
        };
        self.last_cmd = cmd;
        self.last_cmd_s = Some(now_s);
        cmd
    }

    /// Range (m) and bearing (rad) of the target from the robot's base now: the standoff is
    /// the distance between the car and the person, as a user would measure it.
    fn relative(&self, t: &Target, odom: Odometry) -> (f64, f64) {
        let (dx, dy) = (t.x_m - odom.x_m, t.y_m - odom.y_m);
        (dx.hypot(dy), wrap_angle(dy.atan2(dx) - odom.yaw_rad))
    }

    fn track(&self, t: &Target, odom: Odometry) -> Twist {
        let c = &self.config;
        let (range, bearing) = self.relative(t, odom);
        let angular = (c.turn_gain * bearing).clamp(-c.max_turn_radps, c.max_turn_radps);
        // Drive only while the target is roughly ahead; full speed when centred.
        let alignment = (1.0 - bearing.abs() / 0.6).clamp(0.0, 1.0);
        let linear = (c.speed_gain * (range - c.standoff_m))
            .clamp(-c.max_speed_mps / 3.0, c.max_speed_mps)
            * alignment;
        Twist::new(linear, angular)
    }

    fn search(&self, last: Option<&Target>, odom: Odometry) -> Twist {
        let c = &self.config;
        // First face where the target was; once facing it (and still nothing), keep turning
        // the way it was last going.
        if let Some(t) = last {
            let (_, bearing) = self.relative(t, odom);
            if bearing.abs() > 0.15 {
                let angular = (c.turn_gain * bearing).clamp(-c.max_turn_radps, c.max_turn_radps);
                return Twist::new(0.0, angular);
            }
        }
        Twist::new(0.0, self.search_sign * c.search_turn_radps)
    }

    fn limit(&self, wanted: Twist, dt: f64) -> Twist {
        let c = &self.config;
        let step = |from: f64, to: f64, rate: f64| from + (to - from).clamp(-rate * dt, rate * dt);
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
        for (time, odom) in &self.poses {
            if *time <= t + 1e-9 {
                found = Some(*odom);
            } else {
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
            height_px: 480.0,
            height_m: 0.18,
            forward_m: 0.15,
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
        assert!((cmd.linear_mps - 0.5).abs() < 0.01, "{cmd:?}");
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
        assert!(cmd.linear_mps <= 0.6 * 0.01 + 1e-9);
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
        let first = *f.target().expect("target");
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
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(3.0, -0.5)]));
        // Lost: empty messages keep coming.
        let mut cmd = Twist::ZERO;
        for i in 1..=150 {
            let t = i as f64 * 0.01;
            f.observe(&message(t, vec![]));
            cmd = f.command(t, odom, true);
        }
        assert_eq!(f.state(), FollowState::Searching);
        assert!(cmd.angular_radps < 0.0, "turns right toward it: {cmd:?}");
        assert!(cmd.linear_mps.abs() < 1e-9, "never drives while searching");
        // No messages for more than a second: stop.
        let cmd = f.command(1.5 + 1.01, odom, true);
        assert_eq!(f.state(), FollowState::Stale);
        assert_eq!(cmd, Twist::ZERO);
        // No detector: stop.
        let cmd = f.command(2.6, odom, false);
        assert_eq!(cmd, Twist::ZERO);
        assert_eq!(f.state(), FollowState::Waiting);
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
        let (_, bearing) = f.relative(f.target().expect("target"), turned);
        assert!((bearing + 0.3).abs() < 0.05, "{bearing}");
    }
}
