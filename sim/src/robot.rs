//! Robot descriptions loaded from URDF, with the `<gazebo>` extensions rover honours.
//!
//! The standard URDF elements are read by `urdf.rs` with urdfdom's rules, the `<gazebo>`
//! elements by `gazebo.rs`, both from one `roxmltree` document, so that every error names the
//! file, the line and the element.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::error::{Result, SimError};
use crate::gazebo::{self, CameraConfig, DiffDriveConfig, LaserConfig};
use crate::geometry::{Pose, Rgba, Shape, pose_from_xyz_rpy, vec3};
use crate::resource::ResourcePaths;
use crate::xacro::{self, Expanded};

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

/// Mass properties of a link, from its `<inertial>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Inertial {
    /// Mass (kg).
    pub mass_kg: f32,
    /// Pose of the centre of mass and inertia frame in the link frame.
    pub link_from_inertial: Pose,
    /// Inertia tensor about the centre of mass, in the inertial frame: ixx, ixy, ixz, iyy, iyz, izz (kg m^2).
    pub inertia: [f32; 6],
}

/// Something drawn for a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Visual {
    /// Pose of the shape in the link frame.
    pub link_from_shape: Pose,
    /// The shape.
    pub shape: Shape,
    /// Colour from the URDF material (grey when none is given).
    pub color: Rgba,
    /// Whether the description gave the colour; when not, a mesh file's own material colour
    /// is shown (see [`Visual::display_color`]).
    pub color_given: bool,
}

impl Visual {
    /// The colour to draw `mesh` (this visual's triangles) in: the description's colour, else
    /// the mesh file's material, else grey.
    pub fn display_color(&self, mesh: &crate::render::meshes::MeshData) -> Rgba {
        match (self.color_given, mesh.color) {
            (false, Some(c)) => c,
            _ => self.color,
        }
    }
}

/// A collision shape of a link.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// Pose of the shape in the link frame.
    pub link_from_shape: Pose,
    /// The shape.
    pub shape: Shape,
}

/// A URDF link.
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// Link name.
    pub name: String,
    /// Mass properties; `None` when the URDF gives no `<inertial>`.
    pub inertial: Option<Inertial>,
    /// Visual shapes.
    pub visuals: Vec<Visual>,
    /// Collision shapes.
    pub collisions: Vec<Collision>,
    /// Friction coefficient from `<gazebo reference="link"><mu1>`/`<mu2>` (the smaller one).
    pub friction: Option<f32>,
}

/// Kind of a URDF joint that rover simulates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointKind {
    /// Rigidly welded.
    Fixed,
    /// Rotation about the axis without limits.
    Continuous,
    /// Rotation about the axis between limits (rad).
    Revolute {
        /// Lower limit (rad).
        lower_rad: f32,
        /// Upper limit (rad).
        upper_rad: f32,
    },
    /// Translation along the axis between limits (m).
    Prismatic {
        /// Lower limit (m).
        lower_m: f32,
        /// Upper limit (m).
        upper_m: f32,
    },
    /// No constraint: the child moves freely.
    Floating,
}

/// A URDF joint, with links referred to by index into [`RobotModel::links`].
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// Kind and limits.
    pub kind: JointKind,
    /// Parent link index.
    pub parent: usize,
    /// Child link index.
    pub child: usize,
    /// Joint origin: the child link frame expressed in the parent link frame at zero position.
    pub parent_from_child: Pose,
    /// Unit axis in the joint (= child link) frame.
    pub axis: Vec3,
    /// Viscous damping from `<dynamics damping>` (N m s/rad).
    pub damping: f32,
}

