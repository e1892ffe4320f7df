//! Planning: the grasp, the place and the paths between them, all at once, in the world's
//! planning scene.

use std::collections::VecDeque;

use nalgebra::{Isometry3, Point3, Vector3};
use rover_sim::{
    geometry::Pose,
    model::{GraspMode, isometry_from_pose},
    physics::Simulation,
    planning::{PlanningScene, TimedPath, plan_path},
};

use super::state::{Grasp, Gripper, Held, Pick, PickState, Step, Target, Way};

/// The place's steps from the lift, or why the arm does not reach it.
type Placed = Result<Vec<(Step, PickState)>, String>;

/// How far above a place point the object's bottom is let go (m): set down, not dropped.
pub(super) const SET_DOWN_M: f64 = 0.005;
/// A round object's estimated radius may exceed the open hand's half-width by this much (m)
/// before it is refused: the estimate from a box and a depth image is a centimetre or so off
/// (an orange of 7.4 cm is seen as 8.6 cm), and the grasp's fingers close on what is there.
const SPAN_SLACK_M: f64 = 0.005;
/// Turns (deg) round the vertical from the arm's side the hand may take an upright object
/// with, in order.
pub(super) const GRASP_YAWS_DEG: [f64; 5] = [0.0, -20.0, 20.0, -40.0, 40.0];
/// ... and set it down with.
const PLACE_YAWS_DEG: [f64; 7] = [0.0, -20.0, 20.0, -40.0, 40.0, -60.0, 60.0];
/// How much farther than its bounding radius (m) an object is set down inside a place's edges
/// when it goes elsewhere than the place's middle.
const SPOT_MARGIN_M: f64 = 0.03;
/// How far the tool backs up after letting go (m).
const RETREAT_M: f64 = 0.05;
/// Seconds to full speed on a timed path.
const RAMP_S: f64 = 0.3;

impl Pick {
    /// The chain's joint positions now.
    pub(super) fn chain_q(&self, sim: &Simulation) -> Vec<f64> {
        (self.joints().iter())
            .map(|j| sim.joint_state(j.id).map_or(0.0, |s| s.position))
            .collect()
    }

    /// What every plan starts from: the gripper, where the arm's base is, and the planning
    /// scene as the world is now.
    pub(super) fn planning_start(
        &self,
        sim: &Simulation,
    ) -> Result<(Gripper, Isometry3<f64>, PlanningScene), String> {
        let g = self.gripper.clone()?;
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let scene = sim
            .planning_scene(self.solver.chain(), self.config.margin_m as f32)
            .map_err(|e| e.to_string())?;
        Ok((g, world_from_base, scene))
    }

    /// The whole plan for `target` (called `what`): the grasp, then the place (or, with no
    /// place, holding it up).
    pub(super) fn plan(
        &mut self,
        sim: &Simulation,
        what: &str,
        target: Target,
    ) -> Result<VecDeque<(Step, PickState)>, String> {
        let (g, world_from_base, mut scene) = self.planning_start(sim)?;
        let w = world_from_base * Point3::from(target.centre);
        let object = scene.object_near([w.x, w.y, w.z], target.bound_m as f32 + 0.02);
        // Over the place: where the carry ends, and how far it then goes straight down.
        let place_under =
            (self.place_under(sim)?).map(|p| set_down_upright(p, &target, self.config.approach_m));
        let place = place_under.map(|p| over_place(&world_from_base, p, target.half_height_m));
        let q0 = self.chain_q(sim);
        // With a fetch point the base takes it to the place ([`Self::deliver`]); else the
        // place is planned from here, and only out of reach does the base take it there.
        let place_here = place.filter(|_| self.fetch_given(sim).is_none());
        let (grasp, placed) =
            self.grasp_then_place(&mut scene, (what, target, object), &g, &q0, place_here)?;
        self.taken = Some(grasp.way.label.clone());
        self.squeeze_n = match target.upright {
            Some(_) => self.config.squeeze_upright_n,
            None => self.config.squeeze_n,
        };
        let assist = sim.world().robot.grasp == GraspMode::Assist;
        let joints = self.joints().to_vec();
        let speed_scale = self.config.speed_scale;
        let timed = |w: Vec<Vec<f64>>, stop: bool| {
            Step::Move(TimedPath::new(w, &joints, speed_scale, RAMP_S, stop))
        };
        let to_pre_points = grasp.to_pre.len();
        self.path_points = Some(match (self.path_points, &placed) {
            (Some([_, carry, home]), Some(Ok(_))) => [to_pre_points, carry, home],
            _ => [to_pre_points, 0, 0],
        });
        let mut steps = VecDeque::from([
            (
                Step::Gripper {
                    position: g.open,
                    grip: false,
                },
                PickState::Approaching,
            ),
            (timed(grasp.to_pre, true), PickState::Approaching),
            (timed(grasp.descent, false), PickState::Approaching),
            (
                Step::Gripper {
                    position: g.closed,
                    grip: true,
                },
                PickState::Grasping,
            ),
            (
                Step::Wait {
                    s: if assist { 2.0 } else { 0.3 },
                    until_held: assist,
                },
                PickState::Grasping,
            ),
            (timed(grasp.lift, false), PickState::Lifting),
        ]);
        let Some(place) = place_under else {
            // No place: it stays in the hand, held up.
            return Ok(steps);
        };
        match placed {
            Some(Ok(more)) => {
                steps.extend(more);
                return Ok(steps);
            }
            Some(Err(why)) if sim.can_drive() => self.said.push((
                false,
                format!("pick: the place is out of the arm's reach from here ({why}): the base takes it there"),
            )),
            Some(Err(why)) => return Err(why),
            None => {}
        }
        // Held up while the base drives.
        let spots = self.place_spots(sim, place.0, target.bound_m + SPOT_MARGIN_M);
        self.held = Some(Held {
            target,
            way: grasp.way,
            home_q: q0,
            place,
            spots,
        });
        Ok(steps)
    }

