//! The ground truth of each judged image (`--ground-truth`), shaped like darknet_ros's boxes so
//! that the tutorials' nodes and `rostopic echo` read it as they read the detector's:
//! `/rover/ground_truth/bounding_boxes` (darknet_ros_msgs/BoundingBoxes). One message per
//! detection result, right after it, for the same image (`image_header` as the detections'),
//! empty or not (an empty one says nothing labelled is in view); one box per labelled thing in
//! view that is not an ignore region: its visible (tight) box, `Class` its COCO name, `id` its
//! COCO-80 number, `probability` 1.

use super::darknet::BoxesWire;
use super::events::{Detections, Start, TopicFamily};

/// The ground-truth topic.
pub(crate) const GROUND_TRUTH_TOPIC: &str = "/rover/ground_truth/bounding_boxes";

/// The ground-truth family.
pub(crate) struct GroundTruth {
    wire: Box<dyn BoxesWire>,
    /// The camera's optical frame.
    camera_frame: String,
}

impl GroundTruth {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn BoxesWire>) -> Self {
        Self {
            wire,
            camera_frame: String::new(),
        }
    }
}

impl TopicFamily for GroundTruth {
    fn start(&mut self, start: &Start) {
        if let Some(c) = &start.camera {
            self.camera_frame.clone_from(&c.frame_id);
        }
    }

    fn ground_truth(&mut self, truth: &mut Detections) {
        self.wire.boxes(&self.camera_frame, truth);
    }
}
