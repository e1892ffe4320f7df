//! Driving the base for a pick (`[robot] fetch`): brings a point the arm should work at (the
//! object seen, the place) to where the arm reaches it best, then stops.
//!
//! The law is a diff drive's go-to-point on the point's range and bearing from the base, so a
//! goal off the car's axis (the arm car's arm reaches best a little to the left) is met
//! without a heading of its own: turn in place while the bearing is far off, drive as it
//! closes, slow to a stop at the goal. Speeds and accelerations are kept gentle: the arm may be
//! holding something.

use nalgebra::Vector2;
use rover_sim::physics::{Twist, wrap_angle};

/// An object this far (m) or more from the fetch point is driven to before it is picked.
pub(super) const FETCH_FROM_M: f64 = 0.04;
/// The base stands this long (s) after a drive before it trusts a sighting or plans.
pub(super) const SETTLE_BASE_S: f64 = 0.6;
/// A drive that has not got there after this long (s of sim time) gives up.
pub(super) const MAX_DRIVE_S: f64 = 90.0;
/// How far (m) the base backs straight away from the object before it turns to the place: the
/// way it came in, clear of what the object stood on.
pub(super) const BACK_OFF_M: f64 = 0.3;

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
/// A heading within this (rad) of a stance's is there.
const ARRIVED_RAD: f64 = 0.02;
/// A stance behind the base and closer than this (m) is backed into rather than turned to.
const BACK_INTO_M: f64 = 0.5;

/// The base's go-to-point controller; it remembers its last command to limit accelerations.
#[derive(Debug, Clone, Default)]
pub(crate) struct DriveTo {
    last: Twist,
    last_s: Option<f64>,
    /// A pose drive has reached its point and turns to its heading (it goes back to the point
    /// only if it drifts three times the arrival distance off).
    turning: bool,
}

impl DriveTo {
    /// Forgets the last command (the next one starts from rest).
    pub(crate) fn reset(&mut self) {
        *self = Self::default();
    }

    /// Whether a pose drive has reached its point and turns to its heading.
    pub(crate) fn at_point(&self) -> bool {
        self.turning
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
        (self.limited(dt, speed, turn), false)
    }

    /// The command at `now_s` that brings the base to a pose: its origin to `stand` (base
    /// frame, m) and then its heading `turn_rad` further round (left positive), and whether it
    /// is there. For an arm that reaches to the side (Stretch's), whose goal cannot be met by
    /// a point's range and bearing: driving towards a point beside it only circles it. A
    /// stance a little behind is backed into.
    pub(crate) fn pose_command(
        &mut self,
        now_s: f64,
        stand: Vector2<f64>,
        turn_rad: f64,
    ) -> (Twist, bool) {
        let dt = self.last_s.map_or(0.0, |t| (now_s - t).max(0.0));
        self.last_s = Some(now_s);
        let range = stand.norm();
        self.turning = range <= ARRIVED_M * if self.turning { 3.0 } else { 1.0 };
        let (speed, turn) = if !self.turning {
            let bearing = stand.y.atan2(stand.x);
            let backing = range < BACK_INTO_M && bearing.abs() > std::f64::consts::FRAC_PI_2;
            let err = if backing {
                wrap_angle(bearing - std::f64::consts::PI)
            } else {
                bearing
            };
            let turn = (BEARING_GAIN * err).clamp(-MAX_TURN_RADPS, MAX_TURN_RADPS);
            let speed = if err.abs() > TURN_IN_PLACE_RAD {
                0.0
            } else if backing {
                -(RANGE_GAIN * range).min(MAX_BACK_MPS) * err.cos()
            } else {
                (RANGE_GAIN * range).min(MAX_SPEED_MPS) * err.cos()
            };
            (speed, turn)
        } else if turn_rad.abs() > ARRIVED_RAD {
            (
                0.0,
                (BEARING_GAIN * turn_rad).clamp(-MAX_TURN_RADPS, MAX_TURN_RADPS),
            )
        } else {
            self.last = Twist::ZERO;
            return (Twist::ZERO, true);
        };
        (self.limited(dt, speed, turn), false)
    }

    /// `speed` and `turn` reached from the last command within the acceleration limits over
    /// `dt`, remembered.
    fn limited(&mut self, dt: f64, speed: f64, turn: f64) -> Twist {
        let limit = |from: f64, to: f64, rate: f64| from + (to - from).clamp(-rate * dt, rate * dt);
        let cmd = Twist::new(
            limit(self.last.linear_mps, speed, MAX_ACCEL_MPS2),
            limit(self.last.angular_radps, turn, MAX_TURN_ACCEL_RADPS2),
        );
        self.last = cmd;
        cmd
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Drives a unicycle from the origin (heading +x) in 10 ms steps with `control`, given the
    /// time, the world point `target` in the unicycle's frame and its heading; where it is when
    /// `control` says it is there, or `None` after `steps` steps.
    fn drive_unicycle(
        target: Vector2<f64>,
        steps: u32,
        mut control: impl FnMut(f64, Vector2<f64>, f64) -> (Twist, bool),
    ) -> Option<(f64, f64, f64)> {
        let (mut x, mut y, mut yaw) = (0.0f64, 0.0f64, 0.0f64);
        let dt = 0.01;
        for i in 0..steps {
            let (dx, dy) = (target.x - x, target.y - y);
            let (s, c) = yaw.sin_cos();
            let local = Vector2::new(c * dx + s * dy, -s * dx + c * dy);
            let (cmd, there) = control(f64::from(i) * dt, local, yaw);
            if there {
                return Some((x, y, yaw));
            }
            x += cmd.linear_mps * yaw.cos() * dt;
            y += cmd.linear_mps * yaw.sin() * dt;
            yaw += cmd.angular_radps * dt;
        }
        None
    }

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
            let end = drive_unicycle(start, 6000, |t, point, _| drive.command(t, point, goal));
            assert!(end.is_some(), "from {start:?}: never arrived");
        }
    }

    /// Drives a unicycle to poses ahead, behind and beside it with the pose law: it ends
    /// within the arrival distance and heading.
    #[test]
    fn the_base_ends_at_a_pose_from_any_side() {
        for (goal, goal_yaw) in [
            (Vector2::new(1.2, 0.0), 0.0),
            (Vector2::new(-0.3, 0.02), 0.0),
            (Vector2::new(0.1, -0.6), 1.0),
        ] {
            let mut drive = DriveTo::default();
            let end = drive_unicycle(goal, 9000, |t, stand, yaw| {
                drive.pose_command(t, stand, wrap_angle(goal_yaw - yaw))
            });
            let Some((x, y, yaw)) = end else {
                panic!("to {goal:?}: never arrived");
            };
            assert!((goal - Vector2::new(x, y)).norm() < 0.03, "{x} {y}");
            assert!(wrap_angle(goal_yaw - yaw).abs() < 0.03, "{yaw}");
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
