//! Robot descriptions from URDF (or xacro, expanded first), with the `<gazebo>` extensions
//! rover honours.
//!
//! The standard URDF elements are read by `urdf.rs` with urdfdom's rules, the `<gazebo>`
//! elements by `gazebo.rs`, both from one `roxmltree` document, so that every error names the
//! file, the line and the element.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use glam::Vec3;

use crate::description::gazebo;
use crate::description::parts::{ElementLines, Parts};
use crate::description::resource::ResourcePaths;
use crate::description::urdf;
use crate::description::xacro::{self, Expanded};
use crate::description::xml::{line_of, parse_xml};
use crate::error::{Result, SimError, quoted_list as names};
use crate::geometry::{
    MAX_COORDINATE_M, MAX_INERTIA_KGM2, MAX_MAGNITUDE, MAX_MASS_KG, MAX_SIZE_M, Rgba, Shape,
    pose_from_xyz_rpy, vec3,
};
use crate::model::actuation::{HardwareInterface, Transmission};
use crate::model::robot::{
    Collision, Inertial, Joint, JointId, JointKind, Link, LinkId, Mimic, RobotModel, Visual,
};

/// How to read a robot description: xacro arguments and where ROS packages are.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoadOptions {
    /// `name:=value` arguments for `$(arg name)` in xacro files.
    pub xacro_args: BTreeMap<String, String>,
    /// Where `package://` and `$(find)` look.
    pub resources: ResourcePaths,
}

impl LoadOptions {
    /// No xacro arguments; packages from `ROS_PACKAGE_PATH`.
    pub fn from_env() -> Self {
        Self {
            xacro_args: BTreeMap::new(),
            resources: ResourcePaths::from_env(),
        }
    }
}

impl RobotModel {
    /// Loads and validates a URDF or xacro file, with packages from `ROS_PACKAGE_PATH`.
    pub fn load(path: &Path) -> Result<Self> {
        Self::load_with(path, &LoadOptions::from_env())
    }

