//! GPS receivers: hector_gazebo_plugins' `libhector_gazebo_ros_gps.so`, a link's origin as
//! latitude, longitude and altitude on WGS-84 around a reference point, with hector's parameter
//! names, defaults and error models; and Gazebo's `<sensor type="gps">` with gazebo_ros's
//! `libgazebo_ros_gps_sensor.so`, on the world's `<spherical_coordinates>`.

use super::values::{
    Ctx, Node, clean, join_topic, parse_noise, plugin_stem, read_sensor_pose, text_of,
};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::geometry::Pose;
use crate::model::sensors::{ErrorModel, GpsConfig, GpsSource};

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
        update_rate_hz: 4.0,
        frame_id: "/world".to_owned(),
        reference_latitude_deg: 49.9,
        reference_longitude_deg: 8.9,
        ..base(name, GpsSource::Hector, "", line_of(ctx.doc, plugin))
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

/// A `<sensor type="gps">` on `link`; `None` when no `libgazebo_ros_gps_sensor.so` publishes
/// it. Its `<gps>` noise (`position_sensing`/`velocity_sensing`, `horizontal`/`vertical`
/// gaussian mean and stddev, metres) becomes an error model of offset and white noise; the
/// plugin's topics are gazebo_ros's `~/out` and `~/vel` (`/<namespace>/<plugin name>/out`),
/// or what `<ros><remapping>` makes them.
pub(super) fn parse_sensor(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    link: &str,
) -> Result<Option<GpsConfig>> {
    let name = sensor.attribute("name").unwrap_or("gps").to_owned();
    let what = format!("<sensor name=\"{name}\" type=\"gps\">");
    let what = what.as_str();
    let mut c = GpsConfig {
        frame_id: link.to_owned(),
        ..base(name, GpsSource::Sensor, link, line_of(ctx.doc, sensor))
    };
    read_sdf(ctx, sensor, what, &mut c)?;
    let plugin = elements(sensor).find(|s| {
        s.has_tag_name("plugin")
            && plugin_stem(s.attribute("filename").unwrap_or("")) == "gazebo_ros_gps_sensor"
    });
    let Some(plugin) = plugin else {
        return Ok(None);
    };
    let node = plugin.attribute("name").unwrap_or("gps");
    let mut namespace = String::new();
    let (mut out, mut vel) = (format!("{node}/out"), format!("{node}/vel"));
    for p in elements(plugin) {
        match p.tag_name().name() {
            "frame_name" => c.frame_id = text_of(p).to_owned(),
            "ros" => {
                for r in elements(p) {
                    let text = text_of(r);
                    match r.tag_name().name() {
                        "namespace" => namespace = format!("{}/", text.trim_end_matches('/')),
                        "remapping" | "argument" => {
                            if let Some(t) = text.strip_prefix("~/out:=") {
                                out = t.to_owned();
                            } else if let Some(t) = text.strip_prefix("~/vel:=") {
                                vel = t.to_owned();
                            }
                        }
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }
    let root = |t: &str| clean(&format!("/{}", join_topic(&namespace, t)));
    c.topic = root(&out);
    c.velocity_topic = root(&vel);
    Ok(Some(c))
}

/// Reads the SDF side of GPS sensor `what` (`<update_rate>`, `<pose>`, the `<gps>` or
/// `<navsat>` sensing noise) into `c`.
fn read_sdf(ctx: &Ctx<'_, '_>, sensor: Node<'_, '_>, what: &str, c: &mut GpsConfig) -> Result<()> {
    for s in elements(sensor) {
        match s.tag_name().name() {
            "update_rate" => c.update_rate_hz = ctx.non_negative(s, what, "Hz")?,
            "pose" => c.link_from_sensor = read_sensor_pose(ctx, s, what)?,
            "gps" | "navsat" => {
                for sensing in elements(s) {
                    let model = match sensing.tag_name().name() {
                        "position_sensing" => &mut c.position_error,
                        "velocity_sensing" => &mut c.velocity_error,
                        _ => continue,
                    };
                    read_sensing(ctx, sensing, what, model)?;
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// A gz-sim NavSat sensor (no ROS plugin: the NavSat system publishes it) on `link`: a fix on
/// `topic` in `frame` from the world's spherical coordinates; its velocity stays inside gz
/// (ros_gz_bridge's NavSatFix has none), so no velocity topic.
pub(super) fn parse_gz(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    link: &str,
    topic: String,
    frame: String,
) -> Result<GpsConfig> {
    let name = sensor.attribute("name").unwrap_or("navsat").to_owned();
    let what = format!("<sensor name=\"{name}\" type=\"navsat\">");
    let mut c = GpsConfig {
        frame_id: frame,
        topic,
        velocity_topic: String::new(),
        ..base(name, GpsSource::Sensor, link, line_of(ctx.doc, sensor))
    };
    read_sdf(ctx, sensor, &what, &mut c)?;
    Ok(c)
}

/// One `<position_sensing>` or `<velocity_sensing>`: its `<horizontal>` noise on x and y, its
/// `<vertical>` noise on z.
fn read_sensing(
    ctx: &Ctx<'_, '_>,
    sensing: Node<'_, '_>,
    what: &str,
    model: &mut ErrorModel,
) -> Result<()> {
    for axis in elements(sensing) {
        let axes = match axis.tag_name().name() {
            "horizontal" => 0..2,
            "vertical" => 2..3,
            _ => continue,
        };
        for n in elements(axis).filter(|n| n.has_tag_name("noise")) {
            if let Some(noise) = parse_noise(ctx, n, what, "metres")? {
                for i in axes.clone() {
                    model.offset[i] = noise.mean;
                    model.gaussian_noise[i] = noise.stddev;
                }
            }
        }
    }
    Ok(())
}

/// A receiver of `source` named `name` on `link`, declared at `line`: every setting zero,
/// empty or exact (no error), a fix from the GPS service, every physics step.
fn base(name: String, source: GpsSource, link: &str, line: u32) -> GpsConfig {
    GpsConfig {
        name,
        source,
        link: link.to_owned(),
        link_from_sensor: Pose::IDENTITY,
        update_rate_hz: 0.0,
        frame_id: String::new(),
        topic: String::new(),
        velocity_topic: String::new(),
        reference_latitude_deg: 0.0,
        reference_longitude_deg: 0.0,
        reference_heading_deg: 0.0,
        reference_altitude_m: 0.0,
        status: 0,
        service: 1,
        position_error: ErrorModel::default(),
        velocity_error: ErrorModel::default(),
        line: Some(line),
    }
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
