//! Robots described as an SDF `<model>` (modern Gazebo's robots: `--robot model.sdf`, as
//! ros_gz_sim's `create -file` spawns them): links with their poses, inertials, visuals and
//! collisions, joints, the sensors on links and the systems on the model.
//!
//! The model is read into the same parts a URDF gives (links, joints, Gazebo extensions), so
//! every check and every sensor model is shared. SDF places links in the model frame and
//! joints in their child link's frame; URDF puts a moving joint's axis through its child's
//! origin. A link under a moving joint is therefore re-framed at its joint (its visuals,
//! collisions, inertial and sensors moved with it), as sdformat's URDF conversion does. A
//! `ball` joint becomes a fixed joint whose link has no friction: a free caster ball pushes
//! no tangential force on the ground, which is what the ball joint is for on a mobile base.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use glam::EulerRot;
use roxmltree::Node;

use crate::description::gazebo;
use crate::description::parts::{ElementLines, Parts};
use crate::description::resource::ResourcePaths;
use crate::description::sdf::{Ctx, material_color};
use crate::description::urdf::{
    CollisionEl, Geometry, InertialEl, JointEl, JointType, LinkEl, MaterialEl, Origin, RobotEl,
    VisualEl,
};
use crate::description::xml::{child, children, elements, line_of};
use crate::error::Result;
use crate::geometry::Pose;
use crate::model::robot::RobotModel;

/// Loads the `<model>` of an SDF document as a robot.
pub(crate) fn load(
    doc: &roxmltree::Document<'_>,
    text: &str,
    path: &Path,
    resources: &ResourcePaths,
) -> Result<RobotModel> {
    let ctx = Ctx { path, doc };
    let root = doc.root_element();
    let Some(model) = child(root, "model") else {
        let found = if child(root, "world").is_some() {
            "a <world>: pass a world file with --world, and a robot model with --robot"
        } else {
            "no <model>"
        };
        return Err(ctx.err(
            root,
            format!("<sdf> holds {found}; expected a robot <model>"),
        ));
    };
    if let Some(nested) = children(model, "model")
        .next()
        .or_else(|| children(model, "include").next())
    {
        return Err(ctx.err(
            nested,
            format!(
                "<{}> inside a robot <model>: nested models are not supported in a robot; expected links and joints",
                nested.tag_name().name()
            ),
        ));
    }
    let name = model.attribute("name").unwrap_or("robot").to_owned();
    let frames = Frames::read(&ctx, model)?;
    let mut lines = ElementLines::default();
    let mut friction = BTreeMap::new();
    let mut urdf = RobotEl {
        name: name.clone(),
        materials: Vec::new(),
        links: Vec::new(),
        joints: Vec::new(),
        transmissions: Vec::new(),
    };
    for link in children(model, "link") {
        let link_name = link.attribute("name").unwrap_or("");
        lines.links.insert(link_name.to_owned(), line_of(doc, link));
        let urdf_from_sdf = frames.urdf_from_sdf(link_name);
        urdf.links.push(read_link(
            &ctx,
            link,
            link_name,
            urdf_from_sdf,
            &mut friction,
        )?);
    }
    for joint in children(model, "joint") {
        let joint_name = joint.attribute("name").unwrap_or("");
        lines
            .joints
            .insert(joint_name.to_owned(), line_of(doc, joint));
        if let Some(j) = read_joint(&ctx, joint, &frames, &mut friction)? {
            urdf.joints.push(j);
        }
    }
    let blocks = std::iter::once((None, model))
        .chain(children(model, "link").map(|l| (l.attribute("name"), l)));
    let mut extensions = gazebo::parse_blocks(doc, path, &name, true, blocks)?;
    extensions.friction.extend(friction);
    // Sensors sit in their link's SDF frame; the link may have moved to its joint.
    for laser in &mut extensions.lasers {
        laser.link_from_sensor = frames.urdf_from_sdf(&laser.link) * laser.link_from_sensor;
    }
    for lidar in &mut extensions.lidars {
        lidar.rays.link_from_sensor =
            frames.urdf_from_sdf(&lidar.rays.link) * lidar.rays.link_from_sensor;
    }
    for imu in &mut extensions.imus {
        imu.link_from_sensor = frames.urdf_from_sdf(&imu.link) * imu.link_from_sensor;
    }
    for gps in &mut extensions.gpss {
        gps.link_from_sensor = frames.urdf_from_sdf(&gps.link) * gps.link_from_sensor;
    }
    // A camera sits at its link's origin, which a moving joint's child has moved to the joint.
    for camera in &extensions.cameras {
        if frames.urdf_from_sdf(&camera.link).translation.length() > 1e-6 {
            tracing::warn!(
                "{}: camera \"{}\" on link \"{}\": rover's camera sits at the link's joint, not at the link's SDF origin",
                path.display(),
                camera.name,
                camera.link
            );
        }
    }
    // model:// meshes beside the model's own folder (a package's models/), after the paths given.
    let mut resources = resources.clone();
    if let Some(models) = path.parent().and_then(Path::parent) {
        resources.model_search.push(models.to_path_buf());
    }
    RobotModel::build(
        Parts {
            urdf,
            lines,
            extensions,
            root_line: Some(line_of(doc, model)),
        },
        text,
        path,
        &resources,
    )
}

