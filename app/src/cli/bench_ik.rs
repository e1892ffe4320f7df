//! `rover bench ik`: the inverse-kinematics solver's time per solve on a robot's chain.

use std::time::Instant;

use anyhow::Result;
use rover_core::RunConfig;
use rover_sim::{
    SplitMix64,
    model::{IkOptions, IkSolver, IkTarget, KinematicChain},
};

use super::args::WorldArgs;
use super::bench::median;

/// What the IK benchmark measured.
#[derive(Debug, Clone)]
pub struct IkBench {
    /// "base -> tip".
    pub chain: String,
    /// Moving joints in the chain.
    pub joints: usize,
    /// Targets solved.
    pub targets: usize,
    /// Solves within the solver's tolerances.
    pub converged: usize,
    /// Median time per solve (ms).
    pub median_ms: f64,
    /// Slowest solve (ms).
    pub max_ms: f64,
    /// Largest position error left (m).
    pub worst_error_m: f64,
    /// Median iterations per solve.
    pub median_iterations: f64,
}

/// Solves `targets` targets on the chain from `base` (default: the root link) to `ee_link`:
/// each is the tip's pose (or only its position) at a seeded random in-limit pose (the run's
/// seed), solved from the solver's rest pose (the middle of each joint's range).
pub fn ik(
    config: &RunConfig,
    base: Option<&str>,
    ee_link: &str,
    targets: usize,
    pose: bool,
) -> Result<IkBench> {
    let (_, robot) = config.load_world_and_robot()?;
    let base = base.unwrap_or_else(|| robot.link(robot.root).name.as_str());
    let chain = KinematicChain::new(&robot, base, ee_link)?;
    let options = IkOptions::default();
    let mut solver = IkSolver::new(chain.clone(), options)?;
    let start: Vec<f64> = chain.joints().iter().map(|j| j.middle()).collect();
    let mut rng = SplitMix64(config.options.seed ^ 0x1c);
    let goals: Vec<IkTarget> = (0..targets.max(1))
        .map(|_| {
            let goal = chain.base_from_tip(&chain.random_pose(&mut rng))?;
            Ok(if pose {
                IkTarget::pose(&goal)
            } else {
                IkTarget::point(goal.translation.vector)
            })
        })
        .collect::<Result<_>>()?;
    // One warm-up solve.
    solver.solve(&goals[0], &start)?;
    let mut times_ms = Vec::with_capacity(goals.len());
    let mut iterations = Vec::with_capacity(goals.len());
    let (mut converged, mut worst_error_m) = (0, 0.0f64);
    for goal in &goals {
        let began = Instant::now();
        let solution = solver.solve(goal, &start)?;
        times_ms.push(began.elapsed().as_secs_f64() * 1e3);
        iterations.push(solution.iterations as f64);
        converged += usize::from(solution.converged);
        worst_error_m = worst_error_m.max(solution.position_error_m);
    }
    let max_ms = times_ms.iter().copied().fold(0.0, f64::max);
    Ok(IkBench {
        chain: format!("{base} -> {ee_link}"),
        joints: chain.joints().len(),
        targets: goals.len(),
        converged,
        median_ms: median(&mut times_ms),
        max_ms,
        worst_error_m,
        median_iterations: median(&mut iterations),
    })
}

pub(crate) fn bench(
    world: WorldArgs,
    base: Option<&str>,
    ee_link: &str,
    targets: usize,
    pose: bool,
) -> Result<()> {
    let config = world.run_config(None);
    let b = ik(&config, base, ee_link, targets, pose)?;
    say!(
        "ik benchmark: {} ({} joints), {} {} targets: median {:.3} ms, slowest {:.3} ms per solve; {} of {} within tolerance (0.1 mm{}), worst error {:.2e} m, median {} iterations",
        b.chain,
        b.joints,
        b.targets,
        if pose { "pose" } else { "position" },
        b.median_ms,
        b.max_ms,
        b.converged,
        b.targets,
        if pose { ", 1 mrad" } else { "" },
        b.worst_error_m,
        b.median_iterations
    );
    Ok(())
}
