//! Where the base stands when nobody said (no `fetch` point): the arm's reachability at the
//! height of what it must reach, surveyed by IK along a few bearings from the arm's base (a
//! reachability map, as a mobile manipulator chooses a base placement from one), passing over
//! stances where the car's body would stand in what surrounds the object.
//!
//! The survey solves each point once, without random restarts, seeded from the point before
//! on the same bearing: a few hundred IK solves of the arm's own chain, done when a pick finds
//! its object or its place out of reach (the planning time it says includes it).

use nalgebra::{Isometry3, Point3, Vector2, Vector3};
use rover_sim::{
    geometry::Shape,
    model::{IkOptions, IkSolver, isometry_from_pose},
    physics::Simulation,
};

use super::state::Pick;
use super::ways::ik_close;

/// Bearings surveyed (deg from the arm base's x, left positive), in order of preference on a
/// tie: straight ahead is where the base's go-to-point law ends most exactly.
const BEARINGS_DEG: [f64; 7] = [0.0, 10.0, -10.0, 20.0, -20.0, 30.0, -30.0];
/// Ranges surveyed from the arm's base (m).
const RANGES_M: (f64, f64) = (0.05, 1.2);
/// Spacing of the ranges surveyed (m).
const RANGE_STEP_M: f64 = 0.02;
/// The car's body keeps this far (m) from anything standing round the object.
const BODY_CLEARANCE_M: f64 = 0.03;
/// Ranges this close to the ends of a reachable run are not chosen (m): the base stops within
/// a couple of centimetres of its goal and the estimate is a centimetre off.
const RUN_MARGIN_M: f64 = 0.04;

/// A rectangle on the ground: centre, half sizes along its own axes and its yaw (world, m and
/// rad).
#[derive(Debug, Clone, Copy)]
struct Footprint {
    centre: Vector2<f64>,
    half: Vector2<f64>,
    yaw_rad: f64,
}

impl Pick {
    /// Whether the arm reaches something round of `radius_m` at `centre` (base frame) from its
    /// pose now, by IK alone, any way in.
    pub(super) fn reaches(
        &mut self,
        sim: &Simulation,
        centre: Vector3<f64>,
        radius_m: f64,
    ) -> bool {
        let q = self.chain_q(sim);
        let ways = self.ways_round(centre, radius_m);
        ways.iter().any(|way| {
            self.solver
                .solve(&way.target(centre), &q)
                .is_ok_and(|s| ik_close(s.position_error_m, s.orientation_error_rad))
        })
    }

