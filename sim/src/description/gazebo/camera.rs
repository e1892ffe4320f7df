//! Camera sensors, `<sensor type="camera">` (and `depth`; gz-sim's `depth_camera` and
//! `rgbd_camera`): the SDF `<camera>` element and the gazebo_ros_camera plugin's parameters,
//! Gazebo's defaults where both are silent.

use super::values::{Ctx, Node, parse_noise, read_sensor_pose, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::model::sensors::{CameraConfig, DepthOutput, Distortion, PixelFormat};

/// A camera `<sensor>` on `link`: the SDF `<camera>` element and the gazebo_ros_camera plugin's
/// parameters, Gazebo's defaults where both are silent.
pub(super) fn parse(ctx: &Ctx<'_, '_>, sensor: Node<'_, '_>, link: &str) -> Result<CameraConfig> {
    let name = sensor.attribute("name").unwrap_or("camera").to_owned();
    let what = format!("<sensor name=\"{name}\">");
    let what = what.as_str();
    let mut c = CameraConfig {
        name: name.clone(),
        link: link.to_owned(),
        update_rate_hz: 30.0,
        horizontal_fov_rad: 1.047,
        width_px: 320,
        height_px: 240,
        format: PixelFormat::Rgb8,
        clip_near_m: 0.1,
        clip_far_m: 100.0,
        noise: None,
        distortion: Distortion::default(),
        camera_name: name,
        frame_name: link.to_owned(),
        image_topic: "image_raw".to_owned(),
        info_topic: "camera_info".to_owned(),
        depth: matches!(
            sensor.attribute("type"),
            Some("depth" | "depth_camera" | "rgbd_camera")
        )
        .then(DepthOutput::default),
        line: Some(line_of(ctx.doc, sensor)),
    };
    let mut plugin_distortion = Distortion::default();
    let mut sdf_distortion = None;
    for s in elements(sensor) {
        match s.tag_name().name() {
            "update_rate" => c.update_rate_hz = ctx.non_negative(s, what, "Hz")?,
            "pose" => {
                // Read (a malformed pose is an error) but not applied: said, not silent.
                let pose = read_sensor_pose(ctx, s, what)?;
                if pose.translation.length() > 1e-6
                    || pose.rotation.angle_between(glam::Quat::IDENTITY) > 1e-6
                {
                    tracing::warn!(
                        "{}:{}: <pose> of {what}: not applied; rover's camera sits at its link's origin ({}), looking along its x axis",
                        ctx.path.display(),
                        line_of(ctx.doc, s),
                        c.link
                    );
                }
            }
            "camera" => read_camera_element(ctx, s, what, &mut c, &mut sdf_distortion)?,
            "plugin" => {
                // gazebo_ros_depth_camera has no far cutoff; gazebo_ros_openni_kinect's is 5 m.
                if let Some(d) = &mut c.depth
                    && s.attribute("filename")
                        .unwrap_or("")
                        .contains("gazebo_ros_depth_camera")
                {
                    d.cloud_cutoff_max_m = f64::INFINITY;
                }
                read_camera_plugin(ctx, s, what, &mut c, &mut plugin_distortion)?
            }
            _ => {}
        }
    }
    if let Some(d) = &c.depth
        && d.cloud_cutoff_m >= d.cloud_cutoff_max_m
    {
        return Err(ctx.err(
            sensor,
            format!(
                "{what}: expected <pointCloudCutoff> below <pointCloudCutoffMax>, found {} and {}",
                d.cloud_cutoff_m, d.cloud_cutoff_max_m
            ),
        ));
    }
    c.distortion = sdf_distortion.unwrap_or(plugin_distortion);
    Ok(c)
}

/// Reads the SDF `<camera>` element of camera sensor `what` into `c`; its `<distortion>`, when
/// present, goes to `sdf_distortion` (it wins over the plugin's).
fn read_camera_element(
    ctx: &Ctx<'_, '_>,
    camera: Node<'_, '_>,
    what: &str,
    c: &mut CameraConfig,
    sdf_distortion: &mut Option<Distortion>,
) -> Result<()> {
    for cam in elements(camera) {
        match cam.tag_name().name() {
            "horizontal_fov" => {
                let fov = ctx.positive(cam, what, "radians")?;
                if fov >= std::f64::consts::PI {
                    return Err(ctx.err(
                        cam,
                        format!("<horizontal_fov> in {what}: expected less than pi radians for a pinhole camera, found {fov}"),
                    ));
                }
                c.horizontal_fov_rad = fov;
            }
            "image" => read_camera_image(ctx, cam, what, c)?,
            "clip" => read_camera_clip(ctx, cam, what, c)?,
            "noise" => c.noise = parse_noise(ctx, cam, what, "0..1 intensity")?,
            "distortion" => {
                let mut d = Distortion::default();
                for k in elements(cam) {
                    let slot = match k.tag_name().name() {
                        "k1" => &mut d.k1,
                        "k2" => &mut d.k2,
                        "k3" => &mut d.k3,
                        "p1" => &mut d.p1,
                        "p2" => &mut d.p2,
                        _ => continue,
                    };
                    *slot = ctx.number(k, what, "coefficient")?;
                }
                *sdf_distortion = Some(d);
            }
            _ => {}
        }
    }
    Ok(())
}

/// Reads `<camera><image>` (width, height, pixel format) of camera sensor `what` into `c`.
fn read_camera_image(
    ctx: &Ctx<'_, '_>,
    image: Node<'_, '_>,
    what: &str,
    c: &mut CameraConfig,
) -> Result<()> {
    for img in elements(image) {
        match img.tag_name().name() {
            "width" => c.width_px = ctx.pixels(img, what)?,
            "height" => c.height_px = ctx.pixels(img, what)?,
            "format" => {
                c.format = match text_of(img) {
                    "R8G8B8" | "RGB_INT8" => PixelFormat::Rgb8,
                    "B8G8R8" | "BGR_INT8" => PixelFormat::Bgr8,
                    "L8" | "L_INT8" => PixelFormat::Mono8,
                    other => {
                        return Err(ctx.err(
                            img,
                            format!(
                                "<format> in {what}: expected R8G8B8, B8G8R8 or L8, found '{other}'"
                            ),
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Reads `<camera><clip>` (near and far planes) of camera sensor `what` into `c`, which must
/// then have near < far.
fn read_camera_clip(
    ctx: &Ctx<'_, '_>,
    clip_element: Node<'_, '_>,
    what: &str,
    c: &mut CameraConfig,
) -> Result<()> {
    for clip in elements(clip_element) {
        match clip.tag_name().name() {
            "near" => c.clip_near_m = ctx.positive(clip, what, "metres")?,
            "far" => c.clip_far_m = ctx.positive(clip, what, "metres")?,
            _ => {}
        }
    }
    if c.clip_near_m >= c.clip_far_m {
        return Err(ctx.err(
            clip_element,
            format!(
                "<clip> in {what}: expected near < far, found near {} and far {}",
                c.clip_near_m, c.clip_far_m
            ),
        ));
    }
    Ok(())
}

/// Reads the gazebo_ros_camera `<plugin>` parameters of camera sensor `what` into `c`; its
/// distortion coefficients go to `plugin_distortion`.
fn read_camera_plugin(
    ctx: &Ctx<'_, '_>,
    plugin: Node<'_, '_>,
    what: &str,
    c: &mut CameraConfig,
    plugin_distortion: &mut Distortion,
) -> Result<()> {
    for p in elements(plugin) {
        let text = || text_of(p).to_owned();
        match p.tag_name().name() {
            "cameraName" => c.camera_name = text(),
            "frameName" => c.frame_name = text(),
            "imageTopicName" => c.image_topic = text(),
            "cameraInfoTopicName" => c.info_topic = text(),
            "depthImageTopicName" => {
                if let Some(d) = &mut c.depth {
                    d.image_topic = text();
                }
            }
            "depthImageCameraInfoTopicName" => {
                if let Some(d) = &mut c.depth {
                    d.info_topic = text();
                }
            }
            "pointCloudTopicName" => {
                if let Some(d) = &mut c.depth {
                    d.cloud_topic = text();
                }
            }
            "pointCloudCutoff" => {
                let v = ctx.non_negative(p, what, "metres")?;
                if let Some(d) = &mut c.depth {
                    d.cloud_cutoff_m = v;
                }
            }
            "pointCloudCutoffMax" => {
                let v = ctx.positive(p, what, "metres")?;
                if let Some(d) = &mut c.depth {
                    d.cloud_cutoff_max_m = v;
                }
            }
            "distortionK1" => plugin_distortion.k1 = ctx.number(p, what, "coefficient")?,
            "distortionK2" => plugin_distortion.k2 = ctx.number(p, what, "coefficient")?,
            "distortionK3" => plugin_distortion.k3 = ctx.number(p, what, "coefficient")?,
            "distortionT1" => plugin_distortion.p1 = ctx.number(p, what, "coefficient")?,
            "distortionT2" => plugin_distortion.p2 = ctx.number(p, what, "coefficient")?,
            _ => {}
        }
    }
    Ok(())
}
