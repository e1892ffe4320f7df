//! The world's named objects as the pick finds them: a shape and its pose now, or an error
//! listing the names there are; and the place the pick puts what it took on.

use rover_sim::{
    geometry::{Pose, Shape},
    model::Place,
    physics::Simulation,
};

use super::plan::SET_DOWN_M;
use super::state::Pick;

impl Pick {
    /// The place: the configured one, else the world's `[robot] place`.
    fn place(&self, sim: &Simulation) -> Option<Place> {
        (self.config.place.clone()).or_else(|| sim.world().robot.place.clone())
    }

    /// Where the object's bottom goes (world frame), how high above that the carry ends, and
    /// how far the hand then goes straight down before letting go (m): over a world object's
    /// top centre, [`PickConfig::drop_height_m`] and no further (dropped into a bin, onto a
    /// tray); at a point, [`PickConfig::approach_m`], then down to [`SET_DOWN_M`] above it (set
    /// down, as MoveIt's place approaches). From the configured place, else the world's
    /// `[robot] place`; none: the object is held up. An error for an object the world lacks.
    pub(super) fn place_under(
        &self,
        sim: &Simulation,
    ) -> Result<Option<([f64; 3], f64, f64)>, String> {
        let name = match self.place(sim) {
            None => return Ok(None),
            Some(Place::Point(p)) => {
                let above = self.config.approach_m.max(SET_DOWN_M);
                return Ok(Some((p, above, above - SET_DOWN_M)));
            }
            Some(Place::Object(name)) => name,
        };
        let (shape, pose) = world_object(sim, &name, "to place on")?;
        let t = pose.translation;
        let top = t.z + shape.half_height_m().unwrap_or(0.0);
        Ok(Some((
            [f64::from(t.x), f64::from(t.y), f64::from(top)],
            self.config.drop_height_m,
            0.0,
        )))
    }

    /// Where on the place the object may go (world, m, on its top): the place's point
    /// ([`Self::place_under`]) first, then, for a world object with a flat top (a box, an
    /// upright cylinder), the rest of its top `inset_m` or more inside its edges, nearest that
    /// point first, [`SPOT_STEP_M`] apart. The place's point alone for a point place.
    pub(super) fn place_spots(
        &self,
        sim: &Simulation,
        point: [f64; 3],
        inset_m: f64,
    ) -> Vec<[f64; 3]> {
        let mut spots = vec![point];
        let Some(Place::Object(name)) = self.place(sim) else {
            return spots;
        };
        if let Ok((shape, pose)) = world_object(sim, &name, "to place on") {
            spots.extend(
                top_spots(shape, &pose, inset_m)
                    .into_iter()
                    .map(|[x, y]| [x, y, point[2]]),
            );
        }
        spots
    }
}

/// How far apart the spots tried on a place's top are (m).
pub(super) const SPOT_STEP_M: f64 = 0.03;
/// At most this many spots on a place's top besides its point, the nearest (a 0.5 m table's
/// top inset by a can's 10 cm has 121): each is an IK check while the base stops.
pub(super) const MAX_SPOTS: usize = 128;

/// Points (world x, y, m) on the flat top of `shape` at `pose`, `inset_m` or more inside its
/// edges, [`SPOT_STEP_M`] apart, nearest its middle first (the middle itself left out), at
/// most [`MAX_SPOTS`]; none for a shape without a flat top or one smaller than the inset.
fn top_spots(shape: &Shape, pose: &Pose, inset_m: f64) -> Vec<[f64; 2]> {
    // The top's half extents along the shape's x and y, and whether it is round.
    let (half_x, half_y, round) = match shape {
        Shape::Box { size_m } => (f64::from(size_m.x) / 2.0, f64::from(size_m.y) / 2.0, false),
        Shape::Cylinder { radius_m, .. } => (f64::from(*radius_m), f64::from(*radius_m), true),
        _ => return Vec::new(),
    };
    let (reach_x, reach_y) = (half_x - inset_m, half_y - inset_m);
    if reach_x <= 0.0 || reach_y <= 0.0 {
        return Vec::new();
    }
    // A hair over, so a reach of whole steps keeps its last one.
    let steps = |reach: f64| (reach / SPOT_STEP_M + 1e-9).floor() as i32;
    let (nx, ny) = (steps(reach_x), steps(reach_y));
    let mut local: Vec<(f64, f64)> = Vec::new();
    for i in -nx..=nx {
        for j in -ny..=ny {
            let (x, y) = (f64::from(i) * SPOT_STEP_M, f64::from(j) * SPOT_STEP_M);
            let inside = !round || x.hypot(y) <= reach_x;
            if (i, j) != (0, 0) && inside {
                local.push((x, y));
            }
        }
    }
    local.sort_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)));
    local.truncate(MAX_SPOTS);
    local
        .into_iter()
        .map(|(x, y)| {
            let p = pose.translation + pose.rotation * glam::Vec3::new(x as f32, y as f32, 0.0);
            [f64::from(p.x), f64::from(p.y)]
        })
        .collect()
}

/// World object `name`'s shape and pose now; else an error saying what it was wanted for
/// (`"to pick"`) and listing the world's objects.
pub(super) fn world_object<'w>(
    sim: &'w Simulation,
    name: &str,
    wanted: &str,
) -> Result<(&'w Shape, Pose), String> {
    let world = sim.world();
    let index = (world.objects.iter())
        .position(|o| o.name == name)
        .ok_or_else(|| {
            format!(
                "no world object \"{name}\" {wanted}; the world's objects: {}",
                object_names(sim)
            )
        })?;
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    let pose = poses.get(index).copied().unwrap_or(Pose::IDENTITY);
    Ok((&world.objects[index].shape, pose))
}

/// The world's named objects, comma-separated (for errors).
fn object_names(sim: &Simulation) -> String {
    let names: Vec<&str> = (sim.world().objects.iter())
        .map(|o| o.name.as_str())
        .filter(|n| !n.is_empty())
        .collect();
    names.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tops_spots_lie_inside_its_edges_nearest_the_middle_first() {
        let shape = Shape::Box {
            size_m: glam::Vec3::new(0.5, 0.3, 0.9),
        };
        let pose = rover_sim::geometry::pose_from_position_yaw([1.0, -1.0, 0.45], 0.0);
        let spots = top_spots(&shape, &pose, 0.1);
        // x within 0.15 of the middle (5 steps each way), y within 0.05 (1 step).
        assert_eq!(spots.len(), 11 * 3 - 1);
        for [x, y] in &spots {
            assert!((x - 1.0).abs() <= 0.15 + 1e-6 && (y + 1.0).abs() <= 0.05 + 1e-6);
        }
        let from_middle = |[x, y]: [f64; 2]| (x - 1.0).hypot(y + 1.0);
        assert!(
            spots
                .windows(2)
                .all(|w| from_middle(w[0]) <= from_middle(w[1]) + 1e-5)
        );
        assert!((from_middle(spots[0]) - SPOT_STEP_M).abs() < 1e-6);
        // A top narrower than the inset has none; a ball has no flat top.
        assert!(top_spots(&shape, &pose, 0.2).is_empty());
        let ball = Shape::Sphere { radius_m: 0.5 };
        assert!(top_spots(&ball, &pose, 0.0).is_empty());
    }
}
