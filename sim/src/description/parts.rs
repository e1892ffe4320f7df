//! What a robot description file gives before it becomes a robot model: its links and joints
//! as URDF has them, where each is written, its Gazebo extensions. A URDF (`robot.rs`) and an
//! SDF model (`sdf_robot.rs`) are both read into these parts.

use std::collections::HashMap;

use crate::description::gazebo;
use crate::description::urdf;
use crate::description::xml::line_of;

/// What a robot description file gives before it becomes a robot model.
pub(crate) struct Parts {
    /// Links, joints, materials and transmissions, as URDF has them.
    pub urdf: urdf::RobotEl,
    /// Where each link and joint is written.
    pub lines: ElementLines,
    /// The Gazebo plugins and sensors.
    pub extensions: gazebo::Extensions,
    /// The line of the root element.
    pub root_line: Option<u32>,
}

/// Lines of `<link>` and `<joint>` elements by name, for messages about them.
#[derive(Debug, Default)]
pub(crate) struct ElementLines {
    pub links: HashMap<String, u32>,
    pub joints: HashMap<String, u32>,
}

impl ElementLines {
    pub(crate) fn collect(doc: &roxmltree::Document<'_>) -> Self {
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

    pub(crate) fn link(&self, name: &str) -> Option<u32> {
        self.links.get(name).copied()
    }

    pub(crate) fn joint(&self, name: &str) -> Option<u32> {
        self.joints.get(name).copied()
    }
}
