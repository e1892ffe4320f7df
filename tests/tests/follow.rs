//! The follower end to end: real physics, real renderer (lavapipe in CI), real default detector
//! in lockstep on sim time, the follower driving through cmd_vel. Headless, deterministic.

use anyhow::Result;
use rover_core::{RunConfig, run_headless};
use rover_core::{TraceRow, parse_trace};
use rover_sim::model::World;
use rover_tests::repo;

/// The playground with its person replaced by `person` (TOML lines; empty = nobody).
fn playground_with(dir: &std::path::Path, person: &str) -> Result<std::path::PathBuf> {
    let text = std::fs::read_to_string(repo("worlds/playground.toml"))?;
    let start = text
        .find("[[person]]")
        .ok_or_else(|| anyhow::anyhow!("playground has no person"))?;
    let end = start
        + text[start..]
            .find("\n\n")
            .ok_or_else(|| anyhow::anyhow!("person block not closed"))?;
    let text = format!("{}{person}{}", &text[..start], &text[end..])
        .replace("urdf = \"../assets/robots/my_robot.urdf\"\n", "");
    let path = dir.join("world.toml");
    std::fs::write(&path, text)?;
    Ok(path)
}

/// Runs `world` headless for `seconds` with follow mode switched on at 0.5 s.
fn follow(dir: &std::path::Path, world: &std::path::Path, seconds: f64) -> Result<Vec<TraceRow>> {
    let script = dir.join("follow.toml");
    std::fs::write(&script, "steps = [ { at = 0.5, toggle = \"follow\" } ]\n")?;
    let trace = dir.join("trace.csv");
    run_headless(&RunConfig {
        world: Some(world.to_path_buf()),
        robot: Some(repo("assets/robots/my_robot.urdf")),
        script: Some(script),
        duration_s: Some(seconds),
        trace: Some(trace.clone()),
        ..RunConfig::default()
    })?;
    Ok(parse_trace(&std::fs::read_to_string(trace)?)?)
}

/// Distance (m) from the car's base to the person, and how far (deg) the car's heading is
/// from facing them.
fn range_and_facing(row: &TraceRow, person: (f64, f64)) -> (f64, f64) {
    let (dx, dy) = (person.0 - row.x_m, person.1 - row.y_m);
    let off = rover_sim::physics::wrap_angle(dy.atan2(dx) - row.yaw_rad);
    (dx.hypot(dy), off.to_degrees().abs())
}

#[test]
fn follows_a_person_ahead_and_to_the_side_to_the_standoff() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let world = playground_with(
        dir.path(),
        "[[person]]\nname = \"bob\"\nposition_m = [4.0, 1.0]\nheading_deg = 194.0\n",
    )?;
    let rows = follow(dir.path(), &world, 20.0)?;
    let last = rows.last().ok_or_else(|| anyhow::anyhow!("empty trace"))?;
    let (range, facing) = range_and_facing(last, (4.0, 1.0));
    println!("after 20 s: range {range:.2} m, facing off by {facing:.1} deg");
    assert_eq!(last.mode, "follow");
    assert!(
        (range - 1.5).abs() <= 0.3,
        "range {range:.2} m, want 1.5 +- 0.3"
    );
    assert!(facing <= 10.0, "facing off by {facing:.1} deg");
    Ok(())
}

#[test]
fn keeps_up_with_a_person_walking_a_square() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let world_path = repo("worlds/walking.toml");
    let world = World::load(&world_path)?;
    let person = &world.people[0];
    let rows = follow(dir.path(), &world_path, 60.0)?;
    let (mut worst, mut worst_at, mut sum) = (0.0f64, 0.0, 0.0);
    for row in &rows {
        let (x, y, _) = person.pose_at(row.sim_time_s);
        let (range, _) = range_and_facing(row, (x, y));
        sum += range;
        if range > worst {
            (worst, worst_at) = (range, row.sim_time_s);
        }
    }
    println!(
        "walking square: farthest {worst:.2} m (at {worst_at:.1} s), mean {:.2} m over 60 s",
        sum / rows.len() as f64
    );
    assert!(worst <= 3.0, "the car fell {worst:.2} m behind");
    Ok(())
}

#[test]
fn with_nobody_in_view_it_searches_on_the_spot() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let world = playground_with(dir.path(), "")?;
    let rows = follow(dir.path(), &world, 15.0)?;
    let start = &rows[0];
    let moved = rows
        .iter()
        .map(|r| (r.x_m - start.x_m).hypot(r.y_m - start.y_m))
        .fold(0.0, f64::max);
    let turned: f64 = rows
        .windows(2)
        .map(|w| rover_sim::physics::wrap_angle(w[1].yaw_rad - w[0].yaw_rad).abs())
        .sum();
    println!(
        "searching: moved {moved:.3} m, turned {:.0} deg",
        turned.to_degrees()
    );
    assert!(rows.iter().all(|r| r.cmd_linear_mps == 0.0), "never drives");
    assert!(moved < 0.1, "stayed in place (moved {moved:.3} m)");
    assert!(turned > std::f64::consts::PI, "searched around");
    Ok(())
}
