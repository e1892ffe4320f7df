//! MoveIt's SRDF: the arm's planning group as a base link and a tip link, for the IK, look and
//! reach (`--srdf FILE --arm-group NAME`). Read: `<group>` with a `<chain base_link tip_link>`,
//! or `<joint name>`s (the chain from the first joint's parent to the last's child), or
//! `<group name>`s (their joints together); `<end_effector parent_link parent_group>` names the
//! tool when there is one. `<disable_collisions link1 link2>` pairs are read for the planning
//! scene's self-collision checks ([`load_disabled_collisions`]). Virtual joints and group
//! states are not needed here and are skipped.

use std::path::Path;

use roxmltree::Node;

use crate::description::xml::{children, line_of, parse_xml};
use crate::error::{Result, SimError};
use crate::model::{JointKind, LinkId, RobotModel};

/// A planning group resolved to the links of its serial chain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArmGroup {
    /// The group's name.
    pub name: String,
    /// The chain's base link.
    pub base_link: String,
    /// The chain's tip: the end effector's `parent_link` when the SRDF names one for the
    /// group, else the chain's last link.
    pub tip_link: String,
}

/// Reads `path` and resolves group `name` (default: `arm`, else the only group) of `robot`.
pub fn load_arm_group(path: &Path, robot: &RobotModel, name: Option<&str>) -> Result<ArmGroup> {
    let text = crate::io::read_text(path)?;
    parse_arm_group(&text, path, robot, name)
}

/// As [`load_arm_group`], from text; `path` is used in messages.
pub fn parse_arm_group(
    text: &str,
    path: &Path,
    robot: &RobotModel,
    name: Option<&str>,
) -> Result<ArmGroup> {
    let doc = parse_xml(text, path)?;
    let root = srdf_root(&doc, path)?;
    let fail = |node: Node<'_, '_>, message: String| {
        SimError::invalid(path, Some(line_of(&doc, node)), message)
    };
    let groups: Vec<Node<'_, '_>> = children(root, "group").collect();
    let names: Vec<&str> = groups.iter().filter_map(|g| g.attribute("name")).collect();
    let known = || {
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    };
    let group = match name {
        Some(n) => groups.iter().find(|g| g.attribute("name") == Some(n)),
        None => groups
            .iter()
            .find(|g| g.attribute("name") == Some("arm"))
            .or(groups.first().filter(|_| groups.len() == 1)),
    };
    let Some(group) = group.copied() else {
        let wanted = name.map_or(
            "no --arm-group given and no group \"arm\"".to_owned(),
            |n| format!("no group \"{n}\""),
        );
        return Err(fail(root, format!("{wanted}; the groups are: {}", known())));
    };
    let group_name = group.attribute("name").unwrap_or_default().to_owned();
    let (base_link, last_link) = chain_of(group, &groups, robot, &fail, 0)?;
    // MoveIt names the arm in `parent_group`; some files (example-robot-data's panda) put it
    // in `group` and give no parent_group.
    let tip_link = children(root, "end_effector")
        .find(|e| match e.attribute("parent_group") {
            Some(parent) => parent == group_name,
            None => e.attribute("group") == Some(group_name.as_str()),
        })
        .and_then(|e| e.attribute("parent_link"))
        .map_or(last_link, str::to_owned);
    if robot.link_id(&tip_link).is_none() {
        return Err(fail(
            group,
            format!(
                "group \"{group_name}\": its end effector's link \"{tip_link}\" is not in robot \"{}\"",
                robot.name
            ),
        ));
    }
    Ok(ArmGroup {
        name: group_name,
        base_link,
        tip_link,
    })
}

/// An SRDF's `<disable_collisions>` pairs, as [`load_disabled_collisions`] reads them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct DisabledCollisions {
    /// The link pairs the planner does not check against each other.
    pub pairs: Vec<(LinkId, LinkId)>,
    /// Links named in pairs that the robot does not have (those pairs are left out).
    pub unknown_links: Vec<String>,
}

/// The link pairs an SRDF's `<disable_collisions link1 link2 reason>` lines say never collide
/// (or always touch): the planner does not check them against each other. Pairs naming a link
/// the robot does not have are left out (an SRDF written for a fuller variant of the robot),
/// their names kept in [`DisabledCollisions::unknown_links`]. A file that is not an SRDF, or a
/// line without both links, is an error naming the file and line.
pub fn load_disabled_collisions(path: &Path, robot: &RobotModel) -> Result<DisabledCollisions> {
    let text = crate::io::read_text(path)?;
    parse_disabled_collisions(&text, path, robot)
}

/// The link pairs the world's SRDF (`[robot] srdf`) says never collide, if it names one; links
/// the robot does not have are left out, saying so.
pub(crate) fn srdf_disabled_collisions(
    world: &crate::model::world::World,
    robot: &RobotModel,
) -> Result<Vec<(LinkId, LinkId)>> {
    let Some(path) = &world.robot.srdf else {
        return Ok(Vec::new());
    };
    let DisabledCollisions {
        pairs,
        unknown_links: unknown,
    } = load_disabled_collisions(path, robot)?;
    if !unknown.is_empty() {
        tracing::warn!(
            "{}: <disable_collisions> pairs naming links robot \"{}\" does not have are left out: {}",
            path.display(),
            robot.name,
            unknown.join(", ")
        );
    }
    Ok(pairs)
}

