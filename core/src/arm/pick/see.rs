//! Seeing the object: sightings from detector messages and depth, or a named world object
//! by its pose, and the plan that follows once it is known.

use nalgebra::{Isometry3, Point3};
use rover_perception::BoundingBoxes;
use rover_sim::{geometry::Shape, model::isometry_from_pose, physics::Simulation};

use crate::arm::depth::{DepthView, hidden_by_robot, object_estimate};
use crate::arm::shape::upright_extent;

use super::state::{Pick, PickState, Target};
use super::world::world_object;

/// A box of the class this share of [`super::PickConfig::min_probability`] or more counts when
/// its estimate is within [`TRACK_GATE_M`] of where the object was seen last: YOLO's score for
/// one object moves with the view (a tennis ball scores 0.2-0.6 from the arm car's mast as it
/// drives up to it, "apple" at times), and the pick already knows where to look.
const TRACK_SHARE: f64 = 0.4;
/// How close (m) a weak box's estimate must be to the last sighting.
const TRACK_GATE_M: f64 = 0.05;
/// Detector messages in a row without the object, once the base has driven to it and settled,
/// before the pick plans from where it was seen on the way.
const UNSEEN_AFTER_DRIVE: u32 = 5;

impl Pick {
    /// A detector message with the depth image it came from, taken at `captured_s` (sim time)
    /// with the arm's base at `world_from_base`: while seeking, a sighting; once the sightings
    /// agree, the plan. With `fetch`, a sighting out of reach sends the base to it, and each
    /// sighting on the way corrects where it goes.
    pub fn observe(
        &mut self,
        boxes: &BoundingBoxes,
        view: &DepthView<'_>,
        (world_from_base, captured_s): (&Isometry3<f64>, f64),
        sim: &Simulation,
    ) {
        // A named object is taken by its pose ([`Self::update`]), not by what is seen.
        let fetching = self.state == PickState::Fetching;
        if !(self.state == PickState::Seeking || fetching) || self.known_object(sim).is_some() {
            return;
        }
        if captured_s < self.settle_until_s {
            return;
        }
        // Where it was last seen, in the base's frame now (the base may have driven since).
        let expected = (self.last_seen)
            .map(|(p, r)| ((world_from_base.inverse() * Point3::from(p)).coords, r));
        let c = &self.config;
        let seen = boxes
            .bounding_boxes
            .iter()
            .filter(|b| b.class == c.class && b.probability >= TRACK_SHARE * c.min_probability)
            .filter_map(|b| {
                let (centre, radius) = object_estimate(b, view, self.intrinsics, c.max_range_m)?;
                // A tall object stands upright: its axis, radius and height from the depth.
                let seen = match upright_extent(b, view, self.intrinsics, c.max_range_m) {
                    Some(u) => Target::upright(u.centre, u.radius_m, u.half_height_m),
                    None => Target::round(centre, radius),
                };
                // A weak box counts only where the object was seen last (a tracker's gate).
                let gated = expected.is_some_and(|(p, _)| (p - seen.centre).norm() <= TRACK_GATE_M);
                (b.probability >= c.min_probability || gated).then_some((b.probability, seen))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, seen)| seen);
        let Some(seen) = seen else {
            // Behind the arm, the sightings so far stand; gone, they start again.
            self.hidden =
                expected.is_some_and(|(p, r)| hidden_by_robot(view, self.intrinsics, p, r));
            if !self.hidden {
                self.sightings.clear();
            }
            self.unseen += 1;
            if let Some((centre, radius)) = expected
                && self.unseen >= UNSEEN_AFTER_DRIVE
                && self.state == PickState::Seeking
                && self.fetch_at(sim).is_some()
            {
                // The base drove here seeing it all the way: where it was seen last (carried
                // in the world frame) is the estimate.
                let what = format!("the {}", self.config.class);
                self.said.push((
                    false,
                    format!(
                        "pick: {what} is not detected from where the base stopped; it was seen on the way, at ({:.3}, {:.3}, {:.3}) m",
                        centre.x, centre.y, centre.z
                    ),
                ));
                self.plan_for(sim, &what, Target::round(centre, radius));
            }
            return;
        };
        self.unseen = 0;
        self.hidden = false;
        self.last_seen = Some((
            (world_from_base * Point3::from(seen.centre)).coords,
            seen.across_m(),
        ));
        if self.fetch_towards(sim, seen.centre, world_from_base) {
            return;
        }
        let c = &self.config;
        if self
            .sightings
            .first()
            .is_some_and(|first| (first.centre - seen.centre).norm() > c.agree_m)
        {
            self.sightings.clear();
        }
        self.sightings.push(seen);
        if self.sightings.len() < c.sightings as usize {
            return;
        }
        let target = Target::mean(&self.sightings);
        let what = format!("the {}", self.config.class);
        if self.stance_towards(sim, &what, &target, world_from_base) {
            return;
        }
        self.plan_for(sim, &what, target);
    }

