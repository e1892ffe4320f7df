//! Gazebo SDF worlds nobody on the project wrote: loaded, placed and driven in.

use anyhow::Result;
use rover_sim::{ResourcePaths, World};
use rover_tests::shared;

fn playground() -> Result<Option<World>> {
    let (Some(world), Some(models)) = (
        shared("corpus/turtlebot_gazebo/worlds/playground.world"),
        shared("corpus/gazebo_models"),
    ) else {
        return Ok(None);
    };
    let resources = ResourcePaths::default().with_model_path(models);
    Ok(Some(World::load_with(&world, &resources)?))
}

#[test]
fn turtlebot_playground_places_every_model_with_its_state_pose() -> Result<()> {
    let Some(world) = playground()? else {
        return Ok(());
    };
    let names: Vec<&str> = world.models.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "bookshelf",
            "jersey_barrier",
            "ground_plane_0",
            "unit_cylinder_1",
            "Dumpster",
            "cube_20k"
        ]
    );
    assert_eq!(
        world.physics.step_hz, 100.0,
        "<max_step_size>0.01</max_step_size>"
    );
    assert_eq!(world.physics.gravity_mps2, [0.0, 0.0, -9.8]);
    let link = |model: &str| {
        world
            .models
            .iter()
            .find(|m| m.name == model)
            .and_then(|m| m.links.first())
            .ok_or_else(|| anyhow::anyhow!("no model {model}"))
    };
    // <state> poses win over the models' own.
    let cube = link("cube_20k")?;
    let t = cube.world_from_link.translation;
    assert!(
        (t - glam::Vec3::new(1.41131, -1.0, 0.5)).length() < 1e-5,
        "cube at {t}"
    );
    let yaw = rover_sim::yaw_of(cube.world_from_link.rotation);
    assert!((yaw - 0.9).abs() < 1e-5, "cube yaw {yaw}");
    let dumpster = link("Dumpster")?;
    assert!(
        (dumpster.world_from_link.translation - glam::Vec3::new(1.0, -3.44458, 0.0)).length()
            < 1e-5
    );
    // The bookshelf: seven boxes, static; the barrier: a COLLADA visual, box collisions.
    let shelf = link("bookshelf")?;
    assert_eq!((shelf.visuals.len(), shelf.collisions.len()), (7, 7));
    let barrier = link("jersey_barrier")?;
    let rover_sim::Shape::Mesh { path, .. } = &barrier.visuals[0].shape else {
        anyhow::bail!("barrier visual is not a mesh");
    };
    assert!(path.ends_with("jersey_barrier/meshes/jersey_barrier.dae"));
    let mesh = rover_sim::load_mesh(path, glam::Vec3::ONE)?;
    let (lo, hi) = mesh.positions.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    // The COLLADA file's unit and up axis applied: a 4 m long, ~1.1 m high barrier.
    let size = hi - lo;
    assert!(
        (size.x - 4.06).abs() < 0.2 && (size.z - 1.14).abs() < 0.2,
        "barrier {size}"
    );
    Ok(())
}

#[test]
fn the_tutorial_car_drives_in_the_turtlebot_playground() -> Result<()> {
    let (Some(world), Some(models)) = (
        shared("corpus/turtlebot_gazebo/worlds/playground.world"),
        shared("corpus/gazebo_models"),
    ) else {
        return Ok(());
    };
    let tmp = tempfile::tempdir()?;
    let script = tmp.path().join("drive.toml");
    std::fs::write(&script, "steps = [ { at = 0.5, cmd_vel = [0.3, 0.0] } ]\n")?;
    let mut config = rover_core::RunConfig {
        world: Some(world),
        script: Some(script),
        duration_s: Some(4.0),
        ..rover_core::RunConfig::default()
    };
    config.robot_options.resources = ResourcePaths::default().with_model_path(models);
    let summary = rover_core::headless::run(&config)?;
    let last = summary
        .last
        .ok_or_else(|| anyhow::anyhow!("no control samples"))?;
    let x = last.ground_truth.x_m;
    assert!(
        (0.8..1.2).contains(&x),
        "0.3 m/s for 3.5 s reached x = {x} m; expected about 1.05 m"
    );
    Ok(())
}