/// A robot loaded from URDF.
#[derive(Debug, Clone)]
pub struct RobotModel {
    /// `<robot name>`.
    pub name: String,
    /// The file it came from.
    pub source: PathBuf,
    /// Links in file order.
    pub links: Vec<Link>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// Index of the root link (the one that is no joint's child).
    pub root: usize,
    /// The `libgazebo_ros_diff_drive.so` plugin, if present.
    pub diff_drive: Option<DiffDriveConfig>,
    /// Camera sensors (`<sensor type="camera">`).
    pub cameras: Vec<CameraConfig>,
    /// 2D laser scanners (`<sensor type="ray">`).
    pub lasers: Vec<LaserConfig>,
    /// Gazebo sensors and plugins in the file that rover does not simulate (IMU, GPS, ...).
    pub not_simulated: Vec<String>,
    /// The URDF text the model was read from (xacro already expanded): what ROS tools expect in
    /// `/robot_description`.
    pub description: String,
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
        let text = crate::error::read_text(path)?;
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

    /// Parses URDF text; `path` is used for messages and to resolve relative mesh files.
    pub fn from_str(text: &str, path: &Path) -> Result<Self> {
        Self::parse(text, path, &ResourcePaths::from_env())
    }

    fn parse(text: &str, path: &Path, resources: &ResourcePaths) -> Result<Self> {
        let doc = crate::error::parse_xml(text, path)?;
        let root = doc.root_element();
        if root.tag_name().name() != "robot" {
            return Err(SimError::invalid(
                path,
                Some(line_of(&doc, root)),
                format!(
                    "expected a <robot> root element, found <{}>",
                    root.tag_name().name()
                ),
            ));
        }
        validate_numbers(&doc, path)?;
        let lines = ElementLines::collect(&doc);

        let urdf = crate::urdf::read(&doc, path)?;

        let base_dir = path.parent().unwrap_or(Path::new("."));
        let materials: HashMap<&str, Rgba> = urdf
            .materials
            .iter()
            .filter_map(|m| m.color.map(|c| (m.name.as_str(), rgba(c))))
            .collect();

        let mut link_index: BTreeMap<String, usize> = BTreeMap::new();
        let mut links = Vec::with_capacity(urdf.links.len());
        for link in &urdf.links {
            if link_index.insert(link.name.clone(), links.len()).is_some() {
                return Err(SimError::invalid(
                    path,
                    lines.link(&link.name),
                    format!("<link name=\"{}\"> is defined twice", link.name),
                ));
            }
            links.push(convert_link(
                link,
                &materials,
                (base_dir, resources),
                path,
                &lines,
            )?);
        }
        if links.is_empty() {
            return Err(SimError::invalid(
                path,
                Some(line_of(&doc, root)),
                "<robot> has no <link>: expected at least one",
            ));
        }

        let mut joints = Vec::with_capacity(urdf.joints.len());
        let mut parent_of: Vec<Option<usize>> = vec![None; links.len()];
        let mut joint_names = BTreeMap::new();
        for joint in &urdf.joints {
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
                        joint.name, joint.child, urdf.joints[previous].name
                    ),
                ));
            }
            parent_of[child] = Some(joints.len());
            joints.push(convert_joint(joint, parent, child, path, line)?);
        }

        let roots: Vec<usize> = (0..links.len())
            .filter(|&i| parent_of[i].is_none())
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
            for j in &joints {
                if reachable[j.parent] && !reachable[j.child] {
                    reachable[j.child] = true;
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

        let extensions = gazebo::parse(&doc, path)?;
        for (reference, friction) in &extensions.friction {
            match link_index.get(reference) {
                Some(&i) => links[i].friction = Some(*friction),
                None => tracing::warn!(
                    "{}: <gazebo reference=\"{reference}\">: no link of that name; ignored",
                    path.display()
                ),
            }
        }

        let model = Self {
            name: urdf.name.clone(),
            source: path.to_path_buf(),
            links,
            joints,
            root,
            diff_drive: extensions.diff_drive,
            cameras: extensions.cameras,
            lasers: extensions.lasers,
            description: text.to_owned(),
            not_simulated: extensions.ignored,
        };
        if !model.not_simulated.is_empty() {
            tracing::info!(
                "{}: not simulated (rover has no model for them): {}",
                path.display(),
                model.not_simulated.join(", ")
            );
        }
        model.validate_plugins(path)?;
        Ok(model)
    }

    /// Drives the robot's wheels `spec` names like gazebo_ros_diff_drive (replacing a drive
    /// plugin from the URDF). Separation and diameter default to what the URDF says: the
    /// distance between the two joints and the left wheel's collision cylinder or sphere.
    pub fn set_drive(&mut self, spec: &crate::world::DriveSpec) -> Result<()> {
        let setup =
            |m: String| SimError::Setup(format!("[robot.drive] for \"{}\": {m}", self.name));
        let joint = |name: &str| {
            self.joint_index(name).ok_or_else(|| {
                setup(format!(
                    "no joint \"{name}\"; joints in this robot: {}",
                    names(self.joints.iter().map(|j| &j.name))
                ))
            })
        };
        let (left, right) = (joint(&spec.left_joint)?, joint(&spec.right_joint)?);
        let poses = self.root_from_links();
        let separation = match spec.wheel_separation_m {
            Some(s) => s,
            None => f64::from(
                poses[self.joints[left].child]
                    .translation
                    .distance(poses[self.joints[right].child].translation),
            ),
        };
        let diameter = match spec.wheel_diameter_m {
            Some(d) => d,
            None => {
                let wheel = &self.links[self.joints[left].child];
                let radius = wheel.collisions.iter().find_map(|c| match c.shape {
                    Shape::Cylinder { radius_m, .. } | Shape::Sphere { radius_m } => {
                        Some(f64::from(radius_m))
                    }
                    _ => None,
                });
                2.0 * radius.ok_or_else(|| {
                    setup(format!(
                        "cannot tell the diameter of wheel link \"{}\" (no cylinder or sphere collision); give wheel_diameter_m",
                        wheel.name
                    ))
                })?
            }
        };
        for (what, v) in [
            ("wheel_separation_m", separation),
            ("wheel_diameter_m", diameter),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(setup(format!(
                    "{what} is {v}; expected a positive number of metres"
                )));
            }
        }
        let mut config = DiffDriveConfig {
            name: "rover_drive".to_owned(),
            left_joint: spec.left_joint.clone(),
            right_joint: spec.right_joint.clone(),
            wheel_separation_m: separation,
            wheel_diameter_m: diameter,
            ..DiffDriveConfig::default()
        };
        if let Some(t) = spec.wheel_torque_nm {
            config.wheel_torque_nm = t;
        }
        tracing::info!(
            "{}: driving joints \"{}\" and \"{}\" (wheel separation {separation:.3} m, diameter {diameter:.3} m)",
            self.name,
            spec.left_joint,
            spec.right_joint
        );
        self.diff_drive = Some(config);
        self.validate_plugins(&self.source.clone())
    }

    /// Makes the camera sensor called `name` (its `<sensor name>` or plugin `cameraName`) the
    /// one rover renders (the first); the others stay listed after it.
    pub fn select_camera(&mut self, name: &str) -> Result<()> {
        let Some(i) = self
            .cameras
            .iter()
            .position(|c| c.name == name || c.camera_name == name)
        else {
            return Err(SimError::Setup(format!(
                "robot \"{}\" has no camera \"{name}\"; its cameras: {}",
                self.name,
                names(self.cameras.iter().map(|c| &c.name))
            )));
        };
        let chosen = self.cameras.remove(i);
        self.cameras.insert(0, chosen);
        Ok(())
    }

    /// Index of the link called `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    /// Index of the joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Pose of every link in the root link's frame with all joints at zero.
    pub fn root_from_links(&self) -> Vec<Pose> {
        let mut poses = vec![None; self.links.len()];
        poses[self.root] = Some(Pose::IDENTITY);
        let mut pending = true;
        while pending {
            pending = false;
            for j in &self.joints {
                if let (Some(parent), None) = (poses[j.parent], poses[j.child]) {
                    poses[j.child] = Some(parent * j.parent_from_child);
                    pending = true;
                }
            }
        }
        poses.into_iter().map(|p| p.unwrap_or_default()).collect()
    }

    fn validate_plugins(&self, path: &Path) -> Result<()> {
        if let Some(dd) = &self.diff_drive {
            let extras = dd
                .extra_left_joints
                .iter()
                .map(|j| ("leftRearJoint", j))
                .chain(dd.extra_right_joints.iter().map(|j| ("rightRearJoint", j)));
            for (role, name) in [
                ("leftJoint", &dd.left_joint),
                ("rightJoint", &dd.right_joint),
            ]
            .into_iter()
            .chain(extras)
            {
                let Some(index) = self.joint_index(name) else {
                    return Err(SimError::invalid(
                        path,
                        dd.line,
                        format!(
                            "<plugin filename=\"libgazebo_ros_diff_drive.so\"> <{role}>{name}</{role}>: no such joint; joints in this robot: {}",
                            names(self.joints.iter().map(|j| &j.name))
                        ),
                    ));
                };
                let joint = &self.joints[index];
                if !matches!(
                    joint.kind,
                    JointKind::Continuous | JointKind::Revolute { .. }
                ) {
                    return Err(SimError::invalid(
                        path,
                        dd.line,
                        format!(
                            "<plugin filename=\"libgazebo_ros_diff_drive.so\"> <{role}>{name}</{role}>: the joint is {}, expected a continuous or revolute wheel joint",
                            kind_name(&joint.kind)
                        ),
                    ));
                }
            }
            if dd.left_joint == dd.right_joint {
                return Err(SimError::invalid(
                    path,
                    dd.line,
                    format!(
                        "<plugin filename=\"libgazebo_ros_diff_drive.so\">: leftJoint and rightJoint are both \"{}\"; expected two different wheel joints",
                        dd.left_joint
                    ),
                ));
            }
        }
        for laser in &self.lasers {
            if self.link_index(&laser.link).is_none() {
                return Err(SimError::invalid(
                    path,
                    laser.line,
                    format!(
                        "<gazebo reference=\"{}\"> <sensor type=\"ray\">: no such link; links in this robot: {}",
                        laser.link,
                        names(self.links.iter().map(|l| &l.name))
                    ),
                ));
            }
        }
        for camera in &self.cameras {
            if self.link_index(&camera.link).is_none() {
                return Err(SimError::invalid(
                    path,
                    camera.line,
                    format!(
                        "<gazebo reference=\"{}\"> <sensor type=\"camera\">: no such link; links in this robot: {}",
                        camera.link,
                        names(self.links.iter().map(|l| &l.name))
                    ),
                ));
            }
        }
        Ok(())
    }
}

