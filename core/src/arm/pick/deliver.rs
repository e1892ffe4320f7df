//! With the object in the hand (a fetch): the drive to the place, a stop as soon as the arm
//! reaches it, and the place's plan from where the base stopped.

use std::collections::VecDeque;

use nalgebra::{Point3, Vector3};
use rover_sim::{
    model::{IkSolver, isometry_from_pose},
    physics::{Simulation, wrap_angle},
};

use super::fetch::BACK_OFF_M;
use super::ground::beside;
use super::plan::over_place;
use super::stance::yaw_of;
use super::state::{Gripper, Held, Leg, Pick, PickState, Step};
use super::ways::ik_close;

/// How often (s of sim time) a pose drive to the place, at its point, asks whether the arm
/// already reaches the place.
const REACH_CHECK_S: f64 = 0.5;
/// At most this many of a place's spots are planned (each one the arm reaches by IK) before
/// the place's plan gives up.
const SPOTS_PLANNED: usize = 4;

impl Pick {
    /// After the grasp's steps, with the object held for a fetch: the drive to the place,
    /// then (the base settled) the place's plan. Returns whether it took over (`false`:
    /// nothing is held for it, the pick is done).
    pub(super) fn deliver(&mut self, sim: &Simulation, now: f64) -> bool {
        let Some(held) = &self.held else {
            return false;
        };
        if self.state != PickState::Delivering {
            let [x, y, z] = held.place.0;
            if self.fetch_given(sim).is_none()
                && let Err(why) = self.place_stance(sim)
            {
                self.fail(format!("the place is out of the arm's reach: {why}"));
                return true;
            }
            let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
            let base = world_from_base.translation.vector.xy();
            let at = self.fetch_at(sim).unwrap_or_default();
            // The route starts where backing off ends; an arm that works beside the base
            // (its stance beside it) has nothing ahead to back away from.
            let back_m = if beside(at) { 0.0 } else { BACK_OFF_M };
            let backed = base - (world_from_base.rotation * Vector3::x()).xy() * back_m;
            let tool = isometry_from_pose(&sim.world_from_link(self.tool))
                .translation
                .vector;
            let goal = Vector3::new(x, y, z);
            let yaw = yaw_of(&world_from_base);
            let via = self.route_to(sim, (goal, at), (backed, yaw), (tool, 0.1));
            self.leg = Some(Leg {
                goal,
                to_place: true,
                started_s: now,
                back_from: (!beside(at)).then_some(base),
                via,
                yaw_rad: beside(at).then_some(yaw),
                reach_checked_s: now,
            });
            self.drive.reset();
            self.state = PickState::Delivering;
            self.said.push((
                false,
                format!("pick: fetch: driving to the place at ({x:.2}, {y:.2}) m"),
            ));
            return true;
        }
        if self.leg.is_some() || now < self.settle_until_s {
            return true;
        }
        let Some(held) = self.held.take() else {
            return false;
        };
        match self.plan_delivery(sim, held) {
            Ok(steps) => self.steps = VecDeque::from(steps),
            Err(why) => self.fail(format!("fetch: at the place: {why}")),
        }
        true
    }

    /// With no `fetch` point: the stance the arm reaches the place from with the object in the
    /// hand (the object in the hand and round it left out of the obstacles).
    fn place_stance(&mut self, sim: &Simulation) -> Result<(), String> {
        let Some(held) = self.held.clone() else {
            return Ok(());
        };
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let (over, _) = over_place(&world_from_base, held.place, held.target.half_height_m);
        let tool = isometry_from_pose(&sim.world_from_link(self.tool))
            .translation
            .vector;
        let started = std::time::Instant::now();
        let at = self.choose_stance(
            sim,
            (over, held.target.bound_m),
            &world_from_base,
            (tool, held.target.bound_m + 0.05),
        )?;
        self.stance = Some(at);
        self.said.push((
            false,
            format!(
                "pick: the base stands with the place at ({:.2}, {:.2}) m from the arm's base (surveyed in {:.3} s)",
                at.x,
                at.y,
                started.elapsed().as_secs_f64()
            ),
        ));
        Ok(())
    }

