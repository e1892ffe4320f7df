//! Control: from the state and the estimate to cmd_vel (tracking, pursuing, giving way over
//! the trail, avoiding, searching, and the acceleration limits).

use rover_sim::physics::{Odometry, Twist, wrap_angle};

use super::config::range_bearing_from;
use super::state::Follower;
use super::target::FollowState;
use super::tuning::*;

impl Follower {
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
    pub(super) fn follow_state(&self, now_s: f64, odom: Odometry) -> FollowState {
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
    pub(super) fn occluded(&self, target: [f64; 2], now_s: f64, odom: Odometry) -> bool {
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
    pub(super) fn pursue(&mut self, now_s: f64, odom: Odometry, state: FollowState) -> Twist {
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
    pub(super) fn give_way_over_trail(
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
    pub(super) fn trail_behind_yaw(&self, odom: Odometry) -> Option<f64> {
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
    pub(super) fn keep_range_m(&self, moving: bool) -> f64 {
        let c = &self.config;
        if !moving || self.laser.is_some() {
            return c.standoff_m;
        }
        (self.whole_view_m + self.camera.forward_m)
            .clamp(c.standoff_m, c.standoff_m + MAX_EXTRA_STANDOFF_M)
    }

    /// Replaces `preferred` by a free arc when the laser shows an obstacle in its way.
    pub(super) fn avoid(
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
    pub(super) fn aim_search(&mut self, now_s: f64, odom: Odometry) {
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
    pub(super) fn search(&mut self, now_s: f64, odom: Odometry) -> Twist {
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

    pub(super) fn limit(&self, wanted: Twist, dt: f64) -> Twist {
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
}