fn kind_name(kind: &JointKind) -> &'static str {
    match kind {
        JointKind::Fixed => "fixed",
        JointKind::Continuous => "continuous",
        JointKind::Revolute { .. } => "revolute",
        JointKind::Prismatic { .. } => "prismatic",
        JointKind::Floating => "floating",
    }
}

/// `"a", "b", "c"` for messages.
fn names<'a>(items: impl Iterator<Item = &'a String>) -> String {
    let list: Vec<String> = items.map(|n| format!("\"{n}\"")).collect();
    if list.is_empty() {
        "(none)".to_owned()
    } else {
        list.join(", ")
    }
}

fn rgba(c: [f64; 4]) -> Rgba {
    Rgba(c.map(|v| v.clamp(0.0, 1.0) as f32))
}

/// 1-based line of an element.
pub(crate) fn line_of(doc: &roxmltree::Document<'_>, node: roxmltree::Node<'_, '_>) -> u32 {
    doc.text_pos_at(node.range().start).row
}

/// Lines of `<link>` and `<joint>` elements by name, for messages about them.
struct ElementLines {
    links: HashMap<String, u32>,
    joints: HashMap<String, u32>,
}

impl ElementLines {
    fn collect(doc: &roxmltree::Document<'_>) -> Self {
        let mut links = HashMap::new();
        let mut joints = HashMap::new();
        for node in doc.root_element().children().filter(|n| n.is_element()) {
            let Some(name) = node.attribute("name") else {
                continue;
            };
            match node.tag_name().name() {
                "link" => {
                    links.entry(name.to_owned()).or_insert(line_of(doc, node));
                }
                "joint" => {
                    joints.entry(name.to_owned()).or_insert(line_of(doc, node));
                }
                _ => {}
            }
        }
        Self { links, joints }
    }