    /// The grasp of `target` (called `what`; `object` its index in the scene) from `q0`, and
    /// with `place` (over it and how far down) the place's plan from the grasp's lift, or why
    /// the place cannot be reached. An upright object is set down as it was taken (the hand at
    /// the same pitch), so each pitch is tried in turn until one both takes and places it.
    fn grasp_then_place(
        &mut self,
        scene: &mut PlanningScene,
        (what, target, object): (&str, Target, Option<usize>),
        g: &Gripper,
        q0: &[f64],
        place: Option<(Vector3<f64>, f64)>,
    ) -> Result<(Grasp, Option<Placed>), String> {
        let all = self.config.approach_pitches_deg.clone();
        let tries: Vec<Vec<f64>> = match (target.upright, place) {
            (Some(_), Some(_)) => upright_pitches(&all).into_iter().map(|p| vec![p]).collect(),
            (Some(_), None) => vec![upright_pitches(&all)],
            (None, _) => vec![all],
        };
        let mut first: Option<(Grasp, String)> = None;
        let mut grasp_why = Vec::new();
        for pitches in &tries {
            let grasp = match self.plan_grasp(scene, what, (target, object), g, q0, pitches) {
                Ok(grasp) => grasp,
                Err(why) => {
                    grasp_why.push(why);
                    continue;
                }
            };
            let Some(over) = place else {
                return Ok((grasp, None));
            };
            let lift_q = grasp.lift.last().cloned().unwrap_or_default();
            let held = (target, grasp.way.clone());
            match self.plan_place(scene, held, g, (&lift_q, q0), over) {
                Ok(more) => return Ok((grasp, Some(Ok(more)))),
                Err(why) if first.is_none() => first = Some((grasp, why)),
                Err(_) => {}
            }
        }
        match first {
            Some((grasp, why)) => Ok((grasp, Some(Err(why)))),
            None if grasp_why.len() == 1 => Err(grasp_why.remove(0)),
            None => Err(grasp_why.join("; ")),
        }
    }

    /// The ways the hand may come over the place at `over` (base frame) holding `target` as
    /// way `way_held` took it: an upright object at the same pitch, turned round the vertical;
    /// anything else any way round the point.
    pub(super) fn place_ways(
        &self,
        (target, way_held): (&Target, &Way),
        g: &Gripper,
        over: Vector3<f64>,
    ) -> Vec<Way> {
        match target.upright {
            Some(radius_m) => {
                let pitch_deg = (-way_held.along.z).clamp(-1.0, 1.0).asin().to_degrees();
                self.ways_upright(
                    over,
                    (radius_m, target.half_height_m),
                    g,
                    (&[pitch_deg], &PLACE_YAWS_DEG),
                )
            }
            None => self.ways_round(over, g.finger.half_width_m(g.open)),
        }
    }

