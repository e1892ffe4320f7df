//! Placing things by hand: the robot, people, objects and models moved to new poses between
//! steps (no physics in between), people re-dressed. Used to lay out randomized scenes
//! (`rover dataset`); the camera follows every placement at its next image
//! ([`Simulation::layout_version`]).

use rapier3d::prelude::*;

use crate::error::{Result, SimError};
use crate::geometry::{Pose, Rgba};
use crate::model::human::{BodyShape, Outfit};
use crate::physics::build::person_body_pose;
use crate::physics::diff_drive::EncoderOdometry;
use crate::physics::simulation::{Simulation, planar};

/// What [`Simulation::restyle_person`] gives a person.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PersonLook {
    /// MakeHuman's body in this shape (`None`: rover's figure).
    pub shape: Option<BodyShape>,
    /// What that body wears besides its colours (hair style, trousers or a skirt).
    pub outfit: Outfit,
    /// Standing height (m, 0.5 to 2.5).
    pub height_m: f64,
    /// Skin colour.
    pub skin_color: Rgba,
    /// Hair colour.
    pub hair_color: Rgba,
    /// The gait phase they are caught at when they do not walk (rad; 0: standing).
    pub still_gait_phase_rad: f64,
}

impl Simulation {
    /// Changes whenever something is placed or re-dressed, so a camera knows to move its
    /// drawn copies (starts at 0).
    pub fn layout_version(&self) -> u64 {
        self.layout
    }

    /// Moves the whole robot rigidly so that its base link is at `world_from_base`, joints
    /// as they are, every body at rest; the wheel-encoder odometry restarts there.
    pub fn place_robot(&mut self, world_from_base: Pose) -> Result<()> {
        check_pose(&world_from_base, "robot pose")?;
        if self.placement.robot.is_none() {
            // Links welded by fixed joints share a body: each body once, relative to the base
            // as it was at the first placement since the last step, so placing many times
            // gives the same poses as placing once (no drift).
            let base_from_world = self.world_from_base().inverse();
            let mut bodies = self.link_body.clone();
            bodies.sort_unstable_by_key(|h| h.into_raw_parts());
            bodies.dedup();
            let relative = bodies
                .into_iter()
                .filter_map(|h| {
                    self.physics
                        .bodies
                        .get(h)
                        .map(|b| (h, base_from_world * *b.position()))
                })
                .collect();
            self.placement.robot = Some(relative);
        }
        for &(handle, base_from_body) in self.placement.robot.iter().flatten() {
            if let Some(body) = self.physics.bodies.get_mut(handle) {
                put_at_rest(body, world_from_base * base_from_body);
            }
        }
        self.encoder = EncoderOdometry::new(planar(world_from_base), self.drive.config());
        self.layout += 1;
        Ok(())
    }

    /// Stands person `index` (world order) at `position_m` (x, y) facing `heading_rad`; a
    /// walk, if they have one, now starts from there.
    pub fn place_person(
        &mut self,
        index: usize,
        position_m: [f64; 2],
        heading_rad: f64,
    ) -> Result<()> {
        if !(position_m.iter().all(|v| v.is_finite()) && heading_rad.is_finite()) {
            return Err(SimError::Setup(format!(
                "person position must be finite, found {position_m:?}, heading {heading_rad}"
            )));
        }
        let t = self.sim_time_s();
        let person = self
            .world
            .people
            .get_mut(index)
            .ok_or_else(|| no_such("person", index))?;
        person.position_m = position_m;
        person.heading_rad = heading_rad;
        let pose = person_body_pose(person, t);
        if let Some(body) = self
            .people
            .get(index)
            .and_then(|h| self.physics.bodies.get_mut(*h))
        {
            body.set_position(pose, true);
        }
        self.layout += 1;
        Ok(())
    }

    /// Dresses person `index` (world order) in a shirt and trousers of these colours.
    pub fn dress_person(&mut self, index: usize, shirt: Rgba, trousers: Rgba) -> Result<()> {
        let person = self
            .world
            .people
            .get_mut(index)
            .ok_or_else(|| no_such("person", index))?;
        person.shirt_color = shirt;
        person.trousers_color = trousers;
        self.layout += 1;
        Ok(())
    }

    /// Gives person `index` (world order) another look for the next image: their body's shape
    /// (`None`: rover's figure) and height, skin and hair colours, and the gait phase they are
    /// caught at when they do not walk. Their physics capsule keeps its first size.
    pub fn restyle_person(&mut self, index: usize, look: &PersonLook) -> Result<()> {
        let height_ok = look.height_m.is_finite() && (0.5..=2.5).contains(&look.height_m);
        if !(height_ok && look.still_gait_phase_rad.is_finite()) {
            return Err(SimError::Setup(format!(
                "person height must be 0.5 to 2.5 m and the gait phase finite, found {} m, {} rad",
                look.height_m, look.still_gait_phase_rad
            )));
        }
        let person = self
            .world
            .people
            .get_mut(index)
            .ok_or_else(|| no_such("person", index))?;
        person.shape = look.shape;
        person.outfit = look.outfit;
        person.height_m = look.height_m;
        person.skin_color = look.skin_color;
        person.hair_color = look.hair_color;
        person.still_gait_phase_rad = look.still_gait_phase_rad;
        self.layout += 1;
        Ok(())
    }

