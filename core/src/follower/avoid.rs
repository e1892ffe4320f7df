//! Obstacle avoidance for the follower: a dynamic-window search over (linear, angular) commands,
//! each rolled out as a constant-velocity arc and checked against the newest laser returns.
//!
//! The follower's own command (steer to the target, keep the standoff) is kept whenever its arc
//! stays well clear of every return. Otherwise the arcs of a window of commands are scored by
//! how they head toward the target, how much nearer they bring the robot, how much room they
//! leave and how fast they go; arcs that come closer than the hard margin are never taken.
//! Obstacles are points in the robot's base frame (x forward, y left), the robot a circle.

use rover_sim::physics::{Twist, wrap_angle};

/// Avoidance settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AvoidConfig {
    /// Radius of a circle around the base origin that holds the robot's footprint (m).
    pub robot_radius_m: f64,
    /// Arcs passing closer than this to a return (beyond the robot's radius) are never taken (m).
    pub hard_margin_m: f64,
    /// The follower's own command is kept when its arc stays this clear (m).
    pub free_margin_m: f64,
    /// How far ahead arcs are rolled out (s)...
    pub horizon_s: f64,
    /// ... and at least this far along the arc (m): a slow arc is not safe just because it
    /// is short.
    pub lookahead_m: f64,
}

impl Default for AvoidConfig {
    fn default() -> Self {
        Self {
            robot_radius_m: 0.25,
            hard_margin_m: 0.17,
            free_margin_m: 0.3,
            horizon_s: 2.0,
            lookahead_m: 1.5,
        }
    }
}

/// Rollout step (s).
const STEP_S: f64 = 0.1;
/// Longest rollout (s).
const MAX_ROLLOUT_S: f64 = 6.0;

/// How long an arc at `linear_mps` is rolled out (s).
fn rollout_s(linear_mps: f64, config: &AvoidConfig) -> f64 {
    let v = linear_mps.abs();
    if v < 1e-6 {
        0.0
    } else {
        (config.lookahead_m / v).clamp(config.horizon_s, MAX_ROLLOUT_S)
    }
}
/// Linear speeds tried, as fractions of the allowed maximum.
const SPEED_FRACTIONS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];
/// Angular speeds tried across [-max, max].
const TURN_SAMPLES: usize = 17;

/// What the avoidance decided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Avoided {
    /// The command to send.
    pub cmd: Twist,
    /// Whether it differs from the follower's own command (an obstacle was in the way).
    pub steering: bool,
    /// Smallest gap (m) between the robot's circle and a return along the chosen arc.
    pub clearance_m: f64,
}

/// Smallest gap (m) between the robot circle and any obstacle where it is now.
fn clearance_here_m(obstacles: &[[f64; 2]], config: &AvoidConfig) -> f64 {
    let nearest = obstacles
        .iter()
        .map(|o| o[0] * o[0] + o[1] * o[1])
        .fold(f64::INFINITY, f64::min);
    nearest.sqrt() - config.robot_radius_m
}

/// Smallest gap (m) between the robot circle and any obstacle along the arc of `cmd`, from its
/// first step on (where the robot is now is [`clearance_here_m`]; a turn in place stays there).
fn arc_clearance_m(cmd: Twist, obstacles: &[[f64; 2]], config: &AvoidConfig) -> f64 {
    if cmd.linear_mps == 0.0 {
        return clearance_here_m(obstacles, config);
    }
    let steps = (rollout_s(cmd.linear_mps, config) / STEP_S).ceil() as usize;
    let (mut x, mut y, mut yaw) = (0.0f64, 0.0f64, 0.0f64);
    let mut nearest = f64::INFINITY;
    for step in 1..=steps {
        if step > 0 {
            // Exact integration of a constant (v, w) over one step.
            let w = cmd.angular_radps;
            let v = cmd.linear_mps;
            if w.abs() < 1e-6 {
                x += v * STEP_S * yaw.cos();
                y += v * STEP_S * yaw.sin();
            } else {
                let next = yaw + w * STEP_S;
                x += v / w * (next.sin() - yaw.sin());
                y -= v / w * (next.cos() - yaw.cos());
                yaw = next;
            }
        }
        for o in obstacles {
            let d2 = (o[0] - x).powi(2) + (o[1] - y).powi(2);
            if d2 < nearest {
                nearest = d2;
            }
        }
    }
    nearest.sqrt() - config.robot_radius_m
}

