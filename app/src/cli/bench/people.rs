//! `rover bench people`: the detector's people sweep per body and posture, the cost of posing
//! a body, and what walking people add to a camera frame.

use std::time::Instant;

use anyhow::Result;
use rover_core::RunConfig;
use rover_sim::physics::Simulation;

use super::stats::median;

/// `rover bench people`: the sweep table per body and posture, and the cost of posing a body.
pub(crate) fn bench_people(args: crate::cli::args::PeopleBenchArgs) -> Result<()> {
    use crate::cli::args::{PeopleBenchArgs, SweepBody, SweepPostureArg};
    let PeopleBenchArgs {
        world,
        detector,
        bodies,
        postures,
        save,
    } = args;
    let config = detector.tool_config(crate::cli::args::spare_detect_threads())?;
    use rover_core::{SWEEP_DISTANCES_M, SWEEP_HEADINGS_DEG, SWEEP_POSTURES, SweepPosture};
    let mut run = world.run_config(None);
    if run.world.is_none() {
        run.world = Some(rover_core::bundled_path("worlds/people.toml"));
    }
    let mut detector = rover_perception::Detector::load(config)?;
    let wants = |p: &SweepPosture| {
        postures.is_empty()
            || postures.iter().any(|w| {
                matches!(
                    (w, p),
                    (SweepPostureArg::Standing, SweepPosture::Standing)
                        | (SweepPostureArg::Walk, SweepPosture::Walking(_))
                )
            })
    };
    say!(
        "people sweep on {}: 8 headings x {} distances per posture, IoU >= 0.5 against ground truth; cells: detection confidence, `-` missed",
        run.world
            .as_deref()
            .unwrap_or(std::path::Path::new("?"))
            .display(),
        SWEEP_DISTANCES_M.len()
    );
    for body in &bodies {
        let (name, shape) = match body {
            SweepBody::Makehuman => {
                if rover_sim::model::human::shared().is_none() {
                    say!("makehuman: not available (see the warning above); skipped");
                    continue;
                }
                (
                    "makehuman",
                    Some(rover_sim::model::human::BodyShape::default()),
                )
            }
            SweepBody::Figure => ("figure", None),
        };
        let dir = match &save {
            Some(d) => {
                let dir = d.join(name);
                std::fs::create_dir_all(&dir)?;
                Some(dir)
            }
            None => None,
        };
        let (mut all_found, mut all, mut near_found, mut near) = (0, 0, 0, 0);
        for posture in SWEEP_POSTURES.iter().filter(|p| wants(p)) {
            let views = rover_core::sweep(&run, &mut detector, shape, *posture, dir.as_deref())?;
            say!("");
            say!("{name}, {posture}:");
            let mut header = format!("{:>8}", "m \\ deg");
            for h in SWEEP_HEADINGS_DEG {
                header.push_str(&format!("{h:>6.0}"));
            }
            say!("{header}   found");
            for d in SWEEP_DISTANCES_M {
                let row: Vec<_> = views.iter().filter(|v| v.distance_m == d).collect();
                let mut line = format!("{d:>8.1}");
                for v in &row {
                    if v.found {
                        line.push_str(&format!("{:>6.2}", v.confidence));
                    } else {
                        line.push_str(&format!("{:>6}", "-"));
                    }
                }
                let found = row.iter().filter(|v| v.found).count();
                say!("{line}   {found}/{}", row.len());
            }
            let found = views.iter().filter(|v| v.found).count();
            let at_near: Vec<_> = views
                .iter()
                .filter(|v| v.distance_m == SWEEP_DISTANCES_M[0])
                .collect();
            let near_hits = at_near.iter().filter(|v| v.found).count();
            say!(
                "{name}, {posture}: {found}/{} views found, {near_hits}/{} at {} m",
                views.len(),
                at_near.len(),
                SWEEP_DISTANCES_M[0]
            );
            (all_found, all, near_found, near) = (
                all_found + found,
                all + views.len(),
                near_found + near_hits,
                near + at_near.len(),
            );
        }
        say!("");
        say!(
            "{name} in all: {all_found}/{all} views found, {near_found}/{near} at {} m",
            SWEEP_DISTANCES_M[0]
        );
    }
    time_posing()?;
    time_frames(&run)
}

/// Median camera frame time (ms; render + readback, posing included) with `count` people of
/// `shape` (`None`: the figure) walking side by side 3-7 m ahead of the robot.
fn frame_ms(
    run: &RunConfig,
    count: usize,
    shape: Option<rover_sim::model::human::BodyShape>,
) -> Result<f64> {
    let (mut world, robot) = run.load_world_and_robot()?;
    let template = world.people.first().cloned();
    world.people.clear();
    let [rx, ry] = world.robot.position_m;
    for i in 0..count {
        let Some(mut p) = template.clone() else {
            anyhow::bail!("the frame cost needs a world with a person to copy");
        };
        let x = rx + 3.0 + (i % 3) as f64 * 1.5;
        let y = ry + (i as f64 - (count as f64 - 1.0) / 2.0) * 0.7;
        p.name = format!("p{i}");
        p.position_m = [x, y];
        p.shape = shape;
        p.walk = Some(rover_sim::model::Walk {
            waypoints_m: vec![[x + 1.0, y]],
            speed_mps: 0.8,
            repeat: true,
            start_after_s: 0.0,
        });
        world.people.push(p);
    }
    let mut sim = Simulation::new(world, robot, &run.options)?;
    let mut camera = rover_sim::sensors::CameraSensor::new(&sim)?;
    camera.disable_depth();
    camera.capture(&sim)?;
    let mut times = Vec::new();
    for _ in 0..60 {
        for _ in 0..5 {
            sim.step();
        }
        let start = Instant::now();
        camera.capture(&sim)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(&mut times))
}

/// What walking people add to a 640x480 camera frame: 0, 1 and 10 of them, MakeHuman's body
/// beside the figure.
fn time_frames(run: &RunConfig) -> Result<()> {
    let none = frame_ms(run, 0, None)?;
    say!("");
    say!("camera frame (median of 60, posing + render + readback): {none:.2} ms with nobody");
    let mut bodies = vec![("figure", None)];
    if rover_sim::model::human::shared().is_some() {
        bodies.insert(
            0,
            (
                "makehuman",
                Some(rover_sim::model::human::BodyShape::default()),
            ),
        );
    }
    for (name, shape) in bodies {
        for count in [1, 10] {
            let ms = frame_ms(run, count, shape)?;
            say!(
                "{name}: {count:>2} walking 3-7 m ahead: {ms:.2} ms, +{:.2} ms",
                ms - none
            );
        }
    }
    Ok(())
}

/// Times posing (skinning) the default MakeHuman body through a walk.
fn time_posing() -> Result<()> {
    if let Some(human) = rover_sim::model::human::shared() {
        let body = human.body(
            rover_sim::model::human::BodyShape::default(),
            1.75,
            rover_sim::model::human::Outfit::default(),
        )?;
        let mut posed = rover_sim::model::human::PosedBody::default();
        let mut times = Vec::new();
        for k in 0..200 {
            let posture = rover_sim::model::human::Posture::Walking {
                phase_rad: 0.05 * f64::from(k + 1),
                stride_m: 1.2,
            };
            let start = Instant::now();
            body.pose(posture, &mut posed);
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        say!(
            "posing one body ({} vertices, linear-blend skinning on the CPU): median {:.3} ms",
            body.vertex_count(),
            median(&mut times)
        );
    }
    Ok(())
}
