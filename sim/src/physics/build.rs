//! Building the rapier scene from the model: the ground, objects, people and SDF models as
//! colliders and bodies, the robot as rigid bodies (links welded by fixed joints share one,
//! carrying their summed inertials) joined by impulse joints.

use glam::{Mat3, Quat, Vec3};
use rapier3d::prelude::*;

use crate::description::mesh_file::load_mesh;
use crate::error::{Result, SimError};
use crate::geometry::{Pose, Shape, pose_from_position_yaw};
use crate::model::person::Person;
use crate::model::robot::{JointKind, RobotModel};
use crate::model::world::JointSolver;
use crate::model::world::World;
use crate::physics::contact_springs::ContactSprings;
use crate::physics::hull::WideHull;
use crate::physics::joints::{BuiltJoint, add_joints};

/// Collision group of the robot's own colliders (the robot does not collide with itself,
/// like Gazebo's default `self_collide = false`).
pub(crate) const ROBOT_GROUP: Group = Group::GROUP_1;
/// Collision group of everything else.
pub(crate) const WORLD_GROUP: Group = Group::GROUP_2;

pub(crate) fn world_groups() -> InteractionGroups {
    InteractionGroups::new(WORLD_GROUP, Group::ALL, InteractionTestMode::And)
}

/// The pose of a person's physics capsule at sim time `t_s` (its centre at half height).
pub(crate) fn person_body_pose(person: &Person, t_s: f64) -> Pose {
    let (x, y, heading) = person.pose_at(t_s);
    pose_from_position_yaw([x, y, person.height_m / 2.0], heading)
}

/// Adds the SDF models' links, one rigid body each; returns the bodies in model/link order.
pub(crate) fn add_models(
    physics: &mut PhysicsWorld,
    world: &World,
) -> Result<Vec<RigidBodyHandle>> {
    let mut bodies = Vec::new();
    for model in &world.models {
        for link in &model.links {
            let dynamic = link.is_dynamic(model);
            let builder = if dynamic {
                RigidBodyBuilder::dynamic()
            } else {
                RigidBodyBuilder::fixed()
            };
            let body = physics.insert_body(builder.pose(link.world_from_link));
            let count = link.collisions.len().max(1) as f32;
            let mass = link.mass_kg.unwrap_or(0.0) as f32;
            let name = format!("{}::{}", model.name, link.name);
            for c in &link.collisions {
                let (shape, fix) = collider_shape(&c.shape, &world.source, &name, !dynamic)?;
                let mut collider = ColliderBuilder::new(shape)
                    .position(c.link_from_shape * fix)
                    .friction(1.0)
                    .friction_combine_rule(CoefficientCombineRule::Min)
                    .collision_groups(world_groups());
                if dynamic {
                    collider = collider.mass(mass / count);
                }
                physics.insert_collider(collider, Some(body));
            }
            if dynamic
                && link.collisions.is_empty()
                && let Some(b) = physics.bodies.get_mut(body)
            {
                b.set_additional_mass(mass, true);
            }
            bodies.push(body);
        }
    }
    Ok(bodies)
}

/// The bodies [`add_world`] made.
pub(crate) struct WorldBodies {
    pub(crate) ground: RigidBodyHandle,
    /// One per world object, in world order.
    pub(crate) objects: Vec<RigidBodyHandle>,
    /// One per person, in world order.
    pub(crate) people: Vec<RigidBodyHandle>,
}

