//! Where the base stands when nobody said (no `fetch` point): the arm's reachability at the
//! height of what it must reach, surveyed by IK along a few bearings from the arm's base (a
//! reachability map, as a mobile manipulator chooses a base placement from one), passing over
//! stances where the car's body would stand in what surrounds the object.
//!
//! The survey solves each point once, without random restarts, seeded from the point before
//! on the same bearing: a few hundred IK solves of the arm's own chain, done when a pick finds
//! its object or its place out of reach (the planning time it says includes it).

use nalgebra::{Isometry3, Point3, Vector2, Vector3};
use rover_sim::{
    model::{IkOptions, IkSolver},
    physics::Simulation,
};

use super::ground::{body_footprint, obstacles, overlap, stance_pose, stance_yaw};
use super::plan::upright_pitches;
use super::state::{Pick, Target};
use super::ways::ik_close;

/// Bearings surveyed (deg from the side the arm reaches to, [`Pick::arm_side_rad`]; left
/// positive), in order of preference on a tie: straight out is where the base's drive ends
/// most exactly.
const BEARINGS_DEG: [f64; 7] = [0.0, 10.0, -10.0, 20.0, -20.0, 30.0, -30.0];
/// Ranges surveyed from the arm's base (m).
const RANGES_M: (f64, f64) = (0.05, 1.2);
/// Spacing of the ranges surveyed (m).
const RANGE_STEP_M: f64 = 0.02;
/// Ranges this close to the ends of a reachable run are not chosen (m): the base stops within
/// a couple of centimetres of its goal and the estimate is a centimetre off.
const RUN_MARGIN_M: f64 = 0.04;

impl Pick {
    /// An IK solver for the arm's chain that tries once, without random restarts: for surveys
    /// of many points, each seeded from a solution near it.
    pub(super) fn quick_solver(&self) -> Result<IkSolver, String> {
        IkSolver::new(
            self.solver.chain().clone(),
            IkOptions {
                restarts: 0,
                tolerance_m: 5e-4,
                tolerance_rad: 5e-3,
                ..IkOptions::default()
            },
        )
        .map_err(|e| e.to_string())
    }

    /// Whether the arm reaches `target` from its pose now, by IK alone, any of the ways it
    /// would be taken.
    pub(super) fn reaches(&mut self, sim: &Simulation, target: &Target) -> bool {
        let q = self.chain_q(sim);
        let mut pitches = self.config.approach_pitches_deg.clone();
        if target.upright.is_some() {
            pitches = upright_pitches(&pitches);
        }
        let ways = match &self.gripper {
            Ok(g) => self.ways_taking(target, g, &pitches),
            Err(_) => self.ways_round(target.centre, target.bound_m),
        };
        ways.iter().any(|way| {
            self.solver
                .solve(&way.target(target.centre + way.offset), &q)
                .is_ok_and(|s| ik_close(s.position_error_m, s.orientation_error_rad))
        })
    }

    /// The side of the base the arm works on (rad from the arm base's x, left positive): ahead
    /// (0) for an arm that turns its hand as it likes (the arm car's, whose tool may rest
    /// anywhere round its base); for one that holds its hand level and reaches out to one
    /// side (Stretch's telescope, -pi/2), the tool's bearing at `q` to the nearest quarter
    /// turn.
    pub(super) fn arm_side_rad(&self, q: &[f64]) -> f64 {
        if !self.solver.chain().holds_level() {
            return 0.0;
        }
        let tip = (self.solver.chain().base_from_tip(q))
            .map_or_else(|_| Vector3::x(), |t| t.translation.vector);
        let quarter = std::f64::consts::FRAC_PI_2;
        (tip.y.atan2(tip.x) / quarter).round() * quarter
    }

    /// Where (arm base frame, x and y, m) the point `target` (base frame now, the base at
    /// `world_from_base`) should be when the base stops so the arm reaches it: on the bearing
    /// with the longest run of ranges the arm reaches round `radius_m` and the car's body stands
    /// clear of the world's objects (leaving out any within `ignore_m` of the world point
    /// `ignore`: the object itself, or the one in the hand), in the middle of that run.
    pub(super) fn choose_stance(
        &mut self,
        sim: &Simulation,
        (target, radius_m): (Vector3<f64>, f64),
        world_from_base: &Isometry3<f64>,
        (ignore, ignore_m): (Vector3<f64>, f64),
    ) -> Result<Vector2<f64>, String> {
        let mut survey = self.quick_solver()?;
        let target_world = world_from_base * Point3::from(target);
        let body = body_footprint(sim, self.base);
        let obstacles = obstacles(sim, ignore, ignore_m);
        let heading_rad = (target_world.y - world_from_base.translation.y)
            .atan2(target_world.x - world_from_base.translation.x);
        let base_yaw = world_from_base.rotation.euler_angles().2;
        let q0 = self.chain_q(sim);
        let side = self.arm_side_rad(&q0);
        let mut best: Option<(usize, Vector2<f64>)> = None;
        for bearing_deg in BEARINGS_DEG {
            let bearing = side + bearing_deg.to_radians();
            let (s, c) = bearing.sin_cos();
            let mut seed = q0.clone();
            let mut run: Vec<f64> = Vec::new();
            let mut longest: Vec<f64> = Vec::new();
            let steps = ((RANGES_M.1 - RANGES_M.0) / RANGE_STEP_M).round() as usize;
            for k in 0..=steps {
                let range = RANGES_M.0 + k as f64 * RANGE_STEP_M;
                let at = Vector2::new(c * range, s * range);
                let point = Vector3::new(at.x, at.y, target.z);
                let reached = self.ways_round(point, radius_m).iter().find_map(|way| {
                    let solution = survey.solve(&way.target(point), &seed).ok()?;
                    ik_close(solution.position_error_m, solution.orientation_error_rad)
                        .then_some(solution.q)
                });
                // The base facing the object less the bearing (or, beside, as it is), the
                // point brought to `at`.
                let yaw = stance_yaw(at, heading_rad - bearing, base_yaw);
                let clear = body.is_some_and(|body| {
                    let stand = stance_pose(target_world.coords.xy(), at, yaw);
                    let body = body.placed(&stand);
                    obstacles.iter().all(|o| !overlap(&body, o))
                });
                match reached {
                    Some(q) if clear => {
                        seed = q;
                        run.push(range);
                    }
                    _ => {
                        if let Some(q) = reached {
                            seed = q;
                        }
                        if run.len() > longest.len() {
                            longest = std::mem::take(&mut run);
                        }
                        run.clear();
                    }
                }
            }
            if run.len() > longest.len() {
                longest = run;
            }
            let usable = longest.len() as f64 * RANGE_STEP_M - 2.0 * RUN_MARGIN_M;
            if usable <= 0.0 || best.as_ref().is_some_and(|(n, _)| *n >= longest.len()) {
                continue;
            }
            if let (Some(near), Some(far)) = (longest.first(), longest.last()) {
                let middle = (near + far) / 2.0;
                best = Some((longest.len(), Vector2::new(c * middle, s * middle)));
            }
        }
        best.map(|(_, at)| at).ok_or_else(|| {
            format!(
                "no stance found: the arm reaches ({:.2}, {:.2}, {:.2}) m from nowhere the car's body stands clear (bearings {:?} deg from {:.0} deg, ranges {:.2}-{:.2} m)",
                target_world.x, target_world.y, target_world.z, BEARINGS_DEG, side.to_degrees(), RANGES_M.0, RANGES_M.1
            )
        })
    }
}
