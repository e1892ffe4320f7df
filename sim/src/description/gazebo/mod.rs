//! The `<gazebo>` URDF extensions rover honours: the `libgazebo_ros_diff_drive.so` plugin, camera
//! `<sensor>` blocks (with `libgazebo_ros_camera.so`), ray sensors (`ray.rs`: 2D lasers and 3D
//! lidars), IMUs (`imu.rs`), ground-truth poses (`p3d.rs`), hector's GPS (`gps.rs`), bumpers (`bumper.rs`), mimic
//! joint plugins (`mimic.rs`), and per-link friction (`mu1`/`mu2`).
//!
//! Parameters keep gazebo_ros's names and defaults; values that do not parse are errors with the
//! file, line and element.

mod bumper;
mod camera;
mod gps;
pub(crate) mod gz;
pub(crate) mod gz_joints;
mod gz_sensors;
mod imu;
mod mimic;
pub(crate) use mimic::MimicPlugin;
mod p3d;
mod ray;
mod values;

use std::collections::BTreeMap;

use std::path::Path;
use values::{Ctx, Node, text_of};

use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::model::actuation::RosControlPlugin;
use crate::model::drive::{DiffDriveConfig, OdometrySource};
use crate::model::sensors::{
    BumperConfig, CameraConfig, GpsConfig, ImuConfig, LaserConfig, LidarConfig, P3dConfig,
};

/// Everything read from `<gazebo>` elements.
#[derive(Debug, Default)]
pub(crate) struct Extensions {
    pub diff_drive: Option<DiffDriveConfig>,
    pub ros_control: Option<RosControlPlugin>,
    pub cameras: Vec<CameraConfig>,
    pub lasers: Vec<LaserConfig>,
    pub lidars: Vec<LidarConfig>,
    pub imus: Vec<ImuConfig>,
    pub p3ds: Vec<P3dConfig>,
    pub gpss: Vec<GpsConfig>,
    pub bumpers: Vec<BumperConfig>,
    /// Link name -> friction coefficient (min of mu1 and mu2).
    pub friction: BTreeMap<String, f32>,
    /// Link name -> contact stiffness `<kp>` (N/m).
    pub contact_kp: BTreeMap<String, f32>,
    /// Sensors and plugins rover does not simulate, for one summary line.
    pub ignored: Vec<String>,
    /// gz-sim's JointStatePublisher system.
    pub joint_state_publisher: Option<crate::model::sensors::JointStatePublisherConfig>,
    /// gz-sim's joint controller systems, as rover's controllers (each on its gz topic).
    pub gz_controllers: Vec<crate::model::ControllerSpec>,
    /// gz_ros2_control's `<parameters>` (a ros2_control controllers file) and the plugin's line.
    pub ros2_control: Option<(String, u32)>,
    /// Mimic joint plugins: joints that follow another, as `<mimic>` would say.
    pub mimics: Vec<MimicPlugin>,
}

/// Reads every `<gazebo>` element under `<robot>`.
pub(crate) fn parse(doc: &roxmltree::Document<'_>, path: &Path) -> Result<Extensions> {
    let blocks = elements(doc.root_element())
        .filter(|n| n.has_tag_name("gazebo"))
        .map(|gz| (gz.attribute("reference"), gz));
    let robot_name = doc.root_element().attribute("name").unwrap_or("robot");
    parse_blocks(doc, path, robot_name, false, blocks)
}

