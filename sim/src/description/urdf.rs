//! The URDF elements rover reads, taken from a roxmltree document with urdfdom's rules: what
//! ROS's own parser accepts is accepted (unknown elements anywhere are ignored, so racecar's
//! `<material>` inside `<geometry>` loads), what it refuses is refused, with the line.
//!
//! Replaces urdf-rs, whose strict serde mapping rejects files ROS loads and reports errors
//! without lines. Numeric attributes are checked beforehand (`robot::validate_numbers`).

use std::path::Path;

use roxmltree::Node;

use crate::description::xml::{child, children, line_of};
use crate::error::{Result, SimError};

/// `<origin xyz rpy>` (zeros when absent).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Origin {
    pub xyz: [f64; 3],
    pub rpy: [f64; 3],
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct InertialEl {
    pub origin: Origin,
    pub mass: f64,
    /// ixx, ixy, ixz, iyy, iyz, izz.
    pub inertia: [f64; 6],
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Geometry {
    Box {
        size: [f64; 3],
    },
    Cylinder {
        radius: f64,
        length: f64,
    },
    Capsule {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    Mesh {
        filename: String,
        scale: Option<[f64; 3]>,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MaterialEl {
    pub name: String,
    pub color: Option<[f64; 4]>,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct VisualEl {
    pub origin: Origin,
    pub geometry: Geometry,
    pub material: Option<MaterialEl>,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CollisionEl {
    pub origin: Origin,
    pub geometry: Geometry,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LinkEl {
    pub name: String,
    pub inertial: Option<InertialEl>,
    pub visual: Vec<VisualEl>,
    pub collision: Vec<CollisionEl>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum JointType {
    Fixed,
    Continuous,
    Revolute,
    Prismatic,
    Floating,
    Planar,
    Spherical,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct JointEl {
    pub name: String,
    pub joint_type: JointType,
    pub parent: String,
    pub child: String,
    pub origin: Origin,
    pub axis: [f64; 3],
    /// `<limit lower upper>`; urdfdom requires it for revolute and prismatic joints.
    pub limit: Option<(f64, f64)>,
    /// `<limit effort velocity>`.
    pub effort: Option<f64>,
    pub velocity: Option<f64>,
    pub damping: Option<f64>,
    pub friction: Option<f64>,
    /// `<mimic joint multiplier offset>`.
    pub mimic: Option<(String, f64, f64)>,
}

/// A `<transmission>`: its joints, each with the first command interface it lists.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TransmissionEl {
    pub name: String,
    /// Joint name, its `<hardwareInterface>`s, the reduction.
    pub joints: Vec<(String, Vec<String>, f64)>,
    pub line: u32,
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RobotEl {
    pub name: String,
    pub materials: Vec<MaterialEl>,
    pub links: Vec<LinkEl>,
    pub joints: Vec<JointEl>,
    pub transmissions: Vec<TransmissionEl>,
}

struct Reader<'a, 'input> {
    doc: &'a roxmltree::Document<'input>,
    path: &'a Path,
}

impl Reader<'_, '_> {
    fn err(&self, node: Node<'_, '_>, message: impl Into<String>) -> SimError {
        SimError::invalid(self.path, Some(line_of(self.doc, node)), message)
    }

    fn attr<'n>(&self, node: Node<'n, '_>, name: &str) -> Result<&'n str> {
        node.attribute(name).ok_or_else(|| {
            self.err(
                node,
                format!(
                    "<{}> needs a {name}=\"...\" attribute",
                    node.tag_name().name()
                ),
            )
        })
    }

    fn number(&self, node: Node<'_, '_>, name: &str) -> Result<f64> {
        let text = self.attr(node, name)?;
        text.trim().parse().map_err(|_| {
            self.err(
                node,
                format!(
                    "<{} {name}=\"{text}\">: expected a number",
                    node.tag_name().name()
                ),
            )
        })
    }

    fn numbers<const N: usize>(&self, node: Node<'_, '_>, name: &str) -> Result<Option<[f64; N]>> {
        let Some(text) = node.attribute(name) else {
            return Ok(None);
        };
        let values: Option<Vec<f64>> = text.split_whitespace().map(|t| t.parse().ok()).collect();
        values
            .and_then(|v| <[f64; N]>::try_from(v).ok())
            .map(Some)
            .ok_or_else(|| {
                self.err(
                    node,
                    format!(
                        "<{} {name}=\"{text}\">: expected {N} numbers",
                        node.tag_name().name()
                    ),
                )
            })
    }

    fn origin(&self, parent: Node<'_, '_>) -> Result<Origin> {
        let Some(o) = child(parent, "origin") else {
            return Ok(Origin::default());
        };
        Ok(Origin {
            xyz: self.numbers(o, "xyz")?.unwrap_or_default(),
            rpy: self.numbers(o, "rpy")?.unwrap_or_default(),
        })
    }

    fn material(&self, node: Node<'_, '_>) -> Result<MaterialEl> {
        let color = match child(node, "color") {
            Some(c) => Some(
                self.numbers::<4>(c, "rgba")?
                    .ok_or_else(|| self.err(c, "<color> needs an rgba=\"r g b a\" attribute"))?,
            ),
            None => None,
        };
        Ok(MaterialEl {
            name: node.attribute("name").unwrap_or_default().to_owned(),
            color,
        })
    }

    /// urdfdom takes the first element inside `<geometry>` as the shape.
    fn geometry(&self, parent: Node<'_, '_>) -> Result<Geometry> {
        let what = parent.tag_name().name();
        let g = child(parent, "geometry")
            .ok_or_else(|| self.err(parent, format!("<{what}> has no <geometry>")))?;
        let shape = g.children().find(Node::is_element).ok_or_else(|| {
            self.err(
                g,
                "<geometry> is empty: expected box, cylinder, sphere, capsule or mesh",
            )
        })?;
        Ok(match shape.tag_name().name() {
            "box" => Geometry::Box {
                size: self
                    .numbers(shape, "size")?
                    .ok_or_else(|| self.err(shape, "<box> needs a size=\"x y z\" attribute"))?,
            },
            "cylinder" => Geometry::Cylinder {
                radius: self.number(shape, "radius")?,
                length: self.number(shape, "length")?,
            },
            "capsule" => Geometry::Capsule {
                radius: self.number(shape, "radius")?,
                length: self.number(shape, "length")?,
            },
            "sphere" => Geometry::Sphere {
                radius: self.number(shape, "radius")?,
            },
            "mesh" => Geometry::Mesh {
                filename: self.attr(shape, "filename")?.trim().to_owned(),
                scale: self.numbers(shape, "scale")?,
            },
            other => {
                return Err(self.err(
                    shape,
                    format!("unknown geometry <{other}>: expected box, cylinder, sphere, capsule or mesh"),
                ));
            }
        })
    }

    fn link(&self, node: Node<'_, '_>) -> Result<LinkEl> {
        let name = self.attr(node, "name")?.to_owned();
        let inertial = match child(node, "inertial") {
            Some(i) => {
                let mass = child(i, "mass")
                    .ok_or_else(|| self.err(i, "<inertial> has no <mass value=\"...\"/>"))?;
                let mass = self.number(mass, "value")?;
                let inertia = match child(i, "inertia") {
                    Some(n) => {
                        let mut v = [0.0; 6];
                        for (slot, key) in
                            v.iter_mut().zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"])
                        {
                            *slot = self.number(n, key)?;
                        }
                        v
                    }
                    None => {
                        return Err(self.err(i, "<inertial> has no <inertia ixx=... izz=.../>"));
                    }
                };
                Some(InertialEl {
                    origin: self.origin(i)?,
                    mass,
                    inertia,
                })
            }
            None => None,
        };
        let mut visual = Vec::new();
        let mut collision = Vec::new();
        for item in node.children().filter(Node::is_element) {
            match item.tag_name().name() {
                "visual" => visual.push(VisualEl {
                    origin: self.origin(item)?,
                    geometry: self.geometry(item)?,
                    material: child(item, "material")
                        .map(|m| self.material(m))
                        .transpose()?,
                }),
                "collision" => collision.push(CollisionEl {
                    origin: self.origin(item)?,
                    geometry: self.geometry(item)?,
                }),
                _ => {}
            }
        }
        Ok(LinkEl {
            name,
            inertial,
            visual,
            collision,
        })
    }

    fn joint(&self, node: Node<'_, '_>) -> Result<JointEl> {
        let name = self.attr(node, "name")?.to_owned();
        let type_name = self.attr(node, "type")?;
        let joint_type = match type_name {
            "fixed" => JointType::Fixed,
            "continuous" => JointType::Continuous,
            "revolute" => JointType::Revolute,
            "prismatic" => JointType::Prismatic,
            "floating" => JointType::Floating,
            "planar" => JointType::Planar,
            "spherical" => JointType::Spherical,
            other => {
                return Err(self.err(
                    node,
                    format!(
                        "<joint name=\"{name}\" type=\"{other}\">: unknown joint type; expected fixed, continuous, revolute, prismatic, floating or planar"
                    ),
                ));
            }
        };
        let link_of = |role: &str| -> Result<String> {
            let el = child(node, role).ok_or_else(|| {
                self.err(
                    node,
                    format!("<joint name=\"{name}\"> has no <{role} link=\"...\"/>"),
                )
            })?;
            Ok(self.attr(el, "link")?.to_owned())
        };
        let limit = match child(node, "limit") {
            Some(l) => Some((
                l.attribute("lower")
                    .map_or(Ok(0.0), |_| self.number(l, "lower"))?,
                l.attribute("upper")
                    .map_or(Ok(0.0), |_| self.number(l, "upper"))?,
            )),
            None => None,
        };
        if limit.is_none() && matches!(joint_type, JointType::Revolute | JointType::Prismatic) {
            return Err(self.err(
                node,
                format!("<joint name=\"{name}\" type=\"{type_name}\"> has no <limit>: a {type_name} joint needs one (as in ROS's urdfdom)"),
            ));
        }
        let axis = match child(node, "axis") {
            Some(a) => self.numbers(a, "xyz")?.unwrap_or([1.0, 0.0, 0.0]),
            None => [1.0, 0.0, 0.0],
        };
        let optional = |el: Option<Node<'_, '_>>, attr: &str| -> Result<Option<f64>> {
            match el {
                Some(e) if e.attribute(attr).is_some() => Ok(Some(self.number(e, attr)?)),
                _ => Ok(None),
            }
        };
        let dynamics = child(node, "dynamics");
        let limit_el = child(node, "limit");
        let mimic = match child(node, "mimic") {
            Some(m) => Some((
                self.attr(m, "joint")?.to_owned(),
                optional(Some(m), "multiplier")?.unwrap_or(1.0),
                optional(Some(m), "offset")?.unwrap_or(0.0),
            )),
            None => None,
        };
        Ok(JointEl {
            parent: link_of("parent")?,
            child: link_of("child")?,
            origin: self.origin(node)?,
            name,
            joint_type,
            axis,
            limit,
            effort: optional(limit_el, "effort")?,
            velocity: optional(limit_el, "velocity")?,
            damping: optional(dynamics, "damping")?,
            friction: optional(dynamics, "friction")?,
            mimic,
        })
    }

    fn transmission(&self, node: Node<'_, '_>) -> Result<TransmissionEl> {
        let name = node.attribute("name").unwrap_or("").to_owned();
        let mut joints = Vec::new();
        let reduction = children(node, "actuator")
            .find_map(|a| child(a, "mechanicalReduction").and_then(|r| r.text()))
            .map(|t| {
                t.trim().parse::<f64>().map_err(|_| {
                    self.err(
                        node,
                        format!(
                            "<transmission name=\"{name}\"> <mechanicalReduction>{}</mechanicalReduction>: expected a number",
                            t.trim()
                        ),
                    )
                })
            })
            .transpose()?
            .unwrap_or(1.0);
        for joint in children(node, "joint") {
            let joint_name = self.attr(joint, "name")?.to_owned();
            let interfaces = children(joint, "hardwareInterface")
                .filter_map(|h| h.text())
                .map(|t| t.trim().to_owned())
                .collect();
            joints.push((joint_name, interfaces, reduction));
        }
        Ok(TransmissionEl {
            name,
            joints,
            line: line_of(self.doc, node),
        })
    }
}

/// Reads the `<robot>` of a parsed URDF document.
pub(crate) fn read(doc: &roxmltree::Document<'_>, path: &Path) -> Result<RobotEl> {
    let r = Reader { doc, path };
    let root = doc.root_element();
    let mut robot = RobotEl {
        name: r.attr(root, "name")?.to_owned(),
        materials: Vec::new(),
        links: Vec::new(),
        joints: Vec::new(),
        transmissions: Vec::new(),
    };
    for node in root.children().filter(Node::is_element) {
        match node.tag_name().name() {
            "link" => robot.links.push(r.link(node)?),
            "joint" => robot.joints.push(r.joint(node)?),
            "material" => robot.materials.push(r.material(node)?),
            "transmission" => robot.transmissions.push(r.transmission(node)?),
            _ => {}
        }
    }
    Ok(robot)
}