    /// Where (arm base frame, x and y, m) the point `target` (base frame now, the base at
    /// `world_from_base`) should be when the base stops so the arm reaches it: on the bearing
    /// with the longest run of ranges the arm reaches round `radius_m` and the car's body stands
    /// clear of the world's objects (leaving out any within `ignore_m` of the world point
    /// `ignore`: the object itself, or the one in the hand), in the middle of that run.
    pub(super) fn choose_stance(
        &mut self,
        sim: &Simulation,
        (target, radius_m): (Vector3<f64>, f64),
        world_from_base: &Isometry3<f64>,
        (ignore, ignore_m): (Vector3<f64>, f64),
    ) -> Result<Vector2<f64>, String> {
        let mut survey = IkSolver::new(
            self.solver.chain().clone(),
            IkOptions {
                restarts: 0,
                tolerance_m: 5e-4,
                tolerance_rad: 5e-3,
                ..IkOptions::default()
            },
        )
        .map_err(|e| e.to_string())?;
        let target_world = world_from_base * Point3::from(target);
        let body = body_footprint(sim, self.base);
        let obstacles = obstacles(sim, ignore, ignore_m);
        let heading_rad = (target_world.y - world_from_base.translation.y)
            .atan2(target_world.x - world_from_base.translation.x);
        let q0 = self.chain_q(sim);
        let mut best: Option<(usize, Vector2<f64>)> = None;
        for bearing_deg in BEARINGS_DEG {
            let bearing = bearing_deg.to_radians();
            let (s, c) = bearing.sin_cos();
            let mut seed = q0.clone();
            let mut run: Vec<f64> = Vec::new();
            let mut longest: Vec<f64> = Vec::new();
            let steps = ((RANGES_M.1 - RANGES_M.0) / RANGE_STEP_M).round() as usize;
            for k in 0..=steps {
                let range = RANGES_M.0 + k as f64 * RANGE_STEP_M;
                let at = Vector2::new(c * range, s * range);
                let point = Vector3::new(at.x, at.y, target.z);
                let reached = self.ways_round(point, radius_m).iter().find_map(|way| {
                    let solution = survey.solve(&way.target(point), &seed).ok()?;
                    ik_close(solution.position_error_m, solution.orientation_error_rad)
                        .then_some(solution.q)
                });
                // The base facing the object less the bearing, the point brought to `at`.
                let yaw = heading_rad - bearing;
                let clear = body.is_some_and(|body| {
                    let stand = stance_pose(target_world.coords.xy(), at, yaw);
                    let body = body.placed(&stand);
                    obstacles.iter().all(|o| !overlap(&body, o))
                });
                match reached {
                    Some(q) if clear => {
                        seed = q;
                        run.push(range);
                    }
                    _ => {
                        if let Some(q) = reached {
                            seed = q;
                        }
                        if run.len() > longest.len() {
                            longest = std::mem::take(&mut run);
                        }
                        run.clear();
                    }
                }
            }
            if run.len() > longest.len() {
                longest = run;
            }
            let usable = longest.len() as f64 * RANGE_STEP_M - 2.0 * RUN_MARGIN_M;
            if usable <= 0.0 || best.as_ref().is_some_and(|(n, _)| *n >= longest.len()) {
                continue;
            }
            let middle = (longest[0] + longest[longest.len() - 1]) / 2.0;
            best = Some((longest.len(), Vector2::new(c * middle, s * middle)));
        }
        best.map(|(_, at)| at).ok_or_else(|| {
            format!(
                "no stance found: the arm reaches ({:.2}, {:.2}, {:.2}) m from nowhere the car's body stands clear (bearings {:?} deg, ranges {:.2}-{:.2} m)",
                target_world.x, target_world.y, target_world.z, BEARINGS_DEG, RANGES_M.0, RANGES_M.1
            )
        })
    }
}

/// The arm base's pose on the ground (x, y, yaw) when the world point `target_xy` is at `at`
/// in its frame and it faces `yaw_rad`.
fn stance_pose(target_xy: Vector2<f64>, at: Vector2<f64>, yaw_rad: f64) -> (Vector2<f64>, f64) {
    let (s, c) = yaw_rad.sin_cos();
    let at_world = Vector2::new(c * at.x - s * at.y, s * at.x + c * at.y);
    (target_xy - at_world, yaw_rad)
}

/// The robot's root link's collision shapes, as a rectangle in the arm base's frame (inflated
/// by [`BODY_CLEARANCE_M`]); `None` when it has none.
fn body_footprint(sim: &Simulation, base: rover_sim::model::LinkId) -> Option<Footprint> {
    let robot = sim.robot();
    let base_from_root = isometry_from_pose(&sim.world_from_link(base)).inverse()
        * isometry_from_pose(&sim.world_from_link(robot.root));
    let mut lo = Vector2::repeat(f64::INFINITY);
    let mut hi = Vector2::repeat(f64::NEG_INFINITY);
    for collision in &robot.links[robot.root.index()].collisions {
        let Some(half) = half_extents(&collision.shape) else {
            continue;
        };
        let shape = base_from_root * isometry_from_pose(&collision.link_from_shape);
        for (sx, sy, sz) in box_corners() {
            let corner = shape * Point3::new(sx * half.x, sy * half.y, sz * half.z);
            lo = lo.inf(&corner.coords.xy());
            hi = hi.sup(&corner.coords.xy());
        }
    }
    (lo.x.is_finite()).then(|| Footprint {
        centre: (lo + hi) / 2.0,
        half: (hi - lo) / 2.0 + Vector2::repeat(BODY_CLEARANCE_M),
        yaw_rad: 0.0,
    })
}

/// The eight corners of a unit box (signs).
fn box_corners() -> impl Iterator<Item = (f64, f64, f64)> {
    (0..8).map(|k| {
        let sign = |bit: i32| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
        (sign(0), sign(1), sign(2))
    })
}