/// Reads the Gazebo extensions in `blocks`: each an element whose children are plugins,
/// sensors and surface parameters, on the link it names (`<gazebo reference>`, or an SDF
/// `<link>`) or on the model (`None`). `sdf`: the description is an SDF model.
pub(crate) fn parse_blocks<'a, 'input: 'a>(
    doc: &'a roxmltree::Document<'input>,
    path: &Path,
    robot_name: &str,
    sdf: bool,
    blocks: impl Iterator<Item = (Option<&'a str>, Node<'a, 'input>)>,
) -> Result<Extensions> {
    let modern = sdf
        || doc.descendants().any(|n| {
            let file = n.attribute("filename").unwrap_or("");
            n.has_tag_name("plugin")
                && (gz::is_system(file, n.attribute("name").unwrap_or(""))
                    || file.contains("gz_ros2_control"))
        });
    let ctx = Ctx {
        doc,
        path,
        modern,
        model: robot_name,
    };
    let mut ext = Extensions::default();
    for (reference, gz) in blocks {
        let mut mu: [Option<f64>; 2] = [None, None];
        for child in elements(gz) {
            match child.tag_name().name() {
                "plugin" => {
                    let file = child.attribute("filename").unwrap_or("");
                    let name = child.attribute("name").unwrap_or("");
                    if gz::is_system(file, name) {
                        read_system(&ctx, child, &mut ext)?;
                    } else if file.contains("gazebo_ros_diff_drive")
                        || file.contains("gazebo_ros_skid_steer_drive")
                    {
                        if let Some(first) = &ext.diff_drive {
                            return Err(ctx.err(
                                child,
                                format!(
                                    "a second drive plugin (the first is at line {}); expected one diff drive or skid steer plugin",
                                    first.line.unwrap_or(0)
                                ),
                            ));
                        }
                        ext.diff_drive = Some(parse_diff_drive(&ctx, child)?);
                    } else if file.contains("gz_ros2_control") || file.contains("ign_ros2_control")
                    {
                        ext.ros2_control = Some(parse_ros2_control(&ctx, child)?);
                    } else if file.contains("gazebo_ros_control") {
                        ext.ros_control = Some(parse_ros_control(&ctx, child)?);
                    } else if imu::is_model_plugin(file) {
                        ext.imus.push(imu::parse_model_plugin(&ctx, child)?);
                    } else if p3d::is_plugin(file) {
                        ext.p3ds.push(p3d::parse(&ctx, child)?);
                    } else if gps::is_plugin(file) {
                        ext.gpss.push(gps::parse(&ctx, child)?);
                    } else if mimic::is_plugin(file) {
                        ext.mimics.push(mimic::parse(&ctx, child)?);
                    } else {
                        ext.ignored.push(format!(
                            "plugin {}",
                            if file.is_empty() {
                                "(no filename)"
                            } else {
                                file
                            }
                        ));
                    }
                }
                "sensor" => read_sensor(&ctx, child, reference, &mut ext)?,
                "mu1" => {
                    mu[0] = Some(ctx.non_negative(
                        child,
                        "<gazebo reference>",
                        "friction coefficient",
                    )?)
                }
                "kp" => {
                    if let Some(link) = reference {
                        // A soft-contact tuning, not worth refusing a robot over: warned.
                        match ctx.positive(child, "<gazebo reference>", "contact stiffness, N/m") {
                            Ok(kp) => {
                                ext.contact_kp.insert(link.to_owned(), kp as f32);
                            }
                            Err(e) => tracing::warn!("{e}; ignored"),
                        }
                    }
                }
                "mu2" => {
                    mu[1] = Some(ctx.non_negative(
                        child,
                        "<gazebo reference>",
                        "friction coefficient",
                    )?)
                }
                _ => {}
            }
        }
        if let (Some(link), [Some(_), _] | [_, Some(_)]) = (reference, mu) {
            let friction = mu.iter().flatten().fold(f64::INFINITY, |a, &b| a.min(b));
            ext.friction.insert(link.to_owned(), friction as f32);
        }
    }
    Ok(ext)
}

/// A gz-sim system on the model into `ext`.
fn read_system(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>, ext: &mut Extensions) -> Result<()> {
    let file = plugin.attribute("filename").unwrap_or("");
    let name = plugin.attribute("name").unwrap_or("");
    match gz::system(file, name) {
        gz::System::DiffDrive => {
            if let Some(first) = &ext.diff_drive {
                return Err(ctx.err(
                    plugin,
                    format!(
                        "a second drive plugin (the first is at line {}); expected one diff drive system",
                        first.line.unwrap_or(0)
                    ),
                ));
            }
            ext.diff_drive = Some(gz::parse_diff_drive(ctx, plugin, ctx.model)?);
        }
        gz::System::JointStatePublisher => {
            ext.joint_state_publisher =
                Some(gz::parse_joint_state_publisher(plugin, ctx.doc, ctx.model));
        }
        gz::System::Joint(system) => ext
            .gz_controllers
            .push(gz_joints::parse(ctx, plugin, system)?),
        gz::System::World => {}
        gz::System::Other => {
            let entry = format!("system {file} ({name})");
            if !ext.ignored.contains(&entry) {
                ext.ignored.push(entry);
            }
        }
    }
    Ok(())
}

