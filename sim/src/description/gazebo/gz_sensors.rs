//! Modern Gazebo's sensors: a `<sensor>` with no ROS plugin in an SDF model or a description
//! with gz-sim systems publishes on its `<topic>` (gz-sim's default name when absent) with the
//! frame `<gz_frame_id>` names, as gz-sim's Sensors, IMU and NavSat systems do. Each kind is the
//! same sensor model as its Gazebo classic declaration; only the names differ.
//!
//! | type | publishes |
//! |---|---|
//! | `gpu_lidar`, `lidar` (and `ray`, `gpu_ray`) | one plane: LaserScan on `<topic>`; more beams: PointCloud2 on `<topic>/points` |
//! | `camera` | Image on `<topic>`, CameraInfo on `<camera_info_topic>` (default: `camera_info` beside `<topic>`) |
//! | `depth_camera` | depth Image (32FC1) on `<topic>`, PointCloud2 on `<topic>/points` |
//! | `rgbd_camera` | `<topic>/image`, `<topic>/depth_image`, `<topic>/points`, `<topic>/camera_info` |
//! | `imu` | Imu on `<topic>`, orientation against the world |
//! | `navsat`, `gps` | NavSatFix on `<topic>` |

use super::values::{Ctx, Node, text_of};
use super::{camera, gps, imu, ray};
use crate::description::xml::elements;
use crate::error::Result;
use crate::model::sensors::{CameraConfig, GpsConfig, ImuConfig, LaserConfig, LidarConfig};

/// What a gz-sim sensor is to rover.
#[derive(Debug)]
pub(super) enum GzSensor {
    /// A one-plane lidar.
    Laser(LaserConfig),
    /// A multi-beam lidar.
    Lidar(LidarConfig),
    /// A camera (colour, depth or RGB-D).
    Camera(Box<CameraConfig>),
    /// An IMU.
    Imu(ImuConfig),
    /// A NavSat receiver.
    Gps(GpsConfig),
    /// Not simulated: why, for the summary line.
    Ignored(String),
}

/// The `<topic>` and frame a gz-sim sensor names, gz-sim's defaults when absent.
struct Names {
    /// `<topic>`, or `/world/default/model/<model>/link/<link>/sensor/<name>/<leaf>`.
    topic: String,
    /// `<gz_frame_id>` (or Fortress's `<ignition_frame_id>`), or the scoped name
    /// `<model>::<link>::<name>` gz-sim stamps otherwise.
    frame: String,
}

fn names(ctx: &Ctx<'_, '_>, sensor: Node<'_, '_>, link: &str, leaf: &str) -> Names {
    let name = sensor.attribute("name").unwrap_or("sensor");
    let child_text = |tags: &[&str]| {
        elements(sensor)
            .find(|n| tags.contains(&n.tag_name().name()))
            .map(|n| text_of(n).to_owned())
            .filter(|t| !t.is_empty())
    };
    Names {
        topic: child_text(&["topic"]).unwrap_or_else(|| {
            format!(
                "/world/default/model/{}/link/{link}/sensor/{name}/{leaf}",
                ctx.model
            )
        }),
        frame: child_text(&["gz_frame_id", "ignition_frame_id"])
            .unwrap_or_else(|| format!("{}::{link}::{name}", ctx.model)),
    }
}

/// `leaf` beside the last segment of `topic` (`camera/image_raw` -> `camera/camera_info`).
fn sibling(topic: &str, leaf: &str) -> String {
    match topic.rsplit_once('/') {
        Some((dir, _)) => format!("{dir}/{leaf}"),
        None => leaf.to_owned(),
    }
}

