//! The camera's image (sensor_msgs/Image, `rgb8`) and its calibration (sensor_msgs/CameraInfo)
//! on `/<cameraName>/<imageTopicName>` and `/<cameraName>/<cameraInfoTopicName>`, with every
//! image; a depth camera's depth image (`32FC1`, metres along the optical axis, NaN where
//! nothing is in range, as gazebo_ros_openni_kinect publishes it) and its camera_info on
//! `/<cameraName>/<depthImageTopicName>` and `/<cameraName>/<depthImageCameraInfoTopicName>`.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::CameraFrame;

use super::convert::header;
use super::events::{ImageFrame, Start, TopicFamily};
use super::plan::RosPlan;

/// Publishes the camera's topics (none when the robot has no camera).
pub(super) struct Camera {
    image: Option<Publisher<msgs::Image>>,
    info: Option<Publisher<msgs::CameraInfo>>,
    depth_image: Option<Publisher<msgs::Image>>,
    depth_info: Option<Publisher<msgs::CameraInfo>>,
    /// Whether the run has a camera (its calibration is in `info_msg`).
    calibrated: bool,
    image_msg: msgs::Image,
    info_msg: msgs::CameraInfo,
    depth_msg: msgs::Image,
}

impl Camera {
    /// Advertises the plan's camera topics.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            image: plan
                .image_topic
                .as_deref()
                .map(|t| node.advertise(t, 2, false))
                .transpose()?,
            info: plan
                .info_topic
                .as_deref()
                .map(|t| node.advertise(t, 10, false))
                .transpose()?,
            depth_image: plan
                .depth_image_topic
                .as_deref()
                .map(|t| node.advertise(t, 2, false))
                .transpose()?,
            depth_info: plan
                .depth_info_topic
                .as_deref()
                .map(|t| node.advertise(t, 10, false))
                .transpose()?,
            calibrated: false,
            image_msg: msgs::Image {
                encoding: "rgb8".into(),
                ..msgs::Image::default()
            },
            info_msg: msgs::CameraInfo::default(),
            depth_msg: msgs::Image {
                encoding: "32FC1".into(),
                ..msgs::Image::default()
            },
        })
    }
}

impl TopicFamily for Camera {
    fn start(&mut self, start: &Start) {
        if let Some(c) = &start.camera {
            self.info_msg = msgs::CameraInfo {
                header: header(&c.frame_id),
                height: c.height,
                width: c.width,
                distortion_model: c.distortion_model.to_owned(),
                d: c.d.to_vec(),
                k: c.k,
                r: c.r,
                p: c.p,
            };
            self.image_msg.header.frame_id = c.frame_id.clone();
            self.depth_msg.header.frame_id = c.frame_id.clone();
        }
        self.calibrated = start.camera.is_some();
    }

    fn image(&mut self, image: &mut ImageFrame) {
        // The camera's frame number, which the boxes' image_header names too.
        if self.calibrated {
            publish_info(self.info.as_mut(), &mut self.info_msg, image);
        }
        let meta = (image.seq as u32, image.stamp_s, image.width, image.height);
        publish_image(
            self.image.as_mut(),
            &mut self.image_msg,
            meta,
            3,
            &mut image.pixels,
        );
        // A depth camera's depth image and its camera_info (the colour camera's: the depth
        // image is rendered with the same intrinsics).
        if !image.depth.is_empty() {
            if self.calibrated {
                publish_info(self.depth_info.as_mut(), &mut self.info_msg, image);
            }
            publish_image(
                self.depth_image.as_mut(),
                &mut self.depth_msg,
                meta,
                4,
                &mut image.depth,
            );
        }
    }
}

/// Publishes the camera_info stamped like `image`.
fn publish_info(
    publisher: Option<&mut Publisher<msgs::CameraInfo>>,
    msg: &mut msgs::CameraInfo,
    image: &ImageFrame,
) {
    if let Some(p) = publisher {
        msg.header.seq = image.seq as u32;
        msg.header.stamp_s = image.stamp_s;
        p.publish(msg);
    }
}

/// Publishes `data` (rows of `bytes_per_px` x width) as `msg`, stamped with `(seq, stamp,
/// width, height)`: from the event's buffer, which stays with the event.
fn publish_image(
    publisher: Option<&mut Publisher<msgs::Image>>,
    msg: &mut msgs::Image,
    (seq, stamp_s, width, height): (u32, f64, u32, u32),
    bytes_per_px: u32,
    data: &mut Vec<u8>,
) {
    let Some(p) = publisher else {
        return;
    };
    msg.header.seq = seq;
    msg.header.stamp_s = stamp_s;
    msg.width = width;
    msg.height = height;
    msg.step = width * bytes_per_px;
    std::mem::swap(&mut msg.data, data);
    p.publish(msg);
    std::mem::swap(&mut msg.data, data);
}

/// The image to hand over (on the loop thread): `frame` copied into the recycled `pixels`,
/// its depth image (if any) into `depth` as 32FC1 bytes.
pub(crate) fn capture(
    frame: &CameraFrame<'_>,
    mut pixels: Vec<u8>,
    mut depth: Vec<u8>,
) -> ImageFrame {
    pixels.clear();
    pixels.extend_from_slice(frame.rgb);
    depth.clear();
    if let Some(metres) = frame.depth_m {
        depth.reserve(metres.len() * 4);
        for m in metres {
            depth.extend_from_slice(&m.to_le_bytes());
        }
    }
    ImageFrame {
        stamp_s: frame.sim_time_s,
        seq: frame.seq,
        width: frame.width,
        height: frame.height,
        pixels,
        depth,
    }
}