    /// Loads and validates a URDF file, or expands a xacro file (a `.xacro` name, a file that
    /// declares the xacro namespace, or one with `$(...)` substitution args) and loads the
    /// result. Errors in an expanded file name
    /// the xacro file and line the element came from.
    pub fn load_with(path: &Path, options: &LoadOptions) -> Result<Self> {
        let text = crate::io::read_text(path)?;
        let is_xacro = path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.ends_with(".xacro"))
            || xacro::uses_xacro(&text)
            // Substitution args left in a plain URDF (pybullet's husky: `$(optenv ...)`) are
            // expanded as xacro would, rather than failing as numbers.
            || text.contains("$(");
        if is_xacro {
            let expanded = xacro::expand_file(path, &options.xacro_args, &options.resources)?;
            return Self::parse(&expanded.text, path, &options.resources)
                .map_err(|e| remap(e, &expanded));
        }
        Self::parse(&text, path, &options.resources)
    }

    /// Reads a ros_control controllers YAML for this robot (checked against its joints) and
    /// makes it the robot's controllers.
    pub fn load_controllers(&mut self, path: &Path) -> Result<()> {
        self.controllers = Some(super::controllers::load_controllers(path, self)?);
        Ok(())
    }

    /// Parses URDF text; `path` is used for messages and to resolve relative mesh files.
    pub fn from_str(text: &str, path: &Path) -> Result<Self> {
        Self::parse(text, path, &ResourcePaths::from_env())
    }

    fn parse(text: &str, path: &Path, resources: &ResourcePaths) -> Result<Self> {
        let doc = parse_xml(text, path)?;
        let root = doc.root_element();
        if root.has_tag_name("sdf") {
            return super::sdf_robot::load(&doc, text, path, resources);
        }
        if root.tag_name().name() != "robot" {
            return Err(SimError::invalid(
                path,
                Some(line_of(&doc, root)),
                format!(
                    "expected a <robot> root element (URDF) or <sdf> with a <model>, found <{}>",
                    root.tag_name().name()
                ),
            ));
        }
        validate_numbers(&doc, path)?;
        let lines = ElementLines::collect(&doc);
        let urdf = urdf::read(&doc, path)?;
        let extensions = gazebo::parse(&doc, path)?;
        Self::build(
            Parts {
                urdf,
                lines,
                extensions,
                root_line: Some(line_of(&doc, root)),
            },
            text,
            path,
            resources,
        )
    }

    /// The robot from its read parts (a URDF's, or an SDF model's as `sdf_robot.rs` reads
    /// them): links, joints and their checks, the Gazebo extensions applied.
    pub(crate) fn build(
        parts: Parts,
        text: &str,
        path: &Path,
        resources: &ResourcePaths,
    ) -> Result<Self> {
        let Parts {
            urdf,
            lines,
            mut extensions,
            root_line,
        } = parts;
        let base_dir = path.parent().unwrap_or(Path::new("."));
        let materials: HashMap<&str, Rgba> = urdf
            .materials
            .iter()
            .filter_map(|m| m.color.map(|c| (m.name.as_str(), rgba(c))))
            .collect();

        let (mut links, link_index) = read_links(
            &urdf.links,
            &materials,
            (base_dir, resources),
            path,
            &lines,
            || root_line,
        )?;
        let mut joints = read_joints(&urdf.joints, &link_index, links.len(), path, &lines)?;
        resolve_mimics(&urdf.joints, &mut joints, path, &lines)?;
        apply_mimic_plugins(&extensions.mimics, &mut joints, path)?;
        let transmissions = read_transmissions(&urdf, &joints, path)?;
        let root = find_root(&links, &joints, path, &lines)?;

        complete_defaults(
            &mut extensions,
            &urdf.name,
            &links[root.index()].name,
            &joints,
        );
        for (reference, kp) in &extensions.contact_kp {
            if let Some(&i) = link_index.get(reference) {
                links[i].contact_kp_n_per_m = Some(*kp);
            }
        }
        for (reference, friction) in &extensions.friction {
            match link_index.get(reference) {
                Some(&i) => links[i].friction = Some(*friction),
                None => tracing::warn!(
                    "{}: <gazebo reference=\"{reference}\">: no link of that name; ignored",
                    path.display()
                ),
            }
        }

        let gz_controllers = std::mem::take(&mut extensions.gz_controllers);
        let ros2_control = extensions.ros2_control.take();
        let mut model = Self {
            name: urdf.name.clone(),
            source: path.to_path_buf(),
            links,
            joints,
            root,
            diff_drive: extensions.diff_drive,
            cameras: extensions.cameras,
            lasers: extensions.lasers,
            lidars: extensions.lidars,
            imus: extensions.imus,
            p3ds: extensions.p3ds,
            gpss: extensions.gpss,
            bumpers: extensions.bumpers,
            description: text.to_owned(),
            not_simulated: extensions.ignored,
            joint_state_publisher: extensions.joint_state_publisher,
            transmissions,
            ros_control: extensions.ros_control,
            controllers: None,
        };
        if !model.not_simulated.is_empty() {
            tracing::info!(
                "{}: not simulated (rover has no model for them): {}",
                path.display(),
                model.not_simulated.join(", ")
            );
        }
        model.validate_plugins(path)?;
        if !gz_controllers.is_empty() {
            model.controllers = Some(gazebo::gz_joints::config(&model, gz_controllers, path)?);
        }
        if let Some((file, line)) = ros2_control {
            if model.controllers.is_some() {
                return Err(SimError::invalid(
                    path,
                    Some(line),
                    "gz_ros2_control and gz-sim's joint controller systems both drive this robot; expected one of them",
                ));
            }
            let yaml = resources.resolve(&file, base_dir).map_err(|e| {
                SimError::invalid(
                    path,
                    Some(line),
                    format!("gz_ros2_control <parameters>: {e}"),
                )
            })?;
            model.load_controllers(&yaml)?;
        }
        Ok(model)
    }
}

