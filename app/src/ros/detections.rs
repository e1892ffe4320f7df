//! darknet_ros's topics: `/darknet_ros/bounding_boxes` (darknet_ros_msgs/BoundingBoxes, when
//! there are boxes), `/darknet_ros/found_object` (darknet_ros_msgs/ObjectCount, after every
//! detection) and the latched `/darknet_ros/detection_image` (the detected image with the boxes
//! drawn, 2 px in the class colour, by [`rover_perception::draw_box_rgb8`]'s rule).

use anyhow::Result;
use rover_perception::{BoundingBox, BoundingBoxes, draw_box_rgb8};
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use super::convert::{header, seq_of};
use super::events::{Detections, ImageFrame, Start, TopicFamily};
use super::plan::RosPlan;

/// darknet_ros's boxes.
pub(crate) const BOUNDING_BOXES_TOPIC: &str = "/darknet_ros/bounding_boxes";
/// darknet_ros's per-image object count.
pub(crate) const FOUND_OBJECT_TOPIC: &str = "/darknet_ros/found_object";
/// darknet_ros's image with boxes drawn (latched).
pub(crate) const DETECTION_IMAGE_TOPIC: &str = "/darknet_ros/detection_image";

/// Images kept for drawing the detection image: detections arrive after their image, up to
/// the detector's latency later (~0.2 s on 2 cores, 6-7 images of a 30 Hz camera); 16 cover
/// 0.5 s at 30 Hz (15 MB of 640x480 RGB8, allocated once and recycled).
const IMAGE_RING: usize = 16;

/// Outline width in the detection image (px).
const BOX_THICKNESS_PX: u32 = 2;

/// An image kept for the detection image.
struct KeptImage {
    seq: u64,
    width: u32,
    height: u32,
    pixels: Vec<u8>,
}

/// The newest camera images, kept until their detections arrive, and darknet_ros's detection
/// image drawn from them: the boxes, 2 px in the class colour, on their own image. Shared by
/// the ROS 1 and ROS 2 bridges.
#[derive(Default)]
pub(crate) struct DetectionImages {
    /// The newest images, oldest first.
    images: Vec<KeptImage>,
}

impl DetectionImages {
    /// Keeps `image`'s pixels; the oldest kept image's buffer goes back in their place.
    pub fn keep(&mut self, image: &mut ImageFrame) {
        let oldest = (self.images.len() >= IMAGE_RING).then(|| self.images.remove(0));
        self.images.push(KeptImage {
            seq: u64::from(image.seq as u32),
            width: image.width,
            height: image.height,
            pixels: std::mem::replace(
                &mut image.pixels,
                oldest.map(|o| o.pixels).unwrap_or_default(),
            ),
        });
    }

    /// Draws `boxes` on their image (frame `image_seq`) into `out` (RGB8): its width and
    /// height, or `None` when the image is no longer kept.
    pub fn draw(
        &self,
        image_seq: u64,
        boxes: &[BoundingBox],
        out: &mut Vec<u8>,
    ) -> Option<(u32, u32)> {
        let image = self
            .images
            .iter()
            .find(|i| i.seq == u64::from(image_seq as u32))?;
        out.clear();
        out.extend_from_slice(&image.pixels);
        for b in boxes {
            let colour = crate::palette::class_color(b.id).0;
            draw_box_rgb8(out, image.width, image.height, b, BOX_THICKNESS_PX, colour);
        }
        Some((image.width, image.height))
    }
}

/// Publishes darknet_ros's topics.
pub(super) struct DarknetTopics {
    boxes: Publisher<msgs::BoundingBoxes>,
    found: Publisher<msgs::ObjectCount>,
    detection_image: Publisher<msgs::Image>,
    images: DetectionImages,
    boxes_msg: msgs::BoundingBoxes,
    found_msg: msgs::ObjectCount,
    detection_msg: msgs::Image,
}