/// A `<sensor>` in a `<gazebo>` element (on link `reference`) into `ext`; kinds and plugins
/// rover does not simulate are listed in `ext.ignored`.
fn read_sensor(
    ctx: &Ctx<'_, '_>,
    sensor: Node<'_, '_>,
    reference: Option<&str>,
    ext: &mut Extensions,
) -> Result<()> {
    let robot_name = ctx.model;
    let kind = sensor.attribute("type").unwrap_or("?");
    let name = sensor.attribute("name").unwrap_or("?");
    let simulated = matches!(
        kind,
        "camera"
            | "depth"
            | "ray"
            | "gpu_ray"
            | "imu"
            | "contact"
            | "gpu_lidar"
            | "lidar"
            | "depth_camera"
            | "rgbd_camera"
            | "navsat"
    );
    let link = match reference {
        Some(link) => link,
        None if simulated => {
            return Err(ctx.err(
                sensor,
                format!("<sensor type=\"{kind}\"> must sit in <gazebo reference=\"LINK\"> naming the link it is mounted on"),
            ));
        }
        None => "",
    };
    if ctx.modern && !elements(sensor).any(|p| p.has_tag_name("plugin")) {
        match gz_sensors::read(ctx, sensor, link)? {
            gz_sensors::GzSensor::Laser(l) => ext.lasers.push(l),
            gz_sensors::GzSensor::Lidar(l) => ext.lidars.push(l),
            gz_sensors::GzSensor::Camera(c) => ext.cameras.push(*c),
            gz_sensors::GzSensor::Imu(i) => ext.imus.push(i),
            gz_sensors::GzSensor::Gps(g) => ext.gpss.push(g),
            gz_sensors::GzSensor::Ignored(why) => ext.ignored.push(why),
        }
        return Ok(());
    }
    match kind {
        "camera" | "depth" => ext.cameras.push(camera::parse(ctx, sensor, link)?),
        "ray" | "gpu_ray"
            if elements(sensor).any(|p| {
                p.has_tag_name("plugin")
                    && values::plugin_stem(p.attribute("filename").unwrap_or(""))
                        .ends_with("ros_range")
            }) =>
        {
            ext.ignored.push(format!(
                "sensor \"{name}\" (a range finder: sensor_msgs/Range is not simulated)"
            ));
        }
        "ray" | "gpu_ray" => match ray::parse(ctx, sensor, link)? {
            ray::RaySensor::Planar(laser) => ext.lasers.push(laser),
            ray::RaySensor::Lidar(lidar) => ext.lidars.push(lidar),
        },
        "imu" => match imu::parse_sensor(ctx, sensor, link, robot_name)? {
            Some(imu) => ext.imus.push(imu),
            None => ext.ignored.push(format!(
                "sensor \"{name}\" (type imu, no ROS plugin: nothing published)"
            )),
        },
        "gps" => match gps::parse_sensor(ctx, sensor, link)? {
            Some(g) => ext.gpss.push(g),
            None => ext.ignored.push(format!(
                "sensor \"{name}\" (type gps, no libgazebo_ros_gps_sensor.so: nothing published)"
            )),
        },
        "contact" => match bumper::parse(ctx, sensor, link)? {
            Some(b) => ext.bumpers.push(b),
            None => ext.ignored.push(format!(
                "sensor \"{name}\" (type contact, no libgazebo_ros_bumper.so: nothing published)"
            )),
        },
        _ => ext.ignored.push(format!("sensor \"{name}\" (type {kind})")),
    }
    Ok(())
}

