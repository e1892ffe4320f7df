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
        let world = sim.world();
        let name = match self
            .config
            .place
            .clone()
            .or_else(|| world.robot.place.clone())
        {
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
