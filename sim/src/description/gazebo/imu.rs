//! IMUs in `<gazebo>` blocks: `<sensor type="imu">` with gazebo_ros's sensor plugin
//! `libgazebo_ros_imu_sensor.so`, and the older model plugin `libgazebo_ros_imu.so` that
//! TurtleBot3 declares. Parameter names, defaults and topic rules are the plugins' own.

use super::values::{Ctx, Node, clean, join_topic, plugin_stem, read_sensor_pose, text_of, vec3};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::geometry::Pose;
use crate::model::sensors::{AxisNoise, ImuConfig, ImuPlugin, OrientationReference};

/// True for the sensor plugin's file name (`libgazebo_ros_imu_sensor.so`).
pub(super) fn is_sensor_plugin(file: &str) -> bool {
    plugin_stem(file) == "gazebo_ros_imu_sensor"
}

/// True for the model plugin's file name (`libgazebo_ros_imu.so`).
pub(super) fn is_model_plugin(file: &str) -> bool {
    plugin_stem(file) == "gazebo_ros_imu"
}

/// `<sensor type="imu">` on `link`. `Ok(None)` when no ROS plugin publishes it (Gazebo then
/// keeps its readings to itself).
pub(super) fn parse_sensor(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    link: &str,
    robot_name: &str,
) -> Result<Option<ImuConfig>> {
    // Gazebo classic's ImuSensor measures against its own starting orientation.
    let (mut c, what) = sensor_config(ctx, sensor, link, OrientationReference::Initial);
    let what = what.as_str();
    let sensor_rate_hz = read_sdf(ctx, sensor, what, &mut c)?;
    // Read above even without a plugin: a malformed block is an error either way.
    let Some(plugin) = elements(sensor).find(|n| {
        n.has_tag_name("plugin") && n.attribute("filename").is_some_and(is_sensor_plugin)
    }) else {
        return Ok(None);
    };
    // The plugin's defaults: /<model>/ as namespace, imu_data as topic, 1 Hz.
    let mut namespace = format!("/{robot_name}/");
    let mut topic = "/imu_data".to_owned();
    let mut plugin_rate_hz = 1.0;
    let mut frame = None;
    let pwhat = format!("<plugin filename=\"libgazebo_ros_imu_sensor.so\"> in {what}");
    let pwhat = pwhat.as_str();
    for p in elements(plugin) {
        match p.tag_name().name() {
            "robotNamespace" => namespace = format!("{}/", text_of(p)),
            "topicName" => topic = text_of(p).to_owned(),
            "frameName" => frame = Some(text_of(p).to_owned()),
            "updateRateHZ" => plugin_rate_hz = ctx.non_negative(p, pwhat, "Hz")?,
            "gaussianNoise" => c.gaussian_noise = ctx.non_negative(p, pwhat, "stddev")?,
            "rpyOffset" => c.rpy_offset_rad = vec3(ctx, p, pwhat, "radians")?,
            "xyzOffset" => {
                // Read (so a malformed value is an error) but unused, as in gazebo_ros.
                vec3(ctx, p, pwhat, "metres")?;
            }
            "initialOrientationAsReference" | "initial_orientation_as_reference" => {
                c.reference = if ctx.boolean(p, pwhat)? {
                    OrientationReference::Initial
                } else {
                    OrientationReference::World
                };
            }
            _ => {}
        }
    }
    let Some(frame) = frame.filter(|f| !f.is_empty()) else {
        return Err(ctx.err(
            plugin,
            format!("{pwhat}: missing <frameName> (the plugin cannot publish without it)"),
        ));
    };
    c.frame_name = frame;
    c.topic = clean(&format!("{namespace}{topic}"));
    c.update_rate_hz = match (sensor_rate_hz > 0.0, plugin_rate_hz > 0.0) {
        (true, true) => sensor_rate_hz.min(plugin_rate_hz),
        (true, false) => sensor_rate_hz,
        _ => plugin_rate_hz,
    };
    Ok(Some(c))
}

