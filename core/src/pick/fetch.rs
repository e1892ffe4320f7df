//! Driving the base for a pick (`[robot] fetch`): brings a point the arm should work at (the
//! object seen, the place) to where the arm reaches it best, then stops.
//!
//! The law is a diff drive's go-to-point on the point's range and bearing from the base, so a
//! goal off the car's axis (the arm car's arm reaches best a little to the left) is met
//! without a heading of its own: turn in place while the bearing is far off, drive as it
//! closes, slow to a stop at the goal. Speeds and accelerations are kept gentle: the arm may be
//! holding something.

use std::collections::VecDeque;

use nalgebra::{Isometry3, Point3, Vector2, Vector3};
use rover_sim::{Simulation, Twist, isometry_from_pose, wrap_angle};

use super::{Pick, PickState, Step, Target, Way};

/// An object this far (m) or more from the fetch point is driven to before it is picked.
const FETCH_FROM_M: f64 = 0.04;
/// The base stands this long (s) after a drive before it trusts a sighting or plans.
const SETTLE_BASE_S: f64 = 0.6;
/// A drive that has not got there after this long (s of sim time) gives up.
const MAX_DRIVE_S: f64 = 90.0;
/// How far (m) the base backs straight away from the object before it turns to the place: the
/// way it came in, clear of what the object stood on.
const BACK_OFF_M: f64 = 0.3;

/// Where the base is driving to.
#[derive(Debug, Clone, Copy)]
pub(super) struct Leg {
    /// The point brought to the fetch point (world frame, m): the object's centre, or the
    /// place's point under the object.
    goal: Vector3<f64>,
    /// To the place, the object in the hand (else to the object).
    to_place: bool,
    /// When the drive started (s of sim time).
    started_s: f64,
    /// Backing away first, from where the base was (world x, y, m).
    back_from: Option<Vector2<f64>>,
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
}

impl Pick {
    /// Where the object should be when the base stops to pick it (arm base frame, m), when
    /// the pick drives the base.
    pub(super) fn fetch_at(&self, sim: &Simulation) -> Option<Vector2<f64>> {
        (self.config.fetch_at)
            .or(sim.world().robot.fetch)
            .map(|[x, y]| Vector2::new(x, y))
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
        let started_s = match self.leg {
            Some(leg) if driving => leg.started_s,
            _ => {
                self.drive.reset();
                self.said.push((
                    false,
                    format!(
                        "pick: fetch: driving to the object at ({:.2}, {:.2}) m",
                        goal.x, goal.y
                    ),
                ));
                sim.sim_time_s()
            }
        };
        self.sightings.clear();
        self.state = PickState::Fetching;
        self.leg = Some(Leg {
            goal,
            to_place: false,
            started_s,
            back_from: None,
        });
        true
    }

