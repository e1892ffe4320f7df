//! Where the base stands for a pick (`fetch`): driving it to within reach of the object or
//! the place (the drive to the place starts in `deliver.rs`), round what stands between.

use nalgebra::{Isometry3, Point3, Vector2, Vector3};
use rover_sim::{
    model::isometry_from_pose,
    physics::{Simulation, Twist, wrap_angle},
};

use super::fetch::{BACK_OFF_M, FETCH_FROM_M, MAX_DRIVE_S, SETTLE_BASE_S};
use super::ground::{beside, body_footprint, obstacles, stance_pose, stance_yaw};
use super::plan::spans;
use super::route::route;
use super::state::{Leg, Pick, PickState, Target};

/// A corner of a route within this (m) of the arm's base is passed.
const VIA_REACHED_M: f64 = 0.12;

impl Pick {
    /// Where the object should be when the base stops to pick it (arm base frame, m), when
    /// the pick drives the base: the `fetch` point given, else the stance chosen from the
    /// arm's reachability for the leg under way.
    pub(super) fn fetch_at(&self, sim: &Simulation) -> Option<Vector2<f64>> {
        self.fetch_given(sim).or(self.stance)
    }

    /// The `fetch` point given (here or in the world's `[robot] fetch`), if any.
    pub(super) fn fetch_given(&self, sim: &Simulation) -> Option<Vector2<f64>> {
        (self.config.fetch_at)
            .or(sim.world().robot.fetch)
            .map(|[x, y]| Vector2::new(x, y))
    }

    /// With no `fetch` point and a base that drives: when the arm does not reach `target`
    /// (called `what`) from here, the base drives to a stance chosen from the arm's
    /// reachability. Returns whether it does (`false`: plan from here).
    pub(super) fn stance_towards(
        &mut self,
        sim: &Simulation,
        what: &str,
        target: &Target,
        world_from_base: &Isometry3<f64>,
    ) -> bool {
        if let Ok(g) = &self.gripper
            && let Err(why) = spans(g, what, target)
        {
            // No stance helps a hand too small.
            self.fail(why);
            return true;
        }
        if self.fetch_given(sim).is_some() || !sim.can_drive() || self.reaches(sim, target) {
            return false;
        }
        let world = world_from_base * Point3::from(target.centre);
        let started = std::time::Instant::now();
        let chosen = self.choose_stance(
            sim,
            (target.centre, target.bound_m),
            world_from_base,
            (world.coords, target.bound_m + 0.02),
        );
        match chosen {
            Ok(at) => {
                self.stance = Some(at);
                self.said.push((
                    false,
                    format!(
                        "pick: {what} is out of the arm's reach from here: the base stands with it at ({:.2}, {:.2}) m from the arm's base (surveyed in {:.3} s)",
                        at.x,
                        at.y,
                        started.elapsed().as_secs_f64()
                    ),
                ));
                self.fetch_towards(sim, target.centre, world_from_base)
            }
            Err(why) => {
                self.fail(format!("{what} is out of the arm's reach: {why}"));
                true
            }
        }
    }

    /// The object is at `centre` (base frame, the base at `world_from_base`): with fetch, when
    /// it is out of the arm's spot (or already being driven to), the base drives to it.
    /// Returns whether it does.
    pub(super) fn fetch_towards(
        &mut self,
        sim: &Simulation,
        centre: Vector3<f64>,
        world_from_base: &Isometry3<f64>,
    ) -> bool {
        let Some(at) = self.fetch_at(sim) else {
            return false;
        };
        let driving = self.state == PickState::Fetching;
        if !driving && (centre.xy() - at).norm() < FETCH_FROM_M {
            return false;
        }
        let goal = (world_from_base * Point3::from(centre)).coords;
        let (started_s, via) = match self.leg.take() {
            Some(leg) if driving => (leg.started_s, leg.via),
            _ => {
                self.drive.reset();
                self.said.push((
                    false,
                    format!(
                        "pick: fetch: driving to the object at ({:.2}, {:.2}) m",
                        goal.x, goal.y
                    ),
                ));
                let from = (
                    world_from_base.translation.vector.xy(),
                    yaw_of(world_from_base),
                );
                let via = self.route_to(sim, (goal, at), from, (goal, 0.08));
                (sim.sim_time_s(), via)
            }
        };
        let yaw_rad = beside(at).then(|| yaw_of(world_from_base));
        self.sightings.clear();
        self.state = PickState::Fetching;
        let yaw_rad = match &self.leg {
            Some(leg) if driving => leg.yaw_rad,
            _ => yaw_rad,
        };
        self.leg = Some(Leg {
            goal,
            to_place: false,
            started_s,
            back_from: None,
            via,
            yaw_rad,
            reach_checked_s: started_s,
        });
        true
    }