impl AvoidConfig {
    /// Picks the command: `preferred` when its arc is free, else the best admissible arc toward
    /// `goal_m` (base frame) with forward speed at most `max_linear_mps` and turn rate within
    /// `max_turn_radps`. `side` (+1 left, -1 right, 0 none) is the way around the obstacle chosen
    /// before: keeping to it stops the robot from dithering between two equally good ways. With no
    /// admissible arc the robot turns in place toward a free direction, or stops.
    pub fn choose(
        &self,
        preferred: Twist,
        goal_m: [f64; 2],
        obstacles: &[[f64; 2]],
        max_linear_mps: f64,
        max_turn_radps: f64,
        side: f64,
    ) -> Avoided {
        let config = self;
        let own = arc_clearance_m(preferred, obstacles, config);
        // While going around something (a side chosen), the follower's own command must be clearly
        // free to take over again: no flipping between it and the detour.
        let free = if side == 0.0 {
            config.free_margin_m
        } else {
            config.free_margin_m + 0.3
        };
        if own >= free || (preferred.linear_mps == 0.0 && own >= 0.02 && side == 0.0) {
            return Avoided {
                cmd: preferred,
                steering: false,
                clearance_m: own,
            };
        }
        if preferred.linear_mps < 0.0 {
            // Backing away (from a person who comes too close) is only ever the follower's own
            // straight-ish command: blocked behind, it stands (turning if that is free).
            let turn = Twist::new(0.0, preferred.angular_radps);
            let room = arc_clearance_m(turn, obstacles, config);
            return Avoided {
                cmd: if room >= 0.02 { turn } else { Twist::ZERO },
                steering: true,
                clearance_m: room,
            };
        }
        let goal_distance = goal_m[0].hypot(goal_m[1]);
        // Already inside the margin (pushed there, or the obstacle came closer): arcs that do not
        // come closer still than now are the way out.
        let here = clearance_here_m(obstacles, config);
        let floor = config.hard_margin_m.min(here - 0.01);
        let reach = config.lookahead_m.max(1e-3);
        let mut best: Option<(f64, Twist, f64)> = None;
        for fraction in SPEED_FRACTIONS {
            let v = fraction * max_linear_mps.max(0.0);
            for k in 0..TURN_SAMPLES {
                let w = max_turn_radps * (2.0 * k as f64 / (TURN_SAMPLES - 1) as f64 - 1.0);
                let cmd = Twist::new(v, w);
                let clearance = arc_clearance_m(cmd, obstacles, config);
                if v <= 0.0 || clearance < floor {
                    continue;
                }
                // Where the arc ends (constant v, w over the rollout).
                let t = rollout_s(v, config).max(config.horizon_s);
                let (ex, ey, eyaw) = if w.abs() < 1e-6 {
                    (v * t, 0.0, 0.0)
                } else {
                    let yaw = w * t;
                    (v / w * yaw.sin(), v / w * (1.0 - yaw.cos()), yaw)
                };
                let to_goal = wrap_angle((goal_m[1] - ey).atan2(goal_m[0] - ex) - eyaw);
                let heading = 1.0 - to_goal.abs() / std::f64::consts::PI;
                let progress = (goal_distance - (goal_m[0] - ex).hypot(goal_m[1] - ey)) / reach;
                let room = clearance.min(1.0);
                let keep_side = if side != 0.0 && w.abs() > 1e-6 && w.signum() == side {
                    0.3
                } else {
                    0.0
                };
                let score = heading + progress + 0.4 * room + 0.5 * fraction + keep_side
                    - 0.1 * (w - preferred.angular_radps).abs() / max_turn_radps.max(1e-3);
                if best.as_ref().is_none_or(|(s, _, _)| score > *s) {
                    best = Some((score, cmd, clearance));
                }
            }
        }
        if let Some((_, cmd, clearance_m)) = best {
            return Avoided {
                cmd,
                steering: true,
                clearance_m,
            };
        }
        // No arc that moves is free from here: turn in place toward the free direction that leads
        // most toward the target (a wall ahead: face along it, to its end), while nothing touches.
        let heading = free_heading_rad(goal_m, obstacles, floor, side, config)
            .unwrap_or_else(|| goal_m[1].atan2(goal_m[0]));
        let turn = Twist::new(0.0, (2.0 * heading).clamp(-max_turn_radps, max_turn_radps));
        let room = arc_clearance_m(turn, obstacles, config);
        Avoided {
            cmd: if room >= 0.02 { turn } else { Twist::ZERO },
            steering: true,
            clearance_m: room,
        }
    }
}

/// Headings tried by [`free_heading_rad`] (every 5 deg).
const HEADINGS: usize = 72;