/// The defaults that need the whole robot: hector's GPS on the root link, gz-sim DiffDrive's
/// `<model>/<canonical link>` base frame and its wheels' effort limit.
fn complete_defaults(
    extensions: &mut gazebo::Extensions,
    model: &str,
    root_link: &str,
    joints: &[Joint],
) {
    for gps in extensions.gpss.iter_mut().filter(|g| g.link.is_empty()) {
        // hector's default: the model's first link, which for a URDF is its root.
        gps.link = root_link.to_owned();
    }
    if let Some(dd) = extensions
        .diff_drive
        .as_mut()
        .filter(|d| d.robot_base_frame.is_empty())
    {
        // gz-sim's DiffDrive: `<model>/<canonical link>`.
        dd.robot_base_frame = format!("{model}/{root_link}");
    }
    if let Some(dd) = extensions
        .diff_drive
        .as_mut()
        .filter(|d| d.plugin == crate::model::DrivePlugin::GzSim)
    {
        // gz-sim sets the wheels' speeds and the physics engine reaches them within the
        // joints' effort limit (rover's motor torque where they give none).
        let wheels = [&dd.left_joint, &dd.right_joint]
            .into_iter()
            .chain(&dd.extra_left_joints)
            .chain(&dd.extra_right_joints);
        let effort = wheels
            .filter_map(|w| joints.iter().find(|j| &j.name == w)?.effort_limit)
            .fold(f32::INFINITY, f32::min);
        if effort.is_finite() && effort > 0.0 {
            dd.wheel_torque_nm = f64::from(effort);
        }
    }
}

/// Converts the links (file order) and indexes them by name; duplicate names and a robot
/// without links are errors.
fn read_links(
    urdf_links: &[urdf::LinkEl],
    materials: &HashMap<&str, Rgba>,
    base_dir: (&Path, &ResourcePaths),
    path: &Path,
    lines: &ElementLines,
    robot_line: impl Fn() -> Option<u32>,
) -> Result<(Vec<Link>, BTreeMap<String, usize>)> {
    let mut link_index: BTreeMap<String, usize> = BTreeMap::new();
    let mut links = Vec::with_capacity(urdf_links.len());
    for link in urdf_links {
        if link_index.insert(link.name.clone(), links.len()).is_some() {
            return Err(SimError::invalid(
                path,
                lines.link(&link.name),
                format!("<link name=\"{}\"> is defined twice", link.name),
            ));
        }
        links.push(convert_link(link, materials, base_dir, path, lines)?);
    }
    if links.is_empty() {
        return Err(SimError::invalid(
            path,
            robot_line(),
            "<robot> has no <link>: expected at least one",
        ));
    }

    Ok((links, link_index))
}

/// Converts the joints (file order), checking their links exist and form a tree.
fn read_joints(
    urdf_joints: &[urdf::JointEl],
    link_index: &BTreeMap<String, usize>,
    link_count: usize,
    path: &Path,
    lines: &ElementLines,
) -> Result<Vec<Joint>> {
    let mut joints = Vec::with_capacity(urdf_joints.len());
    let mut parent_of: Vec<Option<usize>> = vec![None; link_count];
    let mut joint_names = BTreeMap::new();
    for joint in urdf_joints {
        let line = lines.joint(&joint.name);
        if joint_names.insert(joint.name.clone(), ()).is_some() {
            return Err(SimError::invalid(
                path,
                line,
                format!("<joint name=\"{}\"> is defined twice", joint.name),
            ));
        }
        let find = |role: &str, name: &str| {
            link_index.get(name).copied().ok_or_else(|| {
                SimError::invalid(
                    path,
                    line,
                    format!(
                        "<joint name=\"{}\"> <{role} link=\"{name}\">: no such link; links in this robot: {}",
                        joint.name,
                        names(link_index.keys())
                    ),
                )
            })
        };
        let parent = find("parent", &joint.parent)?;
        let child = find("child", &joint.child)?;
        if let Some(previous) = parent_of[child] {
            return Err(SimError::invalid(
                path,
                line,
                format!(
                    "<joint name=\"{}\">: link \"{}\" already has a parent joint \"{}\"; a URDF must be a tree",
                    joint.name, joint.child, urdf_joints[previous].name
                ),
            ));
        }
        parent_of[child] = Some(joints.len());
        joints.push(convert_joint(
            joint,
            LinkId(parent),
            LinkId(child),
            path,
            line,
        )?);
    }

    Ok(joints)
}

