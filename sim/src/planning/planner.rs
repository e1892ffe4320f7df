//! Motion planning in an arm's joint space: RRT-Connect (Kuffner and LaValle, 2000, OMPL's
//! default planner in MoveIt) between two configurations, each edge checked at a fine step by
//! the caller's collision check, the path then shortened by shortcutting; and the time
//! parameterisation that executes a path within the joints' velocity limits
//! ([`TimedPath`]). Written here rather than taken from a crate: the Rust planning crates
//! (e.g. `pathfinding`) work on graphs, not on a continuous space with a collision callback,
//! and the whole of RRT-Connect is a page.

use crate::model::kinematics::ChainJoint;
use crate::noise::SplitMix64;

/// Planner settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannerOptions {
    /// Largest step of one joint along an edge between two checks (rad or m).
    pub check_step: f64,
    /// Longest extension of a tree toward a sample (the largest joint change, rad or m).
    pub extend_step: f64,
    /// Samples before giving up.
    pub max_samples: usize,
    /// Shortcut attempts on the found path.
    pub shortcuts: usize,
    /// Seed of the samples (the same seed, the same path).
    pub seed: u64,
}

impl Default for PlannerOptions {
    fn default() -> Self {
        Self {
            check_step: 0.02,
            extend_step: 0.3,
            max_samples: 4000,
            shortcuts: 60,
            seed: 0,
        }
    }
}

/// Why no path was found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The start configuration collides (what with, in words).
    #[error("the start collides: {0}")]
    StartInCollision(String),
    /// The goal configuration collides.
    #[error("the goal collides: {0}")]
    GoalInCollision(String),
    /// The samples ran out.
    #[error("no collision-free path found in {0} samples")]
    NotFound(usize),
    /// The start or goal has the wrong number of joints, or is not finite.
    #[error("bad configuration: {0}")]
    BadConfiguration(String),
}

/// A tree of configurations.
struct Tree {
    nodes: Vec<Vec<f64>>,
    parents: Vec<usize>,
}

impl Tree {
    fn new(root: &[f64]) -> Self {
        Self {
            nodes: vec![root.to_vec()],
            parents: vec![0],
        }
    }

    fn nearest(&self, q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = distance(n, q);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// The path from the root to node `i`.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut path = vec![self.nodes[i].clone()];
        while i != 0 {
            i = self.parents[i];
            path.push(self.nodes[i].clone());
        }
        path.reverse();
        path
    }
}

/// The largest joint change between two configurations.
fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Whether the straight edge from `a` to `b` is free, checked every `step`.
fn edge_free(a: &[f64], b: &[f64], step: f64, free: &mut impl FnMut(&[f64]) -> bool) -> bool {
    let n = (distance(a, b) / step).ceil().max(1.0) as usize;
    let mut q = a.to_vec();
    (1..=n).all(|k| {
        let s = k as f64 / n as f64;
        for ((q, a), b) in q.iter_mut().zip(a).zip(b) {
            *q = a + (b - a) * s;
        }
        free(&q)
    })
}

/// How an extension ended.
enum Extend {
    Reached(usize),
    Advanced(usize),
    Trapped,
}

/// Extends `tree` from its node nearest `target` by at most the extension step.
fn extend(
    tree: &mut Tree,
    target: &[f64],
    options: &PlannerOptions,
    free: &mut impl FnMut(&[f64]) -> bool,
) -> Extend {
    let near = tree.nearest(target);
    let from = tree.nodes[near].clone();
    let d = distance(&from, target);
    let (to, reached) = if d <= options.extend_step {
        (target.to_vec(), true)
    } else {
        let s = options.extend_step / d;
        (
            from.iter()
                .zip(target)
                .map(|(a, b)| a + (b - a) * s)
                .collect(),
            false,
        )
    };
    if !edge_free(&from, &to, options.check_step, free) {
        return Extend::Trapped;
    }
    tree.nodes.push(to);
    tree.parents.push(near);
    let i = tree.nodes.len() - 1;
    if reached {
        Extend::Reached(i)
    } else {
        Extend::Advanced(i)
    }
}

