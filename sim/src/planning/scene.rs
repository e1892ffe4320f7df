//! The planning scene: what an arm's motion planner checks a configuration against, as MoveIt
//! checks one against its planning scene. The arm's links (every link one of its chain's joints
//! moves) at the configuration, by forward kinematics over the robot's tree, against:
//! - the world's colliders where they are now (the ground, boxes, spheres, models, people):
//!   the geometry Gazebo's planning-scene plugins hand MoveIt;
//! - the robot's links the chain does not move (the chassis, a mast), except the ones a chain
//!   link touches with every joint at zero (neighbours by construction, as MoveIt's setup
//!   assistant's "adjacent" and "default" pairs);
//! - an object held in the hand, carried with its link ([`PlanningScene::attach_sphere`]);
//! - the arm's own links against each other (overlapping, no margin), as MoveIt checks
//!   self-collision: every pair but neighbours (links one joint apart, or welded by fixed
//!   joints), pairs that touch with every joint at zero (the setup assistant's "adjacent" and
//!   "default" pairs) and the pairs the world's SRDF (`[robot] srdf`) lists in
//!   `<disable_collisions>`.
//!
//! Against the world and the robot's other links, a pair closer than the margin is a collision.

use glam::Quat;
use rapier3d::parry::query;
use rapier3d::prelude::*;

use crate::error::Result;
use crate::geometry::Pose;
use crate::model::kinematics::KinematicChain;
use crate::model::robot::{JointId, JointKind, LinkId, RobotModel};
use crate::physics::build::{ROBOT_GROUP, collider_shape, other_body};
use crate::physics::simulation::Simulation;

/// What a configuration hits.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneContact {
    /// The arm's link (or `held object`).
    pub link: String,
    /// What it comes within the margin of: a world object's name, `ground`, a model link
    /// (`model::link`), a person or one of the robot's other links.
    pub obstacle: String,
    /// Their distance (m; 0 when they overlap).
    pub distance_m: f32,
}

impl std::fmt::Display for SceneContact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.distance_m > 0.0 {
            write!(
                f,
                "{} within {:.3} m of {}",
                self.link, self.distance_m, self.obstacle
            )
        } else {
            write!(f, "{} hits {}", self.link, self.obstacle)
        }
    }
}

/// A link's collision shapes, each with its pose in the link's frame.
type LinkShapes = Vec<(Pose, SharedShape)>;

/// One obstacle, fixed where it was when the scene was taken.
#[derive(Clone)]
struct Obstacle {
    world_from_shape: Pose,
    shape: SharedShape,
    name: String,
    /// The world object's index, for an object.
    object: Option<usize>,
    /// One of the robot's own links.
    robot: bool,
    aabb: rapier3d::parry::bounding_volume::Aabb,
}

/// The scene for one chain.
#[derive(Clone)]
pub struct PlanningScene {
    robot: RobotModel,
    /// The robot's joints parents first.
    order: Vec<JointId>,
    /// Every joint's position (robot joint order), the chain's replaced per check.
    q_all: Vec<f64>,
    chain_joints: Vec<JointId>,
    world_from_root: Pose,
    /// The links the chain moves, whether they are checked against the robot's other links,
    /// and their shapes (link frame).
    moving: Vec<(LinkId, bool, LinkShapes)>,
    /// The pairs of [`Self::moving`] (indices) checked against each other.
    self_pairs: Vec<(usize, usize)>,
    /// The robot's links the chain does not move that count as obstacles, with their shapes.
    fixed_links: Vec<(LinkId, Pose, SharedShape)>,
    obstacles: Vec<Obstacle>,
    /// A held object: its link, where it is on the link, its shape.
    attached: Option<(LinkId, Pose, SharedShape)>,
    /// Objects left out (the one about to be grasped, the one held).
    ignored: Vec<usize>,
    margin_m: f32,
    root_from_link: Vec<Pose>,
}