/// Adds the ground, objects, walls and people.
pub(crate) fn add_world(physics: &mut PhysicsWorld, world: &World) -> Result<WorldBodies> {
    let ground =
        physics.insert_body(RigidBodyBuilder::fixed().translation(Vec3::new(0.0, 0.0, -0.5)));
    let [sx, sy] = world.ground.size_m;
    physics.insert_collider(
        ColliderBuilder::cuboid(sx as f32 / 2.0, sy as f32 / 2.0, 0.5)
            .friction(world.ground.friction)
            .friction_combine_rule(CoefficientCombineRule::Min)
            .collision_groups(world_groups()),
        Some(ground),
    );
    let mut objects = Vec::with_capacity(world.objects.len());
    for object in &world.objects {
        let pose = object.world_from_object();
        let builder = match object.mass_kg {
            Some(_) => RigidBodyBuilder::dynamic(),
            None => RigidBodyBuilder::fixed(),
        };
        let body = physics.insert_body(builder.pose(pose));
        let fixed = object.mass_kg.is_none();
        let (shape, fix) = collider_shape(&object.shape, &world.source, &object.name, fixed)?;
        let shape = ColliderBuilder::new(shape).position(fix);
        let shape = match object.mass_kg {
            Some(mass) => shape.mass(mass as f32),
            None => shape,
        };
        physics.insert_collider(
            shape
                .friction(object.friction)
                .friction_combine_rule(CoefficientCombineRule::Min)
                .collision_groups(world_groups()),
            Some(body),
        );
        objects.push(body);
    }
    let mut people = Vec::with_capacity(world.people.len());
    for person in &world.people {
        let radius = person.body_radius_m() as f32;
        let height = person.height_m as f32;
        let half_segment = (height / 2.0 - radius).max(0.0);
        let body = physics.insert_body(
            RigidBodyBuilder::kinematic_position_based().pose(person_body_pose(person, 0.0)),
        );
        physics.insert_collider(
            ColliderBuilder::capsule_z(half_segment, radius).collision_groups(world_groups()),
            Some(body),
        );
        people.push(body);
    }
    Ok(WorldBodies {
        ground,
        objects,
        people,
    })
}

pub(crate) struct RobotBodies {
    pub(crate) link_body: Vec<RigidBodyHandle>,
    pub(crate) body_from_link: Vec<Pose>,
    pub(crate) joints: Vec<Option<BuiltJoint>>,
    /// Mass of each link's rigid body (kg).
    pub(crate) link_mass_kg: Vec<f32>,
    /// Contacts that give way (`<kp>` links' colliders).
    pub(crate) springs: ContactSprings,
}

/// The body of the collider that `pair` pairs with `collider` (`None`: a collider on no body).
pub(crate) fn other_body(
    physics: &PhysicsWorld,
    pair: &ContactPair,
    collider: ColliderHandle,
) -> Option<RigidBodyHandle> {
    let other = if pair.collider1 == collider {
        pair.collider2
    } else {
        pair.collider1
    };
    physics.colliders.get(other).and_then(|c| c.parent())
}

/// Collision shape for the engine, with the pose correction for rapier's y-axis cylinders.
/// Meshes of static bodies keep their triangles (a concave arch stays passable); moving ones
/// become their convex hull ([`WideHull`]). `source` and `link` name the owner in messages.
pub(crate) fn collider_shape(
    shape: &Shape,
    source: &std::path::Path,
    link: &str,
    fixed: bool,
) -> Result<(SharedShape, Pose)> {
    // URDF cylinders run along z, rapier's along y: rotate y onto z.
    let y_to_z = Pose::from_rotation(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2));
    Ok(match shape {
        Shape::Box { size_m } => (
            SharedShape::cuboid(size_m.x / 2.0, size_m.y / 2.0, size_m.z / 2.0),
            Pose::IDENTITY,
        ),
        Shape::Cylinder { radius_m, length_m } => {
            (SharedShape::cylinder(length_m / 2.0, *radius_m), y_to_z)
        }
        Shape::Sphere { radius_m } => (SharedShape::ball(*radius_m), Pose::IDENTITY),
        Shape::Capsule { radius_m, length_m } => (
            SharedShape::capsule_z(length_m / 2.0, *radius_m),
            Pose::IDENTITY,
        ),
        Shape::Mesh { path, scale } => {
            let mesh = load_mesh(path, *scale)?;
            if fixed {
                let tri = SharedShape::trimesh(mesh.positions, mesh.triangles).map_err(|e| {
                    SimError::invalid(
                        source,
                        None,
                        format!("link \"{link}\": collision mesh {}: {e}", path.display()),
                    )
                })?;
                return Ok((tri, Pose::IDENTITY));
            }
            // Its wide faces (a round foot) rest on their whole extent (physics/hull.rs).
            let hull = WideHull::from_points(&mesh.positions).map(SharedShape::new);
            let hull = hull.ok_or_else(|| {
                SimError::invalid(
                    source,
                    None,
                    format!(
                        "link \"{link}\": collision mesh {} is degenerate (flat or a single point); expected a solid",
                        path.display()
                    ),
                )
            })?;
            (hull, Pose::IDENTITY)
        }
    })
}

