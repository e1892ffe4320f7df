//! The physics benchmark (`rover bench`, `rover bench physics`): the robot drives a figure of
//! eight, optionally holding an object, and the real-time factor is measured.

use std::time::Instant;

use anyhow::Result;
use rover_core::RunConfig;
use rover_sim::physics::{SimOptions, Simulation, Twist};

use crate::cli::args::{PhysicsBenchArgs, WorldArgs};

/// One benchmark measurement.
#[derive(Debug, Clone, Copy)]
pub struct PhysicsBench {
    /// Physics step rate (Hz).
    pub step_hz: f64,
    /// Sim seconds simulated.
    pub sim_s: f64,
    /// Wall seconds it took (best of the repeats).
    pub wall_s: f64,
    /// With an object held: how far it ended from the end effector (m).
    pub held_off_m: Option<f64>,
}

impl PhysicsBench {
    /// Sim seconds per wall second.
    pub fn real_time_factor(&self) -> f64 {
        self.sim_s / self.wall_s
    }

    /// Wall microseconds per physics step.
    pub fn us_per_step(&self) -> f64 {
        self.wall_s * 1e6 / (self.sim_s * self.step_hz)
    }
}

/// Steps the world's physics with the robot driving a figure of eight (forward at
/// [`EIGHT_SPEED_MPS`], a full circle left at [`EIGHT_TURN_RADPS`], then one right) for `sim_s`
/// seconds, `repeats` times; keeps the fastest. The eight closes, so the robot stays within
/// 3.5 m of where it started however long it runs (a 20 m ground holds it).
pub fn physics(
    config: &RunConfig,
    step_hz: Option<f64>,
    (sim_s, repeats): (f64, u32),
    hold: Option<&str>,
) -> Result<PhysicsBench> {
    let (world, robot) = config.load_world_and_robot()?;
    let options = SimOptions {
        step_hz,
        ..config.options.clone()
    };
    let mut best = f64::INFINITY;
    let mut rate = 0.0;
    let mut held_off_m = None;
    for _ in 0..repeats.max(1) {
        let mut sim = Simulation::new(world.clone(), robot.clone(), &options)?;
        rate = 1.0 / sim.dt_s();
        let held = hold.map(|name| grasp(&mut sim, name)).transpose()?;
        let first = sim.step_index();
        let steps = (sim_s / sim.dt_s()).round() as u64;
        let started = Instant::now();
        let mut turning_left = true;
        let lobe_steps = (std::f64::consts::TAU / EIGHT_TURN_RADPS * rate).round() as u64;
        while sim.step_index() - first < steps {
            if (sim.step_index() - first).is_multiple_of(lobe_steps.max(1)) {
                let turn = if turning_left {
                    EIGHT_TURN_RADPS
                } else {
                    -EIGHT_TURN_RADPS
                };
                sim.set_cmd_vel(Twist::new(EIGHT_SPEED_MPS, turn))?;
                turning_left = !turning_left;
            }
            sim.step();
        }
        best = best.min(started.elapsed().as_secs_f64());
        if let Some((object, tool)) = held {
            held_off_m = Some(held_to_link_m(&sim, object, tool));
        }
    }
    Ok(PhysicsBench {
        step_hz: rate,
        sim_s,
        wall_s: best,
        held_off_m,
    })
}

/// The physics benchmark's driving speed (m/s).
const EIGHT_SPEED_MPS: f64 = 0.5;
/// The physics benchmark's turn rate (rad/s): circles of 0.83 m radius.
const EIGHT_TURN_RADPS: f64 = 0.6;

/// What `--hold` holds: a world object, or a Gazebo model (`[[model]]`) by its first link,
/// by index (the model's among the world's models, its first link's among all model links).
#[derive(Debug, Clone, Copy)]
enum Held {
    Object(usize),
    Model { model: usize, link: usize },
}