/// The one link that is no joint's child; every link must be reachable from it.
fn find_root(
    links: &[Link],
    joints: &[Joint],
    path: &Path,
    lines: &ElementLines,
) -> Result<LinkId> {
    let roots: Vec<usize> = (0..links.len())
        .filter(|&i| !joints.iter().any(|j| j.child.0 == i))
        .collect();
    let root = match roots.as_slice() {
        [single] => *single,
        [] => {
            return Err(SimError::invalid(
                path,
                None,
                "every link is some joint's child (a cycle): expected exactly one root link",
            ));
        }
        many => {
            return Err(SimError::invalid(
                path,
                None,
                format!(
                    "the links {} are not connected by joints: expected exactly one root link",
                    names(many.iter().map(|&i| &links[i].name))
                ),
            ));
        }
    };
    // A cycle that does not touch the root leaves some link unreachable from it.
    let mut reachable = vec![false; links.len()];
    reachable[root] = true;
    let mut changed = true;
    while changed {
        changed = false;
        for j in joints {
            if reachable[j.parent.0] && !reachable[j.child.0] {
                reachable[j.child.0] = true;
                changed = true;
            }
        }
    }
    if let Some(lost) = (0..links.len()).find(|&i| !reachable[i]) {
        return Err(SimError::invalid(
            path,
            lines.link(&links[lost].name),
            format!(
                "link \"{}\" is part of a joint cycle: a URDF must be a tree",
                links[lost].name
            ),
        ));
    }

    Ok(LinkId(root))
}

fn rgba(c: [f64; 4]) -> Rgba {
    Rgba(c.map(|v| v.clamp(0.0, 1.0) as f32))
}

/// Checks every numeric URDF attribute before the elements are read, so a typo is reported with its
/// line and element instead of a bare deserialisation message.
fn validate_numbers(doc: &roxmltree::Document<'_>, path: &Path) -> Result<()> {
    for node in doc.descendants().filter(|n| n.is_element()) {
        let element = node.tag_name().name();
        for attr in node.attributes() {
            let expected = match (element, attr.name()) {
                (_, "xyz" | "rpy") | ("box", "size") | ("mesh", "scale") => 3,
                ("color", "rgba") => 4,
                ("mass", "value")
                | ("cylinder" | "sphere" | "capsule", "radius")
                | ("cylinder" | "capsule", "length")
                | ("inertia", "ixx" | "ixy" | "ixz" | "iyy" | "iyz" | "izz")
                | ("limit", "lower" | "upper" | "effort" | "velocity")
                | ("dynamics", "damping" | "friction") => 1,
                _ => continue,
            };
            let fail = |what: String| {
                SimError::invalid(
                    path,
                    Some(line_of(doc, node)),
                    format!("<{element} {}=\"{}\">: {what}", attr.name(), attr.value()),
                )
            };
            let tokens: Vec<&str> = attr.value().split_whitespace().collect();
            let values: Vec<f64> = tokens
                .iter()
                .filter_map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
                .collect();
            if tokens.len() != expected || values.len() != tokens.len() {
                let unit = if expected == 1 { "number" } else { "numbers" };
                let found = match tokens
                    .iter()
                    .find(|t| t.parse::<f64>().map(|v| !v.is_finite()).unwrap_or(true))
                {
                    Some(token) => format!("'{token}' is not a finite number"),
                    None => format!("found {} value(s)", tokens.len()),
                };
                return Err(fail(format!("expected {expected} {unit}; {found}")));
            }
            if let Some((limit, what)) = magnitude_limit(element, attr.name())
                && let Some(i) = values.iter().position(|v| v.abs() > limit)
            {
                return Err(fail(format!(
                    "{} is out of range: expected {what} up to {limit:e}",
                    tokens[i]
                )));
            }
            if matches!(attr.name(), "radius" | "length" | "value" | "size")
                && let Some(i) = values.iter().position(|v| *v < 0.0)
            {
                return Err(fail(format!(
                    "expected non-negative values, found {}",
                    tokens[i]
                )));
            }
        }
    }
    Ok(())
}