impl std::fmt::Debug for PlanningScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlanningScene")
            .field("moving_links", &self.moving.len())
            .field("obstacles", &self.obstacles.len())
            .field("margin_m", &self.margin_m)
            .finish_non_exhaustive()
    }
}

impl PlanningScene {
    /// The margin (m): closer than this is a collision.
    pub fn margin_m(&self) -> f32 {
        self.margin_m
    }

    /// Leaves world object `index` out of the checks (the object a grasp is about to touch),
    /// or takes it back in (`ignore` false).
    pub fn ignore_object(&mut self, index: usize, ignore: bool) {
        self.ignored.retain(|&i| i != index);
        if ignore {
            self.ignored.push(index);
        }
    }

    /// The world object nearest `world_point_m` within `within_m` of its surface, by index
    /// (the object a perceived point belongs to): the world's objects first, then the SDF
    /// models' links (model, then link order) numbered on after them.
    pub fn object_near(&self, world_point_m: [f64; 3], within_m: f32) -> Option<usize> {
        let [x, y, z] = world_point_m.map(|v| v as f32);
        let point = Vec3::new(x, y, z);
        self.obstacles
            .iter()
            .filter_map(|o| {
                let d = o.shape.distance_to_point(&o.world_from_shape, point, true);
                (d <= within_m).then_some((o.object?, d))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// Sets a joint outside the chain (a finger: the gripper open or closed) for the checks
    /// that follow; a joint of the chain is set by each check.
    pub fn set_joint(&mut self, joint: JointId, position: f64) {
        if let Some(q) = self.q_all.get_mut(joint.index()) {
            *q = position;
        }
    }

    /// Carries a sphere of `radius_m` with `link` at `link_from_centre` (a held object), or
    /// nothing (`None`).
    pub fn attach_sphere(&mut self, held: Option<(LinkId, Pose, f32)>) {
        self.attached = held.map(|(link, pose, r)| (link, pose, SharedShape::ball(r)));
    }

    /// Carries a box of half sizes `half_m` with `link`, its centre and axes at
    /// `link_from_box` (a held box, turned as the hand holds it).
    pub fn attach_box(&mut self, link: LinkId, link_from_box: Pose, half_m: [f32; 3]) {
        let [x, y, z] = half_m;
        self.attached = Some((link, link_from_box, SharedShape::cuboid(x, y, z)));
    }

    /// The first thing the chain's links (or the held object) come within the margin of at
    /// `q` (the chain's joint positions), if any.
    pub fn collision(&mut self, q: &[f64]) -> Option<SceneContact> {
        self.forward(q);
        for (link, self_check, shapes) in &self.moving {
            let world_from_link = self.world_from_root * self.root_from_link[link.index()];
            for (link_from_shape, shape) in shapes {
                let name = || self.robot.links[link.index()].name.clone();
                let at = world_from_link * *link_from_shape;
                if let Some(hit) = self.first_hit(&at, shape, *self_check, name) {
                    return Some(hit);
                }
            }
        }
        if let Some((link, pose, shape)) = &self.attached {
            let world = self.world_from_root * self.root_from_link[link.index()] * *pose;
            if let Some(hit) = self.first_hit(&world, shape, true, || "held object".to_owned()) {
                return Some(hit);
            }
        }
        self.self_collision()
    }

    /// The first pair of the arm's own links that overlap, at the pose [`Self::forward`] last
    /// computed. No margin, as MoveIt pads no link by default: a moving link's shape is its
    /// collision mesh's convex hull, larger than the link where it is concave.
    fn self_collision(&self) -> Option<SceneContact> {
        for &(a, b) in &self.self_pairs {
            let ((link_a, _, shapes_a), (link_b, _, shapes_b)) = (&self.moving[a], &self.moving[b]);
            let (root_from_a, root_from_b) = (
                self.root_from_link[link_a.index()],
                self.root_from_link[link_b.index()],
            );
            for (pose_a, shape_a) in shapes_a {
                let at_a = root_from_a * *pose_a;
                let aabb_a = shape_a.compute_aabb(&at_a);
                for (pose_b, shape_b) in shapes_b {
                    let at_b = root_from_b * *pose_b;
                    if !aabb_a.intersects(&shape_b.compute_aabb(&at_b)) {
                        continue;
                    }
                    if query::intersection_test(&at_a, &**shape_a, &at_b, &**shape_b)
                        .is_ok_and(|i| i.intersecting)
                    {
                        let name = |l: &LinkId| self.robot.links[l.index()].name.clone();
                        return Some(SceneContact {
                            link: name(link_a),
                            obstacle: format!("{} (the robot's)", name(link_b)),
                            distance_m: 0.0,
                        });
                    }
                }
            }
        }
        None
    }

    /// The nearest obstacle within the margin of one shape.
    fn first_hit(
        &self,
        world_from_shape: &Pose,
        shape: &SharedShape,
        self_check: bool,
        link: impl Fn() -> String,
    ) -> Option<SceneContact> {
        let aabb = shape.compute_aabb(world_from_shape).loosened(self.margin_m);
        for o in &self.obstacles {
            if o.object.is_some_and(|i| self.ignored.contains(&i))
                || (o.robot && !self_check)
                || !aabb.intersects(&o.aabb)
            {
                continue;
            }
            let Ok(d) = query::distance(world_from_shape, &**shape, &o.world_from_shape, &*o.shape)
            else {
                continue;
            };
            if d.distance < self.margin_m {
                return Some(SceneContact {
                    link: link(),
                    obstacle: o.name.clone(),
                    distance_m: d.distance,
                });
            }
        }
        None
    }

    /// Every link's pose in the root frame with the chain at `q`.
    fn forward(&mut self, q: &[f64]) {
        for (id, v) in self.chain_joints.iter().zip(q) {
            if let Some(slot) = self.q_all.get_mut(id.index()) {
                *slot = *v;
            }
        }
        // Mimic joints follow their leaders.
        for (i, joint) in self.robot.joints.iter().enumerate() {
            if let Some(m) = &joint.mimic {
                let leader = self.q_all.get(m.joint.index()).copied().unwrap_or(0.0);
                self.q_all[i] = f64::from(m.multiplier) * leader + f64::from(m.offset);
            }
        }
        root_from_links_at(
            &self.robot,
            &self.order,
            &self.q_all,
            &mut self.root_from_link,
        );
    }
}

/// The pairs of `moving` (the chain's links with their shapes) a configuration is checked
/// for: all but neighbours (one moving joint apart, or welded by fixed joints), pairs within
/// `margin_m` of each other with every joint at zero (`at_zero`: the links' poses then) and
/// the `disabled` pairs (an SRDF's).
fn self_pairs(
    robot: &RobotModel,
    moving: &[(LinkId, bool, LinkShapes)],
    at_zero: &[Pose],
    (disabled, margin_m): (&[(LinkId, LinkId)], f32),
) -> Vec<(usize, usize)> {
    // Each link's rigid group: the topmost link it is welded to by fixed joints.
    let mut group: Vec<usize> = (0..robot.links.len()).collect();
    for id in joint_order(robot) {
        let joint = robot.joint(id);
        if joint.kind == JointKind::Fixed {
            group[joint.child.index()] = group[joint.parent.index()];
        }
    }
    let neighbours = |a: LinkId, b: LinkId| {
        let (ga, gb) = (group[a.index()], group[b.index()]);
        ga == gb
            || robot.joints.iter().any(|j| {
                let (p, c) = (group[j.parent.index()], group[j.child.index()]);
                (p == ga && c == gb) || (p == gb && c == ga)
            })
    };
    let touch_at_zero = |a: &(LinkId, bool, LinkShapes), b: &(LinkId, bool, LinkShapes)| {
        a.2.iter().any(|(pa, sa)| {
            b.2.iter().any(|(pb, sb)| {
                let (at_a, at_b) = (at_zero[a.0.index()] * *pa, at_zero[b.0.index()] * *pb);
                query::distance(&at_a, &**sa, &at_b, &**sb).is_ok_and(|d| d.distance < margin_m)
            })
        })
    };
    let mut out = Vec::new();
    for (i, a) in moving.iter().enumerate() {
        for (j, b) in moving.iter().enumerate().skip(i + 1) {
            let listed = disabled
                .iter()
                .any(|&(x, y)| (x == a.0 && y == b.0) || (x == b.0 && y == a.0));
            if !listed && !neighbours(a.0, b.0) && !touch_at_zero(a, b) {
                out.push((i, j));
            }
        }
    }
    out
}

/// Every link's pose in the root frame with the joints at `q_all` (robot joint order),
/// visiting joints in `order` (parents first) into `out`.
fn root_from_links_at(robot: &RobotModel, order: &[JointId], q_all: &[f64], out: &mut Vec<Pose>) {
    out.clear();
    out.resize(robot.links.len(), Pose::IDENTITY);
    for id in order {
        let joint = &robot.joints[id.index()];
        let q = q_all.get(id.index()).copied().unwrap_or(0.0) as f32;
        let motion = match joint.kind {
            JointKind::Fixed => Pose::IDENTITY,
            JointKind::Prismatic { .. } => Pose::from_translation(joint.axis * q),
            _ => Pose::from_rotation(Quat::from_axis_angle(joint.axis, q)),
        };
        out[joint.child.index()] = out[joint.parent.index()] * joint.parent_from_child * motion;
    }
}

/// The robot's joints, parents first.
fn joint_order(robot: &RobotModel) -> Vec<JointId> {
    let mut placed = vec![false; robot.links.len()];
    placed[robot.root.index()] = true;
    let mut order = Vec::with_capacity(robot.joints.len());
    let mut progress = true;
    while progress {
        progress = false;
        for (id, joint) in robot.joint_ids() {
            if placed[joint.parent.index()] && !placed[joint.child.index()] {
                placed[joint.child.index()] = true;
                order.push(id);
                progress = true;
            }
        }
    }
    order
}

impl Simulation {
    /// The planning scene for `chain` (a chain of this robot) as things are now, closer than
    /// `margin_m` counting as a collision. Errors: a collision mesh that cannot be read.
    pub fn planning_scene(&self, chain: &KinematicChain, margin_m: f32) -> Result<PlanningScene> {
        let robot = &self.robot;
        let order = joint_order(robot);
        let chain_joints: Vec<JointId> = chain.joints().iter().map(|j| j.id).collect();
        // The links the chain moves: below its first joint.
        let mut moved = vec![false; robot.links.len()];
        // The links only the first joint moves (the arm's first link, welded to it) turn in
        // place beside the robot's body they are mounted on: they are not checked against it.
        let mut first_only = vec![false; robot.links.len()];
        for id in &order {
            let joint = &robot.joints[id.index()];
            let parent = joint.parent.index();
            if chain_joints.first() == Some(id) || moved[parent] {
                moved[joint.child.index()] = true;
                first_only[joint.child.index()] = chain_joints.first() == Some(id)
                    || (first_only[parent] && joint.kind == JointKind::Fixed);
            }
        }
        let mut shapes: Vec<LinkShapes> = vec![Vec::new(); robot.links.len()];
        for (i, link) in robot.links.iter().enumerate() {
            for c in &link.collisions {
                let (shape, fix) = collider_shape(&c.shape, &robot.source, &link.name, false)?;
                shapes[i].push((c.link_from_shape * fix, shape));
            }
        }
        // The robot's other links, where they are now, but not those a chain link touches
        // with every joint at zero.
        let mut at_zero = Vec::new();
        root_from_links_at(robot, &order, &vec![0.0; robot.joints.len()], &mut at_zero);
        let touching_at_zero = |fixed: usize| {
            shapes[fixed].iter().any(|(pf, sf)| {
                (0..robot.links.len()).filter(|&m| moved[m]).any(|m| {
                    shapes[m].iter().any(|(pm, sm)| {
                        query::distance(&(at_zero[fixed] * *pf), &**sf, &(at_zero[m] * *pm), &**sm)
                            .is_ok_and(|d| d.distance < margin_m)
                    })
                })
            })
        };
        let fixed_links: Vec<(LinkId, Pose, SharedShape)> = (0..robot.links.len())
            .filter(|&i| !moved[i] && !shapes[i].is_empty() && !touching_at_zero(i))
            .flat_map(|i| {
                shapes[i]
                    .iter()
                    .map(move |(pose, shape)| (LinkId(i), *pose, shape.clone()))
            })
            .collect();
        let moving: Vec<(LinkId, bool, LinkShapes)> = (0..robot.links.len())
            .filter(|&i| moved[i] && !shapes[i].is_empty())
            .map(|i| (LinkId(i), !first_only[i], shapes[i].clone()))
            .collect();
        let self_pairs = self_pairs(robot, &moving, &at_zero, (&self.srdf_disabled, margin_m));
        let mut scene = PlanningScene {
            robot: robot.clone(),
            order,
            q_all: Vec::new(),
            chain_joints,
            world_from_root: Pose::IDENTITY,
            moving,
            self_pairs,
            fixed_links,
            obstacles: Vec::new(),
            attached: None,
            ignored: Vec::new(),
            margin_m,
            root_from_link: Vec::new(),
        };
        self.refresh_planning_scene(&mut scene);
        Ok(scene)
    }

    /// The box round `link`'s collision shapes in the link's own frame (m: its lowest and
    /// highest corners), meshes as the hulls the physics uses; `None` when it has none.
    pub fn link_collision_box(&self, link: LinkId) -> Result<Option<([f32; 3], [f32; 3])>> {
        let robot = &self.robot;
        let Some(l) = robot.links.get(link.index()) else {
            return Ok(None);
        };
        let mut bounds: Option<([f32; 3], [f32; 3])> = None;
        for c in &l.collisions {
            let (shape, fix) = collider_shape(&c.shape, &robot.source, &l.name, false)?;
            let aabb = shape.compute_aabb(&(c.link_from_shape * fix));
            let (lo, hi) = (aabb.mins, aabb.maxs);
            bounds = Some(match bounds {
                None => (lo.into(), hi.into()),
                Some((a, b)) => (
                    glam::Vec3::from(a).min(lo).into(),
                    glam::Vec3::from(b).max(hi).into(),
                ),
            });
        }
        Ok(bounds)
    }

    /// Brings `scene` (this robot's) up to now: the joints' positions, where the robot is,
    /// where the world's things are; nothing ignored or attached.
    pub fn refresh_planning_scene(&self, scene: &mut PlanningScene) {
        scene.q_all.clear();
        scene.q_all.extend(
            self.robot
                .joint_ids()
                .map(|(id, _)| self.joint_state(id).map_or(0.0, |s| s.position)),
        );
        scene.world_from_root = self.world_from_link(self.robot.root);
        scene.obstacles = self.world_obstacles();
        for (link, pose, shape) in &scene.fixed_links {
            let world_from_shape = self.world_from_link(*link) * *pose;
            scene.obstacles.push(Obstacle {
                aabb: shape.compute_aabb(&world_from_shape),
                world_from_shape,
                shape: shape.clone(),
                name: format!("{} (the robot's)", self.robot.links[link.index()].name),
                object: None,
                robot: true,
            });
        }
        scene.ignored.clear();
        scene.attached = None;
    }

    /// What world object `index` touches now (a contact with force in it): the robot's links
    /// by name (links welded into one body by the first of them), `ground`, other objects by
    /// name, people and models. Empty for an index out of range.
    pub fn object_contacts(&self, index: usize) -> Vec<String> {
        let Some(body) = self.objects.get(index) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let Some(rb) = self.physics.bodies.get(*body) else {
            return out;
        };
        for collider in rb.colliders() {
            for pair in self.physics.narrow_phase.contact_pairs_with(*collider) {
                if !pair.has_any_active_contact() || pair.total_impulse_magnitude() <= 0.0 {
                    continue;
                }
                let name = match other_body(&self.physics, pair, *collider) {
                    Some(b) => match self.link_body.iter().position(|l| *l == b) {
                        Some(link) => self.robot.links[link].name.clone(),
                        None => self.body_name(b),
                    },
                    None => "ground".to_owned(),
                };
                if !out.contains(&name) {
                    out.push(name);
                }
            }
        }
        out
    }

    /// The force (N) the ground (or a collider on no body) pushes on link `link`'s body with,
    /// in the last step (the sum of those contacts' impulses over the step; links welded into
    /// one body share it). 0 for a link not on the ground.
    pub fn ground_force_n(&self, link: crate::model::LinkId) -> f32 {
        let Some(body) = self.link_body.get(link.index()) else {
            return 0.0;
        };
        let Some(rb) = self.physics.bodies.get(*body) else {
            return 0.0;
        };
        let dt = self.physics.integration_parameters.dt.max(f32::EPSILON);
        let mut impulse = 0.0;
        for collider in rb.colliders() {
            for pair in self.physics.narrow_phase.contact_pairs_with(*collider) {
                let parent = other_body(&self.physics, pair, *collider);
                if parent.is_none() || parent == Some(self.ground) {
                    impulse += pair.total_impulse_magnitude();
                }
            }
        }
        impulse / dt
    }

    /// The name of a body that is not the robot's.
    pub(crate) fn body_name(&self, body: RigidBodyHandle) -> String {
        if body == self.ground {
            return "ground".to_owned();
        }
        if let Some(i) = self.objects.iter().position(|b| *b == body) {
            return match self.world.objects.get(i) {
                Some(o) if !o.name.is_empty() => o.name.clone(),
                _ => format!("object {i}"),
            };
        }
        if let Some(i) = self.people.iter().position(|b| *b == body) {
            return format!("person {i}");
        }
        if let Some(k) = self.model_links.iter().position(|b| *b == body) {
            // Models' links in order: the k-th link is the model's whose links reach past it.
            let mut first = 0;
            for model in &self.world.models {
                if k < first + model.links.len() {
                    return format!("model \"{}\"", model.name);
                }
                first += model.links.len();
            }
        }
        "a model".to_owned()
    }

    /// Every collider not the robot's, where it is now, named.
    fn world_obstacles(&self) -> Vec<Obstacle> {
        let name_of = |body: Option<RigidBodyHandle>| -> (String, Option<usize>) {
            let Some(body) = body else {
                return ("ground".to_owned(), None);
            };
            // World objects by their index, then the SDF models' links.
            let object = (self.objects.iter().position(|b| *b == body)).or_else(|| {
                (self.model_links.iter().position(|b| *b == body)).map(|k| self.objects.len() + k)
            });
            (self.body_name(body), object)
        };
        self.physics
            .colliders
            .iter()
            .filter(|(_, c)| !c.collision_groups().memberships.contains(ROBOT_GROUP))
            .map(|(_, c)| {
                let (name, object) = name_of(c.parent());
                let world_from_shape = *c.position();
                Obstacle {
                    aabb: c.shape().compute_aabb(&world_from_shape),
                    world_from_shape,
                    shape: c.shared_shape().clone(),
                    name,
                    object,
                    robot: false,
                }
            })
            .collect()
    }
}
