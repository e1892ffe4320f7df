//! The follower itself: what it keeps between updates, and the poses it has been at.

use std::collections::VecDeque;

use rover_sim::physics::{Odometry, Twist};

use super::avoid::Avoided;
use super::config::{CameraGeometry, FollowerConfig, LaserMount};
use super::target::{FollowState, FollowTarget};
use super::tuning::*;

/// The follower. Feed it the robot's odometry every control update ([`Follower::record_pose`]),
/// every detector message ([`Follower::observe`]) and laser scan ([`Follower::observe_scan`]),
/// and ask for a command every control update in follow mode ([`Follower::command`]).
#[derive(Debug, Clone)]
pub struct Follower {
    pub(super) config: FollowerConfig,
    pub(super) camera: CameraGeometry,
    pub(super) laser: Option<LaserMount>,
    pub(super) target: Option<FollowTarget>,
    pub(super) next_id: u32,
    pub(super) last_message_s: Option<f64>,
    pub(super) last_cmd: Twist,
    pub(super) last_cmd_s: Option<f64>,
    pub(super) state: FollowState,
    /// (sim time, odometry) of recent control updates, oldest first.
    pub(super) poses: VecDeque<(f64, Odometry)>,
    /// Which way to sweep when searching (+1 left, -1 right).
    pub(super) search_sign: f64,
    /// Whether the search is still turning to face the prediction (before it sweeps).
    pub(super) search_facing: bool,
    /// Where the robot has been (odometry frame, m): every [`TRAIL_SPACING_M`], the last
    /// [`TRAIL_POINTS`].
    pub(super) trail: VecDeque<[f64; 2]>,
    /// The newest scan's returns in the odometry frame, and its time.
    pub(super) returns_odom: Vec<[f64; 2]>,
    pub(super) scan_s: Option<f64>,
    /// Obstacles in the base frame for this update (scratch, reused).
    pub(super) obstacles_base: Vec<[f64; 2]>,
    /// Hysteresis at the standoff.
    pub(super) range_settled: bool,
    pub(super) heading_settled: bool,
    /// What the avoidance did at the last update.
    pub(super) avoided: Option<Avoided>,
    /// The way around the current obstacle (+1 left, -1 right, 0 none) and when the avoidance
    /// last steered (s).
    pub(super) detour_side: f64,
    pub(super) detour_s: f64,
    /// When the current pursuit started and when it arrived at the pursued point (s).
    pub(super) pursuit_since_s: f64,
    pub(super) arrived_s: Option<f64>,
    /// The point driven to at the last command (odometry frame, m).
    pub(super) goal: Option<[f64; 2]>,
    /// From how far the camera sees a person of the target height whole (m, from the camera).
    pub(super) whole_view_m: f64,
    /// Up to how far the detector finds a person reliably (m, from the camera): their box is
    /// [`RELIABLE_BOX_PX`] tall there.
    pub(super) reliable_range_m: f64,
    /// Half the camera's horizontal field of view, on its narrower side (rad).
    pub(super) half_fov_rad: f64,
    /// Detector messages in a row that did not show a lost target where its prediction put it
    /// in plain view.
    pub(super) contradictions: u32,
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

    /// Odometry at sim time `t` (nearest recorded control update at or before it).
    pub(super) fn pose_at(&self, t: f64) -> Option<Odometry> {
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