    /// From the lift (`lift_q`) with the object `held` as the hand took it: the carry to over
    /// the place (`over`, base frame), the straight way down `lower_m` (none for a drop), the
    /// release, the retreat and the way home (`home_q`).
    pub(super) fn plan_place(
        &mut self,
        scene: &mut PlanningScene,
        (target, way_held): (Target, Way),
        g: &Gripper,
        (lift_q, home_q): (&[f64], &[f64]),
        (over, lower_m): (Vector3<f64>, f64),
    ) -> Result<Vec<(Step, PickState)>, String> {
        let joints = self.joints().to_vec();
        let speed_scale = self.config.speed_scale;
        let timed = |w: Vec<Vec<f64>>, stop: bool| {
            Step::Move(TimedPath::new(w, &joints, speed_scale, RAMP_S, stop))
        };
        // Carrying: the object on the tool, as the hand holds it.
        self.attach_held(scene, &target, &way_held);
        let ways = self.place_ways((&target, &way_held), g, over);
        let (place_q, _, way) = self
            .reachable(scene, over, lift_q, "the place", None, &ways)
            .map_err(|why| format!("cannot reach over the place: {why}"))?;
        let carry = plan_path(&joints, lift_q, &place_q, &self.config.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("carrying: {e}"))?;
        // Set down: straight down onto the surface, the object (about to touch it) left out.
        scene.attach_sphere(None);
        let set_down = if lower_m > 0.0 {
            let at = over + way.offset;
            self.line_at_least(
                scene,
                &place_q,
                (at, at - Vector3::z() * lower_m),
                Some(&way),
                1.0,
            )
            .map_err(|e| format!("setting it down: {e}"))?
        } else {
            Vec::new()
        };
        let release_q = set_down.last().cloned().unwrap_or_else(|| place_q.clone());
        // Let go; back up and home, the gripper open.
        scene.set_joint(g.joint, g.open);
        let from = self
            .solver
            .chain()
            .base_from_tip(&release_q)
            .map_err(|e| e.to_string())?
            .translation
            .vector;
        // Back out the way it came in from an upright object (the fingers slide off it), else
        // straight up.
        let back = match target.upright {
            Some(_) => -way.along * self.config.approach_m,
            None => Vector3::z() * RETREAT_M.max(lower_m),
        };
        let retreat = self.line_at_least(scene, &release_q, (from, from + back), None, 0.0)?;
        let retreat_q = retreat.last().cloned().unwrap_or_else(|| release_q.clone());
        let home = plan_path(&joints, &retreat_q, home_q, &self.config.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("going home: {e}"))?;
        self.path_points = Some([
            self.path_points.map_or(0, |p| p[0]),
            carry.len(),
            home.len(),
        ]);
        let mut steps = vec![(timed(carry, true), PickState::Carrying)];
        if set_down.len() > 1 {
            steps.push((timed(set_down, false), PickState::Releasing));
        }
        steps.extend([
            (
                Step::Gripper {
                    position: g.open,
                    grip: false,
                },
                PickState::Releasing,
            ),
            (
                Step::Wait {
                    s: 0.5,
                    until_held: false,
                },
                PickState::Releasing,
            ),
            (timed(retreat, false), PickState::Retreating),
            (timed(home, true), PickState::Retreating),
        ]);
        Ok(steps)
    }

