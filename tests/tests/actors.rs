//! Gazebo actors: Gazebo's own walk.dae (a skinned COLLADA person and its walking animation)
//! on walking_actor.world's script, from ../shared/corpus/gazebo_actor: the skin and clip as
//! read, the pose against the world file's waypoints, the planted feet, YOLO's verdict through
//! the tutorial car's camera, and bad actor files as located errors.

use std::path::{Path, PathBuf};

use anyhow::Context;

use rover_core::{NoObserver, RunConfig, Scenario, ScenarioOptions, run_scenario};
use rover_perception::{Detector, DetectorConfig, FrameStamp, RgbView};
use rover_sim::model::actor::PosedSkin;
use rover_sim::{
    description::ResourcePaths,
    model::{Labelled, Person, World},
    physics::Simulation,
    sensors::CameraSensor,
};
use rover_tests::{repo, shared};

/// The corpus world, or `None` (skip recorded) without ../shared.
fn walking_actor() -> anyhow::Result<Option<(PathBuf, World)>> {
    let Some(dir) = shared("corpus/gazebo_actor") else {
        return Ok(None);
    };
    let path = dir.join("walking_actor.world");
    let world = World::load_with(&path, &ResourcePaths::default())?;
    Ok(Some((path, world)))
}

/// The world file's waypoints: (time s, x m, y m).
const WAYPOINTS: [(f64, f64, f64); 9] = [
    (0.0, 3.0, -1.5),
    (3.75, 3.0, 1.5),
    (4.5, 3.0, 1.5),
    (9.5, 7.0, 1.5),
    (10.25, 7.0, 1.5),
    (14.0, 7.0, -1.5),
    (14.75, 7.0, -1.5),
    (19.75, 3.0, -1.5),
    (20.5, 3.0, -1.5),
];

/// Poses the actor's skin as it is at sim time `t_s`; returns the world position of joint
/// `joint` (m).
fn joint_in_world(
    person: &Person,
    t_s: f64,
    posed: &mut PosedSkin,
    joint: usize,
) -> anyhow::Result<glam::Vec3> {
    let actor = person.actor.as_ref().context("an actor")?;
    let skin = actor.skin.as_ref().context("a skin")?;
    let clip_s = actor.clip_time_s(t_s).unwrap_or(0.0);
    skin.pose(clip_s, actor.carried(), posed);
    let world_from_person = person.world_from_person(t_s);
    Ok(world_from_person.transform_point(posed.joints[joint].translation.into()))
}

#[test]
fn the_actor_is_walk_dae_on_its_script() -> anyhow::Result<()> {
    let Some((_, world)) = walking_actor()? else {
        return Ok(());
    };
    assert_eq!(world.people.len(), 1);
    let person = &world.people[0];
    assert_eq!(person.name, "walker");
    let actor = person.actor.as_ref().context("the <actor> is an actor")?;
    let skin = actor.skin.as_ref().context("walk.dae's skin")?;
    let clip = skin.clip.as_ref().context("walk.dae's animation")?;
    let script = actor.script.as_ref().context("the <script>")?;
    println!(
        "walk.dae: {} vertices, {} joints, {} materials; clip {:.2} s, root travel {:.3} m; \
         script {:.2} s",
        skin.vertex_count(),
        skin.joints().len(),
        skin.layers().len(),
        clip.duration_s,
        clip.cycle_m(),
        script.duration_s()
    );
    assert_eq!(skin.vertex_count(), 7845);
    assert_eq!(skin.joints().len(), 31);
    assert_eq!(skin.joints()[0].name, "Hips");
    assert_eq!(skin.layers().len(), 6, "eyes (3), skin, sweater, jeans");
    assert!((clip.duration_s - 5.791666).abs() < 1e-4);
    assert!(clip.interpolate_x);
    assert!(
        (clip.cycle_m() - 1.384).abs() < 0.01,
        "{} m",
        clip.cycle_m()
    );
    assert!((script.duration_s() - 20.5).abs() < 1e-9);
    assert!(script.looped && script.auto_start);
    assert!(person.moves());
    // Standing at rest the body is a person's size: feet on the ground, 1.7-1.9 m tall.
    let mut posed = PosedSkin::default();
    skin.pose(0.0, true, &mut posed);
    let (low, high) = posed
        .positions
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p.z), h.max(p.z)));
    println!("height {:.3} m, lowest point {:.3} m", high - low, low);
    assert!(low.abs() < 0.05, "feet at {low} m");
    assert!((1.6..1.95).contains(&(high - low)), "{} m tall", high - low);
    Ok(())
}

