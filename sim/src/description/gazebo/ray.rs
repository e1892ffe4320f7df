//! Ray sensors, `<sensor type="ray">` and `gpu_ray`: the SDF `<ray>` element and the ROS plugin
//! on it, Gazebo's defaults where both are silent. One vertical sample is a 2D laser
//! (gazebo_ros_laser's sensor_msgs/LaserScan); more is a 3D lidar, published as a point cloud
//! (velodyne_simulator's `libgazebo_ros_velodyne_laser.so` parameters), never flattened.

use super::values::{Ctx, Node, parse_noise, read_sensor_pose, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::geometry::Pose;
use crate::model::sensors::{LaserConfig, LidarConfig, MAX_LASER_SAMPLES};

/// What a ray sensor is.
#[derive(Debug)]
pub(super) enum RaySensor {
    /// One plane of rays: a 2D laser.
    Planar(LaserConfig),
    /// Several beams: a 3D lidar.
    Lidar(LidarConfig),
}

/// One axis of a `<scan>` as written (`<horizontal>` or `<vertical>`): `<samples>` and
/// `<resolution>` (rays per sample) and the angle limits, Gazebo's defaults until read.
struct Axis {
    samples: u32,
    resolution: f64,
    min_angle_rad: f64,
    max_angle_rad: f64,
}

impl Axis {
    /// Rays along the axis, or a located error naming `element`.
    fn rays(
        &self,
        ctx: &Ctx<'_, '_>,
        node: Node<'_, '_>,
        what: &str,
        element: &str,
    ) -> Result<u32> {
        let rays = (f64::from(self.samples) * self.resolution).round();
        if !(1.0..=f64::from(MAX_LASER_SAMPLES)).contains(&rays) {
            return Err(ctx.err(
                node,
                format!("<{element}> in {what}: <samples> x <resolution> gives {rays} rays; expected 1 to {MAX_LASER_SAMPLES}"),
            ));
        }
        if self.max_angle_rad < self.min_angle_rad {
            return Err(ctx.err(
                node,
                format!(
                    "<{element}> in {what}: expected min_angle <= max_angle, found {} and {}",
                    self.min_angle_rad, self.max_angle_rad
                ),
            ));
        }
        Ok(rays as u32)
    }
}

/// The plugin's lidar parameters (velodyne_simulator's names and defaults).
struct LidarPlugin {
    topic: Option<String>,
    min_range_m: f64,
    max_range_m: f64,
    gaussian_noise_m: f64,
    organize: bool,
}

/// A ray `<sensor>` on `link`.
pub(super) fn parse(ctx: &Ctx<'_, '_>, sensor: Node<'_, '_>, link: &str) -> Result<RaySensor> {
    let name = sensor.attribute("name").unwrap_or("laser").to_owned();
    let what = format!("<sensor name=\"{name}\">");
    let what = what.as_str();
    // Gazebo's defaults for a ray sensor.
    let mut c = LaserConfig {
        name,
        link: link.to_owned(),
        link_from_sensor: Pose::IDENTITY,
        update_rate_hz: 10.0,
        samples: 640,
        min_angle_rad: 0.0,
        max_angle_rad: 0.0,
        range_min_m: 0.1,
        range_max_m: 10.0,
        range_resolution_m: 0.01,
        noise: None,
        topic: "scan".to_owned(),
        frame_name: link.to_owned(),
        line: Some(line_of(ctx.doc, sensor)),
    };
    let mut horizontal = Axis {
        samples: 640,
        resolution: 1.0,
        min_angle_rad: 0.0,
        max_angle_rad: 0.0,
    };
    let mut vertical = Axis {
        samples: 1,
        resolution: 1.0,
        min_angle_rad: 0.0,
        max_angle_rad: 0.0,
    };
    let mut plugin = LidarPlugin {
        topic: None,
        min_range_m: 0.0,
        max_range_m: f64::INFINITY,
        gaussian_noise_m: 0.0,
        organize: false,
    };
    for s in elements(sensor) {
        match s.tag_name().name() {
            "update_rate" => c.update_rate_hz = ctx.non_negative(s, what, "Hz")?,
            "pose" => c.link_from_sensor = read_sensor_pose(ctx, s, what)?,
            // gz-sim names the element <lidar>; Gazebo classic <ray>.
            "ray" | "lidar" => {
                read_ray_element(ctx, s, what, &mut c, [&mut horizontal, &mut vertical])?
            }
            "plugin" => read_plugin(ctx, s, what, &mut c, &mut plugin)?,
            _ => {}
        }
    }
    c.samples = horizontal.rays(ctx, sensor, what, "horizontal")?;
    c.min_angle_rad = horizontal.min_angle_rad;
    c.max_angle_rad = horizontal.max_angle_rad;
    let beams = vertical.rays(ctx, sensor, what, "vertical")?;
    if beams == 1 {
        if let Some(topic) = plugin.topic {
            c.topic = topic;
        }
        return Ok(RaySensor::Planar(c));
    }
    c.topic = plugin.topic.unwrap_or_else(|| "points".to_owned());
    if plugin.min_range_m >= plugin.max_range_m {
        return Err(ctx.err(
            sensor,
            format!(
                "{what}: expected <min_range> below <max_range>, found {} and {}",
                plugin.min_range_m, plugin.max_range_m
            ),
        ));
    }
    let rays = u64::from(beams) * u64::from(c.samples);
    if rays > u64::from(MAX_LASER_SAMPLES) * 16 {
        return Err(ctx.err(
            sensor,
            format!(
                "{what}: {beams} beams x {} samples is {rays} rays a scan; expected at most {}",
                c.samples,
                u64::from(MAX_LASER_SAMPLES) * 16
            ),
        ));
    }
    Ok(RaySensor::Lidar(LidarConfig {
        rays: c,
        vertical_samples: beams,
        vertical_min_angle_rad: vertical.min_angle_rad,
        vertical_max_angle_rad: vertical.max_angle_rad,
        min_range_m: plugin.min_range_m,
        max_range_m: plugin.max_range_m,
        gaussian_noise_m: plugin.gaussian_noise_m,
        organize: plugin.organize,
    }))
}

/// The ray plugin's parameters: gazebo_ros_laser's and velodyne_simulator's `topicName` and
/// `frameName`, the lidar's ranges, noise and organization; a ROS 2 gazebo_ros_ray_sensor's
/// `<ros><remapping>~/out:=TOPIC</remapping>`.
fn read_plugin(
    ctx: &Ctx<'_, '_>,
    node: Node<'_, '_>,
    what: &str,
    c: &mut LaserConfig,
    plugin: &mut LidarPlugin,
) -> Result<()> {
    for p in elements(node) {
        match p.tag_name().name() {
            "topicName" => plugin.topic = Some(text_of(p).to_owned()),
            "frameName" | "frame_name" => c.frame_name = text_of(p).to_owned(),
            "min_range" => plugin.min_range_m = ctx.non_negative(p, what, "metres")?,
            "max_range" => plugin.max_range_m = ctx.positive(p, what, "metres")?,
            "gaussianNoise" => plugin.gaussian_noise_m = ctx.non_negative(p, what, "metres")?,
            "organize_cloud" => plugin.organize = ctx.boolean(p, what)?,
            "ros" => {
                for r in elements(p).filter(|r| r.has_tag_name("remapping")) {
                    if let Some(topic) = text_of(r).strip_prefix("~/out:=") {
                        plugin.topic = Some(topic.to_owned());
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Reads the SDF `<ray>` element of ray sensor `what`: its `<scan>` axes, its `<range>` and
/// `<noise>` into `c`.
fn read_ray_element(
    ctx: &Ctx<'_, '_>,
    ray_element: Node<'_, '_>,
    what: &str,
    c: &mut LaserConfig,
    [horizontal, vertical]: [&mut Axis; 2],
) -> Result<()> {
    for ray in elements(ray_element) {
        match ray.tag_name().name() {
            "scan" => {
                for axis in elements(ray) {
                    match axis.tag_name().name() {
                        "horizontal" => read_axis(ctx, axis, what, horizontal)?,
                        "vertical" => read_axis(ctx, axis, what, vertical)?,
                        _ => {}
                    }
                }
            }
            "range" => {
                for r in elements(ray) {
                    match r.tag_name().name() {
                        "min" => c.range_min_m = ctx.non_negative(r, what, "metres")?,
                        "max" => c.range_max_m = ctx.positive(r, what, "metres")?,
                        "resolution" => {
                            c.range_resolution_m = ctx.non_negative(r, what, "metres")?
                        }
                        _ => {}
                    }
                }
                if c.range_min_m >= c.range_max_m {
                    return Err(ctx.err(
                        ray,
                        format!(
                            "<range> in {what}: expected min < max, found min {} and max {}",
                            c.range_min_m, c.range_max_m
                        ),
                    ));
                }
            }
            "noise" => c.noise = parse_noise(ctx, ray, what, "metres")?,
            _ => {}
        }
    }
    Ok(())
}

/// Reads one `<ray><scan><horizontal>` or `<vertical>` of ray sensor `what` into `axis`.
fn read_axis(ctx: &Ctx<'_, '_>, node: Node<'_, '_>, what: &str, axis: &mut Axis) -> Result<()> {
    let element = node.tag_name().name();
    for p in elements(node) {
        match p.tag_name().name() {
            "samples" => {
                let text = text_of(p);
                axis.samples = match text.parse::<u32>() {
                    Ok(n) if (1..=MAX_LASER_SAMPLES).contains(&n) => n,
                    _ => {
                        return Err(ctx.err(
                            p,
                            format!("<samples> in <{element}> of {what}: expected a whole number of rays between 1 and {MAX_LASER_SAMPLES}, found '{text}'"),
                        ));
                    }
                }
            }
            "resolution" => axis.resolution = ctx.positive(p, what, "rays per sample")?,
            "min_angle" => axis.min_angle_rad = ctx.number(p, what, "radians")?,
            "max_angle" => axis.max_angle_rad = ctx.number(p, what, "radians")?,
            _ => {}
        }
    }
    Ok(())
}