/// Reads gz-sim sensor `sensor` on `link`.
pub(super) fn read(ctx: &Ctx<'_, '_>, sensor: Node<'_, '_>, link: &str) -> Result<GzSensor> {
    let kind = sensor.attribute("type").unwrap_or("?");
    let name = sensor.attribute("name").unwrap_or("?");
    Ok(match kind {
        "gpu_lidar" | "lidar" | "gpu_ray" | "ray" => {
            let n = names(ctx, sensor, link, "scan");
            match ray::parse(ctx, sensor, link)? {
                ray::RaySensor::Planar(mut laser) => {
                    laser.topic = n.topic;
                    laser.frame_name = n.frame;
                    GzSensor::Laser(laser)
                }
                ray::RaySensor::Lidar(mut lidar) => {
                    lidar.rays.topic = format!("{}/points", n.topic);
                    lidar.rays.frame_name = n.frame;
                    GzSensor::Lidar(lidar)
                }
            }
        }
        "camera" | "depth_camera" | "depth" | "rgbd_camera" => {
            let leaf = match kind {
                "camera" => "image",
                "rgbd_camera" => "",
                _ => "depth_image",
            };
            let mut n = names(ctx, sensor, link, leaf);
            n.topic = n.topic.trim_end_matches('/').to_owned();
            let mut c = camera::parse(ctx, sensor, link)?;
            let camera_child = |tag: &str| {
                elements(sensor)
                    .filter(|e| e.has_tag_name("camera"))
                    .flat_map(elements)
                    .find(|e| e.has_tag_name(tag))
                    .map(|e| text_of(e).to_owned())
                    .filter(|t| !t.is_empty())
            };
            // Only the plain camera reads <camera_info_topic>; every camera's images carry
            // <optical_frame_id> when given.
            let info = (kind == "camera")
                .then(|| camera_child("camera_info_topic"))
                .flatten();
            c.camera_name = String::new();
            c.frame_name = camera_child("optical_frame_id").unwrap_or(n.frame);
            if kind == "rgbd_camera" {
                let t = &n.topic;
                c.image_topic = format!("{t}/image");
                c.info_topic = info.unwrap_or_else(|| format!("{t}/camera_info"));
                if let Some(d) = &mut c.depth {
                    d.image_topic = format!("{t}/depth_image");
                    d.info_topic = c.info_topic.clone();
                    d.cloud_topic = format!("{t}/points");
                }
            } else {
                c.info_topic = info.unwrap_or_else(|| sibling(&n.topic, "camera_info"));
                if let Some(d) = &mut c.depth {
                    // gz-sim's depth camera has no colour image: rover's goes beside it.
                    c.image_topic = format!("{}/image", n.topic);
                    d.image_topic = n.topic.clone();
                    d.info_topic = c.info_topic.clone();
                    d.cloud_topic = format!("{}/points", n.topic);
                } else {
                    c.image_topic = n.topic;
                }
            }
            if let Some(d) = &mut c.depth {
                // gz-sim's cloud keeps every depth the camera's clip planes allow.
                d.cloud_cutoff_m = c.clip_near_m;
                d.cloud_cutoff_max_m = c.clip_far_m;
            }
            GzSensor::Camera(Box::new(c))
        }
        "imu" => {
            let n = names(ctx, sensor, link, "imu");
            GzSensor::Imu(imu::parse_gz(ctx, sensor, link, n.topic, n.frame)?)
        }
        "navsat" | "gps" => {
            let n = names(ctx, sensor, link, "navsat");
            GzSensor::Gps(gps::parse_gz(ctx, sensor, link, n.topic, n.frame)?)
        }
        "contact" => GzSensor::Ignored(format!(
            "sensor \"{name}\" (gz-sim contact: ros_gz_interfaces/Contacts is not published; a libgazebo_ros_bumper.so plugin gives gazebo_msgs/ContactsState)"
        )),
        _ => GzSensor::Ignored(format!("sensor \"{name}\" (type {kind})")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_info_goes_beside_the_image() {
        assert_eq!(
            sibling("camera/image_raw", "camera_info"),
            "camera/camera_info"
        );
        assert_eq!(sibling("image", "camera_info"), "camera_info");
        assert_eq!(sibling("/a/b/image", "camera_info"), "/a/b/camera_info");
    }
}
