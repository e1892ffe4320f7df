//! The camera's images (sensor_msgs/msg/Image) and camera_info (sensor_msgs/msg/CameraInfo) on
//! ROS 2, best effort as rclcpp's SensorDataQoS.

use anyhow::Result;
use rover_sim::model::CameraInfo;

use super::sinks::{Out, Sinks, header, sensor_qos};
use crate::bridge::RosPlan;
use crate::bridge::camera::{CameraWire, Channel, Channels};
use crate::bridge::copy_fields;
use crate::bridge::events::ImageFrame;
use rover_ros2::msgs::{self, Time};

/// One image topic and its camera_info topic.
struct ImageTopics {
    image: Option<Out<msgs::Image>>,
    info: Option<Out<msgs::CameraInfo>>,
}

/// The camera's topics (none when the robot has no camera).
pub(super) struct Camera {
    topics: Channels<ImageTopics>,
    info_msg: msgs::CameraInfo,
}

impl Camera {
    /// Creates the plan's camera topics on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let qos = sensor_qos();
        let mut topics = |image: &Option<String>, info: &Option<String>| -> Result<ImageTopics> {
            Ok(ImageTopics {
                image: sinks.maybe(image.as_deref(), &qos)?,
                info: sinks.maybe(info.as_deref(), &qos)?,
            })
        };
        Ok(Self {
            topics: Channels {
                colour: topics(&plan.image_topic, &plan.info_topic)?,
                depth: topics(&plan.depth_image_topic, &plan.depth_info_topic)?,
            },
            info_msg: msgs::CameraInfo::default(),
        })
    }
}

impl CameraWire for Camera {
    fn calibrate(&mut self, c: &CameraInfo) {
        let mut msg = msgs::CameraInfo {
            header: header(&c.frame_id),
            distortion_model: c.distortion_model.to_owned(),
            d: c.d.to_vec(),
            ..msgs::CameraInfo::default()
        };
        copy_fields!(msg, c; height, width, k, r, p);
        self.info_msg = msg;
    }

    fn info(&mut self, channel: Channel, image: &ImageFrame) {
        let stamp = Time::from_secs(image.stamp_s);
        self.info_msg.header.stamp = stamp;
        if let Some(out) = &mut self.topics.get_mut(channel).info {
            out.put(stamp, &self.info_msg);
        }
    }

    fn image(&mut self, channel: Channel, image: &mut ImageFrame) {
        let Self { topics, info_msg } = self;
        // The image's header is its camera_info's: the optical frame, the image's stamp.
        info_msg.header.stamp = Time::from_secs(image.stamp_s);
        let (data, encoding) = match channel {
            Channel::Colour => (&mut image.pixels, "rgb8"),
            Channel::Depth => (&mut image.depth, "32FC1"),
        };
        if let Some(out) = &mut topics.get_mut(channel).image {
            out.put_image(
                &info_msg.header,
                (image.width, image.height),
                encoding,
                data,
            );
        }
    }
}
