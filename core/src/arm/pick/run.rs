//! Running the plan: each control update, the steps' joint setpoints and gripper commands
//! to the simulation, one step after another.

use rover_sim::{
    physics::{JointCommand, Simulation, Twist},
    planning::TimedPath,
};

use super::state::{Pick, PickState, Step};

/// Seconds after a path's end before the next step (the joints settle on their setpoints).
const SETTLE_S: f64 = 0.3;
/// The tool this close to a path's end (m) has arrived.
const ARRIVED_M: f64 = 0.004;
/// The most seconds to wait after a path's end for the tool to arrive.
const MAX_SETTLE_S: f64 = 3.0;
/// Seconds a gripper command may take.
const GRIPPER_TIMEOUT_S: f64 = 3.0;

impl Pick {
    /// After a control update: runs the plan's steps (joint setpoints and gripper commands to
    /// `sim`).
    pub fn update(&mut self, sim: &mut Simulation) {
        let now = sim.sim_time_s();
        self.base_cmd = None;
        self.drive_base(sim, now);
        if self.state == PickState::Seeking
            && now >= self.settle_until_s
            && let Some(name) = self.known_object(sim).map(str::to_owned)
        {
            self.seek_known(sim, &name);
        }
        self.run_steps(sim, now);
        if self.fetch_at(sim).is_some()
            && !matches!(self.state, PickState::Done | PickState::Failed)
        {
            // A fetch owns the base: it stands still while the arm works.
            self.base_cmd.get_or_insert(Twist::ZERO);
        }
    }

    /// What the base is told this control update: `Some` while a fetch drives it (zero while
    /// the arm works), `None` when the pick leaves the base alone.
    pub fn base_command(&self) -> Option<Twist> {
        self.base_cmd
    }

    /// Runs the plan's steps.
    fn run_steps(&mut self, sim: &mut Simulation, now: f64) {
        if self.running.is_none() {
            let Some((step, state)) = self.steps.pop_front() else {
                if !matches!(
                    self.state,
                    PickState::Seeking | PickState::Done | PickState::Failed | PickState::Fetching
                ) && !self.deliver(sim, now)
                {
                    self.state = PickState::Done;
                    self.said.push((false, "pick: done".to_owned()));
                }
                return;
            };
            self.state = state;
            if let Step::Gripper { position, grip } = &step
                && let Ok(g) = &self.gripper
            {
                let effort = if *grip {
                    self.squeeze_n * g.finger.effort_per_n()
                } else {
                    0.0
                };
                if let Err(e) = sim.command_gripper(&g.controller, *position, effort) {
                    self.fail(e.to_string());
                    return;
                }
            }
            self.running = Some((step, now));
        }
        let Some((step, started)) = self.running.take() else {
            return;
        };
        let t = now - started;
        let finished = match &step {
            Step::Move(path) => {
                path.sample(t, &mut self.q, &mut self.v);
                for ((joint, q), v) in self
                    .solver
                    .chain()
                    .joints()
                    .iter()
                    .zip(&self.q)
                    .zip(&self.v)
                {
                    let command = JointCommand::Track {
                        position: *q,
                        velocity: *v,
                    };
                    if let Err(e) = sim.command_joint(&joint.name, command) {
                        tracing::debug!("pick: {e}");
                    }
                }
                let over = t - path.duration_s();
                over >= MAX_SETTLE_S
                    || (over >= SETTLE_S
                        && self.tool_off(sim, path).is_some_and(|off| off <= ARRIVED_M))
            }
            Step::Gripper { grip, .. } => {
                let Ok(g) = &self.gripper else {
                    return;
                };
                match sim.gripper_state(&g.controller) {
                    Some(s) if s.reached_goal && *grip && t > 0.1 => {
                        self.fail(format!(
                            "the gripper closed to {:.4} without touching anything",
                            s.position
                        ));
                        return;
                    }
                    Some(s) if t > 0.1 && (s.reached_goal || s.stalled) => true,
                    _ => t > GRIPPER_TIMEOUT_S,
                }
            }
            Step::Wait { s, until_held } => {
                t >= *s || (*until_held && sim.grasp_assist_holds().is_some())
            }
        };
        if !finished {
            self.running = Some((step, started));
        } else if let Step::Move(path) = &step
            && let Some(off) = self.tool_off(sim, path)
            && off > ARRIVED_M
        {
            self.said.push((
                false,
                format!(
                    "pick: {}: the tool stopped {off:.3} m from its goal (the joints cannot hold it there)",
                    self.state.as_str()
                ),
            ));
        }
    }

    /// How far the tool is from where `path` ends (m).
    fn tool_off(&mut self, sim: &Simulation, path: &TimedPath) -> Option<f64> {
        let goal = path.waypoints().last()?;
        self.q.clear();
        self.q.extend(
            self.solver
                .chain()
                .joints()
                .iter()
                .map(|j| sim.joint_state(j.id).map_or(0.0, |s| s.position)),
        );
        let chain = self.solver.chain();
        let (at, want) = (
            chain.base_from_tip(&self.q).ok()?,
            chain.base_from_tip(goal).ok()?,
        );
        Some((at.translation.vector - want.translation.vector).norm())
    }
}
