//! The world's state as gazebo_ros publishes it on `/gazebo/model_states`: every model's name,
//! pose and twist in the world frame. rover's models are the robot, the world's objects (boxes,
//! spheres, walls), the SDF models (by their first link) and the people.

use glam::Vec3;

use super::simulation::Simulation;
use crate::geometry::Pose;
use crate::model::LinkId;

/// One model's state: world pose, and velocity in the world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelState {
    /// `world_from_model`.
    pub pose: Pose,
    /// Linear velocity (m/s, world frame).
    pub linear_mps: Vec3,
    /// Angular velocity (rad/s, world frame).
    pub angular_radps: Vec3,
}

impl Simulation {
    /// The state of a point fixed to one of the robot's links: its world pose (`world_from_link`
    /// times `link_from_point`), the point's linear velocity and the link's angular velocity,
    /// both in the world frame. What an IMU, a GPS or p3d reads.
    pub fn link_point_state(&self, link: LinkId, link_from_point: Pose) -> ModelState {
        let pose = self.world_from_link(link) * link_from_point;
        let Some(body) = self
            .link_body
            .get(link.index())
            .and_then(|h| self.physics.bodies.get(*h))
        else {
            return ModelState {
                pose,
                linear_mps: Vec3::ZERO,
                angular_radps: Vec3::ZERO,
            };
        };
        ModelState {
            pose,
            linear_mps: body.velocity_at_point(pose.translation),
            angular_radps: body.angvel(),
        }
    }

    /// The models' names, in the order of [`Simulation::model_states_into`]: the robot, the
    /// objects, the SDF models, the people.
    pub fn model_state_names(&self) -> Vec<String> {
        let world = self.world();
        std::iter::once(self.robot().name.clone())
            .chain(world.objects.iter().map(|o| o.name.clone()))
            .chain(world.models.iter().map(|m| m.name.clone()))
            .chain(world.people.iter().map(|p| p.name.clone()))
            .collect()
    }

    /// Every model's state now, into `out` (cleared first; no allocation once `out` has the
    /// capacity). People move kinematically: their velocity is their pose's change over the
    /// next step.
    pub fn model_states_into(&self, out: &mut Vec<ModelState>) {
        out.clear();
        let body = |h: rapier3d::prelude::RigidBodyHandle| {
            self.physics.bodies.get(h).map(|b| ModelState {
                pose: *b.position(),
                linear_mps: b.linvel(),
                angular_radps: b.angvel(),
            })
        };
        let still = |pose: Pose| ModelState {
            pose,
            linear_mps: Vec3::ZERO,
            angular_radps: Vec3::ZERO,
        };
        out.push(body(self.base).unwrap_or_else(|| still(self.world_from_base())));
        let world = self.world();
        for (object, h) in world.objects.iter().zip(&self.objects) {
            out.push(body(*h).unwrap_or_else(|| still(object.world_from_object())));
        }
        let mut first_link = 0;
        for model in &world.models {
            let state = self
                .model_links
                .get(first_link)
                .and_then(|h| body(*h))
                .unwrap_or_else(|| still(model.world_from_model));
            out.push(state);
            first_link += model.links.len();
        }
        let (now, dt) = (self.sim_time_s(), self.dt_s());
        for person in &world.people {
            let (a, b) = (
                person.world_from_person(now),
                person.world_from_person(now + dt),
            );
            let turn = b.rotation * a.rotation.inverse();
            let (axis, angle) = turn.to_axis_angle();
            out.push(ModelState {
                pose: a,
                linear_mps: (b.translation - a.translation) / dt as f32,
                angular_radps: axis * (angle / dt as f32),
            });
        }
    }
}