    fn link(&self, name: &str) -> Option<u32> {
        self.links.get(name).copied()
    }

    fn joint(&self, name: &str) -> Option<u32> {
        self.joints.get(name).copied()
    }
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
            let tokens: Vec<&str> = attr.value().split_whitespace().collect();
            let bad = tokens
                .iter()
                .find(|t| t.parse::<f64>().map(|v| !v.is_finite()).unwrap_or(true));
            let unit = if expected == 1 { "number" } else { "numbers" };
            if tokens.len() != expected || bad.is_some() {
                let found = match bad {
                    Some(token) => format!("'{token}' is not a finite number"),
                    None => format!("found {} value(s)", tokens.len()),
                };
                return Err(SimError::invalid(
                    path,
                    Some(line_of(doc, node)),
                    format!(
                        "<{element} {}=\"{}\">: expected {expected} {unit}; {found}",
                        attr.name(),
                        attr.value()
                    ),
                ));
            }
            if matches!(attr.name(), "radius" | "length" | "value" | "size")
                && let Some(neg) = tokens
                    .iter()
                    .find(|t| t.parse::<f64>().is_ok_and(|v| v < 0.0))
            {
                return Err(SimError::invalid(
                    path,
                    Some(line_of(doc, node)),
                    format!(
                        "<{element} {}=\"{}\">: expected non-negative values, found {neg}",
                        attr.name(),
                        attr.value()
                    ),
                ));
            }
        }
    }
    Ok(())
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
    link: &crate::urdf::LinkEl,
    materials: &HashMap<&str, Rgba>,
    base_dir: (&Path, &ResourcePaths),
    path: &Path,
    lines: &ElementLines,
) -> Result<Link> {
    let line = lines.link(&link.name);
    let geometry =
        |g: &crate::urdf::Geometry| convert_geometry(g, base_dir, path, line, &link.name);
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
    })
}