/// A collision-free path from `start` to `goal` (both the chain's joints, within `joints`'
/// limits) by RRT-Connect, shortcut. `check(q)` says what `q` hits (`None`: free).
pub fn plan_path(
    joints: &[ChainJoint],
    start: &[f64],
    goal: &[f64],
    options: &PlannerOptions,
    mut check: impl FnMut(&[f64]) -> Option<String>,
) -> Result<Vec<Vec<f64>>, PlanError> {
    for (what, q) in [("start", start), ("goal", goal)] {
        if q.len() != joints.len() || !q.iter().all(|v| v.is_finite()) {
            return Err(PlanError::BadConfiguration(format!(
                "the {what} has {} values for {} joints, or one is not finite",
                q.len(),
                joints.len()
            )));
        }
    }
    if let Some(hit) = check(start) {
        return Err(PlanError::StartInCollision(hit));
    }
    if let Some(hit) = check(goal) {
        return Err(PlanError::GoalInCollision(hit));
    }
    let mut free = |q: &[f64]| check(q).is_none();
    if edge_free(start, goal, options.check_step, &mut free) {
        return Ok(vec![start.to_vec(), goal.to_vec()]);
    }
    let mut rng = SplitMix64(options.seed);
    let mut trees = (Tree::new(start), Tree::new(goal));
    let mut forward = true;
    let mut sample = vec![0.0; joints.len()];
    for _ in 0..options.max_samples {
        for (q, j) in sample.iter_mut().zip(joints) {
            let (lo, hi) = (
                j.lower.max(-std::f64::consts::PI),
                j.upper.min(std::f64::consts::PI),
            );
            *q = lo + (hi - lo) * rng.unit();
        }
        let (a, b) = if forward {
            (&mut trees.0, &mut trees.1)
        } else {
            (&mut trees.1, &mut trees.0)
        };
        let new = match extend(a, &sample, options, &mut free) {
            Extend::Trapped => {
                forward = !forward;
                continue;
            }
            Extend::Advanced(i) | Extend::Reached(i) => i,
        };
        let target = a.nodes[new].clone();
        // Connect: the other tree grows toward the new node until it gets there or is stopped.
        let joined = loop {
            match extend(b, &target, options, &mut free) {
                Extend::Reached(j) => break Some(j),
                Extend::Advanced(_) => {}
                Extend::Trapped => break None,
            }
        };
        if let Some(j) = joined {
            let (from_a, from_b) = (a.path_to(new), b.path_to(j));
            let (mut path, other) = if forward {
                (from_a, from_b)
            } else {
                (from_b, from_a)
            };
            path.extend(other.into_iter().rev().skip(1));
            shortcut(&mut path, options, &mut rng, &mut free);
            return Ok(path);
        }
        forward = !forward;
    }
    Err(PlanError::NotFound(options.max_samples))
}

/// Shortens a path: random pairs of points joined straight where that edge is free, then
/// every point that its neighbours can do without.
fn shortcut(
    path: &mut Vec<Vec<f64>>,
    options: &PlannerOptions,
    rng: &mut SplitMix64,
    free: &mut impl FnMut(&[f64]) -> bool,
) {
    for _ in 0..options.shortcuts {
        if path.len() < 3 {
            return;
        }
        let n = path.len();
        let i = ((rng.unit() * n as f64) as usize).min(n - 1);
        let j = ((rng.unit() * n as f64) as usize).min(n - 1);
        let (i, j) = (i.min(j), i.max(j));
        if j > i + 1 && edge_free(&path[i], &path[j], options.check_step, free) {
            path.drain(i + 1..j);
        }
    }
    let mut i = 0;
    while i + 2 < path.len() {
        if edge_free(&path[i], &path[i + 2], options.check_step, free) {
            path.remove(i + 1);
        } else {
            i += 1;
        }
    }
}

/// A path through joint-space waypoints timed within the joints' velocity limits: one
/// trapezoidal profile along the whole path (`stop_at_waypoints` false: for close waypoints
/// such as a straight-line move's) or one per segment, stopping at each waypoint (a planner's
/// corners).
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    waypoints: Vec<Vec<f64>>,
    /// Per segment: its start on the path (s) and its length (s at full speed).
    segments: Vec<(f64, f64)>,
    /// Per profile: the segments it covers, when it starts (s of time), its length and
    /// duration.
    profiles: Vec<Profile>,
    accel: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Profile {
    first: usize,
    last: usize,
    start_s: f64,
    length: f64,
    duration_s: f64,
}

