//! darknet_ros's topics and the ground truth's boxes (darknet_ros_msgs/msg/BoundingBoxes,
//! ObjectCount, the detection image, transient local as darknet_ros latches it) on ROS 2.

use anyhow::Result;

use super::sinks::{Out, Sinks, header, latched_qos};
use crate::bridge::copy_fields;
use crate::bridge::darknet::{
    BOUNDING_BOXES_TOPIC, BoxesWire, DETECTION_IMAGE_TOPIC, DarknetWire, FOUND_OBJECT_TOPIC,
};
use crate::bridge::events::Detections;
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// A BoundingBoxes topic.
pub(super) struct Boxes {
    out: Out<msgs::BoundingBoxes>,
    msg: msgs::BoundingBoxes,
}

impl Boxes {
    /// Creates `topic` on `sinks`, its header in frame `frame`.
    pub fn create(sinks: &mut Sinks<'_>, topic: &str, frame: &str) -> Result<Self> {
        Ok(Self {
            out: sinks.out(topic, &default_qos())?,
            msg: msgs::BoundingBoxes {
                header: header(frame),
                ..msgs::BoundingBoxes::default()
            },
        })
    }
}

impl BoxesWire for Boxes {
    fn boxes(&mut self, camera_frame: &str, d: &Detections) {
        let out = &mut self.msg;
        out.image_header.frame_id.clear();
        out.image_header.frame_id.push_str(camera_frame);
        out.header.stamp = Time::from_secs(d.stamp_s);
        out.image_header.stamp = Time::from_secs(d.image_stamp_s);
        out.bounding_boxes
            .resize_with(d.boxes.len(), msgs::BoundingBox::default);
        for (m, b) in out.bounding_boxes.iter_mut().zip(&d.boxes) {
            copy_fields!(m, b; probability, xmin, ymin, xmax, ymax, id);
            m.class_id.clone_from(&b.class);
        }
        self.out.put(out.header.stamp, out);
    }
}

/// darknet_ros's topics.
pub(super) struct Darknet {
    boxes: Boxes,
    found: Out<msgs::ObjectCount>,
    detection_image: Out<msgs::Image>,
    found_msg: msgs::ObjectCount,
}

impl Darknet {
    /// Creates darknet_ros's topics on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>) -> Result<Self> {
        Ok(Self {
            boxes: Boxes::create(sinks, BOUNDING_BOXES_TOPIC, "detection")?,
            found: sinks.out(FOUND_OBJECT_TOPIC, &default_qos())?,
            detection_image: sinks.out_large(DETECTION_IMAGE_TOPIC, &latched_qos())?,
            found_msg: msgs::ObjectCount {
                header: header("detection"),
                count: 0,
            },
        })
    }
}

impl BoxesWire for Darknet {
    fn boxes(&mut self, camera_frame: &str, boxes: &Detections) {
        self.boxes.boxes(camera_frame, boxes);
    }
}

impl DarknetWire for Darknet {
    fn found_object(&mut self, d: &Detections) {
        let stamp = Time::from_secs(d.stamp_s);
        self.found_msg.header.stamp = stamp;
        self.found_msg.count = i8::try_from(d.boxes.len()).unwrap_or(i8::MAX);
        self.found.put(stamp, &self.found_msg);
    }

    fn detection_image(
        &mut self,
        camera_frame: &str,
        d: &Detections,
        size: (u32, u32),
        pixels: &mut Vec<u8>,
    ) {
        let header = msgs::Header {
            stamp: Time::from_secs(d.image_stamp_s),
            frame_id: camera_frame.to_owned(),
        };
        self.detection_image
            .put_image(&header, size, "rgb8", pixels);
    }
}
