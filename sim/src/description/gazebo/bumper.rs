//! `<sensor type="contact">` with `libgazebo_ros_bumper.so`: what a link touches, as
//! gazebo_msgs/ContactsState, with gazebo_ros's (ROS 1) parameter names and defaults.

use super::values::{Ctx, Node, clean, join_topic, plugin_stem, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::model::sensors::BumperConfig;

/// True for the plugin's file name.
fn is_plugin(file: &str) -> bool {
    plugin_stem(file) == "gazebo_ros_bumper"
}

/// The contact sensor on `link`; `None` when no bumper plugin publishes it.
pub(super) fn parse(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    link: &str,
) -> Result<Option<BumperConfig>> {
    let name = sensor.attribute("name").unwrap_or("bumper").to_owned();
    let what = format!("<sensor name=\"{name}\" type=\"contact\">");
    let what = what.as_str();
    let mut c = BumperConfig {
        name,
        link: link.to_owned(),
        collision: String::new(),
        update_rate_hz: 0.0,
        topic: "bumper_states".to_owned(),
        frame_name: "world".to_owned(),
        reference_link: None,
        line: Some(line_of(ctx.doc, sensor)),
    };
    let mut plugin = None;
    for s in elements(sensor) {
        match s.tag_name().name() {
            "update_rate" => c.update_rate_hz = ctx.non_negative(s, what, "Hz")?,
            "contact" => {
                for e in elements(s).filter(|e| e.has_tag_name("collision")) {
                    c.collision = text_of(e).to_owned();
                }
            }
            "plugin" if is_plugin(s.attribute("filename").unwrap_or("")) => plugin = Some(s),
            _ => {}
        }
    }
    let Some(plugin) = plugin else {
        return Ok(None);
    };
    if c.collision.is_empty() {
        return Err(ctx.err(
            sensor,
            format!(
                "{what}: missing <contact><collision> (the collision it watches, e.g. {link}_collision)"
            ),
        ));
    }
    let mut namespace = String::new();
    for p in elements(plugin) {
        match p.tag_name().name() {
            "robotNamespace" => namespace = format!("{}/", text_of(p)),
            "bumperTopicName" => c.topic = text_of(p).to_owned(),
            "frameName" => c.frame_name = text_of(p).to_owned(),
            _ => {}
        }
    }
    if c.topic.is_empty() {
        return Err(ctx.err(
            plugin,
            format!("{what}: an empty <bumperTopicName>; expected a topic name"),
        ));
    }
    c.topic = clean(&join_topic(&namespace, &c.topic));
    if !matches!(c.frame_name.trim_start_matches('/'), "world" | "map" | "") {
        c.reference_link = Some(c.frame_name.trim_start_matches('/').to_owned());
    }
    Ok(Some(c))
}