/// Every link's frame in the model, and where its URDF frame is.
struct Frames {
    /// Link name -> its SDF frame in the model (`<link><pose>`).
    model_from_link: HashMap<String, Pose>,
    /// Link name -> its URDF frame in the model: the joint frame for a moving joint's child,
    /// else the SDF frame.
    model_from_urdf: HashMap<String, Pose>,
}

impl Frames {
    fn read(ctx: &Ctx<'_, '_>, model: Node<'_, '_>) -> Result<Self> {
        let mut model_from_link: HashMap<String, Pose> = HashMap::new();
        let links: Vec<Node<'_, '_>> = children(model, "link").collect();
        // Poses relative to other links: resolved in passes, at most one per link.
        let mut pending: Vec<Node<'_, '_>> = links.clone();
        for _ in 0..=links.len() {
            let mut left = Vec::new();
            for link in pending {
                let name = link.attribute("name").unwrap_or("").to_owned();
                let (pose, relative_to) = match child(link, "pose") {
                    Some(p) => (ctx.pose(p)?, p.attribute("relative_to").unwrap_or("")),
                    None => (Pose::IDENTITY, ""),
                };
                match relative_to {
                    "" | "__model__" => {
                        model_from_link.insert(name, pose);
                    }
                    other => match model_from_link.get(other) {
                        Some(base) => {
                            let p = *base * pose;
                            model_from_link.insert(name, p);
                        }
                        None if links.iter().any(|l| l.attribute("name") == Some(other)) => {
                            left.push(link)
                        }
                        None => {
                            return Err(ctx.err(
                                link,
                                format!(
                                    "<link name=\"{name}\"> <pose relative_to=\"{other}\">: no link of that name in the model; expected a link or __model__"
                                ),
                            ));
                        }
                    },
                }
            }
            pending = left;
            if pending.is_empty() {
                break;
            }
        }
        if let Some(link) = pending.first() {
            return Err(ctx.err(
                *link,
                "<pose relative_to>: the links' poses refer to each other in a cycle",
            ));
        }
        let mut model_from_urdf = model_from_link.clone();
        for joint in children(model, "joint") {
            if !moving(joint.attribute("type").unwrap_or("")) {
                continue;
            }
            let child_name = child(joint, "child")
                .and_then(|c| c.text())
                .unwrap_or("")
                .trim();
            let Some(child_pose) = model_from_link.get(child_name) else {
                continue;
            };
            // A joint's <pose> is in its child link's frame unless `relative_to` says otherwise.
            let model_from_joint = match child(joint, "pose") {
                None => *child_pose,
                Some(p) => {
                    let pose = ctx.pose(p)?;
                    match p.attribute("relative_to").unwrap_or("") {
                        "" => *child_pose * pose,
                        "__model__" => pose,
                        other => match model_from_link.get(other) {
                            Some(base) => *base * pose,
                            None => {
                                return Err(ctx.err(
                                    p,
                                    format!(
                                        "<joint name=\"{}\"> <pose relative_to=\"{other}\">: no link of that name in the model; expected a link or __model__",
                                        joint.attribute("name").unwrap_or("")
                                    ),
                                ));
                            }
                        },
                    }
                }
            };
            model_from_urdf.insert(child_name.to_owned(), model_from_joint);
        }
        Ok(Self {
            model_from_link,
            model_from_urdf,
        })
    }