#[test]
fn the_actor_keeps_to_its_waypoints_and_plants_its_feet() -> anyhow::Result<()> {
    let Some((_, world)) = walking_actor()? else {
        return Ok(());
    };
    let person = &world.people[0];
    let skin = person
        .actor
        .as_ref()
        .and_then(|a| a.skin.clone())
        .context("skin")?;
    let joint = |name: &str| {
        skin.joints()
            .iter()
            .position(|j| j.name == name)
            .context("joint")
    };
    let mut posed = PosedSkin::default();
    // The hips at each waypoint's time, against the world file's numbers.
    let mut worst_m = 0.0f64;
    for (t, x, y) in WAYPOINTS {
        // The last waypoint's time is the loop's end: the same place as its start.
        let hips = joint_in_world(person, t.min(20.5 - 1e-6), &mut posed, 0)?;
        let off = (f64::from(hips.x) - x).hypot(f64::from(hips.y) - y);
        worst_m = worst_m.max(off);
    }
    // And between them, against the script's own interpolation.
    let dt = 0.02;
    let mut between_m = 0.0f64;
    for k in 0..=(41.0 / dt) as usize {
        let t = k as f64 * dt;
        let hips = joint_in_world(person, t, &mut posed, 0)?;
        let (x, y, _) = person.pose_at(t);
        between_m = between_m.max((f64::from(hips.x) - x).hypot(f64::from(hips.y) - y));
    }
    println!(
        "hips off the waypoints: {:.1} cm at most; off the interpolated path over two loops: {:.1} cm",
        worst_m * 100.0,
        between_m * 100.0
    );
    assert!(worst_m < 0.05, "{worst_m} m from a waypoint");
    assert!(between_m < 0.05, "{between_m} m from the path");
    // Feet: a step is a run of frames with the ball of the foot (the toe joint) on the ground,
    // within 1 cm of its lowest; how far it slides in that run, on the straight legs and in
    // the turns. (walk.dae's own clip moves the planted ball of the foot about 4 cm forward
    // over a stance, measured in the clip's frame: that is the asset, played as Gazebo does.)
    let straight = |t: f64| {
        let t = t.rem_euclid(20.5);
        [(0.0, 3.75), (4.5, 9.5), (10.25, 14.0), (14.75, 19.75)]
            .iter()
            .any(|(a, b)| t > a + 0.1 && t < b - 0.1)
    };
    let mut report = Vec::new();
    for foot in ["LeftToeBase", "RightToeBase"] {
        let j = joint(foot)?;
        let track: Vec<(f64, glam::Vec3)> = (0..=(20.5 / dt) as usize)
            .map(|k| {
                let t = k as f64 * dt;
                Ok((t, joint_in_world(person, t, &mut posed, j)?))
            })
            .collect::<anyhow::Result<_>>()?;
        let lowest = track.iter().map(|p| p.1.z).fold(f32::MAX, f32::min);
        let (mut straight_slide, mut turn_slide, mut steps) = (0.0f32, 0.0f32, 0);
        let mut run: Vec<&(f64, glam::Vec3)> = Vec::new();
        for sample in track
            .iter()
            .chain(std::iter::once(&(f64::MAX, glam::Vec3::splat(1e9))))
        {
            if sample.1.z < lowest + 0.01 {
                run.push(sample);
                continue;
            }
            if run.len() >= 3 {
                steps += 1;
                let start = run[0].1.truncate();
                let slide = run
                    .iter()
                    .map(|p| p.1.truncate().distance(start))
                    .fold(0.0, f32::max);
                if run.iter().all(|p| straight(p.0)) {
                    straight_slide = straight_slide.max(slide);
                } else {
                    turn_slide = turn_slide.max(slide);
                }
            }
            run.clear();
        }
        report.push(format!(
            "{foot}: {steps} steps, slide {:.1} cm on the straights, {:.1} cm in the turns",
            straight_slide * 100.0,
            turn_slide * 100.0
        ));
        assert!(steps >= 8, "{foot}: {steps} steps in a 14 m loop");
        assert!(
            straight_slide < 0.05,
            "{foot} slid {straight_slide} m in a step"
        );
    }
    println!("{}", report.join("; "));
    Ok(())
}

