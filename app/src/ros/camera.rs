//! The camera's images (sensor_msgs/Image) and camera_info (sensor_msgs/CameraInfo) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::model::CameraInfo;

use super::convert::header;
use crate::bridge::RosPlan;
use crate::bridge::camera::{CameraWire, Channel, Channels};
use crate::bridge::copy_fields;
use crate::bridge::events::ImageFrame;

/// One image topic and its camera_info topic.
struct ImageTopics {
    image: Option<Publisher<msgs::Image>>,
    info: Option<Publisher<msgs::CameraInfo>>,
    msg: msgs::Image,
}

impl ImageTopics {
    fn advertise(
        node: &Node,
        image: Option<&str>,
        info: Option<&str>,
        encoding: &str,
    ) -> Result<Self> {
        Ok(Self {
            image: image.map(|t| node.advertise(t, 2, false)).transpose()?,
            info: info.map(|t| node.advertise(t, 10, false)).transpose()?,
            msg: msgs::Image {
                encoding: encoding.into(),
                ..msgs::Image::default()
            },
        })
    }
}

/// The camera's publishers (none when the robot has no camera).
pub(super) struct Camera {
    topics: Channels<ImageTopics>,
    info_msg: msgs::CameraInfo,
}

impl Camera {
    /// Advertises the plan's camera topics.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let (image, info) = (plan.image_topic.as_deref(), plan.info_topic.as_deref());
        let depth = (
            plan.depth_image_topic.as_deref(),
            plan.depth_info_topic.as_deref(),
        );
        Ok(Self {
            topics: Channels {
                colour: ImageTopics::advertise(node, image, info, "rgb8")?,
                depth: ImageTopics::advertise(node, depth.0, depth.1, "32FC1")?,
            },
            info_msg: msgs::CameraInfo::default(),
        })
    }
}

impl CameraWire for Camera {
    fn calibrate(&mut self, c: &CameraInfo) {
        let msg = &mut self.info_msg;
        msg.header = header(&c.frame_id);
        msg.distortion_model = c.distortion_model.to_owned();
        msg.d = c.d.to_vec();
        copy_fields!(msg, c; height, width, k, r, p);
        for topics in [&mut self.topics.colour, &mut self.topics.depth] {
            topics.msg.header.frame_id.clone_from(&c.frame_id);
        }
    }

    fn info(&mut self, channel: Channel, image: &ImageFrame) {
        let msg = &mut self.info_msg;
        // The camera's frame number, which the boxes' image_header names too.
        msg.header.seq = image.seq as u32;
        msg.header.stamp_s = image.stamp_s;
        if let Some(p) = self.topics.get_mut(channel).info.as_mut() {
            p.publish(msg);
        }
    }

    fn image(&mut self, channel: Channel, image: &mut ImageFrame) {
        let topics = self.topics.get_mut(channel);
        let Some(p) = topics.image.as_mut() else {
            return;
        };
        let (data, bytes_per_px) = match channel {
            Channel::Colour => (&mut image.pixels, 3),
            Channel::Depth => (&mut image.depth, 4),
        };
        let msg = &mut topics.msg;
        msg.header.seq = image.seq as u32;
        msg.header.stamp_s = image.stamp_s;
        msg.width = image.width;
        msg.height = image.height;
        msg.step = image.width * bytes_per_px;
        // Published from the frame's buffer, which stays with the frame.
        std::mem::swap(&mut msg.data, data);
        p.publish(msg);
        std::mem::swap(&mut msg.data, data);
    }
}