/// An IMU `<sensor>` on `link` before its elements are read (no topic or frame yet), and the
/// words naming it in messages.
fn sensor_config(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    link: &str,
    reference: OrientationReference,
) -> (ImuConfig, String) {
    let name = sensor.attribute("name").unwrap_or("imu").to_owned();
    let what = format!("<sensor name=\"{name}\" type=\"imu\">");
    let c = ImuConfig {
        name,
        plugin: ImuPlugin::Sensor,
        link: link.to_owned(),
        link_from_sensor: Pose::IDENTITY,
        update_rate_hz: 0.0,
        topic: String::new(),
        frame_name: String::new(),
        rpy_offset_rad: [0.0; 3],
        reference,
        gaussian_noise: 0.0,
        angular_velocity_noise: [AxisNoise::default(); 3],
        linear_acceleration_noise: [AxisNoise::default(); 3],
        line: Some(line_of(ctx.doc, sensor)),
    };
    (c, what)
}

/// Reads the SDF side of IMU sensor `what` (`<update_rate>`, `<pose>`, `<imu>` noise) into `c`;
/// returns the sensor's update rate (Hz, 0 = every step).
fn read_sdf(ctx: &Ctx<'_, '_>, sensor: Node<'_, '_>, what: &str, c: &mut ImuConfig) -> Result<f64> {
    let mut sensor_rate_hz = 0.0;
    for s in elements(sensor) {
        match s.tag_name().name() {
            "update_rate" => sensor_rate_hz = ctx.non_negative(s, what, "Hz")?,
            "pose" => c.link_from_sensor = read_sensor_pose(ctx, s, what)?,
            "imu" => read_imu_noise(ctx, s, what, c)?,
            _ => {}
        }
    }
    Ok(sensor_rate_hz)
}

/// A gz-sim IMU (no ROS plugin: the IMU system publishes it) on `link`, on `topic` in `frame`:
/// orientation against the world (gz-sim's default), at the sensor's `<update_rate>`.
pub(super) fn parse_gz(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    link: &str,
    topic: String,
    frame: String,
) -> Result<ImuConfig> {
    let (mut c, what) = sensor_config(ctx, sensor, link, OrientationReference::World);
    c.topic = topic;
    c.frame_name = frame;
    c.update_rate_hz = read_sdf(ctx, sensor, &what, &mut c)?;
    Ok(c)
}

