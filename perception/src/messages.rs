//! Detection results shaped like darknet_ros's messages, stamped with the frame they came from.

use serde::Serialize;

/// Identifies the camera frame a result belongs to (darknet_ros users suffer boxes out of sync;
/// rover stamps every result with its image).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct FrameStamp {
    /// Sim time at which the image was taken (s).
    pub sim_time_s: f64,
    /// Camera frame sequence number.
    pub frame: u64,
}

/// One detection, as darknet_ros_msgs/BoundingBox.
#[derive(Debug, PartialEq, Serialize)]
pub struct BoundingBox {
    /// Class name (darknet_ros's `Class`).
    #[serde(rename = "Class")]
    pub class: String,
    /// Confidence, 0..1.
    pub probability: f64,
    /// Left edge (px, source image).
    pub xmin: i64,
    /// Top edge (px).
    pub ymin: i64,
    /// Right edge (px).
    pub xmax: i64,
    /// Bottom edge (px).
    pub ymax: i64,
    /// Class index.
    pub id: i16,
}

impl Clone for BoundingBox {
    fn clone(&self) -> Self {
        Self {
            class: self.class.clone(),
            ..*self
        }
    }

    /// Copies `source` keeping this box's class string (and its capacity), so refilling a
    /// recycled `Vec<BoundingBox>` with `clone_from` allocates nothing once warm.
    fn clone_from(&mut self, source: &Self) {
        let mut class = std::mem::take(&mut self.class);
        class.clone_from(&source.class);
        *self = Self { class, ..*source };
    }
}

impl BoundingBox {
    /// Box width (px).
    pub fn width(&self) -> i64 {
        self.xmax - self.xmin
    }

    /// Box height (px).
    pub fn height(&self) -> i64 {
        self.ymax - self.ymin
    }

    /// Intersection over union with another box (pixel rectangles, inclusive-exclusive).
    pub fn iou(&self, other: &BoundingBox) -> f64 {
        let ix = (self.xmax.min(other.xmax) - self.xmin.max(other.xmin)).max(0);
        let iy = (self.ymax.min(other.ymax) - self.ymin.max(other.ymin)).max(0);
        let inter = (ix * iy) as f64;
        let union = (self.width() * self.height() + other.width() * other.height()) as f64 - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }
}

/// All detections of one image, as darknet_ros_msgs/BoundingBoxes.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct BoundingBoxes {
    /// The image the boxes came from.
    pub image_stamp: FrameStamp,
    /// Camera frame id (the optical frame).
    pub frame_id: String,
    /// Detections, highest probability first.
    pub bounding_boxes: Vec<BoundingBox>,
    /// Wall time spent on this image: preprocess + inference + decode (ms).
    pub latency_ms: f64,
}

impl BoundingBoxes {
    /// darknet_ros_msgs/ObjectCount for this result.
    pub fn object_count(&self) -> ObjectCount {
        ObjectCount {
            image_stamp: self.image_stamp,
            count: self.bounding_boxes.len() as i8,
        }
    }
}

/// Number of detections in an image, as darknet_ros_msgs/ObjectCount (published every cycle,
/// 0 when nothing is seen).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ObjectCount {
    /// The image counted.
    pub image_stamp: FrameStamp,
    /// How many boxes (saturating at 127, like darknet_ros's int8).
    pub count: i8,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bb(xmin: i64, ymin: i64, xmax: i64, ymax: i64) -> BoundingBox {
        BoundingBox {
            class: "person".into(),
            probability: 0.9,
            xmin,
            ymin,
            xmax,
            ymax,
            id: 0,
        }
    }

    #[test]
    fn iou_of_boxes() {
        assert_eq!(bb(0, 0, 10, 10).iou(&bb(0, 0, 10, 10)), 1.0);
        assert_eq!(bb(0, 0, 10, 10).iou(&bb(20, 20, 30, 30)), 0.0);
        assert!((bb(0, 0, 10, 10).iou(&bb(5, 0, 15, 10)) - 50.0 / 150.0).abs() < 1e-12);
    }

    #[test]
    fn json_uses_darknet_ros_field_names() {
        let json = serde_json::to_string(&bb(1, 2, 3, 4)).unwrap_or_default();
        assert_eq!(
            json,
            r#"{"Class":"person","probability":0.9,"xmin":1,"ymin":2,"xmax":3,"ymax":4,"id":0}"#
        );
    }
}