fn convert_geometry(
    g: &crate::urdf::Geometry,
    (base_dir, resources): (&Path, &ResourcePaths),
    path: &Path,
    line: Option<u32>,
    link: &str,
) -> Result<Shape> {
    Ok(match g {
        crate::urdf::Geometry::Box { size } => Shape::Box {
            size_m: vec3(*size),
        },
        crate::urdf::Geometry::Cylinder { radius, length } => Shape::Cylinder {
            radius_m: *radius as f32,
            length_m: *length as f32,
        },
        crate::urdf::Geometry::Capsule { radius, length } => Shape::Capsule {
            radius_m: *radius as f32,
            length_m: *length as f32,
        },
        crate::urdf::Geometry::Sphere { radius } => Shape::Sphere {
            radius_m: *radius as f32,
        },
        crate::urdf::Geometry::Mesh { filename, scale } => {
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
    joint: &crate::urdf::JointEl,
    parent: usize,
    child: usize,
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
        crate::urdf::JointType::Fixed => JointKind::Fixed,
        crate::urdf::JointType::Continuous => JointKind::Continuous,
        crate::urdf::JointType::Revolute => {
            limits_ok()?;
            JointKind::Revolute {
                lower_rad: lower as f32,
                upper_rad: upper as f32,
            }
        }
        crate::urdf::JointType::Prismatic => {
            limits_ok()?;
            JointKind::Prismatic {
                lower_m: lower as f32,
                upper_m: upper as f32,
            }
        }
        crate::urdf::JointType::Floating => JointKind::Floating,
        crate::urdf::JointType::Planar | crate::urdf::JointType::Spherical => {
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
    })
}