/// The model plugin `libgazebo_ros_imu.so`: an IMU on link `<bodyName>`, orientation against
/// the world, every physics step unless `<updateRate>` says otherwise. Like gazebo_ros, it
/// reads only `<gaussianNoise>`: an SDF `<imu><noise>` block inside it is not used.
pub(super) fn parse_model_plugin(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<ImuConfig> {
    let name = plugin.attribute("name").unwrap_or("imu").to_owned();
    let what = format!("<plugin name=\"{name}\" filename=\"libgazebo_ros_imu.so\">");
    let what = what.as_str();
    let mut namespace = String::new();
    let mut topic = "/default_imu".to_owned();
    let mut body = None;
    let mut frame = None;
    let mut c = ImuConfig {
        name,
        plugin: ImuPlugin::Model,
        link: String::new(),
        link_from_sensor: Pose::IDENTITY,
        update_rate_hz: 0.0,
        topic: String::new(),
        frame_name: String::new(),
        rpy_offset_rad: [0.0; 3],
        reference: OrientationReference::World,
        gaussian_noise: 0.0,
        angular_velocity_noise: [AxisNoise::default(); 3],
        linear_acceleration_noise: [AxisNoise::default(); 3],
        line: Some(line_of(ctx.doc, plugin)),
    };
    for p in elements(plugin) {
        match p.tag_name().name() {
            "robotNamespace" => namespace = format!("{}/", text_of(p)),
            "topicName" => topic = text_of(p).to_owned(),
            "bodyName" => body = Some(text_of(p).to_owned()),
            "frameName" => frame = Some(text_of(p).to_owned()),
            "updateRate" => c.update_rate_hz = ctx.non_negative(p, what, "Hz")?,
            "gaussianNoise" => c.gaussian_noise = ctx.non_negative(p, what, "stddev")?,
            "rpyOffset" | "rpyOffsets" => c.rpy_offset_rad = vec3(ctx, p, what, "radians")?,
            "xyzOffset" | "xyzOffsets" => {
                vec3(ctx, p, what, "metres")?;
            }
            _ => {}
        }
    }
    let Some(body) = body.filter(|b| !b.is_empty()) else {
        return Err(ctx.err(
            plugin,
            format!("{what}: missing <bodyName> (the link the IMU is on)"),
        ));
    };
    c.frame_name = frame.unwrap_or_else(|| body.clone());
    c.link = body;
    c.topic = clean(&join_topic(&namespace, &topic));
    Ok(c)
}

/// The SDF `<imu>` element's noise, in either form: SDF 1.5's per-axis
/// `<angular_velocity><x><noise>` and `<linear_acceleration>`, or SDF 1.4's
/// `<noise><rate>`/`<accel>` for all three axes.
fn read_imu_noise(
    ctx: &Ctx<'_, '_>,
    imu: Node<'_, '_>,
    what: &str,
    c: &mut ImuConfig,
) -> Result<()> {
    for part in elements(imu) {
        match part.tag_name().name() {
            "angular_velocity" | "linear_acceleration" => {
                let (out, unit) = if part.has_tag_name("angular_velocity") {
                    (&mut c.angular_velocity_noise, "rad/s")
                } else {
                    (&mut c.linear_acceleration_noise, "m/s^2")
                };
                for (i, axis) in ["x", "y", "z"].iter().enumerate() {
                    let noise = elements(part)
                        .filter(|n| n.has_tag_name(*axis))
                        .flat_map(elements)
                        .find(|n| n.has_tag_name("noise"));
                    if let Some(noise) = noise {
                        out[i] = axis_noise(ctx, noise, what, unit)?;
                    }
                }
            }
            "noise" => {
                let kind = noise_type(part);
                for block in elements(part) {
                    let (out, unit) = match block.tag_name().name() {
                        "rate" => (&mut c.angular_velocity_noise, "rad/s"),
                        "accel" => (&mut c.linear_acceleration_noise, "m/s^2"),
                        _ => continue,
                    };
                    let axis = axis_values(ctx, block, what, unit)?;
                    *out = [check_type(ctx, part, what, &kind, axis)?; 3];
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// One `<noise type="...">` of an axis.
fn axis_noise(ctx: &Ctx<'_, '_>, noise: Node<'_, '_>, what: &str, unit: &str) -> Result<AxisNoise> {
    let kind = noise_type(noise);
    let axis = axis_values(ctx, noise, what, unit)?;
    check_type(ctx, noise, what, &kind, axis)
}

/// A noise element's type: its `type` attribute or `<type>` child (default gaussian).
fn noise_type(noise: Node<'_, '_>) -> String {
    noise
        .attribute("type")
        .map(str::to_owned)
        .or_else(|| {
            elements(noise)
                .find(|n| n.has_tag_name("type"))
                .map(|n| text_of(n).to_owned())
        })
        .unwrap_or_else(|| "gaussian".to_owned())
}

fn check_type(
    ctx: &Ctx<'_, '_>,
    noise: Node<'_, '_>,
    what: &str,
    kind: &str,
    axis: AxisNoise,
) -> Result<AxisNoise> {
    match kind {
        "gaussian" | "gaussian_quantized" => Ok(axis),
        "none" => Ok(AxisNoise::default()),
        other => Err(ctx.err(
            noise,
            format!("<noise> in {what}: expected type gaussian or none, found '{other}'"),
        )),
    }
}

/// `<mean>`, `<stddev>`, `<bias_mean>` and `<bias_stddev>` under `node`.
fn axis_values(ctx: &Ctx<'_, '_>, node: Node<'_, '_>, what: &str, unit: &str) -> Result<AxisNoise> {
    let mut a = AxisNoise::default();
    for n in elements(node) {
        match n.tag_name().name() {
            "mean" => a.mean = ctx.number(n, what, unit)?,
            "stddev" => a.stddev = ctx.non_negative(n, what, unit)?,
            "bias_mean" => a.bias_mean = ctx.number(n, what, unit)?,
            "bias_stddev" => a.bias_stddev = ctx.non_negative(n, what, unit)?,
            _ => {}
        }
    }
    Ok(a)
}
