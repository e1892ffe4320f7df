//! The mimic joint plugins Gazebo Classic users add where a URDF has no `<mimic>` (a gripper's
//! second finger driven by the same motor): roboticsgroup_upatras_gazebo_plugins'
//! `libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so` and its older names. rover reads
//! them as the `<mimic>` they stand for: the mimic joint follows `joint` times `multiplier`
//! plus `offset` (docs/ARM.md).

use super::values::{Ctx, Node, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::Result;

/// One mimic plugin: `mimic_joint` follows `multiplier` x `joint` + `offset`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MimicPlugin {
    /// The leader (`<joint>`).
    pub joint: String,
    /// The follower (`<mimicJoint>`).
    pub mimic_joint: String,
    /// `<multiplier>` (default 1).
    pub multiplier: f64,
    /// `<offset>` (default 0; rad or m).
    pub offset: f64,
    /// The plugin's line.
    pub line: u32,
}

/// Whether a plugin file is a mimic joint plugin.
pub(super) fn is_plugin(file: &str) -> bool {
    super::values::plugin_stem(file).contains("mimic_joint_plugin")
}

/// Reads one mimic joint plugin: `<joint>` and `<mimicJoint>` are required.
pub(super) fn parse(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<MimicPlugin> {
    const WHAT: &str = "the mimic joint plugin";
    let mut out = MimicPlugin {
        joint: String::new(),
        mimic_joint: String::new(),
        multiplier: 1.0,
        offset: 0.0,
        line: line_of(ctx.doc, plugin),
    };
    for p in elements(plugin) {
        match p.tag_name().name() {
            "joint" => text_of(p).clone_into(&mut out.joint),
            "mimicJoint" => text_of(p).clone_into(&mut out.mimic_joint),
            "multiplier" => out.multiplier = ctx.number(p, WHAT, "the follower per leader")?,
            "offset" => out.offset = ctx.number(p, WHAT, "rad or m")?,
            _ => {}
        }
    }
    for (value, tag) in [(&out.joint, "joint"), (&out.mimic_joint, "mimicJoint")] {
        if value.is_empty() {
            return Err(ctx.err(
                plugin,
                format!("{WHAT}: expected <{tag}> naming a joint of the robot"),
            ));
        }
    }
    Ok(out)
}