    /// One control update of a drive: the base's command, and what comes after it gets there
    /// (a fresh look at the object, or the place's plan once the base has settled).
    pub(super) fn drive_base(&mut self, sim: &Simulation, now: f64) {
        let Some(leg) = self.leg else {
            return;
        };
        let Some(at) = self.fetch_at(sim) else {
            self.leg = None;
            return;
        };
        if now - leg.started_s > MAX_DRIVE_S {
            self.leg = None;
            return self.fail(format!(
                "fetch: the base did not get there in {MAX_DRIVE_S:.0} s"
            ));
        }
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        if let Some(from) = leg.back_from {
            if (world_from_base.translation.vector.xy() - from).norm() < BACK_OFF_M {
                self.base_cmd = Some(self.drive.back(now));
                return;
            }
            self.leg = Some(Leg {
                back_from: None,
                ..leg
            });
        }
        let point = world_from_base.inverse() * Point3::from(leg.goal);
        let (cmd, there) = self.drive.command(now, point.coords.xy(), at);
        self.base_cmd = Some(cmd);
        if !there {
            return;
        }
        self.leg = None;
        self.settle_until_s = now + SETTLE_BASE_S;
        let (x, y) = (point.x, point.y);
        if leg.to_place {
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

    /// After the grasp's steps, with the object held for a fetch: the drive to the place,
    /// then (the base settled) the place's plan. Returns whether it took over (`false`:
    /// nothing is held for it, the pick is done).
    pub(super) fn deliver(&mut self, sim: &Simulation, now: f64) -> bool {
        let Some(held) = &self.held else {
            return false;
        };
        if self.state != PickState::Delivering {
            let [x, y, z] = held.place.0;
            let base = sim.world_from_link(self.base).translation;
            self.leg = Some(Leg {
                goal: Vector3::new(x, y, z),
                to_place: true,
                started_s: now,
                back_from: Some(Vector2::new(f64::from(base.x), f64::from(base.y))),
            });
            self.drive.reset();
            self.state = PickState::Delivering;
            self.said.push((
                false,
                format!("pick: fetch: driving to the place at ({x:.2}, {y:.2}) m"),
            ));
            return true;
        }
        if self.leg.is_some() || now < self.settle_until_s {
            return true;
        }
        let Some(held) = self.held.take() else {
            return false;
        };
        match self.plan_delivery(sim, held) {
            Ok(steps) => self.steps = VecDeque::from(steps),
            Err(why) => self.fail(format!("fetch: at the place: {why}")),
        }
        true
    }

    /// The place's plan from where the arm is now, the object held as it was taken.
    fn plan_delivery(
        &mut self,
        sim: &Simulation,
        held: Held,
    ) -> Result<Vec<(Step, PickState)>, String> {
        let g = self.gripper.clone()?;
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let mut scene = sim
            .planning_scene(self.solver.chain(), self.config.margin_m as f32)
            .map_err(|e| e.to_string())?;
        let q: Vec<f64> = (self.joints().iter())
            .map(|j| sim.joint_state(j.id).map_or(0.0, |s| s.position))
            .collect();
        // The object in the hand is carried, not avoided.
        let tool = self
            .solver
            .chain()
            .base_from_tip(&q)
            .map_err(|e| e.to_string())?;
        let in_hand = world_from_base * Point3::from(tool.translation.vector);
        if let Some(i) = scene.object_near(
            [in_hand.x, in_hand.y, in_hand.z],
            held.target.bound_m as f32 + 0.02,
        ) {
            scene.ignore_object(i, true);
        }
        let ([x, y, z], drop_m, lower_m) = held.place;
        let over =
            world_from_base.inverse() * Point3::new(x, y, z + drop_m + held.target.half_height_m);
        self.plan_place(
            &mut scene,
            (held.target, held.way),
            &g,
            (&q, &held.home_q),
            (over.coords, lower_m),
        )
    }
}

/// Forward speed limit (m/s).
const MAX_SPEED_MPS: f64 = 0.25;
/// Backing-up speed limit (m/s).
const MAX_BACK_MPS: f64 = 0.1;
/// Turn rate limit (rad/s).
const MAX_TURN_RADPS: f64 = 0.6;
/// Speed change limit (m/s^2).
const MAX_ACCEL_MPS2: f64 = 0.4;
/// Turn rate change limit (rad/s^2).
const MAX_TURN_ACCEL_RADPS2: f64 = 1.5;
/// Range error (m) to speed (m/s).
const RANGE_GAIN: f64 = 0.8;
/// Bearing error (rad) to turn rate (rad/s).
const BEARING_GAIN: f64 = 1.5;
/// Bearing errors beyond this (rad) turn in place.
const TURN_IN_PLACE_RAD: f64 = 0.35;
/// The point within this (m) of the goal is there.
pub(crate) const ARRIVED_M: f64 = 0.02;

/// The base's go-to-point controller; it remembers its last command to limit accelerations.
#[derive(Debug, Clone, Default)]
pub(crate) struct DriveTo {
    last: Twist,
    last_s: Option<f64>,
}

impl DriveTo {
    /// Forgets the last command (the next one starts from rest).
    pub(crate) fn reset(&mut self) {
        *self = Self::default();
    }

    /// The command at `now_s` that backs straight up.
    pub(crate) fn back(&mut self, now_s: f64) -> Twist {
        let dt = self.last_s.map_or(0.0, |t| (now_s - t).max(0.0));
        self.last_s = Some(now_s);
        let step = MAX_ACCEL_MPS2 * dt;
        self.last = Twist::new((self.last.linear_mps - step).max(-MAX_BACK_MPS), 0.0);
        self.last
    }

    /// The command at `now_s` that brings `point` (base frame, m, x forward, y left) to `goal`
    /// (same frame), and whether it is there (the command is then zero).
    pub(crate) fn command(
        &mut self,
        now_s: f64,
        point: Vector2<f64>,
        goal: Vector2<f64>,
    ) -> (Twist, bool) {
        let dt = self.last_s.map_or(0.0, |t| (now_s - t).max(0.0));
        self.last_s = Some(now_s);
        if (point - goal).norm() <= ARRIVED_M {
            self.last = Twist::ZERO;
            return (Twist::ZERO, true);
        }
        let bearing_err = wrap_angle(point.y.atan2(point.x) - goal.y.atan2(goal.x));
        let range_err = point.norm() - goal.norm();
        let turn = (BEARING_GAIN * bearing_err).clamp(-MAX_TURN_RADPS, MAX_TURN_RADPS);
        let speed = if bearing_err.abs() > TURN_IN_PLACE_RAD {
            0.0
        } else {
            (RANGE_GAIN * range_err).clamp(-MAX_BACK_MPS, MAX_SPEED_MPS) * bearing_err.cos()
        };
        let limit = |from: f64, to: f64, rate: f64| from + (to - from).clamp(-rate * dt, rate * dt);
        let cmd = Twist::new(
            limit(self.last.linear_mps, speed, MAX_ACCEL_MPS2),
            limit(self.last.angular_radps, turn, MAX_TURN_ACCEL_RADPS2),
        );
        self.last = cmd;
        (cmd, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Drives a unicycle with the controller's commands: it ends with the point at the goal,
    /// from ahead, behind and beside, within the arrival distance.
    #[test]
    fn the_point_ends_at_the_goal_from_any_side() {
        let goal = Vector2::new(0.27, 0.08);
        for start in [
            Vector2::new(1.5, 0.0),
            Vector2::new(-1.0, -1.0),
            Vector2::new(0.0, 1.2),
        ] {
            let mut drive = DriveTo::default();
            // The point in the world; the base at (x, y, yaw).
            let (mut x, mut y, mut yaw) = (0.0f64, 0.0f64, 0.0f64);
            let dt = 0.01;
            let mut arrived = false;
            for i in 0..6000 {
                let (dx, dy) = (start.x - x, start.y - y);
                let (s, c) = yaw.sin_cos();
                let point = Vector2::new(c * dx + s * dy, -s * dx + c * dy);
                let (cmd, there) = drive.command(f64::from(i) * dt, point, goal);
                if there {
                    arrived = true;
                    break;
                }
                x += cmd.linear_mps * yaw.cos() * dt;
                y += cmd.linear_mps * yaw.sin() * dt;
                yaw += cmd.angular_radps * dt;
            }
            assert!(arrived, "from {start:?}: never arrived");
        }
    }

    /// Accelerations stay within the limits from rest.
    #[test]
    fn commands_ramp_up() {
        let mut drive = DriveTo::default();
        let (first, _) = drive.command(0.0, Vector2::new(2.0, 0.0), Vector2::new(0.3, 0.0));
        assert_eq!(first, Twist::ZERO);
        let (next, _) = drive.command(0.1, Vector2::new(2.0, 0.0), Vector2::new(0.3, 0.0));
        assert!(
            (next.linear_mps - MAX_ACCEL_MPS2 * 0.1).abs() < 1e-9,
            "{next:?}"
        );
    }
}