    /// Puts `target`, held as `way_held` takes it, on the tool in `scene` (for the carry's
    /// checks): upright, a box across its faces, else the sphere round it.
    fn attach_held(&self, scene: &mut PlanningScene, target: &Target, way_held: &Way) {
        match (target.cuboid, way_held.turn) {
            (None, Some(turn)) if target.upright.is_some() => {
                // Upright, its axes the base's: the tool `offset` from its centre.
                let r = target.across_m();
                let box_from_tool = turn.inverse();
                let at = box_from_tool * -way_held.offset;
                let q = box_from_tool.into_inner();
                scene.attach_box(
                    self.tool,
                    Pose::from_parts(
                        glam::Vec3::new(at.x as f32, at.y as f32, at.z as f32),
                        glam::Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32),
                    ),
                    [r, r, target.half_height_m].map(|h| h as f32),
                );
            }
            (Some((r, half)), Some(turn)) => {
                let q = (turn.inverse() * r).into_inner();
                let tool_from_box =
                    glam::Quat::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32);
                scene.attach_box(
                    self.tool,
                    Pose::from_rotation(tool_from_box),
                    half.map(|h| h as f32),
                );
            }
            _ => scene.attach_sphere(Some((self.tool, Pose::IDENTITY, target.bound_m as f32))),
        }
    }

    /// The way to the object and up with it, from `q0`: the path to the pre-grasp (the object
    /// in the scene), the straight way in and the lift (the object left out, the fingers on
    /// it).
    fn plan_grasp(
        &mut self,
        scene: &mut PlanningScene,
        what: &str,
        (object, target): (Target, Option<usize>),
        g: &Gripper,
        q0: &[f64],
        pitches: &[f64],
    ) -> Result<Grasp, String> {
        let c = self.config.clone();
        let centre = object.centre;
        scene.set_joint(g.joint, g.open);
        if let Some(t) = target {
            scene.ignore_object(t, true);
        }
        spans(g, what, &object)?;
        let ways = self.ways_taking(&object, g, pitches);
        if ways.is_empty() {
            return Err(format!(
                "cannot grasp {what}: it is wider than the open gripper ({:.3} m) every way",
                2.0 * g.widest_m()
            ));
        }
        let (grasp_q, mut descent, way) = self
            .reachable(scene, centre, q0, "the grasp", Some(c.approach_m), &ways)
            .map_err(|why| format!("cannot grasp {what}: {why}"))?;
        let pre_q = descent.last().cloned().unwrap_or_else(|| grasp_q.clone());
        descent.reverse();
        if let Some(t) = target {
            scene.ignore_object(t, false);
        }
        let joints = self.joints().to_vec();
        let to_pre = plan_path(&joints, q0, &pre_q, &c.planner, |q| {
            scene.collision(q).map(|h| h.to_string())
        })
        .map_err(|e| format!("to the pre-grasp: {e}"))?;
        if let Some(t) = target {
            scene.ignore_object(t, true);
        }
        let (lo, hi) = (g.closed.min(g.open), g.closed.max(g.open));
        scene.set_joint(g.joint, g.joint_at(way.grip_m).clamp(lo, hi));
        // Straight up off what it rests on; the hand may turn on the way (the object turns
        // with it). The arm is checked, the object (touching its support, as far as the
        // estimate knows) only from the lift's top.
        let at = centre + way.offset;
        let lift = self.line_at_least(
            scene,
            &grasp_q,
            (at, at + Vector3::z() * c.lift_m),
            None,
            0.5,
        )?;
        Ok(Grasp {
            to_pre,
            descent,
            lift,
            way,
        })
    }
}

/// Whether the open gripper `g` spans `target` (called `what`): a round one within
/// [`SPAN_SLACK_M`] (a box is checked face by face); else why not.
pub(super) fn spans(g: &Gripper, what: &str, target: &Target) -> Result<(), String> {
    if target.cuboid.is_none() && target.across_m() > g.widest_m() + SPAN_SLACK_M {
        return Err(format!(
            "cannot grasp {what}: it is {:.3} m across, wider than the open gripper ({:.3} m)",
            2.0 * target.across_m(),
            2.0 * g.widest_m()
        ));
    }
    Ok(())
}

/// Where the carry ends over a place ([`Pick::place_under`]: the point under the object, how
/// high above it the carry ends, how far the hand then goes down), in the arm's base frame for
/// an object `half_height_m` tall above its centre, and how far it goes down.
pub(super) fn over_place(
    world_from_base: &Isometry3<f64>,
    ([x, y, z], above_m, lower_m): ([f64; 3], f64, f64),
    half_height_m: f64,
) -> (Vector3<f64>, f64) {
    let over = world_from_base.inverse() * Point3::new(x, y, z + above_m + half_height_m);
    (over.coords, lower_m)
}

/// The place ([`Pick::place_under`]) for `target`: an upright object is set down on a world
/// object rather than dropped (from half `approach_m` above its top, straight down to
/// [`SET_DOWN_M`] above it), so it stays standing.
fn set_down_upright(
    (point, above_m, lower_m): ([f64; 3], f64, f64),
    target: &Target,
    approach_m: f64,
) -> ([f64; 3], f64, f64) {
    if target.upright.is_none() || lower_m > 0.0 {
        return (point, above_m, lower_m);
    }
    let above = (approach_m / 2.0).max(SET_DOWN_M);
    (point, above, above - SET_DOWN_M)
}

/// The pitches (deg below horizontal) an upright object is taken at: `pitches` and level,
/// steepest first. The pads' length along its side holds it upright; a level hand's pads
/// touch it only 2 cm high, and a 390 g can turns about the fingers' line as it is lifted.
pub(super) fn upright_pitches(pitches: &[f64]) -> Vec<f64> {
    let mut all = pitches.to_vec();
    if !all.contains(&0.0) {
        all.push(0.0);
    }
    all.sort_by(|a, b| b.total_cmp(a));
    all
}