impl Profile {
    /// Trapezoid with top speed 1 and acceleration `a` over `length`: (position, speed) at
    /// `t` (s from its start).
    fn sample(&self, a: f64, t: f64) -> (f64, f64) {
        let t = t.clamp(0.0, self.duration_s);
        let ramp = (1.0 / a).min((self.length / a).sqrt());
        let top = a * ramp;
        let cruise = self.duration_s - 2.0 * ramp;
        if t < ramp {
            (0.5 * a * t * t, a * t)
        } else if t < ramp + cruise {
            (0.5 * top * ramp + top * (t - ramp), top)
        } else {
            let r = self.duration_s - t;
            (self.length - 0.5 * a * r * r, a * r)
        }
    }

    fn new(first: usize, last: usize, start_s: f64, length: f64, a: f64) -> Self {
        let ramp = (1.0 / a).min((length / a).sqrt());
        let top = a * ramp;
        let duration_s = if top > 0.0 {
            2.0 * ramp + (length - top * ramp).max(0.0) / top
        } else {
            0.0
        };
        Self {
            first,
            last,
            start_s,
            length,
            duration_s,
        }
    }
}

impl TimedPath {
    /// Times `waypoints` (at least one) for `joints`: each joint at most `speed_scale` of its
    /// velocity limit (joints without one: 1 rad/s or m/s), reaching full speed in
    /// `ramp_s` seconds.
    pub fn new(
        waypoints: Vec<Vec<f64>>,
        joints: &[ChainJoint],
        speed_scale: f64,
        ramp_s: f64,
        stop_at_waypoints: bool,
    ) -> Self {
        let speed: Vec<f64> = joints
            .iter()
            .map(|j| j.velocity_limit.unwrap_or(1.0) * speed_scale.clamp(1e-3, 1.0))
            .collect();
        let mut segments = Vec::new();
        let mut at = 0.0;
        for w in waypoints.windows(2) {
            let length = w[0]
                .iter()
                .zip(&w[1])
                .zip(&speed)
                .map(|((a, b), v)| (b - a).abs() / v)
                .fold(0.0, f64::max);
            segments.push((at, length));
            at += length;
        }
        let accel = 1.0 / ramp_s.max(1e-3);
        let mut profiles = Vec::new();
        if stop_at_waypoints {
            let mut start_s = 0.0;
            for (i, (_, length)) in segments.iter().enumerate() {
                let p = Profile::new(i, i, start_s, *length, accel);
                start_s += p.duration_s;
                profiles.push(p);
            }
        } else if !segments.is_empty() {
            profiles.push(Profile::new(0, segments.len() - 1, 0.0, at, accel));
        }
        Self {
            waypoints,
            segments,
            profiles,
            accel,
        }
    }

    /// How long it takes (s).
    pub fn duration_s(&self) -> f64 {
        self.profiles
            .last()
            .map_or(0.0, |p| p.start_s + p.duration_s)
    }

    /// The waypoints.
    pub fn waypoints(&self) -> &[Vec<f64>] {
        &self.waypoints
    }

    /// Positions and velocities at `t_s` from the start into `q` and `v` (the chain's joints;
    /// the last waypoint, at rest, after the end).
    pub fn sample(&self, t_s: f64, q: &mut Vec<f64>, v: &mut Vec<f64>) {
        q.clear();
        v.clear();
        let Some(last) = self.waypoints.last() else {
            return;
        };
        let profile = self
            .profiles
            .iter()
            .rev()
            .find(|p| t_s >= p.start_s)
            .or(self.profiles.first());
        let Some(p) = profile.filter(|p| t_s < p.start_s + p.duration_s) else {
            q.extend_from_slice(last);
            v.resize(last.len(), 0.0);
            return;
        };
        let (s_local, speed) = p.sample(self.accel, t_s - p.start_s);
        let s = self.segments[p.first].0 + s_local;
        let k = (p.first..=p.last)
            .find(|&k| s < self.segments[k].0 + self.segments[k].1)
            .unwrap_or(p.last);
        let (start, length) = self.segments[k];
        let f = if length > 0.0 {
            ((s - start) / length).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (a, b) = (&self.waypoints[k], &self.waypoints[k + 1]);
        for (x, y) in a.iter().zip(b) {
            q.push(x + (y - x) * f);
            v.push(if length > 0.0 {
                (y - x) / length * speed
            } else {
                0.0
            });
        }
    }
}

#[cfg(test)]
#[allow(
    clippy::expect_used,
    reason = "tests: a failed expect is a failed test"
)]
mod tests {
    use super::*;
    use crate::model::kinematics::KinematicChain;

