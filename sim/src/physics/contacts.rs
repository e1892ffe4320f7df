//! What a robot link touches, from rapier's contact manifolds: per other collision its contact
//! points, normals, penetration depths and the force on the link, as a bumper reports them.
//! Rapier's world-space manifold normal points from the pair's first collider to its second;
//! its impulses push the first away along it.

use glam::Vec3;

use crate::model::LinkId;
use crate::physics::build::other_body;
use crate::physics::simulation::Simulation;

/// A contact point farther apart than this (m) is not touching yet (rapier keeps predicted
/// contacts a little ahead of the surfaces).
const TOUCHING_M: f32 = 1e-3;

/// One other collision a link touches.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkContact {
    /// The other collision, as Gazebo names collisions: `ground_plane::link::collision`,
    /// `<object>::link::collision`, `<robot>::<link>::<link>_collision`, ...
    pub other: String,
    /// Contact points (world frame, m).
    pub positions_m: Vec<Vec3>,
    /// Contact normals (world frame, unit), pointing from the other collision into the link.
    pub normals: Vec<Vec3>,
    /// Penetration depths (m, 0 when just touching).
    pub depths_m: Vec<f32>,
    /// The force the contact pushes the link with over the last step (world frame, N).
    pub force_n: Vec3,
    /// Its torque about the link's origin (world frame, N m).
    pub torque_nm: Vec3,
}

impl Simulation {
    /// What link `link`'s own collision shapes touch after the last step, one entry per other
    /// collision, into `out` (cleared first).
    pub fn link_contacts(&self, link: LinkId, out: &mut Vec<LinkContact>) {
        out.clear();
        let Some(rb) = self
            .link_body
            .get(link.index())
            .and_then(|b| self.physics.bodies.get(*b))
        else {
            return;
        };
        let origin = self.world_from_link(link).translation;
        let dt = self.physics.integration_parameters.dt.max(f32::EPSILON);
        // The link's own colliders, not those of links welded to it (Gazebo names those
        // `<link>_fixed_joint_lump__...`, and a bumper does not watch them).
        let own = |c: &rapier3d::geometry::ColliderHandle| {
            self.physics
                .colliders
                .get(*c)
                .is_some_and(|c| c.user_data == link.index() as u128 + 1)
        };
        for collider in rb.colliders().iter().filter(|c| own(c)) {
            for pair in self.physics.narrow_phase.contact_pairs_with(*collider) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let ours_first = pair.collider1 == *collider;
                let mut contact = LinkContact {
                    other: self.collision_name(other_body(&self.physics, pair, *collider)),
                    ..LinkContact::default()
                };
                for m in pair.manifolds() {
                    // Into our link: against the normal when we are the first collider.
                    let into_link = if ours_first {
                        -m.data.normal
                    } else {
                        m.data.normal
                    };
                    let impulse: f32 = m.points.iter().map(|p| p.data.impulse).sum();
                    let force = into_link * (impulse / dt);
                    // The solver's contacts, through the bodies' current poses (a manifold's
                    // own points keep the separation of their first detection).
                    for sc in &m.data.solver_contacts {
                        let (p1, p2) = m.data.solver_contact_world_points(sc, &self.physics.bodies);
                        let separation_m = (p2 - p1).dot(m.data.normal);
                        if separation_m > TOUCHING_M {
                            continue;
                        }
                        let at = (p1 + p2) / 2.0;
                        contact.positions_m.push(at);
                        contact.normals.push(into_link);
                        contact.depths_m.push((-separation_m).max(0.0));
                        let share = force / m.data.solver_contacts.len() as f32;
                        contact.force_n += share;
                        contact.torque_nm += (at - origin).cross(share);
                    }
                }
                if !contact.positions_m.is_empty() {
                    out.push(contact);
                }
            }
        }
    }

    /// Gazebo's name of the collision on `body` (`None`: a collider on no body, the ground's).
    fn collision_name(&self, body: Option<rapier3d::dynamics::RigidBodyHandle>) -> String {
        let Some(body) = body else {
            return "ground_plane::link::collision".to_owned();
        };
        if let Some(i) = self.link_body.iter().position(|b| *b == body) {
            let link = &self.robot().links[i].name;
            return format!("{}::{link}::{link}_collision", self.robot().name);
        }
        match self.body_name(body).as_str() {
            "ground" => "ground_plane::link::collision".to_owned(),
            name => format!("{name}::link::collision"),
        }
    }
}