    /// Moves world object `index` (world order) to centre `position_m` with heading `yaw_rad`,
    /// at rest.
    pub fn place_object(&mut self, index: usize, position_m: [f64; 3], yaw_rad: f64) -> Result<()> {
        let object = self
            .world
            .objects
            .get_mut(index)
            .ok_or_else(|| no_such("object", index))?;
        object.position_m = position_m;
        object.yaw_rad = yaw_rad;
        let pose = object.world_from_object();
        check_pose(&pose, "object pose")?;
        if let Some(body) = self
            .objects
            .get(index)
            .and_then(|h| self.physics.bodies.get_mut(*h))
        {
            put_at_rest(body, pose);
        }
        self.layout += 1;
        Ok(())
    }

    /// Where SDF model `index`'s (world order) frame is now: carried along by its first link
    /// since it was loaded or last placed (physics moves the links, not the model's stored
    /// `world_from_model`). `None` for no such model.
    pub fn world_from_model_now(&self, index: usize) -> Option<Pose> {
        let model = self.world.models.get(index)?;
        let Some(link) = model.links.first() else {
            return Some(model.world_from_model);
        };
        let first: usize = (self.world.models.iter().take(index))
            .map(|m| m.links.len())
            .sum();
        let now = (self.model_links.get(first))
            .and_then(|h| self.physics.bodies.get(*h))
            .map_or(link.world_from_link, |b| *b.position());
        Some(now * link.world_from_link.inverse() * model.world_from_model)
    }

    /// Moves SDF model `index` (world order) rigidly so that its frame is at
    /// `world_from_model`, its links at rest. The frame is where the model's links have taken
    /// it ([`Self::world_from_model_now`]): a can that has fallen over is set upright at
    /// `world_from_model`.
    pub fn place_model(&mut self, index: usize, world_from_model: Pose) -> Result<()> {
        check_pose(&world_from_model, "model pose")?;
        let first: usize = self
            .world
            .models
            .iter()
            .take(index)
            .map(|m| m.links.len())
            .sum();
        let model_from_world = self
            .world_from_model_now(index)
            .ok_or_else(|| no_such("model", index))?
            .inverse();
        let model = self
            .world
            .models
            .get_mut(index)
            .ok_or_else(|| no_such("model", index))?;
        let cached = self.placement.models.iter().find(|(i, _)| *i == index);
        let model_from_links = match cached {
            Some((_, links)) => links.clone(),
            None => {
                // Its links as they are now (their joints' positions kept), relative to the
                // model's frame as it is now.
                let links: Vec<Pose> = (0..model.links.len())
                    .map(|k| {
                        let now = self
                            .model_links
                            .get(first + k)
                            .and_then(|h| self.physics.bodies.get(*h))
                            .map_or(model.links[k].world_from_link, |b| *b.position());
                        model_from_world * now
                    })
                    .collect();
                self.placement.models.push((index, links.clone()));
                links
            }
        };
        model.world_from_model = world_from_model;
        for (k, (link, model_from_link)) in model.links.iter_mut().zip(model_from_links).enumerate()
        {
            link.world_from_link = world_from_model * model_from_link;
            if let Some(body) = self
                .model_links
                .get(first + k)
                .and_then(|h| self.physics.bodies.get_mut(*h))
            {
                put_at_rest(body, link.world_from_link);
            }
        }
        self.layout += 1;
        Ok(())
    }

    /// World pose of every world object (world order) into `out` (cleared first; no
    /// allocation once `out` has the capacity).
    pub fn object_poses_into(&self, out: &mut Vec<Pose>) {
        out.clear();
        out.extend(self.world.objects.iter().zip(&self.objects).map(|(o, h)| {
            self.physics
                .bodies
                .get(*h)
                .map_or_else(|| o.world_from_object(), |b| *b.position())
        }));
    }
}

/// Moves `body` to `pose`, still.
fn put_at_rest(body: &mut RigidBody, pose: Pose) {
    body.set_position(pose, true);
    body.set_linvel(Vec3::ZERO, true);
    body.set_angvel(Vec3::ZERO, true);
}

fn check_pose(pose: &Pose, what: &str) -> Result<()> {
    if pose.translation.is_finite() && pose.rotation.is_finite() {
        Ok(())
    } else {
        Err(SimError::Setup(format!(
            "{what} must be finite, found {pose:?}"
        )))
    }
}

fn no_such(what: &str, index: usize) -> SimError {
    SimError::Setup(format!("no {what} number {index} in the world"))
}