/// Adds the robot: one rigid body per group of links welded by fixed joints, its colliders
/// and its moving joints, resting on the ground at the world's spawn pose.
pub(crate) fn add_robot(
    physics: &mut PhysicsWorld,
    world: &World,
    robot: &RobotModel,
    solver: JointSolver,
) -> Result<RobotBodies> {
    let (body_root, body_from_link) = weld_fixed_links(robot);
    let root_from_links = robot.root_from_links();
    let (shapes, min_z) = robot_shapes(robot, &root_from_links)?;
    let spawn = &world.robot;
    let anchored = robot.is_anchored();
    // An anchored robot's `world` link sits at the spawn point; a free one rests on the ground.
    let z_m = if anchored {
        0.0
    } else {
        f64::from(SPAWN_CLEARANCE_M - min_z)
    };
    let world_from_root = pose_from_position_yaw(
        [spawn.position_m[0], spawn.position_m[1], z_m],
        spawn.yaw_rad,
    );
    let anchor = anchored.then_some(body_root[robot.root.0]);
    let (link_body, link_mass_kg) = add_link_bodies(
        physics,
        robot,
        (&body_root, &body_from_link),
        anchor,
        |root| world_from_root * root_from_links[root],
    );
    let robot_groups = InteractionGroups::new(ROBOT_GROUP, !ROBOT_GROUP, InteractionTestMode::And);
    let mass_kg: f32 = (robot.links.iter())
        .filter_map(|l| l.inertial.as_ref())
        .map(|i| i.mass_kg)
        .sum();
    let weight_n = mass_kg * world.physics.gravity_mps2[2].abs() as f32;
    let mut springs = ContactSprings::default();
    for (i, shape, link_from_shape) in shapes {
        let kp = robot.links[i].contact_kp_n_per_m;
        let collider = physics.insert_collider(
            ColliderBuilder::new(shape)
                .position(body_from_link[i] * link_from_shape)
                .density(0.0)
                .friction(robot.links[i].friction.unwrap_or(1.0))
                .friction_combine_rule(CoefficientCombineRule::Min)
                .collision_groups(robot_groups)
                // Which link the collider is, behind its welded body: `link + 1`.
                .user_data(i as u128 + 1)
                .active_hooks(if kp.is_some() {
                    ActiveHooks::MODIFY_SOLVER_CONTACTS
                } else {
                    ActiveHooks::empty()
                }),
            Some(link_body[i]),
        );
        if let Some(kp) = kp {
            springs.insert(collider, kp, weight_n);
        }
    }
    let joints = add_joints(physics, robot, &link_body, &body_from_link, solver);
    Ok(RobotBodies {
        link_body,
        link_mass_kg,
        body_from_link,
        joints,
        springs,
    })
}

/// Links welded by fixed joints share a rigid body: each link's body root and its pose in that
/// body.
fn weld_fixed_links(robot: &RobotModel) -> (Vec<usize>, Vec<Pose>) {
    let n = robot.links.len();
    let mut body_root: Vec<usize> = (0..n).collect();
    let mut body_from_link = vec![Pose::IDENTITY; n];
    let mut settled = vec![false; n];
    settled[robot.root.0] = true;
    let mut progress = true;
    while progress {
        progress = false;
        for joint in &robot.joints {
            if settled[joint.parent.0] && !settled[joint.child.0] {
                if joint.kind == JointKind::Fixed {
                    body_root[joint.child.0] = body_root[joint.parent.0];
                    body_from_link[joint.child.0] =
                        body_from_link[joint.parent.0] * joint.parent_from_child;
                }
                settled[joint.child.0] = true;
                progress = true;
            }
        }
    }
    (body_root, body_from_link)
}

/// A collision shape of link `.0`, with its pose in the link frame.
type LinkShape = (usize, SharedShape, Pose);