/// A shape's half extents along its own axes (m); `None` for a mesh.
fn half_extents(shape: &Shape) -> Option<Vector3<f64>> {
    let v = |x: f32, y: f32, z: f32| Vector3::new(f64::from(x), f64::from(y), f64::from(z));
    match shape {
        Shape::Box { size_m } => Some(v(size_m.x, size_m.y, size_m.z) / 2.0),
        Shape::Sphere { radius_m } => Some(v(*radius_m, *radius_m, *radius_m)),
        Shape::Cylinder { radius_m, length_m } => Some(v(*radius_m, *radius_m, length_m / 2.0)),
        Shape::Capsule { radius_m, length_m } => {
            Some(v(*radius_m, *radius_m, length_m / 2.0 + radius_m))
        }
        Shape::Mesh { .. } => None,
    }
}

impl Footprint {
    /// This rectangle (arm base frame) with the base at `(xy, yaw)` in the world.
    fn placed(&self, (xy, yaw_rad): &(Vector2<f64>, f64)) -> Self {
        let (s, c) = yaw_rad.sin_cos();
        let centre = xy
            + Vector2::new(
                c * self.centre.x - s * self.centre.y,
                s * self.centre.x + c * self.centre.y,
            );
        Self {
            centre,
            half: self.half,
            yaw_rad: self.yaw_rad + yaw_rad,
        }
    }

    /// Its two axes (unit, world).
    fn axes(&self) -> [Vector2<f64>; 2] {
        let (s, c) = self.yaw_rad.sin_cos();
        [Vector2::new(c, s), Vector2::new(-s, c)]
    }

    /// Half its extent along the unit direction `d`.
    fn reach_along(&self, d: &Vector2<f64>) -> f64 {
        let [a, b] = self.axes();
        self.half.x * a.dot(d).abs() + self.half.y * b.dot(d).abs()
    }
}

/// Whether two rectangles overlap (separating axes).
fn overlap(a: &Footprint, b: &Footprint) -> bool {
    let gap = b.centre - a.centre;
    a.axes()
        .iter()
        .chain(b.axes().iter())
        .all(|axis| gap.dot(axis).abs() <= a.reach_along(axis) + b.reach_along(axis))
}

/// The world's objects on the ground as rectangles (their own axes, their yaw now), but those
/// within `ignore_m` of the world point `ignore`; meshes are left out.
fn obstacles(sim: &Simulation, ignore: Vector3<f64>, ignore_m: f64) -> Vec<Footprint> {
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    (sim.world().objects.iter())
        .zip(&poses)
        .filter_map(|(object, pose)| {
            let half = half_extents(&object.shape)?;
            let centre = isometry_from_pose(pose).translation.vector;
            if (centre - ignore).norm() <= ignore_m {
                return None;
            }
            let yaw_rad = isometry_from_pose(pose).rotation.euler_angles().2;
            Some(Footprint {
                centre: centre.xy(),
                half: half.xy(),
                yaw_rad,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangles_overlap_unless_an_axis_separates_them() {
        let square = |x: f64, y: f64, yaw_rad: f64| Footprint {
            centre: Vector2::new(x, y),
            half: Vector2::new(0.5, 0.5),
            yaw_rad,
        };
        assert!(overlap(&square(0.0, 0.0, 0.0), &square(0.9, 0.0, 0.0)));
        assert!(!overlap(&square(0.0, 0.0, 0.0), &square(1.1, 0.0, 0.0)));
        // Turned 45 degrees, its corner reaches 0.707 m: 1.1 m apart it still touches, 1.3 m
        // apart it does not.
        let turned = std::f64::consts::FRAC_PI_4;
        assert!(overlap(&square(0.0, 0.0, 0.0), &square(1.1, 0.0, turned)));
        assert!(!overlap(&square(0.0, 0.0, 0.0), &square(1.3, 0.0, turned)));
    }

    #[test]
    fn the_stance_pose_brings_the_target_to_its_point() {
        let target = Vector2::new(2.0, 1.0);
        let at = Vector2::new(0.3, 0.1);
        let yaw = 0.7f64;
        let (xy, _) = stance_pose(target, at, yaw);
        let (s, c) = yaw.sin_cos();
        let d = target - xy;
        let in_base = Vector2::new(c * d.x + s * d.y, -s * d.x + c * d.y);
        assert!((in_base - at).norm() < 1e-12, "{in_base:?}");
    }
}