    /// The corners (world x, y) the base drives through from `from` until `goal` (world) is at
    /// `at` in its frame, round the world's objects (leaving out any within `ignore_m` of
    /// `ignore`, world): empty when the straight way is clear; said and empty when no way is
    /// found (the base then drives straight, as before).
    pub(super) fn route_to(
        &mut self,
        sim: &Simulation,
        (goal, at): (Vector3<f64>, Vector2<f64>),
        (from, from_yaw): (Vector2<f64>, f64),
        (ignore, ignore_m): (Vector3<f64>, f64),
    ) -> Vec<Vector2<f64>> {
        let Some(body) = body_footprint(sim, self.base) else {
            return Vec::new();
        };
        let radius_m = body.far_corner_m();
        let heading = (goal.y - from.y).atan2(goal.x - from.x);
        let yaw = stance_yaw(at, heading - at.y.atan2(at.x), from_yaw);
        let (stand, _) = stance_pose(goal.xy(), at, yaw);
        match route(from, stand, radius_m, &obstacles(sim, ignore, ignore_m)) {
            Ok(via) => {
                if !via.is_empty() {
                    let corners: Vec<String> = via
                        .iter()
                        .map(|p| format!("({:.2}, {:.2})", p.x, p.y))
                        .collect();
                    self.said.push((
                        false,
                        format!(
                            "pick: fetch: round what stands between, by {}",
                            corners.join(", ")
                        ),
                    ));
                }
                via
            }
            Err(why) => {
                self.said
                    .push((true, format!("pick: fetch: {why}; driving straight")));
                Vec::new()
            }
        }
    }

    /// One control update of a drive: the base's command, and what comes after it gets there
    /// (a fresh look at the object, or the place's plan once the base has settled).
    pub(super) fn drive_base(&mut self, sim: &Simulation, now: f64) {
        // Taken while it runs; put back unless it ends here.
        let Some(mut leg) = self.leg.take() else {
            return;
        };
        let Some(at) = self.fetch_at(sim) else {
            return;
        };
        if now - leg.started_s > MAX_DRIVE_S {
            return self.fail(format!(
                "fetch: the base did not get there in {MAX_DRIVE_S:.0} s"
            ));
        }
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        if let Some(from) = leg.back_from {
            if (world_from_base.translation.vector.xy() - from).norm() < BACK_OFF_M {
                self.base_cmd = Some(self.drive.back(now));
                self.leg = Some(leg);
                return;
            }
            leg.back_from = None;
        }
        if let Some(corner) = leg.via.first().copied() {
            let z = world_from_base.translation.z;
            let p = world_from_base.inverse() * Point3::new(corner.x, corner.y, z);
            if p.coords.xy().norm() > VIA_REACHED_M {
                let (cmd, _) = self.drive.command(now, p.coords.xy(), Vector2::zeros());
                self.base_cmd = Some(cmd);
                self.leg = Some(leg);
                return;
            }
            leg.via.remove(0);
        }
        let point = world_from_base.inverse() * Point3::from(leg.goal);
        let (cmd, there) = match leg.yaw_rad {
            // Beside: to the pose that brings it there.
            Some(yaw) => {
                let (stand, _) = stance_pose(leg.goal.xy(), at, yaw);
                let z = world_from_base.translation.z;
                let stand = world_from_base.inverse() * Point3::new(stand.x, stand.y, z);
                let turn = wrap_angle(yaw - yaw_of(&world_from_base));
                self.drive.pose_command(now, stand.coords.xy(), turn)
            }
            None => self.drive.command(now, point.coords.xy(), at),
        };
        let (cmd, there) = if !there && self.near_enough(sim, &mut leg, now) {
            self.drive.reset();
            (Twist::ZERO, true)
        } else {
            (cmd, there)
        };
        self.base_cmd = Some(cmd);
        let to_place = leg.to_place;
        if !there {
            self.leg = Some(leg);
            return;
        }
        self.settle_until_s = now + SETTLE_BASE_S;
        self.unseen = 0;
        let (x, y) = (point.x, point.y);
        if to_place {
            self.said.push((
                false,
                format!("pick: fetch: at the place ({x:.3}, {y:.3}) m from the arm's base"),
            ));
        } else {
            self.state = PickState::Seeking;
            self.said.push((
                false,
                format!(
                    "pick: fetch: the object should be at ({x:.3}, {y:.3}) m from the arm's base; looking again"
                ),
            ));
        }
    }
}

/// The base's heading (world, rad) at `world_from_base`.
pub(super) fn yaw_of(world_from_base: &Isometry3<f64>) -> f64 {
    world_from_base.rotation.euler_angles().2
}