    /// Whether a pose drive to the place (`leg`), at its point and turning to its heading,
    /// may stop where it is: the arm reaches one of the place's spots from here (checked
    /// every [`REACH_CHECK_S`]). A base that reaches its point a little off its heading
    /// (Stretch's, on its box-shaped wheels) need not turn in place the last few degrees,
    /// which drags it off the point again.
    pub(super) fn near_enough(&mut self, sim: &Simulation, leg: &mut Leg, now: f64) -> bool {
        if !leg.to_place || leg.yaw_rad.is_none() || !self.drive.at_point() {
            return false;
        }
        if now - leg.reach_checked_s < REACH_CHECK_S {
            return false;
        }
        leg.reach_checked_s = now;
        let (Some(held), Ok(g)) = (&self.held, &self.gripper) else {
            return false;
        };
        let Ok(mut quick) = self.quick_solver() else {
            return false;
        };
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let q = self.chain_q(sim);
        let reached = held.spots.iter().position(|spot| {
            let (over, _) = over_place(
                &world_from_base,
                (*spot, held.place.1, held.place.2),
                held.target.half_height_m,
            );
            self.reaches_over(&mut quick, (held, g), over, &q)
        });
        let spots = held.spots.len();
        if let Some(k) = reached {
            let heading = leg
                .yaw_rad
                .map_or(0.0, |yaw| wrap_angle(yaw - yaw_of(&world_from_base)));
            self.said.push((
                false,
                format!(
                    "pick: fetch: the arm reaches the place from here ({:.1} deg off the stance's heading; spot {k} of {spots})",
                    heading.to_degrees(),
                ),
            ));
        }
        reached.is_some()
    }

    /// Whether the arm, at `q`, reaches over the place at `over` (base frame) with the object
    /// `held` as it was taken, any of the place's ways, by IK alone (`quick`).
    fn reaches_over(
        &self,
        quick: &mut IkSolver,
        (held, g): (&Held, &Gripper),
        over: Vector3<f64>,
        q: &[f64],
    ) -> bool {
        let ways = self.place_ways((&held.target, &held.way), g, over);
        ways.iter().any(|way| {
            quick
                .solve(&way.target(over + way.offset), q)
                .is_ok_and(|s| ik_close(s.position_error_m, s.orientation_error_rad))
        })
    }

    /// The place's plan from where the arm is now, the object held as it was taken: over the
    /// place's point, else over the first of its other spots the arm reaches (at most
    /// [`SPOTS_PLANNED`] of them planned).
    fn plan_delivery(
        &mut self,
        sim: &Simulation,
        held: Held,
    ) -> Result<Vec<(Step, PickState)>, String> {
        let (g, world_from_base, mut scene) = self.planning_start(sim)?;
        let q = self.chain_q(sim);
        // The object in the hand is carried, not avoided.
        let tool = self
            .solver
            .chain()
            .base_from_tip(&q)
            .map_err(|e| e.to_string())?;
        let in_hand = world_from_base * Point3::from(tool.translation.vector);
        if let Some(i) = scene.object_near(
            [in_hand.x, in_hand.y, in_hand.z],
            held.target.bound_m as f32 + 0.02,
        ) {
            scene.ignore_object(i, true);
        }
        let mut quick = self.quick_solver()?;
        let mut first_why: Option<String> = None;
        let mut planned = 0;
        for (k, spot) in held.spots.iter().enumerate() {
            let over = over_place(
                &world_from_base,
                (*spot, held.place.1, held.place.2),
                held.target.half_height_m,
            );
            if k > 0 && !self.reaches_over(&mut quick, (&held, &g), over.0, &q) {
                continue;
            }
            let mut tried = scene.clone();
            let way = (held.target, held.way.clone());
            match self.plan_place(&mut tried, way, &g, (&q, &held.home_q), over) {
                Ok(steps) => {
                    if k > 0 {
                        self.said.push((
                            false,
                            format!(
                                "pick: fetch: the place's middle is out of reach from where the base stopped ({}): setting it down at ({:.2}, {:.2}) m",
                                first_why.as_deref().unwrap_or("?"),
                                spot[0],
                                spot[1]
                            ),
                        ));
                    }
                    return Ok(steps);
                }
                Err(why) => {
                    first_why.get_or_insert(why);
                    planned += 1;
                    if planned >= SPOTS_PLANNED {
                        break;
                    }
                }
            }
        }
        Err(first_why.unwrap_or_else(|| "no spot on the place is in the arm's reach".to_owned()))
    }
}