    /// Maps a link's SDF frame into its URDF frame (identity unless it was re-framed).
    fn urdf_from_sdf(&self, link: &str) -> Pose {
        match (
            self.model_from_urdf.get(link),
            self.model_from_link.get(link),
        ) {
            (Some(urdf), Some(sdf)) => urdf.inverse() * *sdf,
            _ => Pose::IDENTITY,
        }
    }

    fn model_from_urdf(&self, link: &str) -> Pose {
        self.model_from_urdf
            .get(link)
            .copied()
            .unwrap_or(Pose::IDENTITY)
    }
}

/// Whether a joint type moves (and so has its axis through its child's URDF frame).
fn moving(kind: &str) -> bool {
    matches!(kind, "revolute" | "continuous" | "prismatic")
}

/// A pose as a URDF `<origin>`.
fn origin(p: Pose) -> Origin {
    let (yaw, pitch, roll) = p.rotation.to_euler(EulerRot::ZYX);
    let t = p.translation;
    Origin {
        xyz: [t.x, t.y, t.z].map(f64::from),
        rpy: [roll, pitch, yaw].map(f64::from),
    }
}

fn read_link(
    ctx: &Ctx<'_, '_>,
    link: Node<'_, '_>,
    name: &str,
    urdf_from_sdf: Pose,
    friction: &mut BTreeMap<String, f32>,
) -> Result<LinkEl> {
    let local = |node: Node<'_, '_>| -> Result<Origin> {
        Ok(origin(urdf_from_sdf * ctx.local_pose(node)?))
    };
    let inertial = match child(link, "inertial") {
        Some(i) => {
            let mass = child(i, "mass").map_or(Ok(1.0), |m| ctx.number(m))?;
            let mut inertia = [1.0, 0.0, 0.0, 1.0, 0.0, 1.0];
            if let Some(t) = child(i, "inertia") {
                for (k, tag) in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]
                    .iter()
                    .enumerate()
                {
                    if let Some(v) = child(t, tag) {
                        inertia[k] = ctx.number(v)?;
                    }
                }
            }
            Some(InertialEl {
                origin: local(i)?,
                mass,
                inertia,
            })
        }
        None => None,
    };
    let mut visual = Vec::new();
    for v in children(link, "visual") {
        let Some(geometry) = read_geometry(ctx, v)? else {
            continue;
        };
        let material = material_color(ctx, v)?.map(|c| MaterialEl {
            name: String::new(),
            color: Some(c.0.map(f64::from)),
        });
        visual.push(VisualEl {
            origin: local(v)?,
            geometry,
            material,
        });
    }
    let mut collision = Vec::new();
    for c in children(link, "collision") {
        if let Some(mu) = surface_friction(ctx, c)? {
            let slot = friction.entry(name.to_owned()).or_insert(f32::INFINITY);
            *slot = slot.min(mu);
        }
        let Some(geometry) = read_geometry(ctx, c)? else {
            continue;
        };
        collision.push(CollisionEl {
            origin: local(c)?,
            geometry,
        });
    }
    Ok(LinkEl {
        name: name.to_owned(),
        inertial,
        visual,
        collision,
    })
}