    /// A chain of `n` revolute joints about z, each within ±3 rad at 1 rad/s at most.
    fn joints(n: usize) -> Vec<ChainJoint> {
        let links: String = (0..=n).map(|i| format!("<link name=\"l{i}\"/>")).collect();
        let joints: String = (0..n)
            .map(|i| {
                format!(
                    "<joint name=\"j{i}\" type=\"revolute\"><parent link=\"l{i}\"/><child link=\"l{}\"/><axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>",
                    i + 1
                )
            })
            .collect();
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("chain.urdf");
        std::fs::write(
            &path,
            format!("<robot name=\"chain\">{links}{joints}</robot>"),
        )
        .expect("write");
        let robot = crate::model::robot::RobotModel::load(&path).expect("chain loads");
        KinematicChain::new(&robot, "l0", &format!("l{n}"))
            .expect("chain")
            .joints()
            .to_vec()
    }

    /// A wall across the plane at x in [0.5, 0.7], open above y = 1.5: the planner goes
    /// round it, every point of its path free, and the same seed gives the same path.
    #[test]
    fn rrt_connect_goes_round_a_wall_and_repeats_itself() {
        let j = joints(2);
        let wall =
            |q: &[f64]| (q[0] > 0.5 && q[0] < 0.7 && q[1] < 1.5).then(|| "the wall".to_owned());
        let plan = || {
            plan_path(
                &j,
                &[0.0, 0.0],
                &[1.2, 0.0],
                &PlannerOptions::default(),
                wall,
            )
            .expect("a path")
        };
        let path = plan();
        assert!(path.len() >= 3, "{path:?}");
        let mut free = |q: &[f64]| wall(q).is_none();
        for w in path.windows(2) {
            assert!(edge_free(&w[0], &w[1], 0.01, &mut free), "{w:?}");
        }
        assert_eq!(path, plan());
        assert!(matches!(
            plan_path(
                &j,
                &[0.6, 0.0],
                &[1.2, 0.0],
                &PlannerOptions::default(),
                wall
            ),
            Err(PlanError::StartInCollision(_))
        ));
        let boxed = |q: &[f64]| (q[0] > 0.5).then(|| "everything".to_owned());
        assert!(matches!(
            plan_path(&j, &[0.0, 0.0], &[0.4, 0.0], &PlannerOptions::default(), boxed),
            Ok(p) if p.len() == 2
        ));
    }

    /// The timed path starts and ends at rest on its waypoints, and no joint goes faster than
    /// its scaled limit.
    #[test]
    fn timed_paths_keep_to_the_velocity_limits() {
        let j = joints(2);
        let waypoints = vec![vec![0.0, 0.0], vec![1.0, 0.2], vec![1.0, -0.5]];
        for stop in [false, true] {
            let path = TimedPath::new(waypoints.clone(), &j, 0.5, 0.2, stop);
            assert!(path.duration_s() > 3.4, "{}", path.duration_s());
            let (mut q, mut v) = (Vec::new(), Vec::new());
            path.sample(0.0, &mut q, &mut v);
            assert_eq!(q, vec![0.0, 0.0]);
            path.sample(path.duration_s() + 1.0, &mut q, &mut v);
            assert_eq!((q.clone(), v.clone()), (vec![1.0, -0.5], vec![0.0, 0.0]));
            let mut t = 0.0;
            let mut last = vec![0.0, 0.0];
            while t < path.duration_s() {
                path.sample(t, &mut q, &mut v);
                assert!(v.iter().all(|v| v.abs() <= 0.5 + 1e-9), "{t}: {v:?}");
                for (a, b) in q.iter().zip(&last) {
                    assert!(
                        (a - b).abs() <= 0.5 * 0.01 + 1e-9,
                        "{t}: {q:?} after {last:?}"
                    );
                }
                last.clone_from(&q);
                t += 0.01;
            }
        }
    }
}