/// The accepted magnitude of a numeric URDF attribute, where rover bounds it: positions,
/// sizes, masses and inertias far outside physical sense would reach the physics engine (f32)
/// and parry's contact code, which can fail on them.
fn magnitude_limit(element: &str, attribute: &str) -> Option<(f64, &'static str)> {
    match (element, attribute) {
        (_, "xyz") => Some((MAX_COORDINATE_M, "positions (m)")),
        ("box", "size") | (_, "radius" | "length") => Some((MAX_SIZE_M, "sizes (m)")),
        ("mass", "value") => Some((MAX_MASS_KG, "a mass (kg)")),
        ("inertia", _) => Some((MAX_INERTIA_KGM2, "inertia components (kg m^2)")),
        ("mesh", "scale") => Some((MAX_MAGNITUDE, "scale factors")),
        _ => None,
    }
}

/// Points an error in expanded text back at the xacro file and line it came from.
fn remap(e: SimError, expanded: &Expanded) -> SimError {
    match e {
        SimError::Invalid { location, message } => {
            let location = location
                .line
                .and_then(|line| expanded.source_of(line))
                .unwrap_or(location);
            SimError::Invalid { location, message }
        }
        other => other,
    }
}

fn convert_link(
    link: &urdf::LinkEl,
    materials: &HashMap<&str, Rgba>,
    base_dir: (&Path, &ResourcePaths),
    path: &Path,
    lines: &ElementLines,
) -> Result<Link> {
    let line = lines.link(&link.name);
    let geometry = |g: &urdf::Geometry| convert_geometry(g, base_dir, path, line, &link.name);
    let inertial = link
        .inertial
        .as_ref()
        .filter(|i| i.mass > 0.0)
        .map(|i| Inertial {
            mass_kg: i.mass as f32,
            link_from_inertial: pose_from_xyz_rpy(i.origin.xyz, i.origin.rpy),
            inertia: i.inertia.map(|v| v as f32),
        });
    let mut visuals = Vec::with_capacity(link.visual.len());
    for v in &link.visual {
        let color = v.material.as_ref().and_then(|m| {
            m.color
                .map(rgba)
                .or_else(|| materials.get(m.name.as_str()).copied())
        });
        visuals.push(Visual {
            link_from_shape: pose_from_xyz_rpy(v.origin.xyz, v.origin.rpy),
            shape: geometry(&v.geometry)?,
            color: color.unwrap_or(Rgba::rgb(0.7, 0.7, 0.7)),
            color_given: color.is_some(),
            texture: None,
        });
    }
    let mut collisions = Vec::with_capacity(link.collision.len());
    for c in &link.collision {
        collisions.push(Collision {
            link_from_shape: pose_from_xyz_rpy(c.origin.xyz, c.origin.rpy),
            shape: geometry(&c.geometry)?,
        });
    }
    Ok(Link {
        name: link.name.clone(),
        inertial,
        visuals,
        collisions,
        friction: None,
        contact_kp_n_per_m: None,
    })
}

fn convert_geometry(
    g: &urdf::Geometry,
    (base_dir, resources): (&Path, &ResourcePaths),
    path: &Path,
    line: Option<u32>,
    link: &str,
) -> Result<Shape> {
    Ok(match g {
        urdf::Geometry::Box { size } => Shape::Box {
            size_m: vec3(*size),
        },
        urdf::Geometry::Cylinder { radius, length } => Shape::Cylinder {
            radius_m: *radius as f32,
            length_m: *length as f32,
        },
        urdf::Geometry::Capsule { radius, length } => Shape::Capsule {
            radius_m: *radius as f32,
            length_m: *length as f32,
        },
        urdf::Geometry::Sphere { radius } => Shape::Sphere {
            radius_m: *radius as f32,
        },
        urdf::Geometry::Mesh { filename, scale } => {
            let resolved = resources.resolve(filename, base_dir).map_err(|e| {
                SimError::invalid(path, line, format!("<link name=\"{link}\"> <mesh>: {e}"))
            })?;
            let ext = resolved
                .extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase);
            if !matches!(ext.as_deref(), Some("stl" | "obj" | "dae")) {
                return Err(SimError::invalid(
                    path,
                    line,
                    format!(
                        "<link name=\"{link}\"> <mesh filename=\"{filename}\">: unsupported mesh format; expected .stl, .obj or .dae (COLLADA)"
                    ),
                ));
            }
            Shape::Mesh {
                path: resolved,
                scale: scale.map(vec3).unwrap_or(Vec3::ONE),
            }
        }
    })
}