/// `<surface><friction><ode><mu>`/`<mu2>` (the smaller), if given.
fn surface_friction(ctx: &Ctx<'_, '_>, collision: Node<'_, '_>) -> Result<Option<f32>> {
    let Some(ode) = child(collision, "surface")
        .and_then(|s| child(s, "friction"))
        .and_then(|f| child(f, "ode"))
    else {
        return Ok(None);
    };
    let mut mu: Option<f64> = None;
    for tag in ["mu", "mu2"] {
        if let Some(n) = child(ode, tag) {
            let v = ctx.number(n)?;
            if v < 0.0 {
                return Err(ctx.err(
                    n,
                    format!("<{tag}>: expected a friction coefficient of 0 or more, found {v}"),
                ));
            }
            mu = Some(mu.map_or(v, |m| m.min(v)));
        }
    }
    Ok(mu.map(|m| m as f32))
}

/// A visual's or collision's `<geometry>`; `None` for a plane or an empty geometry (nothing a
/// robot link can use).
fn read_geometry(ctx: &Ctx<'_, '_>, element: Node<'_, '_>) -> Result<Option<Geometry>> {
    let Some(geometry) = child(element, "geometry") else {
        return Err(ctx.err(
            element,
            format!("<{}> has no <geometry>", element.tag_name().name()),
        ));
    };
    let Some(shape) = elements(geometry).next() else {
        return Ok(None);
    };
    let number = |tag: &str| -> Result<f64> {
        let n = child(shape, tag).ok_or_else(|| {
            ctx.err(
                shape,
                format!("<{}> has no <{tag}>", shape.tag_name().name()),
            )
        })?;
        let v = ctx.number(n)?;
        if v <= 0.0 {
            return Err(ctx.err(
                n,
                format!("<{tag}>: expected a positive size in metres, found {v}"),
            ));
        }
        Ok(v)
    };
    Ok(Some(match shape.tag_name().name() {
        "box" => {
            let size_node =
                child(shape, "size").ok_or_else(|| ctx.err(shape, "<box> has no <size>"))?;
            Geometry::Box {
                size: ctx.numbers::<3>(size_node)?,
            }
        }
        "cylinder" => Geometry::Cylinder {
            radius: number("radius")?,
            length: number("length")?,
        },
        "capsule" => Geometry::Capsule {
            radius: number("radius")?,
            length: number("length")?,
        },
        "sphere" => Geometry::Sphere {
            radius: number("radius")?,
        },
        "mesh" => {
            let uri = child(shape, "uri")
                .and_then(|u| u.text())
                .map(str::trim)
                .filter(|u| !u.is_empty())
                .ok_or_else(|| ctx.err(shape, "<mesh> has no <uri>"))?;
            Geometry::Mesh {
                filename: uri.to_owned(),
                scale: child(shape, "scale")
                    .map(|s| ctx.numbers::<3>(s))
                    .transpose()?,
            }
        }
        "plane" | "empty" => return Ok(None),
        other => {
            return Err(ctx.err(
                shape,
                format!(
                    "<geometry><{other}>: unsupported in a robot link; expected box, cylinder, capsule, sphere or mesh"
                ),
            ));
        }
    }))
}