/// As [`load_disabled_collisions`], from text; `path` is used in messages.
pub fn parse_disabled_collisions(
    text: &str,
    path: &Path,
    robot: &RobotModel,
) -> Result<DisabledCollisions> {
    let doc = parse_xml(text, path)?;
    let root = srdf_root(&doc, path)?;
    let fail = |node: Node<'_, '_>, message: String| {
        SimError::invalid(path, Some(line_of(&doc, node)), message)
    };
    let (mut pairs, mut unknown) = (Vec::new(), Vec::new());
    for node in children(root, "disable_collisions") {
        let link = |attr: &str| {
            node.attribute(attr).ok_or_else(|| {
                fail(
                    node,
                    format!("<disable_collisions> needs {attr}=\"...\" (a link name)"),
                )
            })
        };
        let (a, b) = (link("link1")?, link("link2")?);
        match (robot.link_id(a), robot.link_id(b)) {
            (Some(a), Some(b)) => pairs.push((a, b)),
            (first, _) => {
                let missing = if first.is_none() { a } else { b };
                if !unknown.iter().any(|u| u == missing) {
                    unknown.push(missing.to_owned());
                }
            }
        }
    }
    Ok(DisabledCollisions {
        pairs,
        unknown_links: unknown,
    })
}

/// The document's `<robot>` element; anything else is an error at its line.
fn srdf_root<'a, 'input>(
    doc: &'a roxmltree::Document<'input>,
    path: &Path,
) -> Result<Node<'a, 'input>> {
    let root = doc.root_element();
    if !root.has_tag_name("robot") {
        return Err(SimError::invalid(
            path,
            Some(line_of(doc, root)),
            format!(
                "expected an SRDF <robot>, found <{}>",
                root.tag_name().name()
            ),
        ));
    }
    Ok(root)
}

/// The base and last link of `group`'s chain (a subgroup's joints count as the group's).
fn chain_of(
    group: Node<'_, '_>,
    groups: &[Node<'_, '_>],
    robot: &RobotModel,
    fail: &dyn Fn(Node<'_, '_>, String) -> SimError,
    depth: usize,
) -> Result<(String, String)> {
    let name = group.attribute("name").unwrap_or_default();
    if depth > 8 {
        return Err(fail(
            group,
            format!("group \"{name}\": subgroups nest too deep (a loop?)"),
        ));
    }
    if let Some(chain) = children(group, "chain").next() {
        let link = |attr: &str| -> Result<String> {
            let l = chain.attribute(attr).ok_or_else(|| {
                fail(
                    chain,
                    format!("group \"{name}\": <chain> needs {attr}=\"...\""),
                )
            })?;
            if robot.link_id(l).is_none() {
                return Err(fail(
                    chain,
                    format!(
                        "group \"{name}\": no link \"{l}\" in robot \"{}\"",
                        robot.name
                    ),
                ));
            }
            Ok(l.to_owned())
        };
        return Ok((link("base_link")?, link("tip_link")?));
    }
    // Joints, with those of subgroups, ordered from the root: the chain runs from the first
    // one's parent to the last one's child.
    let mut joints = Vec::new();
    for node in group.children().filter(Node::is_element) {
        match node.tag_name().name() {
            "joint" => {
                let j = node.attribute("name").unwrap_or_default();
                let id = robot.joint_id(j).ok_or_else(|| {
                    fail(
                        node,
                        format!(
                            "group \"{name}\": no joint \"{j}\" in robot \"{}\"",
                            robot.name
                        ),
                    )
                })?;
                joints.push(id);
            }
            "group" => {
                let sub = node.attribute("name").unwrap_or_default();
                let Some(sub_group) = groups.iter().find(|g| g.attribute("name") == Some(sub))
                else {
                    return Err(fail(
                        node,
                        format!("group \"{name}\": no subgroup \"{sub}\""),
                    ));
                };
                let (base, tip) = chain_of(*sub_group, groups, robot, fail, depth + 1)?;
                for link in [base, tip] {
                    if let Some(l) = robot.link_id(&link) {
                        // The joint above the link, when it moves: enough to order the ends.
                        if let Some((id, _)) = robot.joint_ids().find(|(_, j)| j.child == l) {
                            joints.push(id);
                        }
                    }
                }
            }
            _ => {}
        }
    }
    let depth_of = |id: crate::model::JointId| {
        let mut d = 0;
        let mut link = robot.joint(id).parent;
        while let Some((up, _)) = robot.joint_ids().find(|(_, j)| j.child == link) {
            d += 1;
            link = robot.joint(up).parent;
        }
        d
    };
    joints.retain(|id| !matches!(robot.joint(*id).kind, JointKind::Fixed));
    let first = joints.iter().copied().min_by_key(|id| depth_of(*id));
    let last = joints.iter().copied().max_by_key(|id| depth_of(*id));
    let (Some(first), Some(last)) = (first, last) else {
        return Err(fail(
            group,
            format!(
                "group \"{name}\" has no <chain> and no moving joint; give the tool with --ee-link and the base with --arm-base"
            ),
        ));
    };
    let link_name = |id| robot.links[crate::model::LinkId::index(id)].name.clone();
    Ok((
        link_name(robot.joint(first).parent),
        link_name(robot.joint(last).child),
    ))
}