/// The heading (rad, base frame) of a straight path that stays `floor` clear for the lookahead
/// distance and points most toward `goal_m` (on `side` when one was chosen: +1 left, -1 right);
/// None when every direction is blocked.
fn free_heading_rad(
    goal_m: [f64; 2],
    obstacles: &[[f64; 2]],
    floor: f64,
    side: f64,
    config: &AvoidConfig,
) -> Option<f64> {
    let goal_bearing = goal_m[1].atan2(goal_m[0]);
    let steps = (config.lookahead_m / 0.1).ceil() as usize;
    let mut best: Option<(f64, f64)> = None;
    for k in 0..HEADINGS {
        let heading = wrap_angle(k as f64 * std::f64::consts::TAU / HEADINGS as f64);
        let (s, c) = heading.sin_cos();
        let mut nearest = f64::INFINITY;
        for step in 1..=steps {
            let d = step as f64 * 0.1;
            let (x, y) = (d * c, d * s);
            for o in obstacles {
                nearest = nearest.min((o[0] - x).powi(2) + (o[1] - y).powi(2));
            }
        }
        if nearest.sqrt() - config.robot_radius_m < floor {
            continue;
        }
        let off = wrap_angle(heading - goal_bearing);
        let on_side = side != 0.0 && off.abs() > 1e-6 && off.signum() == side;
        let score = off.cos() + if on_side { 0.5 } else { 0.0 };
        if best.is_none_or(|(b, _)| score > b) {
            best = Some((score, heading));
        }
    }
    best.map(|(_, h)| h)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Returns from the face of a 0.6 m box whose near side is `ahead_m` in front.
    fn crate_ahead(ahead_m: f64) -> Vec<[f64; 2]> {
        let mut points = Vec::new();
        for i in 0..=12 {
            let y = -0.3 + 0.05 * f64::from(i);
            points.push([ahead_m, y]);
        }
        points
    }

    #[test]
    fn a_free_path_keeps_the_followers_command() {
        let cmd = Twist::new(0.5, 0.1);
        let out = AvoidConfig::default().choose(cmd, [4.0, 0.0], &[[0.0, 3.0]], 0.8, 1.0, 0.0);
        assert_eq!(out.cmd, cmd);
        assert!(!out.steering);
    }

    #[test]
    fn an_obstacle_in_the_way_is_passed_with_room_to_spare() {
        let config = AvoidConfig::default();
        let obstacles = crate_ahead(1.2);
        let straight = Twist::new(0.8, 0.0);
        assert!(arc_clearance_m(straight, &obstacles, &config) < 0.0);
        let out = config.choose(straight, [4.0, 0.0], &obstacles, 0.8, 1.0, 0.0);
        assert!(out.steering);
        assert!(out.cmd.angular_radps.abs() > 0.1, "{out:?}");
        assert!(out.clearance_m >= config.hard_margin_m, "{out:?}");
        assert!(out.cmd.linear_mps > 0.0, "{out:?}");
    }

    #[test]
    fn boxed_in_it_stops_rather_than_touches() {
        let config = AvoidConfig::default();
        let mut ring = Vec::new();
        for i in 0..72 {
            let a = f64::from(i) * 5f64.to_radians();
            ring.push([0.26 * a.cos(), 0.26 * a.sin()]);
        }
        let out = config.choose(Twist::new(0.5, 0.0), [4.0, 0.0], &ring, 0.8, 1.0, 0.0);
        assert_eq!(out.cmd.linear_mps, 0.0);
        assert_eq!(out.cmd.angular_radps, 0.0, "touching: not even a turn");
        // With room to turn but none to drive: turn toward the target.
        let mut wide = Vec::new();
        for i in 0..72 {
            let a = f64::from(i) * 5f64.to_radians();
            wide.push([0.5 * a.cos(), 0.5 * a.sin()]);
        }
        let out = config.choose(Twist::new(0.5, 0.0), [1.0, 4.0], &wide, 0.8, 1.0, 0.0);
        assert_eq!(out.cmd.linear_mps, 0.0);
        assert!(out.cmd.angular_radps > 0.0, "{out:?}");
    }

    #[test]
    fn facing_a_wall_it_turns_toward_the_walls_open_end() {
        // A wall 0.45 m ahead from y = -1.2 to y = 0.5; the target beyond it, dead ahead.
        let config = AvoidConfig::default();
        let wall: Vec<[f64; 2]> = (0..=34)
            .map(|i| [0.45, -1.2 + 0.05 * f64::from(i)])
            .collect();
        let out = config.choose(Twist::new(0.5, 0.0), [3.0, 0.0], &wall, 0.8, 1.2, 0.0);
        assert!(
            out.cmd.angular_radps > 0.1,
            "turns left, to the open end: {out:?}"
        );
        // Having chosen to go right, it keeps to the right.
        let out = config.choose(Twist::new(0.5, 0.0), [3.0, 0.0], &wall, 0.8, 1.2, -1.0);
        assert!(out.cmd.angular_radps < -0.1, "keeps its side: {out:?}");
    }
}
