//! darknet_ros's topics and the ground truth's boxes (darknet_ros_msgs/BoundingBoxes,
//! ObjectCount, the detection image) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use super::convert::{header, seq_of};
use crate::bridge::copy_fields;
use crate::bridge::darknet::{
    BOUNDING_BOXES_TOPIC, BoxesWire, DETECTION_IMAGE_TOPIC, DarknetWire, FOUND_OBJECT_TOPIC,
};
use crate::bridge::events::Detections;

/// A BoundingBoxes topic's publisher.
pub(super) struct Boxes {
    publisher: Publisher<msgs::BoundingBoxes>,
    msg: msgs::BoundingBoxes,
}

impl Boxes {
    /// Advertises `topic`, its header in frame `frame`.
    pub fn advertise(node: &Node, topic: &str, frame: &str) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise(topic, 10, false)?,
            msg: msgs::BoundingBoxes {
                header: header(frame),
                ..msgs::BoundingBoxes::default()
            },
        })
    }
}

impl BoxesWire for Boxes {
    fn boxes(&mut self, camera_frame: &str, boxes: &Detections) {
        let out = &mut self.msg;
        out.image_header.frame_id.clear();
        out.image_header.frame_id.push_str(camera_frame);
        out.header.seq = seq_of(&self.publisher);
        out.header.stamp_s = boxes.stamp_s;
        out.image_header.seq = boxes.image_seq as u32;
        out.image_header.stamp_s = boxes.image_stamp_s;
        out.bounding_boxes
            .resize_with(boxes.boxes.len(), msgs::BoundingBox::default);
        for (m, b) in out.bounding_boxes.iter_mut().zip(&boxes.boxes) {
            copy_fields!(m, b; probability, xmin, ymin, xmax, ymax, id);
            m.class_id.clone_from(&b.class);
        }
        self.publisher.publish(out);
    }
}

/// darknet_ros's publishers.
pub(super) struct Darknet {
    boxes: Boxes,
    found: Publisher<msgs::ObjectCount>,
    detection_image: Publisher<msgs::Image>,
    found_msg: msgs::ObjectCount,
    detection_msg: msgs::Image,
}

impl Darknet {
    /// Advertises darknet_ros's topics.
    pub fn advertise(node: &Node) -> Result<Self> {
        Ok(Self {
            boxes: Boxes::advertise(node, BOUNDING_BOXES_TOPIC, "detection")?,
            found: node.advertise(FOUND_OBJECT_TOPIC, 10, false)?,
            detection_image: node.advertise(DETECTION_IMAGE_TOPIC, 2, true)?,
            found_msg: msgs::ObjectCount {
                header: header("detection"),
                count: 0,
            },
            detection_msg: msgs::Image {
                encoding: "rgb8".into(),
                ..msgs::Image::default()
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
    fn found_object(&mut self, boxes: &Detections) {
        self.found_msg.header.seq = seq_of(&self.found);
        self.found_msg.header.stamp_s = boxes.stamp_s;
        self.found_msg.count = i8::try_from(boxes.boxes.len()).unwrap_or(i8::MAX);
        self.found.publish(&self.found_msg);
    }

    fn detection_image(
        &mut self,
        camera_frame: &str,
        boxes: &Detections,
        (width, height): (u32, u32),
        pixels: &mut Vec<u8>,
    ) {
        let d = &mut self.detection_msg;
        d.header.seq = boxes.image_seq as u32;
        d.header.stamp_s = boxes.image_stamp_s;
        d.header.frame_id.clear();
        d.header.frame_id.push_str(camera_frame);
        d.width = width;
        d.height = height;
        d.step = width * 3;
        std::mem::swap(&mut d.data, pixels);
        self.detection_image.publish(d);
        std::mem::swap(&mut d.data, pixels);
    }
}