fn convert_joint(
    joint: &urdf::JointEl,
    parent: LinkId,
    child: LinkId,
    path: &Path,
    line: Option<u32>,
) -> Result<Joint> {
    let (lower, upper) = joint.limit.unwrap_or((0.0, 0.0));
    let limits_ok = || {
        if lower > upper {
            Err(SimError::invalid(
                path,
                line,
                format!(
                    "<joint name=\"{}\"> <limit lower=\"{}\" upper=\"{}\">: expected lower <= upper",
                    joint.name, lower, upper
                ),
            ))
        } else {
            Ok(())
        }
    };
    let kind = match joint.joint_type {
        urdf::JointType::Fixed => JointKind::Fixed,
        urdf::JointType::Continuous => JointKind::Continuous,
        urdf::JointType::Revolute => {
            limits_ok()?;
            JointKind::Revolute {
                lower_rad: lower as f32,
                upper_rad: upper as f32,
            }
        }
        urdf::JointType::Prismatic => {
            limits_ok()?;
            JointKind::Prismatic {
                lower_m: lower as f32,
                upper_m: upper as f32,
            }
        }
        urdf::JointType::Floating => JointKind::Floating,
        urdf::JointType::Planar | urdf::JointType::Spherical => {
            return Err(SimError::invalid(
                path,
                line,
                format!(
                    "<joint name=\"{}\" type=\"{:?}\">: unsupported joint type; expected fixed, continuous, revolute, prismatic or floating",
                    joint.name, joint.joint_type
                ),
            ));
        }
    };
    let axis = vec3(joint.axis);
    let needs_axis = !matches!(kind, JointKind::Fixed | JointKind::Floating);
    if needs_axis && axis.length() < 1e-6 {
        return Err(SimError::invalid(
            path,
            line,
            format!(
                "<joint name=\"{}\"> <axis xyz=\"0 0 0\">: expected a non-zero axis",
                joint.name
            ),
        ));
    }
    Ok(Joint {
        name: joint.name.clone(),
        kind,
        parent,
        child,
        parent_from_child: pose_from_xyz_rpy(joint.origin.xyz, joint.origin.rpy),
        axis: axis.normalize_or(Vec3::X),
        damping: joint.damping.map_or(0.0, |d| d as f32),
        friction: joint.friction.map_or(0.0, |f| f as f32),
        effort_limit: joint.effort.map(|e| e.abs() as f32),
        velocity_limit: joint.velocity.map(|v| v.abs() as f32),
        // Resolved once every joint is known (`resolve_mimics`).
        mimic: None,
    })
}

/// Fills in `<mimic joint>` now that every joint has an id.
fn resolve_mimics(
    urdf_joints: &[urdf::JointEl],
    joints: &mut [Joint],
    path: &Path,
    lines: &ElementLines,
) -> Result<()> {
    for (el, joint) in urdf_joints.iter().zip(joints.iter_mut()) {
        let Some((name, multiplier, offset)) = &el.mimic else {
            continue;
        };
        let Some(index) = urdf_joints.iter().position(|j| &j.name == name) else {
            return Err(SimError::invalid(
                path,
                lines.joint(&el.name),
                format!(
                    "<joint name=\"{}\"> <mimic joint=\"{name}\">: no such joint; joints in this robot: {}",
                    el.name,
                    names(urdf_joints.iter().map(|j| &j.name))
                ),
            ));
        };
        if &el.name == name {
            return Err(SimError::invalid(
                path,
                lines.joint(&el.name),
                format!("<joint name=\"{name}\"> <mimic>: a joint cannot mimic itself"),
            ));
        }
        joint.mimic = Some(Mimic {
            joint: JointId(index),
            multiplier: *multiplier as f32,
            offset: *offset as f32,
        });
    }
    Ok(())
}