#[test]
fn yolo_finds_the_actor_whenever_it_is_in_view() -> anyhow::Result<()> {
    let Some((path, _)) = walking_actor()? else {
        return Ok(());
    };
    let config = RunConfig {
        world: Some(path),
        robot: Some(repo("assets/robots/my_robot.urdf")),
        ..RunConfig::default()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let mut sim = Simulation::new(world, robot, &config.options)?;
    let mut camera = CameraSensor::new(&sim)?;
    camera.disable_depth();
    camera.enable_ground_truth(&sim)?;
    let mut detector = Detector::load(DetectorConfig::default())?;
    let mut judge = rover_core::LiveJudge::default();
    let (mut in_view, mut found) = (0, 0);
    let mut missed = Vec::new();
    // One loop, a frame every 0.25 s, the car standing at the origin facing the loop.
    while sim.sim_time_s() < 20.5 {
        let until = sim.sim_time_s() + 0.25;
        while sim.sim_time_s() + 0.5 * sim.dt_s() < until {
            sim.step();
        }
        let frame = camera.capture(&sim)?;
        let truth = frame.ground_truth;
        let Some(person) = truth
            .iter()
            .position(|t| t.entity == Labelled::Person(0) && !t.truncated && !t.ignore)
        else {
            continue;
        };
        in_view += 1;
        let boxes = detector.detect(
            RgbView {
                width: frame.width as usize,
                height: frame.height as usize,
                pixels: frame.rgb,
            },
            FrameStamp {
                sim_time_s: frame.sim_time_s,
                frame: frame.seq,
            },
        )?;
        let judged = judge.judge(&boxes, truth);
        if judged
            .matches
            .iter()
            .any(|m| m.ground_truth == person && m.iou >= rover_core::MATCH_IOU)
        {
            found += 1;
        } else {
            missed.push(format!("{:.2} s", frame.sim_time_s));
        }
    }
    let recall = found as f64 / in_view.max(1) as f64;
    println!(
        "fully in view in {in_view} frames, found in {found}: recall {recall:.2}; missed at {missed:?}"
    );
    assert!(
        in_view >= 40,
        "only {in_view} frames with the actor fully in view"
    );
    assert!(recall >= 0.9, "recall {recall:.2}: missed at {missed:?}");
    Ok(())
}

/// Runs tests/scenarios/walking_actor.toml (the follower after the actor) on `robot`.
fn follow_the_actor(robot: &str) -> anyhow::Result<()> {
    if shared("corpus/gazebo_actor").is_none() {
        return Ok(());
    }
    let scenario = Scenario::load_with_robot(
        &repo("tests/scenarios/walking_actor.toml"),
        Some(&repo(robot)),
    )?;
    let result = run_scenario(
        &scenario,
        &ScenarioOptions {
            detector: DetectorConfig {
                threads: 1,
                ..DetectorConfig::default()
            },
            ..ScenarioOptions::default()
        },
        &mut NoObserver,
    )?;
    for c in &result.checks {
        println!(
            "walking_actor @ {}: {} {} (want {}) {}",
            scenario.robot_name,
            c.name,
            c.value,
            c.limit,
            if c.passed { "ok" } else { "FAILED" }
        );
    }
    assert!(result.passed, "{:#?}", result.checks);
    Ok(())
}

#[test]
fn the_laser_car_follows_the_actor() -> anyhow::Result<()> {
    follow_the_actor("assets/robots/my_robot_laser.urdf.xacro")
}

#[test]
fn the_camera_only_car_follows_the_actor() -> anyhow::Result<()> {
    follow_the_actor("assets/robots/my_robot.urdf")
}

/// A copy of the corpus world (`world_edit` applied) beside walk.dae (`dae_edit` applied)
/// and, when given, a second COLLADA file `other.dae`, loaded: the error.
fn broken(
    dir: &Path,
    world_edit: impl Fn(&str) -> String,
    dae_edit: impl Fn(&str) -> String,
    other: Option<&str>,
) -> anyhow::Result<String> {
    let Some(corpus) = shared("corpus/gazebo_actor") else {
        return Ok(String::new());
    };
    let world = std::fs::read_to_string(corpus.join("walking_actor.world"))?;
    std::fs::write(dir.join("walking_actor.world"), world_edit(&world))?;
    let dae = std::fs::read_to_string(corpus.join("walk.dae"))?;
    std::fs::write(dir.join("walk.dae"), dae_edit(&dae))?;
    if let Some(text) = other {
        std::fs::write(dir.join("other.dae"), text)?;
    }
    match World::load_with(&dir.join("walking_actor.world"), &ResourcePaths::default()) {
        Ok(_) => anyhow::bail!("a broken actor loaded"),
        Err(e) => Ok(e.to_string()),
    }
}

#[test]
fn broken_actor_files_are_located_errors() -> anyhow::Result<()> {
    let Some(corpus) = shared("corpus/gazebo_actor") else {
        return Ok(());
    };
    let dir = tempfile::tempdir()?;
    let same = |t: &str| t.to_owned();
    // A skin with no skeleton: no skinned controller, no joints.
    let e = broken(
        dir.path(),
        same,
        |t| {
            t.replace("<instance_controller", "<instance_nothing")
                .replace("</instance_controller>", "</instance_nothing>")
                .replace("type=\"JOINT\"", "type=\"NODE\"")
        },
        None,
    )?;
    println!("{e}");
    assert!(
        e.contains("walk.dae:") && e.contains("no <instance_controller>"),
        "{e}"
    );
    // An animation for another skeleton: other.dae's LeftFoot is called LFoot.
    let other = std::fs::read_to_string(corpus.join("walk.dae"))?
        .replace(
            "id=\"LeftFoot\" name=\"LeftFoot\" sid=\"LeftFoot\"",
            "id=\"LFoot\" name=\"LFoot\" sid=\"LFoot\"",
        )
        .replace(
            "target=\"LeftFoot/transform\"",
            "target=\"LFoot/transform\"",
        );
    let e = broken(
        dir.path(),
        |w| {
            w.replacen("<filename>walk.dae</filename>\n        <scale>1.0</scale>\n        <interpolate_x>", "<filename>other.dae</filename>\n        <scale>1.0</scale>\n        <interpolate_x>", 1)
        },
        same,
        Some(&other),
    )?;
    println!("{e}");
    assert!(e.contains("other.dae:") && e.contains("\"LFoot\""), "{e}");
    // Weights naming a joint past the list.
    let e = broken(
        dir.path(),
        same,
        |t| t.replacen("<v>17 ", "<v>99 ", 1),
        None,
    )?;
    println!("{e}");
    assert!(
        e.contains("walk.dae:") && e.contains("joint index 99"),
        "{e}"
    );
    // A skin file that is not there: the world's line.
    let e = broken(
        dir.path(),
        |w| {
            w.replacen(
                "<filename>walk.dae</filename>",
                "<filename>nowhere.dae</filename>",
                1,
            )
        },
        same,
        None,
    )?;
    println!("{e}");
    assert!(
        e.contains("walking_actor.world:") && e.contains("nowhere.dae"),
        "{e}"
    );
    Ok(())
}
