//! The ground truth of each judged image (`--ground-truth`), shaped like darknet_ros's boxes so
//! that the tutorials' nodes and `rostopic echo` read it as they read the detector's:
//! `/rover/ground_truth/bounding_boxes` (darknet_ros_msgs/BoundingBoxes). One message per
//! detection result, right after it, for the same image (`image_header` as the detections');
//! one box per labelled thing in view that is not an ignore region: its visible (tight) box,
//! `Class` its COCO name, `id` its COCO-80 number, `probability` 1.

use anyhow::Result;
use rover_perception::{BoundingBox, BoundingBoxes};
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::GroundTruthBox;

use super::convert::{header, seq_of};
use super::detections::fill;
use super::events::{Detections, Start, TopicFamily};

/// The ground-truth topic.
pub(super) const GROUND_TRUTH_TOPIC: &str = "/rover/ground_truth/bounding_boxes";

/// Publishes the ground-truth boxes.
pub(super) struct GroundTruthTopic {
    boxes: Publisher<msgs::BoundingBoxes>,
    msg: msgs::BoundingBoxes,
}

impl GroundTruthTopic {
    /// Advertises the topic.
    pub fn advertise(node: &Node) -> Result<Self> {
        Ok(Self {
            boxes: node.advertise(GROUND_TRUTH_TOPIC, 10, false)?,
            msg: msgs::BoundingBoxes {
                header: header("ground_truth"),
                ..msgs::BoundingBoxes::default()
            },
        })
    }
}

impl TopicFamily for GroundTruthTopic {
    fn start(&mut self, start: &Start) {
        if let Some(c) = &start.camera {
            self.msg.image_header.frame_id = c.frame_id.clone();
        }
    }

    fn ground_truth(&mut self, truth: &mut Detections) {
        fill(&mut self.msg, seq_of(&self.boxes), truth);
        // Every judged image, empty or not: an empty message says nothing labelled is in view.
        self.boxes.publish(&self.msg);
    }
}

/// The ground truth of the image `boxes` came from, to hand over (on the loop thread) in the
/// recycled `out`: labelled things in view that are not ignore regions, visible boxes.
pub(super) fn capture(
    boxes: &BoundingBoxes,
    truth: &[GroundTruthBox],
    now_s: f64,
    mut out: Vec<BoundingBox>,
) -> Detections {
    let shown = truth.iter().filter(|t| !t.ignore).filter_map(|t| {
        let v = t.visible?;
        Some((t, v))
    });
    let count = shown.clone().count();
    out.resize_with(count, || BoundingBox {
        class: String::new(),
        probability: 0.0,
        xmin: 0,
        ymin: 0,
        xmax: 0,
        ymax: 0,
        id: 0,
    });
    for (b, (t, v)) in out.iter_mut().zip(shown) {
        b.class.clone_from(&t.class);
        b.probability = 1.0;
        // Visible boxes are pixel edges, as darknet_ros's.
        b.xmin = v.xmin.round() as i64;
        b.ymin = v.ymin.round() as i64;
        b.xmax = v.xmax.round() as i64;
        b.ymax = v.ymax.round() as i64;
        b.id = rover_core::yolo_class(&t.class).map_or(-1, |i| i as i16);
    }
    Detections {
        stamp_s: now_s.max(boxes.image_stamp.sim_time_s),
        image_stamp_s: boxes.image_stamp.sim_time_s,
        image_seq: boxes.image_stamp.frame,
        boxes: out,
    }
}
