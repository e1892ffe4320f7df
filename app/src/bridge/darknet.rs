//! darknet_ros's topics: `/darknet_ros/bounding_boxes` (darknet_ros_msgs/BoundingBoxes, when
//! there are boxes), `/darknet_ros/found_object` (darknet_ros_msgs/ObjectCount, after every
//! detection) and `/darknet_ros/detection_image` (the detected image with the boxes drawn,
//! 2 px in the class colour, by [`rover_perception::draw_box_rgb8`]'s rule; latched, as
//! darknet_ros publishes it).

use rover_perception::{BoundingBox, draw_box_rgb8};

use super::events::{Detections, ImageFrame, Start, TopicFamily};

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

/// A darknet_ros_msgs/BoundingBoxes topic on one transport.
pub(crate) trait BoxesWire: Send {
    /// Publishes `boxes`; `image_header` names their image and `camera_frame`, the camera's
    /// optical frame.
    fn boxes(&mut self, camera_frame: &str, boxes: &Detections);
}

/// darknet_ros's topics on one transport.
pub(crate) trait DarknetWire: BoxesWire {
    /// Publishes the number of boxes.
    fn found_object(&mut self, boxes: &Detections);
    /// Publishes the detection image (`(width, height)`, RGB8 `pixels`, lent) of `boxes`'
    /// image, in `camera_frame`.
    fn detection_image(
        &mut self,
        camera_frame: &str,
        boxes: &Detections,
        size: (u32, u32),
        pixels: &mut Vec<u8>,
    );
}

/// An image kept for the detection image.
struct KeptImage {
    seq: u64,
    width: u32,
    height: u32,
    pixels: Vec<u8>,
}

/// The newest camera images, kept until their detections arrive, and the detection image drawn
/// from them.
#[derive(Default)]
struct DetectionImages {
    /// The newest images, oldest first.
    images: Vec<KeptImage>,
}

impl DetectionImages {
    /// Keeps `image`'s pixels; the oldest kept image's buffer goes back in their place.
    fn keep(&mut self, image: &mut ImageFrame) {
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
    fn draw(&self, image_seq: u64, boxes: &[BoundingBox], out: &mut Vec<u8>) -> Option<(u32, u32)> {
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

/// The darknet_ros family.
pub(crate) struct Darknet {
    wire: Box<dyn DarknetWire>,
    /// The camera's optical frame.
    camera_frame: String,
    images: DetectionImages,
    /// The detection image's pixels, reused.
    pixels: Vec<u8>,
}

impl Darknet {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn DarknetWire>) -> Self {
        Self {
            wire,
            camera_frame: String::new(),
            images: DetectionImages::default(),
            pixels: Vec::new(),
        }
    }
}

impl TopicFamily for Darknet {
    fn start(&mut self, start: &Start) {
        if let Some(c) = &start.camera {
            self.camera_frame.clone_from(&c.frame_id);
        }
    }

    fn image(&mut self, image: &mut ImageFrame) {
        self.images.keep(image);
    }

    fn detections(&mut self, detections: &mut Detections) {
        self.wire.found_object(detections);
        if !detections.boxes.is_empty() {
            self.wire.boxes(&self.camera_frame, detections);
        }
        let pixels = &mut self.pixels;
        if let Some(size) = self
            .images
            .draw(detections.image_seq, &detections.boxes, pixels)
        {
            let frame = &self.camera_frame;
            self.wire.detection_image(frame, detections, size, pixels);
        }
    }
}
