//! The ground plan a drive and a stance are checked on: the car's body and the world's objects
//! as rectangles on the ground (their own axes, their yaw now), and the base's pose at a
//! stance.

use nalgebra::{Point3, Vector2, Vector3};
use rover_sim::{
    geometry::Shape,
    model::{LinkId, isometry_from_pose},
    physics::Simulation,
};

/// The car's body keeps this far (m) from anything standing round the object.
const BODY_CLEARANCE_M: f64 = 0.03;

/// A rectangle on the ground: centre, half sizes along its own axes and its yaw (world, m and
/// rad).
#[derive(Debug, Clone, Copy)]
pub(super) struct Footprint {
    pub(super) centre: Vector2<f64>,
    pub(super) half: Vector2<f64>,
    pub(super) yaw_rad: f64,
}

/// The arm base's pose on the ground (x, y, yaw) when the world point `target_xy` is at `at`
/// in its frame and it faces `yaw_rad`.
pub(super) fn stance_pose(
    target_xy: Vector2<f64>,
    at: Vector2<f64>,
    yaw_rad: f64,
) -> (Vector2<f64>, f64) {
    let (s, c) = yaw_rad.sin_cos();
    let at_world = Vector2::new(c * at.x - s * at.y, s * at.x + c * at.y);
    (target_xy - at_world, yaw_rad)
}

/// Whether a stance `at` (arm base frame) puts the object beside the base (its bearing beyond
/// 45 degrees): an arm that reaches to the side (Stretch's), whose base brings the object
/// beside it by driving along its own axis, keeping its heading.
pub(super) fn beside(at: Vector2<f64>) -> bool {
    at.y.atan2(at.x).abs() > std::f64::consts::FRAC_PI_4
}

/// The heading (world, rad) the base stands at for the stance `at`: `facing_rad` (the object
/// ahead, less the stance's bearing), or beside, the heading it has now, `base_yaw_rad`.
pub(super) fn stance_yaw(at: Vector2<f64>, facing_rad: f64, base_yaw_rad: f64) -> f64 {
    if beside(at) { base_yaw_rad } else { facing_rad }
}

/// The robot's root link's collision shapes, as a rectangle in the arm base's frame (inflated
/// by [`BODY_CLEARANCE_M`]); a mesh (Stretch's base) as the box round its hull. `None` when
/// it has none.
pub(super) fn body_footprint(sim: &Simulation, base: LinkId) -> Option<Footprint> {
    let robot = sim.robot();
    let base_from_root = isometry_from_pose(&sim.world_from_link(base)).inverse()
        * isometry_from_pose(&sim.world_from_link(robot.root));
    let mut lo = Vector2::repeat(f64::INFINITY);
    let mut hi = Vector2::repeat(f64::NEG_INFINITY);
    let mut add = |shape: &nalgebra::Isometry3<f64>, centre: Vector3<f64>, half: Vector3<f64>| {
        for (sx, sy, sz) in box_corners() {
            let corner =
                shape * Point3::from(centre + Vector3::new(sx * half.x, sy * half.y, sz * half.z));
            lo = lo.inf(&corner.coords.xy());
            hi = hi.sup(&corner.coords.xy());
        }
    };
    let collisions = &robot.links[robot.root.index()].collisions;
    for collision in collisions {
        if let Some(half) = half_extents(&collision.shape) {
            let shape = base_from_root * isometry_from_pose(&collision.link_from_shape);
            add(&shape, Vector3::zeros(), half);
        }
    }
    let meshes = collisions
        .iter()
        .any(|c| matches!(c.shape, Shape::Mesh { .. }));
    if meshes && let Ok(Some((a, b))) = sim.link_collision_box(robot.root) {
        let v = |p: [f32; 3]| Vector3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
        let (a, b) = (v(a), v(b));
        add(&base_from_root, (a + b) / 2.0, (b - a) / 2.0);
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
    pub(super) fn placed(&self, (xy, yaw_rad): &(Vector2<f64>, f64)) -> Self {
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

    /// How far its furthest corner is from its frame's origin (m): the circle round the arm
    /// base that holds the whole body.
    pub(super) fn far_corner_m(&self) -> f64 {
        (self.centre.abs() + self.half).norm()
    }

    /// How far the point `p` is from it (m; 0 inside).
    pub(super) fn distance_to(&self, p: Vector2<f64>) -> f64 {
        let [a, b] = self.axes();
        let d = p - self.centre;
        let out = Vector2::new(
            (a.dot(&d).abs() - self.half.x).max(0.0),
            (b.dot(&d).abs() - self.half.y).max(0.0),
        );
        out.norm()
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
pub(super) fn overlap(a: &Footprint, b: &Footprint) -> bool {
    let gap = b.centre - a.centre;
    a.axes()
        .iter()
        .chain(b.axes().iter())
        .all(|axis| gap.dot(axis).abs() <= a.reach_along(axis) + b.reach_along(axis))
}

/// The world's objects on the ground as rectangles (their own axes, their yaw now), but those
/// within `ignore_m` of the world point `ignore`; meshes are left out.
pub(super) fn obstacles(sim: &Simulation, ignore: Vector3<f64>, ignore_m: f64) -> Vec<Footprint> {
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
