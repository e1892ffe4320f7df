//! The detector against ground truth, live: each detection result matched to the ground truth
//! of its own image with COCO's rule at IoU 0.5 ([`rover_perception::match_frame`]), running
//! tallies per class (true and false positives, misses, IoU of the matches) for the Rerun
//! recorder's plots, the HUD and `rover eval`'s probe. Ground truth counts its visible box; a
//! thing with nothing visible or an ignore flag is an ignore region.

use std::collections::BTreeMap;

use rover_perception::{BoundingBoxes, Detection, EvalBox, FrameMatch, GroundTruthObject};
use rover_sim::sensors::GroundTruthBox;

/// Fills `truth` and `found` with one frame's ground truth and detections as the evaluator
/// takes them, reusing the objects (and their class strings) already there.
pub fn eval_objects(
    boxes: &BoundingBoxes,
    ground_truth: &[GroundTruthBox],
    truth: &mut Vec<GroundTruthObject>,
    found: &mut Vec<Detection>,
) {
    truth.truncate(ground_truth.len());
    for (i, t) in ground_truth.iter().enumerate() {
        let b = t.visible.unwrap_or(t.full);
        let bbox = EvalBox {
            xmin: b.xmin,
            ymin: b.ymin,
            xmax: b.xmax,
            ymax: b.ymax,
        };
        let ignore = t.ignore || t.visible.is_none();
        match truth.get_mut(i) {
            Some(o) => {
                o.class.clone_from(&t.class);
                (o.bbox, o.ignore) = (bbox, ignore);
            }
            None => truth.push(GroundTruthObject {
                class: t.class.clone(),
                bbox,
                ignore,
            }),
        }
    }
    found.truncate(boxes.bounding_boxes.len());
    for (i, b) in boxes.bounding_boxes.iter().enumerate() {
        let bbox = EvalBox {
            xmin: b.xmin as f64,
            ymin: b.ymin as f64,
            xmax: b.xmax as f64,
            ymax: b.ymax as f64,
        };
        match found.get_mut(i) {
            Some(d) => {
                d.class.clone_from(&b.class);
                (d.bbox, d.score) = (bbox, b.probability);
            }
            None => found.push(Detection {
                class: b.class.clone(),
                bbox,
                score: b.probability,
            }),
        }
    }
}

/// One class's running tally.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClassTally {
    /// Detections that found a thing (IoU >= 0.5).
    pub true_positives: u64,
    /// Detections that found nothing (and lie on no ignore region).
    pub false_positives: u64,
    /// Things no detection found.
    pub misses: u64,
    /// Sum of the matches' IoU.
    pub iou_sum: f64,
}

impl ClassTally {
    /// True / all positives so far (`None` before the first detection).
    pub fn precision(&self) -> Option<f64> {
        let n = self.true_positives + self.false_positives;
        (n > 0).then(|| self.true_positives as f64 / n as f64)
    }

    /// Found / to find so far (`None` before the first thing to find).
    pub fn recall(&self) -> Option<f64> {
        let n = self.true_positives + self.misses;
        (n > 0).then(|| self.true_positives as f64 / n as f64)
    }

    /// Mean IoU of the matches so far.
    pub fn mean_iou(&self) -> Option<f64> {
        (self.true_positives > 0).then(|| self.iou_sum / self.true_positives as f64)
    }
}

/// Judges each detection result against its image's ground truth and keeps running tallies.
#[derive(Debug, Default)]
pub struct LiveJudge {
    truth: Vec<GroundTruthObject>,
    found: Vec<Detection>,
    last: FrameMatch,
    tallies: BTreeMap<String, ClassTally>,
}

/// Updates `class`'s tally (a new class's name is the only allocation).
fn tally(
    tallies: &mut BTreeMap<String, ClassTally>,
    class: Option<&str>,
    update: impl FnOnce(&mut ClassTally),
) {
    let class = class.unwrap_or("?");
    match tallies.get_mut(class) {
        Some(t) => update(t),
        None => {
            let mut t = ClassTally::default();
            update(&mut t);
            tallies.insert(class.to_owned(), t);
        }
    }
}