/// Puts world object (or Gazebo model) `name` in the robot's gripper, untimed: the first
/// gripper controller opens once the arm is still in its start pose, the object's centre (a
/// model's first link's centre of mass) goes to the end effector (the world's `[robot]
/// ee_link`) and is held there while the gripper closes on it with 5 N until the finger stops
/// on it (and, with the world's grasp assist, until the assist takes it), then it settles.
/// Returns what is held and the end effector.
fn grasp(sim: &mut Simulation, name: &str) -> Result<(Held, rover_sim::model::LinkId)> {
    let world = sim.world();
    let held = match world.objects.iter().position(|o| o.name == name) {
        Some(i) => Held::Object(i),
        None => {
            let model = world.models.iter().position(|m| m.name == name);
            let model = model.ok_or_else(|| {
                anyhow::anyhow!("--hold {name}: the world has no object or model \"{name}\"")
            })?;
            let link = world.models[..model].iter().map(|m| m.links.len()).sum();
            Held::Model { model, link }
        }
    };
    let ee = sim.world().robot.ee_link.clone().ok_or_else(|| {
        anyhow::anyhow!("--hold needs the world's [robot] ee_link (where the object is held)")
    })?;
    let tool = sim
        .robot()
        .link_id(&ee)
        .ok_or_else(|| anyhow::anyhow!("--hold: the robot has no link \"{ee}\" (ee_link)"))?;
    let (controller, joint) = sim
        .robot()
        .controllers
        .as_ref()
        .and_then(|c| c.first_gripper())
        .map(|(name, g)| (name.to_owned(), g.joint.clone()))
        .ok_or_else(|| anyhow::anyhow!("--hold needs a gripper controller"))?;
    // Open at the finger's upper limit, closed at its lower (sliding fingers close at 0).
    let (closed, open) = sim
        .robot()
        .joint_id(&joint)
        .and_then(|j| sim.robot().joint(j).position_limits())
        .map_or((0.0, 0.0), |(lo, hi)| (f64::from(lo), f64::from(hi)));
    sim.command_gripper(&controller, open, 0.0)?;
    let settle = |sim: &mut Simulation, s: f64| {
        let end = sim.sim_time_s() + s;
        while sim.sim_time_s() < end {
            sim.step();
        }
    };
    // Until the arm has reached its start pose (the world's `[robot] pose`): the tool still,
    // after a second at least (a slow lift may not have started yet).
    settle(sim, 1.0);
    let still_by_s = sim.sim_time_s() + ARM_SETTLE_S;
    loop {
        let before = sim.world_from_link(tool).translation;
        settle(sim, 0.1);
        let moved = (sim.world_from_link(tool).translation - before).length();
        if f64::from(moved) < TOOL_STILL_M || sim.sim_time_s() >= still_by_s {
            break;
        }
    }
    let at = sim.world_from_link(tool).translation;
    // A model moved rigidly from where it is now, its first link's centre of mass to the end
    // effector.
    let world_from_model = match held {
        Held::Object(_) => None,
        Held::Model { model, link } => sim.world_from_model_now(model).map(|now| {
            let centre = sim.model_link_centre(link).unwrap_or(at);
            rover_sim::geometry::Pose::from_translation(at - centre) * now
        }),
    };
    let put = |sim: &mut Simulation| -> Result<()> {
        match (held, world_from_model) {
            (Held::Model { model, .. }, Some(pose)) => sim.place_model(model, pose)?,
            (Held::Object(i), _) => {
                sim.place_object(i, [f64::from(at.x), f64::from(at.y), f64::from(at.z)], 0.0)?
            }
            (Held::Model { .. }, None) => {}
        }
        Ok(())
    };
    // Held at the tool while the fingers close on it (a wide-open hand takes longer to close
    // than the object takes to fall out of it), until they stop on it.
    let finger = sim.robot().joint_id(&joint);
    let finger_q = |sim: &Simulation| {
        finger
            .and_then(|j| sim.joint_state(j))
            .map_or(0.0, |s| s.position)
    };
    sim.command_gripper(&controller, closed, 5.0)?;
    let closing_until_s = sim.sim_time_s() + CLOSING_S;
    let (mut still_steps, mut started) = (0, false);
    while sim.sim_time_s() < closing_until_s && still_steps < STOPPED_STEPS {
        put(sim)?;
        let q = finger_q(sim);
        sim.step();
        let moved = (finger_q(sim) - q).abs() >= STOPPED_RAD_PER_STEP;
        started |= moved;
        // Counted once the finger has started to close.
        still_steps = if moved || !started {
            0
        } else {
            still_steps + 1
        };
    }
    // With the grasp assist (gazebo_grasp_fix's rule), held there until it takes it: a grip
    // held for about a second attaches, and the object may slip out of the squeeze before.
    if sim.world().robot.grasp == rover_sim::model::GraspMode::Assist {
        let until_s = sim.sim_time_s() + CLOSING_S;
        while sim.grasp_assist_holds().is_none() && sim.sim_time_s() < until_s {
            put(sim)?;
            sim.step();
        }
    }
    settle(sim, 1.5);
    let off = held_to_link_m(sim, held, tool);
    anyhow::ensure!(
        off < 0.02,
        "--hold {name}: the gripper did not take it ({off:.3} m from {ee} after closing)"
    );
    Ok((held, tool))
}

