//! Ray casting for the range sensors (the 2D laser, the 3D lidar): the physics scene's
//! colliders through rapier's query pipeline, and people with a skinned body (MakeHuman's, a
//! Gazebo actor's) as their posed skeleton's bones, each a capsule as thick as the skin it
//! moves (`SkinnedBody::bone_capsules`): two legs that scissor as they walk, arms, the torso at
//! its height. Capsules rather than the posed mesh: a scan needs the bones posed without
//! skinning 20,000 vertices, and a capsule's surface is within a centimetre or two of the
//! skin's. rover's figure stays its one physics capsule, which the rays pass through.

use glam::Vec3;
use rapier3d::parry::query::{Ray, RayCast};
use rapier3d::parry::shape::Capsule;

use crate::model::actor::BoneCapsule;
use crate::physics::simulation::Simulation;
use crate::render::body::SkinnedBody;

/// A person the rays see as bone capsules.
struct SeenPerson {
    body: SkinnedBody,
    capsules: Vec<BoneCapsule>,
    /// Reused: the posed joints (person frame).
    joints: Vec<Vec3>,
}

/// One person's posed capsules in [`RayCaster::near`], behind a bounding sphere.
#[derive(Debug, Clone, Copy)]
struct Group {
    centre: Vec3,
    radius_m: f32,
    end: usize,
}

/// Casts rays at the world and the people's bones.
pub(crate) struct RayCaster {
    /// Per person (world order): their bones, when they have a skinned body.
    people: Vec<Option<SeenPerson>>,
    /// Which people are seen as bones (their physics capsule is not).
    skip: Vec<bool>,
    /// Reused: the posed capsules (world frame) kept by the last [`RayCaster::pose_people`].
    near: Vec<Capsule>,
    /// Reused: one group per person in `near`.
    groups: Vec<Group>,
}

impl std::fmt::Debug for RayCaster {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let bones: usize = self.people.iter().flatten().map(|p| p.capsules.len()).sum();
        write!(f, "RayCaster({} people, {bones} bones)", self.people.len())
    }
}

impl RayCaster {
    /// The caster for `sim`'s world and people.
    pub fn new(sim: &Simulation) -> Self {
        let people: Vec<Option<SeenPerson>> = sim
            .world()
            .people
            .iter()
            .map(|p| {
                let body = SkinnedBody::of(p)?;
                let capsules = body.bone_capsules();
                (!capsules.is_empty()).then(|| SeenPerson {
                    body,
                    capsules,
                    joints: Vec::new(),
                })
            })
            .collect();
        let skip = people.iter().map(Option::is_some).collect();
        Self {
            people,
            skip,
            near: Vec::new(),
            groups: Vec::new(),
        }
    }

    /// Poses the people seen as bones, as they stand now, keeping the capsules that reach
    /// heights `band_z_m` (world, low and high; every capsule when `None`).
    pub fn pose_people(&mut self, sim: &Simulation, band_z_m: Option<(f32, f32)>) {
        self.near.clear();
        self.groups.clear();
        for (i, seen) in self.people.iter_mut().enumerate() {
            let Some(seen) = seen else { continue };
            let person = &sim.world().people[i];
            seen.body.pose_joints(
                sim.person_gait_phase_rad(i),
                person.stride_m(),
                &mut seen.joints,
            );
            let world_from_person = sim.world_from_person(i);
            let start = self.near.len();
            for c in &seen.capsules {
                let (Some(a), Some(b)) = (seen.joints.get(c.from), seen.joints.get(c.to)) else {
                    continue;
                };
                let (a, b) = (
                    world_from_person.transform_point(*a),
                    world_from_person.transform_point(*b),
                );
                let r = c.radius_m;
                let reaches = band_z_m
                    .is_none_or(|(lo, hi)| a.z.min(b.z) - r <= hi && a.z.max(b.z) + r >= lo);
                if reaches {
                    self.near.push(Capsule::new(a, b, r));
                }
            }
            let kept = &self.near[start..];
            if kept.is_empty() {
                continue;
            }
            let centre = kept.iter().map(|c| c.segment.a + c.segment.b).sum::<Vec3>()
                / (2 * kept.len()) as f32;
            let radius_m = kept
                .iter()
                .map(|c| {
                    centre
                        .distance(c.segment.a)
                        .max(centre.distance(c.segment.b))
                        + c.radius
                })
                .fold(0.0, f32::max);
            self.groups.push(Group {
                centre,
                radius_m,
                end: self.near.len(),
            });
        }
    }

    /// The distance (m) along the ray from `origin` in unit direction `dir` to the first thing
    /// it hits within `max_m`: a world collider or a bone posed by the last
    /// [`RayCaster::pose_people`].
    pub fn cast(&self, sim: &Simulation, origin: Vec3, dir: Vec3, max_m: f32) -> Option<f32> {
        let ray = Ray::new(origin, dir);
        let mut best = sim.cast_world_ray_past_people(origin, dir, max_m, &self.skip);
        let mut start = 0;
        for g in &self.groups {
            let capsules = &self.near[start..g.end];
            start = g.end;
            // The ray's closest approach to the group's sphere, within its length.
            let along = (g.centre - origin).dot(dir).clamp(0.0, max_m);
            if (origin + dir * along).distance_squared(g.centre) > g.radius_m * g.radius_m {
                continue;
            }
            let limit = best.unwrap_or(max_m);
            if let Some(hit) = capsules
                .iter()
                .filter_map(|c| c.cast_local_ray(&ray, limit, true))
                .reduce(f32::min)
            {
                best = Some(best.map_or(hit, |b| b.min(hit)));
            }
        }
        best
    }
}
