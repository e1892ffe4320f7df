//! Reading values out of `<gazebo>` elements: numbers with their units, booleans, pixel
//! counts, poses, each a located error (file, line, element) when it does not parse. Shared by
//! the plugin and sensor readers beside it.

use std::path::Path;

use crate::description::xml::{elements, line_of};
use crate::error::{Result, SimError};
use crate::geometry::{Pose, pose_from_xyz_rpy};
use crate::model::sensors::GaussianNoise;

pub(super) type Node<'a, 'input> = roxmltree::Node<'a, 'input>;

pub(super) struct Ctx<'a, 'input> {
    pub doc: &'a roxmltree::Document<'input>,
    pub path: &'a Path,
    /// Whether the description is modern Gazebo's (an SDF model, or one with gz-sim systems):
    /// its sensors without a ROS plugin publish on their `<topic>`, as gz-sim's do.
    pub modern: bool,
    /// The model's name, for gz-sim's default topic and frame names.
    pub model: &'a str,
}

impl<'a, 'input> Ctx<'a, 'input> {
    pub fn err(&self, node: Node<'_, '_>, message: String) -> SimError {
        SimError::invalid(self.path, Some(line_of(self.doc, node)), message)
    }

    pub fn number(&self, node: Node<'_, '_>, what: &str, unit: &str) -> Result<f64> {
        let text = text_of(node);
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.err(
                node,
                format!(
                    "<{}> in {what}: expected a number ({unit}), found '{text}'",
                    node.tag_name().name()
                ),
            )),
        }
    }

    pub fn positive(&self, node: Node<'_, '_>, what: &str, unit: &str) -> Result<f64> {
        let v = self.number(node, what, unit)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(
                node,
                format!(
                    "<{}> in {what}: expected a positive number ({unit}), found {v}",
                    node.tag_name().name()
                ),
            ))
        }
    }

    pub fn non_negative(&self, node: Node<'_, '_>, what: &str, unit: &str) -> Result<f64> {
        let v = self.number(node, what, unit)?;
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(
                node,
                format!(
                    "<{}> in {what}: expected zero or a positive number ({unit}), found {v}",
                    node.tag_name().name()
                ),
            ))
        }
    }

    pub fn boolean(&self, node: Node<'_, '_>, what: &str) -> Result<bool> {
        match text_of(node) {
            "true" | "1" => Ok(true),
            "false" | "0" => Ok(false),
            other => Err(self.err(
                node,
                format!(
                    "<{}> in {what}: expected true or false, found '{other}'",
                    node.tag_name().name()
                ),
            )),
        }
    }

    pub fn pixels(&self, node: Node<'_, '_>, what: &str) -> Result<u32> {
        let text = text_of(node);
        match text.parse::<u32>() {
            Ok(v) if (1..=16384).contains(&v) => Ok(v),
            _ => Err(self.err(
                node,
                format!(
                    "<{}> in {what}: expected a whole number of pixels between 1 and 16384, found '{text}'",
                    node.tag_name().name()
                ),
            )),
        }
    }
}

/// Trimmed text content of an element ("" when empty).
/// Trimmed text of an element, or its `value` attribute (the older `<mu1 value="1.0"/>` form
/// Gazebo's URDF reader accepts too).
pub(super) fn text_of<'a>(node: Node<'a, '_>) -> &'a str {
    match node.text().map(str::trim) {
        Some(text) if !text.is_empty() => text,
        _ => node.attribute("value").map_or("", str::trim),
    }
}

/// A sensor's `<pose>`: six numbers `x y z roll pitch yaw`, the sensor in its link's frame.
pub(super) fn read_sensor_pose(ctx: &Ctx<'_, '_>, pose: Node<'_, '_>, what: &str) -> Result<Pose> {
    let text = text_of(pose);
    let v: Vec<f64> = text
        .split_whitespace()
        .map(str::parse::<f64>)
        .collect::<std::result::Result<_, _>>()
        .ok()
        .filter(|v: &Vec<f64>| v.len() == 6 && v.iter().all(|x| x.is_finite()))
        .ok_or_else(|| {
            ctx.err(
                pose,
                format!(
                    "<pose> in {what}: expected six numbers 'x y z roll pitch yaw', found '{text}'"
                ),
            )
        })?;
    Ok(pose_from_xyz_rpy([v[0], v[1], v[2]], [v[3], v[4], v[5]]))
}

/// `libNAME.so` -> `NAME` (a path before it is dropped).
pub(super) fn plugin_stem(file: &str) -> &str {
    let base = file.rsplit('/').next().unwrap_or(file);
    let base = base.strip_prefix("lib").unwrap_or(base);
    base.strip_suffix(".so").unwrap_or(base)
}

/// A topic as a ROS node handle in `namespace` resolves `topic`: absolute names stay.
pub(super) fn join_topic(namespace: &str, topic: &str) -> String {
    if topic.starts_with('/') || namespace.is_empty() {
        topic.to_owned()
    } else {
        format!("{namespace}{topic}")
    }
}

/// A ROS name with its doubled slashes collapsed, as roscpp cleans it (`/robot//imu` is
/// `/robot/imu`).
pub(super) fn clean(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        if !(c == '/' && out.ends_with('/')) {
            out.push(c);
        }
    }
    out
}

/// Three numbers `x y z`.
pub(super) fn vec3(
    ctx: &Ctx<'_, '_>,
    node: Node<'_, '_>,
    what: &str,
    unit: &str,
) -> Result<[f64; 3]> {
    let text = text_of(node);
    let v: Vec<f64> = text
        .split_whitespace()
        .filter_map(|t| t.parse::<f64>().ok())
        .filter(|x| x.is_finite())
        .collect();
    if v.len() != 3 || text.split_whitespace().count() != 3 {
        return Err(ctx.err(
            node,
            format!(
                "<{}> in {what}: expected three numbers 'x y z' ({unit}), found '{text}'",
                node.tag_name().name()
            ),
        ));
    }
    Ok([v[0], v[1], v[2]])
}

/// An SDF `<noise>` element in `what`: `None` when its type is `none` or it adds nothing.
pub(super) fn parse_noise(
    ctx: &Ctx<'_, '_>,
    node: Node<'_, '_>,
    what: &str,
    unit: &str,
) -> Result<Option<GaussianNoise>> {
    // SDF writes the type as an attribute (`<noise type="gaussian">`) or an element.
    let mut kind = node.attribute("type").unwrap_or("gaussian").to_owned();
    let mut noise = GaussianNoise {
        mean: 0.0,
        stddev: 0.0,
    };
    for n in elements(node) {
        match n.tag_name().name() {
            "type" => kind = text_of(n).to_owned(),
            "mean" => noise.mean = ctx.number(n, what, unit)?,
            "stddev" => noise.stddev = ctx.non_negative(n, what, unit)?,
            _ => {}
        }
    }
    match kind.as_str() {
        "gaussian" => Ok((noise.stddev > 0.0 || noise.mean != 0.0).then_some(noise)),
        "none" => Ok(None),
        other => Err(ctx.err(
            node,
            format!("<noise><type> in {what}: expected gaussian or none, found '{other}'"),
        )),
    }
}