/// Mimic joint plugins (`<gazebo>`): each follower gets the `<mimic>` the plugin stands for.
/// A joint the robot lacks, a fixed joint, a joint following itself or one already mimicking
/// is refused at the plugin's line.
fn apply_mimic_plugins(
    plugins: &[gazebo::MimicPlugin],
    joints: &mut [Joint],
    path: &Path,
) -> Result<()> {
    for plugin in plugins {
        let err = |message: String| {
            SimError::invalid(
                path,
                Some(plugin.line),
                format!("the mimic joint plugin: {message}"),
            )
        };
        let find = |name: &str| -> Result<usize> {
            joints.iter().position(|j| j.name == name).ok_or_else(|| {
                err(format!(
                    "no joint \"{name}\"; joints in this robot: {}",
                    names(joints.iter().map(|j| &j.name))
                ))
            })
        };
        let (leader, follower) = (find(&plugin.joint)?, find(&plugin.mimic_joint)?);
        if leader == follower {
            return Err(err(format!(
                "<mimicJoint> {}: a joint cannot follow itself",
                plugin.mimic_joint
            )));
        }
        for index in [leader, follower] {
            if !joints[index].is_moving() {
                return Err(err(format!(
                    "joint \"{}\" is fixed: expected a revolute or prismatic joint",
                    joints[index].name
                )));
            }
        }
        if joints[follower].mimic.is_some() {
            return Err(err(format!(
                "joint \"{}\" already mimics another joint",
                plugin.mimic_joint
            )));
        }
        joints[follower].mimic = Some(Mimic {
            joint: JointId(leader),
            multiplier: plugin.multiplier as f32,
            offset: plugin.offset as f32,
        });
    }
    Ok(())
}

/// The `<transmission>`s, checked against the joints: each names a moving joint and a
/// position, velocity or effort interface.
fn read_transmissions(
    urdf: &urdf::RobotEl,
    joints: &[Joint],
    path: &Path,
) -> Result<Vec<Transmission>> {
    let mut out = Vec::new();
    for t in &urdf.transmissions {
        let line = Some(t.line);
        for (joint_name, interfaces, reduction) in &t.joints {
            let what = format!(
                "<transmission name=\"{}\"> <joint name=\"{joint_name}\">",
                t.name
            );
            let Some(joint) = joints.iter().find(|j| &j.name == joint_name) else {
                return Err(SimError::invalid(
                    path,
                    line,
                    format!(
                        "{what}: no such joint; joints in this robot: {}",
                        names(joints.iter().map(|j| &j.name))
                    ),
                ));
            };
            if !joint.is_moving() {
                return Err(SimError::invalid(
                    path,
                    line,
                    format!(
                        "{what}: the joint is fixed or floating; a transmission drives a revolute, continuous or prismatic joint"
                    ),
                ));
            }
            let state_only = !interfaces.is_empty()
                && interfaces
                    .iter()
                    .all(|i| i.ends_with("JointStateInterface"));
            if state_only {
                // Reported, not driven: ros_control reads such joints and commands nothing.
                continue;
            }
            let Some(interface) = interfaces.iter().find_map(|i| HardwareInterface::parse(i))
            else {
                return Err(SimError::invalid(
                    path,
                    line,
                    format!(
                        "{what}: <hardwareInterface> {}; expected hardware_interface/PositionJointInterface, VelocityJointInterface or EffortJointInterface",
                        if interfaces.is_empty() {
                            "missing".to_owned()
                        } else {
                            format!("is {}", interfaces.join(", "))
                        }
                    ),
                ));
            };
            if !(reduction.is_finite() && *reduction != 0.0) {
                return Err(SimError::invalid(
                    path,
                    line,
                    format!(
                        "{what}: <mechanicalReduction> is {reduction}; expected a non-zero number"
                    ),
                ));
            }
            out.push(Transmission {
                name: t.name.clone(),
                joint: joint_name.clone(),
                interface,
                reduction: *reduction,
                line,
            });
        }
    }
    Ok(out)
}