impl DarknetTopics {
    /// Advertises darknet_ros's topics.
    pub fn advertise(node: &Node, _plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            boxes: node.advertise(BOUNDING_BOXES_TOPIC, 10, false)?,
            found: node.advertise(FOUND_OBJECT_TOPIC, 10, false)?,
            detection_image: node.advertise(DETECTION_IMAGE_TOPIC, 2, true)?,
            images: DetectionImages::default(),
            boxes_msg: msgs::BoundingBoxes {
                header: header("detection"),
                ..msgs::BoundingBoxes::default()
            },
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

    /// Draws the boxes on their image, if it is still kept, and publishes it.
    fn publish_detection_image(&mut self, image_seq: u64, boxes: &[BoundingBox]) {
        let d = &mut self.detection_msg;
        let Some((width, height)) = self.images.draw(image_seq, boxes, &mut d.data) else {
            return;
        };
        d.header.clone_from(&self.boxes_msg.image_header);
        d.width = width;
        d.height = height;
        d.step = width * 3;
        self.detection_image.publish(d);
    }
}

impl TopicFamily for DarknetTopics {
    fn start(&mut self, start: &Start) {
        if let Some(c) = &start.camera {
            self.boxes_msg.image_header.frame_id = c.frame_id.clone();
        }
    }

    fn image(&mut self, image: &mut ImageFrame) {
        self.images.keep(image);
    }

    fn detections(&mut self, detections: &mut Detections) {
        self.found_msg.header.seq = seq_of(&self.found);
        self.found_msg.header.stamp_s = detections.stamp_s;
        self.found_msg.count = i8::try_from(detections.boxes.len()).unwrap_or(i8::MAX);
        self.found.publish(&self.found_msg);

        let out = &mut self.boxes_msg;
        fill(out, seq_of(&self.boxes), detections);
        if !out.bounding_boxes.is_empty() {
            self.boxes.publish(out);
        }
        self.publish_detection_image(detections.image_seq, &detections.boxes);
    }
}

/// Fills a darknet_ros_msgs/BoundingBoxes with `boxes` (numbered `seq`, stamped when
/// published, `image_header` their image's). Class strings keep their capacity: no allocation
/// once warm.
pub(super) fn fill(out: &mut msgs::BoundingBoxes, seq: u32, boxes: &Detections) {
    out.header.seq = seq;
    out.header.stamp_s = boxes.stamp_s;
    out.image_header.seq = boxes.image_seq as u32;
    out.image_header.stamp_s = boxes.image_stamp_s;
    out.bounding_boxes
        .resize_with(boxes.boxes.len(), msgs::BoundingBox::default);
    for (m, b) in out.bounding_boxes.iter_mut().zip(&boxes.boxes) {
        m.probability = b.probability;
        m.xmin = b.xmin;
        m.ymin = b.ymin;
        m.xmax = b.xmax;
        m.ymax = b.ymax;
        m.id = b.id;
        m.class.clone_from(&b.class);
    }
}

/// The detections to hand over (on the loop thread), published at `now_s` (never before their
/// image): `boxes` copied into the recycled `out`, whose class strings keep their capacity.
pub(crate) fn capture(boxes: &BoundingBoxes, now_s: f64, mut out: Vec<BoundingBox>) -> Detections {
    out.clone_from(&boxes.bounding_boxes);
    Detections {
        stamp_s: now_s.max(boxes.image_stamp.sim_time_s),
        image_stamp_s: boxes.image_stamp.sim_time_s,
        image_seq: boxes.image_stamp.frame,
        boxes: out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rover_perception::FrameStamp;

    fn person(xmin: i64) -> BoundingBox {
        BoundingBox {
            class: "person".into(),
            probability: 0.5,
            xmin,
            ymin: 1,
            xmax: xmin + 3,
            ymax: 4,
            id: 0,
        }
    }

    #[test]
    fn captured_boxes_reuse_the_recycled_buffer() {
        let boxes = BoundingBoxes {
            image_stamp: FrameStamp {
                sim_time_s: 2.0,
                frame: 7,
            },
            bounding_boxes: vec![person(1), person(5)],
            ..BoundingBoxes::default()
        };
        let recycled = vec![person(0), person(0), person(0)];
        let first_class = recycled[0].class.as_ptr();
        let d = capture(&boxes, 1.5, recycled);
        assert_eq!(d.boxes, boxes.bounding_boxes);
        assert_eq!(
            d.boxes[0].class.as_ptr(),
            first_class,
            "the string was reused"
        );
        assert_eq!((d.stamp_s, d.image_stamp_s, d.image_seq), (2.0, 2.0, 7));
        let d = capture(&boxes, 3.0, Vec::new());
        assert_eq!(d.boxes, boxes.bounding_boxes);
        assert_eq!(d.stamp_s, 3.0);
    }
}
