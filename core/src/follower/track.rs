//! Tracking: detector messages and laser scans into the target's estimate (association, the
//! Kalman filter, what a miss in plain view means).

use nalgebra::Matrix2;
use rover_perception::BoundingBoxes;
use rover_sim::{physics::wrap_angle, sensors::LaserScan};

use super::filter::{TargetFilter, polar_covariance};
use super::state::Follower;
use super::target::{Candidate, FollowTarget};
use super::tuning::*;

impl Follower {
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
    pub(super) fn note_missed(&mut self, t_image: f64, camera_xy: [f64; 2], camera_yaw_rad: f64) {
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
    pub(super) fn fold_in(&mut self, t_image: f64, yaw_rad: f64, keeping: bool, c: &Candidate) {
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
}