/// gz_ros2_control's `<parameters>`: the controllers file (one; a second is an error).
fn parse_ros2_control(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<(String, u32)> {
    let files: Vec<Node<'_, '_>> = elements(plugin)
        .filter(|p| p.has_tag_name("parameters"))
        .collect();
    match files.as_slice() {
        [one] if !text_of(*one).is_empty() => {
            Ok((text_of(*one).to_owned(), line_of(ctx.doc, plugin)))
        }
        [] | [_] => Err(ctx.err(
            plugin,
            "the gz_ros2_control plugin: expected <parameters> naming its controllers YAML"
                .to_owned(),
        )),
        [_, second, ..] => Err(ctx.err(
            *second,
            "a second <parameters> in the gz_ros2_control plugin: rover reads one controllers file"
                .to_owned(),
        )),
    }
}

/// gazebo_ros_control: the namespace of the controllers' topics and the control period.
fn parse_ros_control(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<RosControlPlugin> {
    let mut out = RosControlPlugin {
        line: Some(line_of(ctx.doc, plugin)),
        ..RosControlPlugin::default()
    };
    for p in elements(plugin) {
        match p.tag_name().name() {
            "robotNamespace" => out.namespace = text_of(p).trim_matches('/').to_owned(),
            "controlPeriod" => {
                out.control_period_s =
                    Some(ctx.positive(p, "the libgazebo_ros_control.so plugin", "seconds")?)
            }
            "robotSimType" if !text_of(p).is_empty() => out.sim_type = text_of(p).to_owned(),
            _ => {}
        }
    }
    Ok(out)
}

/// gazebo_ros_diff_drive and gazebo_ros_skid_steer_drive (same wheel speed formula; the skid
/// steer drives a front and a rear joint per side).
fn parse_diff_drive(ctx: &Ctx<'_, '_>, plugin: Node<'_, '_>) -> Result<DiffDriveConfig> {
    let skid = plugin
        .attribute("filename")
        .is_some_and(|f| f.contains("skid_steer_drive"));
    let what = if skid {
        "the libgazebo_ros_skid_steer_drive.so plugin"
    } else {
        "the libgazebo_ros_diff_drive.so plugin"
    };
    let mut c = DiffDriveConfig {
        name: plugin
            .attribute("name")
            .unwrap_or("differential_drive_controller")
            .to_owned(),
        line: Some(line_of(ctx.doc, plugin)),
        ..DiffDriveConfig::default()
    };
    for p in elements(plugin) {
        let text = || text_of(p).to_owned();
        match p.tag_name().name() {
            "commandTopic" => c.command_topic = text(),
            "odometryTopic" => c.odometry_topic = text(),
            "odometryFrame" => c.odometry_frame = text(),
            "robotBaseFrame" => c.robot_base_frame = text(),
            "leftJoint" | "leftFrontJoint" => c.left_joint = text(),
            "rightJoint" | "rightFrontJoint" => c.right_joint = text(),
            "leftRearJoint" => c.extra_left_joints.push(text()),
            "rightRearJoint" => c.extra_right_joints.push(text()),
            "wheelSeparation" => c.wheel_separation_m = ctx.positive(p, what, "metres")?,
            "wheelDiameter" => c.wheel_diameter_m = ctx.positive(p, what, "metres")?,
            "wheelTorque" | "torque" => c.wheel_torque_nm = ctx.positive(p, what, "N m")?,
            "wheelAcceleration" => {
                c.wheel_acceleration_mps2 =
                    ctx.non_negative(p, what, "m/s^2 of rim speed, 0 = unlimited")?
            }
            "updateRate" => c.update_rate_hz = ctx.non_negative(p, what, "Hz")?,
            "odometrySource" => {
                c.odometry_source = match text_of(p) {
                    "world" | "1" => OdometrySource::World,
                    "encoder" | "0" => OdometrySource::Encoder,
                    other => {
                        return Err(ctx.err(
                            p,
                            format!("<odometrySource> in {what}: expected world or encoder, found '{other}'"),
                        ));
                    }
                }
            }
            "publishWheelTF" => c.publish_wheel_tf = ctx.boolean(p, what)?,
            "publishOdomTF" | "publishTf" => c.publish_odom_tf = ctx.boolean(p, what)?,
            "publishWheelJointState" => c.publish_wheel_joint_state = ctx.boolean(p, what)?,
            "cmdTimeout" => {
                let t = ctx.non_negative(p, what, "seconds, 0 = off")?;
                c.cmd_timeout_s = (t > 0.0).then_some(t);
            }
            "alwaysOn" | "legacyMode" | "rosDebugLevel" | "robotNamespace" | "odometryRate"
            | "publishOdom" | "broadcastTF" | "covariance_x" | "covariance_y"
            | "covariance_yaw" => {}
            other => tracing::warn!(
                "{}:{}: <{other}> in {what}: unknown parameter, ignored",
                ctx.path.display(),
                line_of(ctx.doc, p)
            ),
        }
    }
    Ok(c)
}
