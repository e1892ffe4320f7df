//! `libgazebo_ros_p3d.so`: a link's ground-truth pose and velocity as nav_msgs/Odometry, with
//! gazebo_ros's (ROS 1) parameter names and defaults.

use super::values::{Ctx, Node, clean, join_topic, plugin_stem, text_of, vec3};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::model::sensors::P3dConfig;

/// True for the plugin's file name.
pub(super) fn is_plugin(file: &str) -> bool {
    plugin_stem(file) == "gazebo_ros_p3d"
}

/// The plugin element: `<bodyName>` and `<topicName>` are required, as gazebo_ros requires
/// them; `<frameName>` (default `world`) is the world when `world` or `map`, else a link.
pub(super) fn parse(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<P3dConfig> {
    let name = plugin.attribute("name").unwrap_or("p3d").to_owned();
    let what = format!("<plugin name=\"{name}\" filename=\"libgazebo_ros_p3d.so\">");
    let what = what.as_str();
    let mut namespace = String::new();
    let (mut body, mut topic) = (None, None);
    let mut c = P3dConfig {
        name,
        link: String::new(),
        topic: String::new(),
        frame_name: "world".to_owned(),
        reference_link: None,
        xyz_offset_m: [0.0; 3],
        rpy_offset_rad: [0.0; 3],
        gaussian_noise: 0.0,
        update_rate_hz: 0.0,
        line: Some(line_of(ctx.doc, plugin)),
    };
    for p in elements(plugin) {
        match p.tag_name().name() {
            "robotNamespace" => namespace = format!("{}/", text_of(p)),
            "bodyName" => body = Some(text_of(p).to_owned()),
            "topicName" => topic = Some(text_of(p).to_owned()),
            "frameName" => c.frame_name = text_of(p).to_owned(),
            "xyzOffsets" | "xyzOffset" => c.xyz_offset_m = vec3(ctx, p, what, "metres")?,
            "rpyOffsets" | "rpyOffset" => c.rpy_offset_rad = vec3(ctx, p, what, "radians")?,
            "gaussianNoise" => c.gaussian_noise = ctx.non_negative(p, what, "stddev")?,
            "updateRate" => c.update_rate_hz = ctx.non_negative(p, what, "Hz")?,
            _ => {}
        }
    }
    let missing = |element: &str, why: &str| {
        ctx.err(
            plugin,
            format!(
                "{what}: missing <{element}> ({why}; gazebo_ros's p3d cannot start without it)"
            ),
        )
    };
    c.link = body
        .filter(|b| !b.is_empty())
        .ok_or_else(|| missing("bodyName", "the link whose pose it reports"))?;
    let topic = topic
        .filter(|t| !t.is_empty())
        .ok_or_else(|| missing("topicName", "where it publishes"))?;
    c.topic = clean(&join_topic(&namespace, &topic));
    if !matches!(c.frame_name.trim_start_matches('/'), "world" | "map" | "") {
        c.reference_link = Some(c.frame_name.trim_start_matches('/').to_owned());
    }
    Ok(c)
}