/// The longest the arm takes to reach its start pose before the object is put in the hand (s
/// of sim time).
const ARM_SETTLE_S: f64 = 10.0;
/// A tool that moves less than this in 0.1 s (m) is still.
const TOOL_STILL_M: f64 = 1e-3;
/// The longest the fingers take to close on what `--hold` holds (s of sim time).
const CLOSING_S: f64 = 3.0;

/// A finger that moves less than this in a step (m or rad) ...
const STOPPED_RAD_PER_STEP: f64 = 1e-4;
/// ... for this many steps in a row has stopped on what it closes on.
const STOPPED_STEPS: u32 = 10;

/// An object this close to the end effector (m) is still in the hand.
const HELD_WITHIN_M: f64 = 0.05;

/// How far what is held (a world object's centre, a model link's centre of mass) is from link
/// `link` (m).
fn held_to_link_m(sim: &Simulation, held: Held, link: rover_sim::model::LinkId) -> f64 {
    let at = match held {
        Held::Object(i) => {
            let mut poses = Vec::new();
            sim.object_poses_into(&mut poses);
            poses.get(i).map(|p| p.translation).unwrap_or_default()
        }
        Held::Model { link, .. } => sim.model_link_centre(link).unwrap_or_default(),
    };
    f64::from((at - sim.world_from_link(link).translation).length())
}

pub(crate) fn bench_cmd(world: WorldArgs, args: PhysicsBenchArgs) -> Result<()> {
    let (sim_seconds, repeats, rates) = (args.sim_seconds, args.repeats, args.rates);
    anyhow::ensure!(
        sim_seconds.is_finite() && sim_seconds > 0.0,
        "--sim-seconds must be positive, found {sim_seconds}"
    );
    let config = world.run_config(None);
    let mut plan: Vec<Option<f64>> = vec![world.physics_hz];
    plan.extend(rates.into_iter().map(Some));
    say!("physics-only benchmark: {sim_seconds} sim s per run, best of {repeats}, one thread");
    say!(
        "{:>10} {:>12} {:>12} {:>14}",
        "step_hz",
        "wall_s",
        "us/step",
        "real-time x"
    );
    for step_hz in plan {
        let b = physics(
            &config,
            step_hz,
            (sim_seconds, repeats),
            args.hold.as_deref(),
        )?;
        say!(
            "{:>10.0} {:>12.3} {:>12.1} {:>14.0}",
            b.step_hz,
            b.wall_s,
            b.us_per_step(),
            b.real_time_factor()
        );
        if let (Some(name), Some(off)) = (&args.hold, b.held_off_m) {
            let verdict = if off < HELD_WITHIN_M {
                "still in the hand"
            } else {
                "dropped"
            };
            say!("  {name}: {verdict}, {off:.3} m from the end effector at the end");
        }
    }
    Ok(())
}
