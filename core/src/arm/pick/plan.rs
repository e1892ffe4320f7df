//! Planning: the grasp, the place and the paths between them, all at once, in the world's
//! planning scene.

use std::collections::VecDeque;

use nalgebra::{Isometry3, Point3, Vector3};
use rover_sim::{
    geometry::Pose,
    model::{GraspMode, Place, isometry_from_pose},
    physics::Simulation,
    planning::{PlanningScene, TimedPath, plan_path},
};

use super::state::{Grasp, Gripper, Held, Pick, PickState, Step, Target, Way};
use super::world::world_object;

/// How far above a place point the object's bottom is let go (m): set down, not dropped.
const SET_DOWN_M: f64 = 0.005;
/// A round object's estimated radius may exceed the open hand's half-width by this much (m)
/// before it is refused: the estimate from a box and a depth image is a centimetre or so off
/// (an orange of 7.4 cm is seen as 8.6 cm), and the grasp's fingers close on what is there.
const SPAN_SLACK_M: f64 = 0.005;
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
        let place_under = self.place_under(sim)?;
        let place = place_under.map(|p| over_place(&world_from_base, p, target.half_height_m));
        let q0 = self.chain_q(sim);
        let grasp = self.plan_grasp(&mut scene, what, target, object, &g, &q0)?;
        let assist = sim.world().robot.grasp == GraspMode::Assist;
        let joints = self.joints().to_vec();
        let speed_scale = self.config.speed_scale;
        let timed = |w: Vec<Vec<f64>>, stop: bool| {
            Step::Move(TimedPath::new(w, &joints, speed_scale, RAMP_S, stop))
        };
        let lift_q = grasp.lift.last().cloned().unwrap_or_default();
        self.path_points = Some([grasp.to_pre.len(), 0, 0]);
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
        let Some((over, lower_m)) = place else {
            // No place: it stays in the hand, held up.
            return Ok(steps);
        };
        let Some(place) = place_under else {
            return Ok(steps);
        };
        // With a fetch point the base takes it to the place ([`Self::deliver`]); else the
        // place is planned from here, and only out of reach does the base take it there.
        let drive_there = match self.fetch_given(sim) {
            Some(_) => true,
            None => {
                let held = (target, grasp.way.clone());
                match self.plan_place(&mut scene, held, &g, (&lift_q, &q0), (over, lower_m)) {
                    Ok(more) => {
                        steps.extend(more);
                        false
                    }
                    Err(why) if sim.can_drive() => {
                        self.said.push((
                            false,
                            format!("pick: the place is out of the arm's reach from here ({why}): the base takes it there"),
                        ));
                        true
                    }
                    Err(why) => return Err(why),
                }
            }
        };
        if drive_there {
            // Held up while the base drives.
            self.held = Some(Held {
                target,
                way: grasp.way,
                home_q: q0,
                place,
            });
        }
        Ok(steps)
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
        match (target.cuboid, way_held.turn) {
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
        let ways = self.ways_round(over, g.open);
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
            self.line_at_least(
                scene,
                &place_q,
                (over, over - Vector3::z() * lower_m),
                Some(&ways[way]),
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
        let retreat = self.line_at_least(
            scene,
            &release_q,
            (from, from + Vector3::z() * RETREAT_M.max(lower_m)),
            None,
            0.0,
        )?;
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

    /// The way to the object and up with it, from `q0`: the path to the pre-grasp (the object
    /// in the scene), the straight way in and the lift (the object left out, the fingers on
    /// it).
    fn plan_grasp(
        &mut self,
        scene: &mut PlanningScene,
        what: &str,
        object: Target,
        target: Option<usize>,
        g: &Gripper,
        q0: &[f64],
    ) -> Result<Grasp, String> {
        let c = self.config.clone();
        let centre = object.centre;
        scene.set_joint(g.joint, g.open);
        if let Some(t) = target {
            scene.ignore_object(t, true);
        }
        spans(g, what, &object)?;
        let ways = match object.cuboid {
            Some((r, half)) => self.ways_across(
                [(r * Vector3::x(), half[0]), (r * Vector3::y(), half[1])],
                g,
            ),
            None => self.ways_round(centre, object.bound_m),
        };
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
        scene.set_joint(g.joint, ways[way].grip_m.clamp(lo, hi));
        // Straight up off what it rests on; the hand may turn on the way (the object turns
        // with it). The arm is checked, the object (touching its support, as far as the
        // estimate knows) only from the lift's top.
        let lift = self.line_at_least(
            scene,
            &grasp_q,
            (centre, centre + Vector3::z() * c.lift_m),
            None,
            0.5,
        )?;
        Ok(Grasp {
            to_pre,
            descent,
            lift,
            way: ways[way].clone(),
        })
    }

    /// Where the object's bottom goes (world frame), how high above that the carry ends, and
    /// how far the hand then goes straight down before letting go (m): over a world object's
    /// top centre, [`PickConfig::drop_height_m`] and no further (dropped into a bin, onto a
    /// tray); at a point, [`PickConfig::approach_m`], then down to [`SET_DOWN_M`] above it (set
    /// down, as MoveIt's place approaches). From the configured place, else the world's
    /// `[robot] place`; none: the object is held up. An error for an object the world lacks.
    pub(super) fn place_under(
        &self,
        sim: &Simulation,
    ) -> Result<Option<([f64; 3], f64, f64)>, String> {
        let world = sim.world();
        let name = match self
            .config
            .place
            .clone()
            .or_else(|| world.robot.place.clone())
        {
            None => return Ok(None),
            Some(Place::Point(p)) => {
                let above = self.config.approach_m.max(SET_DOWN_M);
                return Ok(Some((p, above, above - SET_DOWN_M)));
            }
            Some(Place::Object(name)) => name,
        };
        let (shape, pose) = world_object(sim, &name, "to place on")?;
        let t = pose.translation;
        let top = t.z + shape.half_height_m().unwrap_or(0.0);
        Ok(Some((
            [f64::from(t.x), f64::from(t.y), f64::from(top)],
            self.config.drop_height_m,
            0.0,
        )))
    }
}

/// Whether the open gripper `g` spans `target` (called `what`): a round one within
/// [`SPAN_SLACK_M`] (a box is checked face by face); else why not.
pub(super) fn spans(g: &Gripper, what: &str, target: &Target) -> Result<(), String> {
    if target.cuboid.is_none() && target.bound_m > g.widest_m() + SPAN_SLACK_M {
        return Err(format!(
            "cannot grasp {what}: it is {:.3} m across, wider than the open gripper ({:.3} m)",
            2.0 * target.bound_m,
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