    /// Plans the whole pick of `target` (called `what`), and starts it or says why not.
    fn plan_for(&mut self, sim: &Simulation, what: &str, target: Target) {
        let centre = target.centre;
        self.object = Some((centre, target.bound_m));
        let started = std::time::Instant::now();
        let planned = self.plan(sim, what, target);
        self.planning_s = Some(started.elapsed().as_secs_f64());
        match planned {
            Ok(steps) => {
                self.steps = steps;
                self.state = PickState::Approaching;
                self.said.push((
                    false,
                    format!(
                        "pick: {what} at ({:.3}, {:.3}, {:.3}) m, {}, taken {}; planned in {:.3} s",
                        centre.x,
                        centre.y,
                        centre.z,
                        target.size_text(),
                        self.taken.as_deref().unwrap_or("?"),
                        self.planning_s.unwrap_or_default()
                    ),
                ));
            }
            Err(why) => self.fail(format!(
                "{what} at ({:.3}, {:.3}, {:.3}) m, {}: {why}",
                centre.x,
                centre.y,
                centre.z,
                target.size_text()
            )),
        }
    }

    /// The world object to take by its known pose, if one is named (here or in the world's
    /// `[robot] pick`).
    pub fn known_object<'a>(&'a self, sim: &'a Simulation) -> Option<&'a str> {
        (self.config.object.as_deref()).or(sim.world().robot.pick.as_deref())
    }

    /// Takes the named world object by its pose now (arm base frame): a box by its faces, a
    /// sphere or anything else as round.
    pub(super) fn seek_known(&mut self, sim: &Simulation, name: &str) {
        let (shape, pose) = match world_object(sim, name, "to pick") {
            Ok(found) => found,
            Err(why) => return self.fail(why),
        };
        let world_from_base = isometry_from_pose(&sim.world_from_link(self.base));
        let base_from_object = world_from_base.inverse() * isometry_from_pose(&pose);
        let centre = base_from_object.translation.vector;
        if self.fetch_towards(sim, centre, &world_from_base) {
            return;
        }
        let Some(half_height_m) = shape.half_height_m().map(f64::from) else {
            return self.fail(format!(
                "\"{name}\" is a mesh: pick takes boxes, spheres, cylinders and capsules by name"
            ));
        };
        let target = match shape {
            Shape::Box { size_m } => {
                let half = [size_m.x, size_m.y, size_m.z].map(|v| f64::from(v) / 2.0);
                Target {
                    centre,
                    half_height_m,
                    bound_m: half.iter().map(|h| h * h).sum::<f64>().sqrt(),
                    cuboid: Some((base_from_object.rotation, half)),
                    upright: None,
                }
            }
            Shape::Sphere { radius_m }
            | Shape::Cylinder { radius_m, .. }
            | Shape::Capsule { radius_m, .. } => Target {
                half_height_m,
                ..Target::round(centre, f64::from(*radius_m))
            },
            Shape::Mesh { .. } => return,
        };
        let what = format!("\"{name}\"");
        if self.stance_towards(sim, &what, &target, &world_from_base) {
            return;
        }
        self.plan_for(sim, &what, target);
    }
}
