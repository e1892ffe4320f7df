//! The world's named objects as the pick finds them: a shape and its pose now, or an error
//! listing the names there are.

use rover_sim::{
    geometry::{Pose, Shape},
    physics::Simulation,
};

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
