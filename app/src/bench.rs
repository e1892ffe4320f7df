//! `rover bench`: physics-only real-time factor on a world, single-threaded.

use std::time::Instant;

use anyhow::Result;
use rover_sim::{SimOptions, Simulation, Twist};

use crate::headless::{self, RunConfig};

/// One benchmark measurement.
#[derive(Debug, Clone, Copy)]
pub struct PhysicsBench {
    /// Physics step rate (Hz).
    pub step_hz: f64,
    /// Sim seconds simulated.
    pub sim_s: f64,
    /// Wall seconds it took (best of the repeats).
    pub wall_s: f64,
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

/// Steps the world's physics with the robot driving a figure of eight (forward at 0.5 m/s,
/// turning left then right every 4 s) for `sim_s` seconds, `repeats` times; keeps the fastest.
pub fn physics(
    config: &RunConfig,
    step_hz: Option<f64>,
    sim_s: f64,
    repeats: u32,
) -> Result<PhysicsBench> {
    let (world, robot) = headless::load(config)?;
    let options = SimOptions {
        step_hz,
        ..config.options.clone()
    };
    let mut best = f64::INFINITY;
    let mut rate = 0.0;
    for _ in 0..repeats.max(1) {
        let mut sim = Simulation::new(world.clone(), robot.clone(), &options)?;
        rate = 1.0 / sim.dt_s();
        let steps = (sim_s / sim.dt_s()).round() as u64;
        let started = Instant::now();
        let mut turning_left = true;
        sim.set_cmd_vel(Twist::new(0.5, 0.6))?;
        while sim.step_index() < steps {
            if sim.step_index() % (4 * rate as u64) == 0 {
                let turn = if turning_left { 0.6 } else { -0.6 };
                sim.set_cmd_vel(Twist::new(0.5, turn))?;
                turning_left = !turning_left;
            }
            sim.step();
        }
        best = best.min(started.elapsed().as_secs_f64());
    }
    Ok(PhysicsBench {
        step_hz: rate,
        sim_s,
        wall_s: best,
    })
}