/// The IoU at which a detection counts as finding a thing.
pub const MATCH_IOU: f64 = 0.5;

impl LiveJudge {
    /// Matches one result; returns the frame's match (indices into `boxes.bounding_boxes` and
    /// `ground_truth`).
    pub fn judge(&mut self, boxes: &BoundingBoxes, ground_truth: &[GroundTruthBox]) -> &FrameMatch {
        eval_objects(boxes, ground_truth, &mut self.truth, &mut self.found);
        self.last = rover_perception::match_frame(&self.truth, &self.found, MATCH_IOU);
        let tallies = &mut self.tallies;
        let class_of_detection = |d: usize| self.found.get(d).map(|d| d.class.as_str());
        for m in &self.last.matches {
            tally(tallies, class_of_detection(m.detection), |t| {
                t.true_positives += 1;
                t.iou_sum += m.iou;
            });
        }
        for &d in &self.last.false_positives {
            tally(tallies, class_of_detection(d), |t| t.false_positives += 1);
        }
        for &g in &self.last.misses {
            let class = self.truth.get(g).map(|t| t.class.as_str());
            tally(tallies, class, |t| t.misses += 1);
        }
        &self.last
    }

    /// The running tallies by class.
    pub fn tallies(&self) -> &BTreeMap<String, ClassTally> {
        &self.tallies
    }

    /// The last judged frame's match.
    pub fn last(&self) -> &FrameMatch {
        &self.last
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rover_perception::{BoundingBox, FrameStamp};
    use rover_sim::{model::Labelled, sensors::PixelBox};

    fn truth(class: &str, b: [f64; 4], visible_px: u32) -> GroundTruthBox {
        let [xmin, ymin, xmax, ymax] = b;
        let pb = PixelBox {
            xmin,
            ymin,
            xmax,
            ymax,
        };
        GroundTruthBox {
            id: 1,
            entity: Labelled::Person(0),
            class: class.into(),
            name: "t".into(),
            full: pb,
            visible: (visible_px > 0).then_some(pb),
            visible_px,
            unoccluded_px: visible_px,
            visibility: 1.0,
            truncated: false,
            truncation: 0.0,
            ignore: visible_px < 100,
        }
    }

    fn found(class: &str, b: [i64; 4], p: f64) -> BoundingBox {
        BoundingBox {
            class: class.into(),
            probability: p,
            xmin: b[0],
            ymin: b[1],
            xmax: b[2],
            ymax: b[3],
            id: 0,
        }
    }

    #[test]
    fn tallies_count_matches_misses_and_false_positives_per_class() {
        let mut judge = LiveJudge::default();
        let gt = [
            truth("person", [100.0, 100.0, 200.0, 300.0], 5000),
            truth("dog", [400.0, 300.0, 500.0, 400.0], 3000),
            truth("person", [600.0, 100.0, 605.0, 110.0], 40),
        ];
        let boxes = BoundingBoxes {
            bounding_boxes: vec![
                found("person", [101, 100, 200, 302], 0.9),
                found("person", [300, 100, 350, 200], 0.8),
                found("person", [600, 100, 606, 110], 0.6),
            ],
            image_stamp: FrameStamp::default(),
            ..BoundingBoxes::default()
        };
        let m = judge.judge(&boxes, &gt).clone();
        assert_eq!(
            (m.matches.len(), m.false_positives, m.misses),
            (1, vec![1], vec![1])
        );
        assert_eq!(m.ignored, vec![2], "the tiny person is an ignore region");
        let person = judge.tallies()["person"];
        assert_eq!(
            (person.true_positives, person.false_positives, person.misses),
            (1, 1, 0)
        );
        assert_eq!(person.precision(), Some(0.5));
        assert!(person.mean_iou().is_some_and(|iou| iou > 0.97));
        assert_eq!(judge.tallies()["dog"].recall(), Some(0.0));
    }
}
