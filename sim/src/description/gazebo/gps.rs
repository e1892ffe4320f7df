//! hector_gazebo_plugins' GPS, `libhector_gazebo_ros_gps.so`: a link's origin as latitude,
//! longitude and altitude on WGS-84 around a reference point, with hector's parameter names,
//! defaults and error models.

use super::values::{Ctx, Node, clean, join_topic, plugin_stem, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::model::sensors::{ErrorModel, GpsConfig};

/// True for the plugin's file name.
pub(super) fn is_plugin(file: &str) -> bool {
    plugin_stem(file) == "hector_gazebo_ros_gps"
}

/// The plugin element. `link` is empty when `<bodyName>` is absent: the robot's root link then,
/// as hector takes the model's first link.
pub(super) fn parse(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<GpsConfig> {
    let name = plugin.attribute("name").unwrap_or("gps").to_owned();
    let what = format!("<plugin name=\"{name}\" filename=\"libhector_gazebo_ros_gps.so\">");
    let what = what.as_str();
    let mut namespace = String::new();
    let mut topic = "fix".to_owned();
    let mut velocity_topic = "fix_velocity".to_owned();
    let mut c = GpsConfig {
        name,
        link: String::new(),
        update_rate_hz: 4.0,
        frame_id: "/world".to_owned(),
        topic: String::new(),
        velocity_topic: String::new(),
        reference_latitude_deg: 49.9,
        reference_longitude_deg: 8.9,
        reference_heading_deg: 0.0,
        reference_altitude_m: 0.0,
        status: 0,
        service: 1,
        position_error: ErrorModel::default(),
        velocity_error: ErrorModel::default(),
        line: Some(line_of(ctx.doc, plugin)),
    };
    for p in elements(plugin) {
        let tag = p.tag_name().name();
        match tag {
            "robotNamespace" => namespace = format!("{}/", text_of(p)),
            "bodyName" => c.link = text_of(p).to_owned(),
            "frameId" => c.frame_id = text_of(p).to_owned(),
            "topicName" => topic = text_of(p).to_owned(),
            "velocityTopicName" => velocity_topic = text_of(p).to_owned(),
            "updateRate" => c.update_rate_hz = ctx.non_negative(p, what, "Hz")?,
            "referenceLatitude" => c.reference_latitude_deg = latitude(ctx, p, what)?,
            "referenceLongitude" => c.reference_longitude_deg = ctx.number(p, what, "degrees")?,
            "referenceHeading" => c.reference_heading_deg = ctx.number(p, what, "degrees")?,
            "referenceAltitude" => c.reference_altitude_m = ctx.number(p, what, "metres")?,
            "status" => c.status = integer(ctx, p, what, -1, 2)? as i8,
            "service" => c.service = integer(ctx, p, what, 0, 15)? as u16,
            _ => {
                let (model, key) = match tag.strip_prefix("velocity") {
                    Some(rest) if !rest.is_empty() => (&mut c.velocity_error, rest),
                    _ => (&mut c.position_error, tag),
                };
                let (unit, slot) = match key {
                    "Offset" | "offset" => ("metres", &mut model.offset),
                    "Drift" | "drift" => ("metres", &mut model.drift),
                    "DriftFrequency" | "driftFrequency" => ("Hz", &mut model.drift_frequency_hz),
                    "GaussianNoise" | "gaussianNoise" => ("metres", &mut model.gaussian_noise),
                    _ => continue,
                };
                *slot = axes(ctx, p, what, unit)?;
            }
        }
    }
    c.topic = clean(&join_topic(&namespace, &topic));
    c.velocity_topic = clean(&join_topic(&namespace, &velocity_topic));
    Ok(c)
}

fn latitude(ctx: &Ctx<'_, '_>, node: Node<'_, '_>, what: &str) -> Result<f64> {
    let v = ctx.number(node, what, "degrees")?;
    if v.abs() < 90.0 {
        Ok(v)
    } else {
        Err(ctx.err(
            node,
            format!("<referenceLatitude> in {what}: expected degrees between -90 and 90 (poles excluded), found {v}"),
        ))
    }
}

fn integer(ctx: &Ctx<'_, '_>, node: Node<'_, '_>, what: &str, lo: i64, hi: i64) -> Result<i64> {
    let text = text_of(node);
    match text.parse::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(ctx.err(
            node,
            format!(
                "<{}> in {what}: expected a whole number from {lo} to {hi}, found '{text}'",
                node.tag_name().name()
            ),
        )),
    }
}

/// One number for all three axes, or three `x y z` (hector reads either), none negative.
fn axes(ctx: &Ctx<'_, '_>, node: Node<'_, '_>, what: &str, unit: &str) -> Result<[f64; 3]> {
    let text = text_of(node);
    let values: Option<Vec<f64>> = text
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    match values.as_deref() {
        Some([v]) => Ok([*v; 3]),
        Some([x, y, z]) => Ok([*x, *y, *z]),
        _ => Err(ctx.err(
            node,
            format!(
                "<{}> in {what}: expected one number or three 'x y z' ({unit}), found '{text}'",
                node.tag_name().name()
            ),
        )),
    }
}