/// Every collision shape of the robot, and the lowest point of them all with the joints at
/// zero (root frame), to rest the robot on the ground.
fn robot_shapes(robot: &RobotModel, root_from_links: &[Pose]) -> Result<(Vec<LinkShape>, f32)> {
    let mut shapes = Vec::new();
    let mut min_z = f32::INFINITY;
    for (i, link) in robot.links.iter().enumerate() {
        for c in &link.collisions {
            let (shape, fix) = collider_shape(&c.shape, &robot.source, &link.name, false)?;
            let root_from_shape = root_from_links[i] * c.link_from_shape * fix;
            min_z = min_z.min(shape.compute_aabb(&root_from_shape).mins.z);
            shapes.push((i, shape, c.link_from_shape * fix));
        }
    }
    if shapes.is_empty() {
        return Err(SimError::Setup(format!(
            "{}: the robot has no <collision> shapes, so it would fall through the ground; give its wheels and base collision geometry",
            robot.source.display()
        )));
    }
    Ok((shapes, min_z))
}

/// One rigid body per body root, carrying the summed inertials of its links (the `anchor`
/// body, when given, is fixed to the world); returns each link's body and that body's mass
/// (kg).
fn add_link_bodies(
    physics: &mut PhysicsWorld,
    robot: &RobotModel,
    (body_root, body_from_link): (&[usize], &[Pose]),
    anchor: Option<usize>,
    world_from_root_link: impl Fn(usize) -> Pose,
) -> (Vec<RigidBodyHandle>, Vec<f32>) {
    let n = robot.links.len();
    let mut link_body = vec![RigidBodyHandle::invalid(); n];
    let mut link_mass_kg = vec![0.0f32; n];
    for root in 0..n {
        if body_root[root] != root {
            continue;
        }
        let mut mass = MassProperties::default();
        for (i, link) in robot.links.iter().enumerate() {
            if body_root[i] != root {
                continue;
            }
            if let Some(inertial) = &link.inertial {
                let [ixx, ixy, ixz, iyy, iyz, izz] = inertial.inertia;
                let local = Mat3::from_cols(
                    Vec3::new(ixx, ixy, ixz),
                    Vec3::new(ixy, iyy, iyz),
                    Vec3::new(ixz, iyz, izz),
                );
                let r = Mat3::from_quat(inertial.link_from_inertial.rotation);
                let props = MassProperties::with_inertia_matrix(
                    inertial.link_from_inertial.translation,
                    inertial.mass_kg,
                    r * local * r.transpose(),
                );
                mass += props.transform_by(&body_from_link[i]);
            }
        }
        if mass.mass() <= 0.0 && anchor != Some(root) {
            tracing::warn!(
                "{}: link \"{}\" moves on its own but has no <inertial>; giving it 10 g",
                robot.source.display(),
                robot.links[root].name
            );
            mass = MassProperties::new(Vec3::ZERO, 0.01, Vec3::splat(1e-6));
        }
        let builder = if anchor == Some(root) {
            RigidBodyBuilder::fixed()
        } else {
            RigidBodyBuilder::dynamic()
        };
        let body = physics.insert_body(
            builder
                .pose(world_from_root_link(root))
                .additional_mass_properties(mass)
                .can_sleep(false),
        );
        for (i, slot) in link_body.iter_mut().enumerate() {
            if body_root[i] == root {
                *slot = body;
                link_mass_kg[i] = mass.mass();
            }
        }
    }
    (link_body, link_mass_kg)
}

/// Above this mass ratio between jointed bodies the solver gets [`STIFF_SOLVER_ITERATIONS`].
pub(crate) const STIFF_MASS_RATIO: f32 = 15.0;
/// Solver iterations for robots with light links on heavy ones.
pub(crate) const STIFF_SOLVER_ITERATIONS: usize = 16;

/// The largest mass ratio between two bodies connected by a moving joint.
pub(crate) fn joint_mass_ratio(robot: &RobotModel, bodies: &RobotBodies) -> f32 {
    let mass = |link: usize| bodies.link_mass_kg[link];
    robot
        .joints
        .iter()
        .filter(|j| bodies.link_body[j.parent.0] != bodies.link_body[j.child.0])
        .map(|j| {
            let (a, b) = (mass(j.parent.0), mass(j.child.0));
            if a.min(b) > 0.0 {
                a.max(b) / a.min(b)
            } else {
                1.0
            }
        })
        .fold(1.0, f32::max)
}

/// Gap between the robot's lowest collision point and the ground at spawn (m).
const SPAWN_CLEARANCE_M: f32 = 0.0;