/// A joint as URDF has it (its origin from the links' URDF frames); `None` for a joint to the
/// world, which rover's mobile robots do not have.
fn read_joint(
    ctx: &Ctx<'_, '_>,
    joint: Node<'_, '_>,
    frames: &Frames,
    friction: &mut BTreeMap<String, f32>,
) -> Result<Option<JointEl>> {
    let name = joint.attribute("name").unwrap_or("").to_owned();
    let kind = joint.attribute("type").unwrap_or("");
    let text_of = |tag: &str| -> Result<String> {
        child(joint, tag)
            .and_then(|n| n.text())
            .map(|t| t.trim().to_owned())
            .filter(|t| !t.is_empty())
            .ok_or_else(|| ctx.err(joint, format!("<joint name=\"{name}\"> has no <{tag}>")))
    };
    let parent = text_of("parent")?;
    let child_name = text_of("child")?;
    let mut joint_type = match kind {
        "revolute" => JointType::Revolute,
        "continuous" => JointType::Continuous,
        "prismatic" => JointType::Prismatic,
        "fixed" => JointType::Fixed,
        "ball" => {
            // A free caster ball: welded, and slipping freely on the ground.
            friction.insert(child_name.clone(), 0.0);
            JointType::Fixed
        }
        other => {
            return Err(ctx.err(
                joint,
                format!(
                    "<joint name=\"{name}\" type=\"{other}\">: unsupported joint type; expected revolute, continuous, prismatic, fixed or ball"
                ),
            ));
        }
    };
    if parent == "world" {
        tracing::info!(
            "{}:{}: <joint name=\"{name}\"> holds the model to the world; rover's robot is free (it rests where it is spawned)",
            ctx.path.display(),
            line_of(ctx.doc, joint)
        );
        return Ok(None);
    }
    let parent_from_child =
        frames.model_from_urdf(&parent).inverse() * frames.model_from_urdf(&child_name);
    let axis_el = child(joint, "axis");
    let mut axis = [1.0, 0.0, 0.0];
    let (mut limit, mut effort, mut velocity, mut damping, mut joint_friction) =
        (None, None, None, None, None);
    if let Some(a) = axis_el {
        if let Some(xyz) = child(a, "xyz") {
            let v = ctx.numbers::<3>(xyz)?;
            let in_model = xyz.attribute("expressed_in") == Some("__model__")
                || child(a, "use_parent_model_frame").is_some_and(|n| ctx.flag(n));
            axis = if in_model && moving(kind) {
                let r = frames.model_from_urdf(&child_name).rotation.inverse();
                let a = r * glam::Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
                [a.x, a.y, a.z].map(f64::from)
            } else {
                v
            };
        }
        if let Some(l) = child(a, "limit") {
            let get = |tag: &str| child(l, tag).map(|n| ctx.number(n)).transpose();
            let (lower, upper) = (get("lower")?, get("upper")?);
            effort = get("effort")?.filter(|e| *e >= 0.0);
            velocity = get("velocity")?.filter(|v| *v >= 0.0);
            if let (Some(lo), Some(hi)) = (lower, upper) {
                limit = Some((lo, hi));
            }
        }
        if let Some(d) = child(a, "dynamics") {
            damping = child(d, "damping").map(|n| ctx.number(n)).transpose()?;
            joint_friction = child(d, "friction").map(|n| ctx.number(n)).transpose()?;
        }
    }
    // gz-sim's unlimited revolute (no limits, or the 1e16 it writes for none) is continuous.
    if joint_type == JointType::Revolute
        && limit.is_none_or(|(lo, hi): (f64, f64)| lo <= -1e15 || hi >= 1e15)
    {
        joint_type = JointType::Continuous;
        limit = None;
    }
    if joint_type == JointType::Prismatic && limit.is_none() {
        return Err(ctx.err(
            joint,
            format!("<joint name=\"{name}\" type=\"prismatic\">: expected <axis><limit><lower> and <upper>"),
        ));
    }
    Ok(Some(JointEl {
        name,
        joint_type,
        parent,
        child: child_name,
        origin: origin(parent_from_child),
        axis,
        limit,
        effort,
        velocity,
        damping,
        friction: joint_friction,
        mimic: None,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn origins_round_trip_rpy() {
        let p = crate::geometry::pose_from_xyz_rpy([0.1, -0.2, 0.3], [-1.57, 0.2, 0.7]);
        let o = origin(p);
        let back = crate::geometry::pose_from_xyz_rpy(o.xyz, o.rpy);
        assert!((back.translation - p.translation).length() < 1e-6);
        assert!(back.rotation.dot(p.rotation).abs() > 1.0 - 1e-6);
    }

    #[test]
    fn a_joint_pose_may_be_relative_to_the_model_or_a_link() -> crate::error::Result<()> {
        let model = |pose: &str| {
            format!(
                "<sdf version=\"1.8\"><model name=\"m\">\
                 <link name=\"a\"/><link name=\"b\"><pose>0 0.1 0 0 0 0</pose></link>\
                 <joint name=\"j\" type=\"revolute\"><parent>a</parent><child>b</child>{pose}\
                 <axis><xyz>0 0 1</xyz></axis></joint></model></sdf>"
            )
        };
        let at = |pose: &str| -> crate::error::Result<glam::Vec3> {
            let robot = RobotModel::from_str(&model(pose), Path::new("m.sdf"))?;
            Ok(robot.joints[0].parent_from_child.translation)
        };
        let expected = glam::Vec3::new(0.2, 0.1, 0.0);
        for pose in [
            "<pose>0.2 0 0 0 0 0</pose>",
            "<pose relative_to=\"__model__\">0.2 0.1 0 0 0 0</pose>",
            "<pose relative_to=\"a\">0.2 0.1 0 0 0 0</pose>",
        ] {
            assert!((at(pose)? - expected).length() < 1e-6, "{pose}");
        }
        Ok(())
    }

    #[test]
    fn an_unknown_system_is_listed_once_by_file_and_name() -> crate::error::Result<()> {
        let text = "<sdf version=\"1.8\">\n<model name=\"m\">\n<link name=\"a\"/>\n\
            <plugin filename=\"gz-sim-buoyancy-system\" name=\"gz::sim::systems::Buoyancy\"/>\n\
            <plugin filename=\"gz-sim-buoyancy-system\" name=\"gz::sim::systems::Buoyancy\"/>\n\
            <plugin filename=\"gz-sim-sensors-system\" name=\"gz::sim::systems::Sensors\"/>\n\
            </model></sdf>";
        let robot = RobotModel::from_str(text, Path::new("robot.sdf"))?;
        assert_eq!(
            robot.not_simulated,
            ["system gz-sim-buoyancy-system (gz::sim::systems::Buoyancy)"]
        );
        Ok(())
    }

    #[test]
    fn errors_name_the_file_and_line() {
        let path = Path::new("robot.sdf");
        let cases = [
            (
                "<sdf version=\"1.8\"><world name=\"w\"/></sdf>",
                "expected a robot <model>",
                1,
            ),
            (
                "<sdf version=\"1.8\">\n<model name=\"m\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n<joint name=\"j\" type=\"screw\"><parent>a</parent><child>b</child></joint>\n</model></sdf>",
                "unsupported joint type",
                5,
            ),
            (
                "<sdf version=\"1.8\">\n<model name=\"m\">\n<link name=\"a\"><pose relative_to=\"nope\">0 0 0 0 0 0</pose></link>\n</model></sdf>",
                "no link of that name",
                3,
            ),
            (
                "<sdf version=\"1.8\">\n<model name=\"m\">\n<link name=\"a\"/>\n<plugin filename=\"gz-sim-diff-drive-system\" name=\"gz::sim::systems::DiffDrive\">\n<wheel_radius>0.1</wheel_radius></plugin>\n</model></sdf>",
                "expected at least one <left_joint> and one <right_joint>",
                4,
            ),
        ];
        for (text, expected, line) in cases {
            let err = match RobotModel::from_str(text, path) {
                Ok(_) => panic!("loaded {text}"),
                Err(e) => e.to_string(),
            };
            assert!(err.contains(expected), "{err}");
            assert!(err.contains(&format!("robot.sdf:{line}")), "{err}");
        }
    }
}
