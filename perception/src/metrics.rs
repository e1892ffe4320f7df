//! COCO-style detection metrics: the same numbers as pycocotools' `COCOeval` with
//! `iouType='bbox'`, area range `all` and at most 100 detections per image and class.
//!
//! * [`CocoEvaluator`] accumulates images ([`CocoEvaluator::add_image`]) and summarises them
//!   ([`CocoEvaluator::summary`]): AP at IoU 0.5, 0.75 and averaged over 0.50:0.05:0.95, per
//!   class and averaged over the classes that have ground truth, plus counts, precision and
//!   recall at IoU 0.5.
//! * [`match_frame`] matches one frame at one IoU threshold with the same rule, for live use:
//!   which detection found which object, which objects were missed, which detections are false.
//!
//! The rules, as `COCOeval.evaluateImg` and `COCOeval.accumulate` apply them:
//!
//! * Each image and class is matched on its own. Ground truth is ordered non-ignored first
//!   (stable); detections by score, highest first (stable: equal scores keep their input order),
//!   and only the first 100 of an image and class are evaluated.
//! * At each IoU threshold, each detection in turn takes the unmatched ground truth it overlaps
//!   best, if that IoU is at least the threshold (a later object wins a tie). Ignore regions
//!   (COCO's `iscrowd`) are scored by intersection over the *detection's* area, can take any
//!   number of detections, and are only considered when no ordinary object matched: a detection
//!   on an ignore region is neither a true nor a false positive.
//! * Per class, the detections of all images (in the order the images were added, each image's
//!   by score) are sorted by score (stable) and counted cumulatively; precision is made
//!   non-increasing from the right and sampled at the 101 recall points 0, 0.01, ..., 1 (0 past
//!   the highest recall reached); AP is the mean of those 101 samples. A class without any
//!   non-ignored ground truth has no AP and is left out of the averages.
//!
//! Boxes are converted to COCO's `[x, y, w, h]` before the IoU is taken, exactly as
//! pycocotools computes it, so results are identical to the bit for the same input.

use std::cmp::Ordering;
use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// COCO's IoU thresholds, `np.linspace(0.5, 0.95, 10)` (0.9 is `0.8999999999999999` there).
pub const COCO_IOU_THRESHOLDS: [f64; 10] = [
    0.5,
    0.55,
    0.6,
    0.65,
    0.7,
    0.75,
    0.8,
    0.85,
    0.899_999_999_999_999_9,
    0.95,
];

/// Detections evaluated per image and class (COCO's `maxDets` of 100); the rest, lowest scores
/// first, are dropped.
pub const COCO_MAX_DETECTIONS: usize = 100;

/// Number of recall points AP is sampled at (`np.linspace(0, 1, 101)`).
const RECALL_POINTS: usize = 101;
/// Index of IoU 0.5 and 0.75 in [`COCO_IOU_THRESHOLDS`].
const T50: usize = 0;
const T75: usize = 5;
/// COCO's area range `all`: objects and unmatched detections with an area outside it are
/// ignored (only degenerate boxes, with a negative area, ever are).
const AREA_MAX: f64 = 1e10;

/// The `i`-th recall point, computed as `np.linspace(0, 1, 101)` does.
fn recall_point(i: usize) -> f64 {
    if i + 1 == RECALL_POINTS {
        1.0
    } else {
        i as f64 * (1.0 / (RECALL_POINTS - 1) as f64)
    }
}

/// An axis-aligned box in pixels, by its edges. COCO's `[x, y, w, h]` is
/// `[xmin, ymin, xmax - xmin, ymax - ymin]`; there is no `+1` pixel anywhere.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct EvalBox {
    /// Left edge (px).
    pub xmin: f64,
    /// Top edge (px).
    pub ymin: f64,
    /// Right edge (px).
    pub xmax: f64,
    /// Bottom edge (px).
    pub ymax: f64,
}

impl EvalBox {
    /// A box from its edges.
    pub fn new(xmin: f64, ymin: f64, xmax: f64, ymax: f64) -> Self {
        Self {
            xmin,
            ymin,
            xmax,
            ymax,
        }
    }

    /// A box from COCO's `[x, y, w, h]`.
    pub fn from_xywh(x: f64, y: f64, w: f64, h: f64) -> Self {
        Self::new(x, y, x + w, y + h)
    }

    /// Width, `xmax - xmin` (px).
    pub fn width(&self) -> f64 {
        self.xmax - self.xmin
    }

    /// Height, `ymax - ymin` (px).
    pub fn height(&self) -> f64 {
        self.ymax - self.ymin
    }

    /// Area, width times height (px²); negative for a box with inverted edges.
    pub fn area(&self) -> f64 {
        self.width() * self.height()
    }

    /// Intersection over union; 0 when the boxes do not overlap.
    pub fn iou(&self, other: &EvalBox) -> f64 {
        overlap(self, other, false)
    }
}

/// pycocotools' `bbIou` for one pair, from `[x, y, w, h]`: intersection over union, or over the
/// detection's area when the ground truth is a crowd (ignore region).
fn overlap(det: &EvalBox, gt: &EvalBox, crowd: bool) -> f64 {
    let (dw, dh, gw, gh) = (det.width(), det.height(), gt.width(), gt.height());
    let w = (det.xmin + dw).min(gt.xmin + gw) - det.xmin.max(gt.xmin);
    if w <= 0.0 {
        return 0.0;
    }
    let h = (det.ymin + dh).min(gt.ymin + gh) - det.ymin.max(gt.ymin);
    if h <= 0.0 {
        return 0.0;
    }
    let intersection = w * h;
    let det_area = dw * dh;
    let union = if crowd {
        det_area
    } else {
        det_area + gw * gh - intersection
    };
    intersection / union
}

/// One annotated object of an image.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroundTruthObject {
    /// Class name; detections are only matched to objects of their own class.
    pub class: String,
    /// Where it is.
    pub bbox: EvalBox,
    /// An ignore region (COCO's `iscrowd`): it need not be detected, and detections on it
    /// (intersection over the detection's area at the IoU threshold) are neither true nor
    /// false positives.
    pub ignore: bool,
}

/// One detection of an image.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Detection {
    /// Class name.
    pub class: String,
    /// Where it is.
    pub bbox: EvalBox,
    /// Confidence: detections are matched and ranked highest first.
    pub score: f64,
}

/// Highest score first, as numpy's `argsort(-score)` orders (NaN last); a stable sort with this
/// keeps equal scores in input order, as `kind='mergesort'` does.
fn by_score(a: f64, b: f64) -> Ordering {
    match (a.is_nan(), b.is_nan()) {
        (false, false) => b.partial_cmp(&a).unwrap_or(Ordering::Equal),
        (true, true) => Ordering::Equal,
        (true, false) => Ordering::Greater,
        (false, true) => Ordering::Less,
    }
}

/// Whether COCO's area range `all` leaves out a box of this area (not a NaN one, as in COCO).
#[allow(
    clippy::manual_range_contains,
    reason = "a NaN area is inside, as in COCO; `!(0.0..=AREA_MAX).contains(&area)` would put it outside"
)]
fn outside_area_range(area: f64) -> bool {
    area < 0.0 || area > AREA_MAX
}

/// The matching of one image and class, reused between calls.
#[derive(Debug, Default)]
struct Matcher {
    /// Indices of the class's ground truth, non-ignored first.
    gt_order: Vec<usize>,
    /// Indices of the class's detections, highest score first.
    det_order: Vec<usize>,
    /// IoU of each detection (rows, `det_order`) with each object (columns, `gt_order`).
    ious: Vec<f64>,
    /// Per object (`gt_order`): ignored (crowd, or outside the area range).
    gt_ignore: Vec<bool>,
    /// Per object (`gt_order`): a crowd, matched by intersection over the detection's area and
    /// any number of times.
    gt_crowd: Vec<bool>,
    /// Per object (`gt_order`): taken at the current threshold.
    taken: Vec<bool>,
    /// Per detection (`det_order`): the position in `gt_order` it matched at the current
    /// threshold.
    matched: Vec<Option<usize>>,
}

impl Matcher {
    /// Orders `class`'s objects and detections and computes their IoUs; keeps at most
    /// `max_detections` detections and returns how many it dropped.
    fn prepare(
        &mut self,
        class: &str,
        ground_truth: &[GroundTruthObject],
        detections: &[Detection],
        max_detections: usize,
    ) -> usize {
        let ignored = |g: &GroundTruthObject| g.ignore || outside_area_range(g.bbox.area());
        self.gt_order.clear();
        self.gt_order.extend(
            (0..ground_truth.len())
                .filter(|&i| ground_truth[i].class == class && !ignored(&ground_truth[i])),
        );
        self.gt_order.extend(
            (0..ground_truth.len())
                .filter(|&i| ground_truth[i].class == class && ignored(&ground_truth[i])),
        );
        self.det_order.clear();
        self.det_order
            .extend((0..detections.len()).filter(|&i| detections[i].class == class));
        self.det_order
            .sort_by(|&a, &b| by_score(detections[a].score, detections[b].score));
        let dropped = self.det_order.len().saturating_sub(max_detections);
        self.det_order.truncate(max_detections);

        self.gt_ignore.clear();
        self.gt_crowd.clear();
        for &g in &self.gt_order {
            self.gt_ignore.push(ignored(&ground_truth[g]));
            self.gt_crowd.push(ground_truth[g].ignore);
        }
        self.ious.clear();
        for &d in &self.det_order {
            for &g in &self.gt_order {
                let gt = &ground_truth[g];
                self.ious
                    .push(overlap(&detections[d].bbox, &gt.bbox, gt.ignore));
            }
        }
        dropped
    }

    /// Matches every detection at `threshold` into `self.matched`.
    fn run(&mut self, threshold: f64) {
        let n_gt = self.gt_order.len();
        self.taken.clear();
        self.taken.resize(n_gt, false);
        self.matched.clear();
        for row in self
            .ious
            .chunks_exact(n_gt.max(1))
            .take(self.det_order.len())
        {
            let mut best = threshold.min(1.0 - 1e-10);
            let mut found: Option<usize> = None;
            for (g, &iou) in row.iter().enumerate() {
                if self.taken[g] && !self.gt_crowd[g] {
                    continue;
                }
                // Matched to an ordinary object: ignore regions (all after it) cannot win.
                if found.is_some_and(|m| !self.gt_ignore[m]) && self.gt_ignore[g] {
                    break;
                }
                if iou < best {
                    continue;
                }
                best = iou;
                found = Some(g);
            }
            if let Some(g) = found {
                self.taken[g] = true;
            }
            self.matched.push(found);
        }
        // No ground truth: `chunks_exact(1)` of an empty slice yields nothing.
        self.matched.resize(self.det_order.len(), None);
    }

    /// Whether the detection at position `d` of `det_order` is ignored given its match.
    fn det_ignored(&self, d: usize, detections: &[Detection]) -> bool {
        match self.matched[d] {
            Some(g) => self.gt_ignore[g],
            None => outside_area_range(detections[self.det_order[d]].bbox.area()),
        }
    }
}

/// The distinct classes of an image, sorted.
fn classes_of<'a>(
    ground_truth: &'a [GroundTruthObject],
    detections: &'a [Detection],
) -> Vec<&'a str> {
    let mut classes: Vec<&str> = ground_truth
        .iter()
        .map(|g| g.class.as_str())
        .chain(detections.iter().map(|d| d.class.as_str()))
        .collect();
    classes.sort_unstable();
    classes.dedup();
    classes
}

/// A detection that found an object, in [`FrameMatch`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MatchedPair {
    /// Index into the frame's detections.
    pub detection: usize,
    /// Index into the frame's ground truth.
    pub ground_truth: usize,
    /// Their IoU.
    pub iou: f64,
}

/// How one frame's detections match its ground truth at one IoU threshold ([`match_frame`]).
/// Indices refer to the slices given; each list is in increasing index order.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FrameMatch {
    /// True positives: detections matched to a (non-ignored) object.
    pub matches: Vec<MatchedPair>,
    /// Objects (not ignore regions) that no detection matched.
    pub misses: Vec<usize>,
    /// Detections that matched nothing and lie on no ignore region.
    pub false_positives: Vec<usize>,
    /// Detections on an ignore region: neither true nor false positives.
    pub ignored: Vec<usize>,
}

/// Matches one frame's detections to its ground truth at `iou_threshold` with COCO's rule
/// (per class, greedily by score, ignore regions last; see the module documentation). Unlike
/// [`CocoEvaluator`], every detection is matched (no cap of 100 per class).
pub fn match_frame(
    ground_truth: &[GroundTruthObject],
    detections: &[Detection],
    iou_threshold: f64,
) -> FrameMatch {
    let mut out = FrameMatch::default();
    let mut matcher = Matcher::default();
    for class in classes_of(ground_truth, detections) {
        matcher.prepare(class, ground_truth, detections, usize::MAX);
        matcher.run(iou_threshold);
        let n_gt = matcher.gt_order.len();
        for (d, &det) in matcher.det_order.iter().enumerate() {
            match matcher.matched[d] {
                Some(g) if !matcher.gt_ignore[g] => out.matches.push(MatchedPair {
                    detection: det,
                    ground_truth: matcher.gt_order[g],
                    iou: matcher.ious[d * n_gt + g],
                }),
                _ if matcher.det_ignored(d, detections) => out.ignored.push(det),
                _ => out.false_positives.push(det),
            }
        }
        for (g, &gt) in matcher.gt_order.iter().enumerate() {
            if !matcher.taken[g] && !matcher.gt_ignore[g] {
                out.misses.push(gt);
            }
        }
    }
    out.matches.sort_by_key(|m| m.detection);
    out.misses.sort_unstable();
    out.false_positives.sort_unstable();
    out.ignored.sort_unstable();
    out
}

/// One evaluated detection: its score and outcome at each IoU threshold.
#[derive(Debug, Clone, Copy)]
struct Outcome {
    score: f64,
    /// Bit `t`: matched to an object or ignore region at threshold `t`.
    matched: u16,
    /// Bit `t`: ignored at threshold `t` (on an ignore region, or a degenerate box).
    ignored: u16,
    /// IoU with its object at IoU 0.5 (meaningful when a true positive there).
    iou50: f64,
}

impl Outcome {
    fn true_positive(&self, t: usize) -> bool {
        self.matched & (1 << t) != 0 && self.ignored & (1 << t) == 0
    }

    fn false_positive(&self, t: usize) -> bool {
        (self.matched | self.ignored) & (1 << t) == 0
    }
}

/// Everything accumulated for one class.
#[derive(Debug, Default, Clone)]
struct ClassTally {
    /// Non-ignored objects.
    positives: usize,
    /// Ignored objects (ignore regions).
    ignored_gt: usize,
    /// Evaluated detections, image by image, each image's by score.
    outcomes: Vec<Outcome>,
    /// Detections beyond the 100 per image.
    dropped: usize,
}

/// Accumulates images of ground truth and detections and computes COCO's detection metrics
/// over them ([`CocoEvaluator::summary`]), as pycocotools' `COCOeval` (`bbox`, area `all`,
/// `maxDets` 100) would over the same images in the order they were added.
#[derive(Debug, Default)]
pub struct CocoEvaluator {
    classes: BTreeMap<String, ClassTally>,
    images: usize,
    matcher: Matcher,
}

impl CocoEvaluator {
    /// An evaluator with no images.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of images added.
    pub fn images(&self) -> usize {
        self.images
    }

    /// Adds one image: its objects and its detections (any order; classes are matched
    /// separately).
    pub fn add_image(&mut self, ground_truth: &[GroundTruthObject], detections: &[Detection]) {
        self.images += 1;
        for class in classes_of(ground_truth, detections) {
            let dropped =
                self.matcher
                    .prepare(class, ground_truth, detections, COCO_MAX_DETECTIONS);
            if !self.classes.contains_key(class) {
                self.classes.insert(class.to_owned(), ClassTally::default());
            }
            let Some(tally) = self.classes.get_mut(class) else {
                continue;
            };
            tally.dropped += dropped;
            let ignored_gt = self.matcher.gt_ignore.iter().filter(|&&i| i).count();
            tally.ignored_gt += ignored_gt;
            tally.positives += self.matcher.gt_order.len() - ignored_gt;

            let first = tally.outcomes.len();
            tally
                .outcomes
                .extend(self.matcher.det_order.iter().map(|&d| Outcome {
                    score: detections[d].score,
                    matched: 0,
                    ignored: 0,
                    iou50: 0.0,
                }));
            let n_gt = self.matcher.gt_order.len();
            for (t, &threshold) in COCO_IOU_THRESHOLDS.iter().enumerate() {
                self.matcher.run(threshold);
                for (d, outcome) in tally.outcomes[first..].iter_mut().enumerate() {
                    if let Some(g) = self.matcher.matched[d] {
                        outcome.matched |= 1 << t;
                        if t == T50 {
                            outcome.iou50 = self.matcher.ious[d * n_gt + g];
                        }
                    }
                    if self.matcher.det_ignored(d, detections) {
                        outcome.ignored |= 1 << t;
                    }
                }
            }
        }
    }

    /// The metrics of all images added so far.
    pub fn summary(&self) -> DetectionMetrics {
        let mut classes = Vec::with_capacity(self.classes.len());
        let mut order = Vec::new();
        for (name, tally) in &self.classes {
            order.clear();
            order.extend(0..tally.outcomes.len());
            order.sort_by(|&a, &b| by_score(tally.outcomes[a].score, tally.outcomes[b].score));
            let ap: Option<[f64; 10]> = (tally.positives > 0).then(|| {
                let mut ap = [0.0; 10];
                for (t, ap) in ap.iter_mut().enumerate() {
                    *ap = average_precision(tally, &order, t);
                }
                ap
            });
            let at50 = |f: fn(&Outcome, usize) -> bool| {
                tally.outcomes.iter().filter(|o| f(o, T50)).count()
            };
            let tp = at50(Outcome::true_positive);
            let fp = at50(Outcome::false_positive);
            let iou_sum: f64 = tally
                .outcomes
                .iter()
                .filter(|o| o.true_positive(T50))
                .map(|o| o.iou50)
                .sum();
            classes.push(ClassMetrics {
                class: name.clone(),
                ap50: ap.map(|ap| ap[T50]),
                ap75: ap.map(|ap| ap[T75]),
                ap50_95: ap.map(|ap| ap.iter().sum::<f64>() / ap.len() as f64),
                precision: (tp + fp > 0).then(|| tp as f64 / (tp + fp) as f64),
                recall: (tally.positives > 0).then(|| tp as f64 / tally.positives as f64),
                mean_iou: (tp > 0).then(|| iou_sum / tp as f64),
                ground_truth: tally.positives,
                ignored_ground_truth: tally.ignored_gt,
                detections: tally.outcomes.len(),
                dropped_detections: tally.dropped,
                true_positives: tp,
                false_positives: fp,
                ignored_detections: tally.outcomes.len() - tp - fp,
            });
        }
        let mean = |f: fn(&ClassMetrics) -> Option<f64>| {
            let values: Vec<f64> = classes.iter().filter_map(f).collect();
            (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
        };
        DetectionMetrics {
            ap50: mean(|c| c.ap50),
            ap75: mean(|c| c.ap75),
            ap50_95: mean(|c| c.ap50_95),
            images: self.images,
            classes,
        }
    }
}

/// COCO's AP of one class at threshold `t`: the interpolated precision at 101 recall points,
/// averaged. `order` ranks the class's outcomes by score (stable).
fn average_precision(tally: &ClassTally, order: &[usize], t: usize) -> f64 {
    let positives = tally.positives as f64;
    let mut recall = Vec::with_capacity(order.len());
    let mut precision = Vec::with_capacity(order.len());
    let (mut tp, mut fp) = (0.0_f64, 0.0_f64);
    for &i in order {
        let outcome = &tally.outcomes[i];
        if outcome.true_positive(t) {
            tp += 1.0;
        } else if outcome.false_positive(t) {
            fp += 1.0;
        }
        recall.push(tp / positives);
        precision.push(tp / (fp + tp + f64::EPSILON));
    }
    // Precision envelope: the best precision at this recall or any higher one.
    for i in (1..precision.len()).rev() {
        if precision[i] > precision[i - 1] {
            precision[i - 1] = precision[i];
        }
    }
    let mut sum = 0.0;
    let mut at = 0;
    for r in 0..RECALL_POINTS {
        let point = recall_point(r);
        // np.searchsorted(recall, point, side='left'): `recall` never decreases.
        while at < recall.len() && recall[at] < point {
            at += 1;
        }
        match precision.get(at) {
            Some(&p) => sum += p,
            None => break,
        }
    }
    sum / RECALL_POINTS as f64
}

/// One class's results in [`DetectionMetrics`]. The AP fields and `recall` are `None` for a
/// class without non-ignored ground truth (COCO's `-1`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClassMetrics {
    /// Class name.
    pub class: String,
    /// AP at IoU 0.5.
    pub ap50: Option<f64>,
    /// AP at IoU 0.75.
    pub ap75: Option<f64>,
    /// AP averaged over IoU 0.50:0.05:0.95 (COCO's AP).
    pub ap50_95: Option<f64>,
    /// True positives / (true + false positives) at IoU 0.5 over all evaluated detections;
    /// `None` without any.
    pub precision: Option<f64>,
    /// True positives / ground truth at IoU 0.5 over all evaluated detections.
    pub recall: Option<f64>,
    /// Mean IoU of the true positives at IoU 0.5; `None` without any.
    pub mean_iou: Option<f64>,
    /// Objects to find (non-ignored ground truth).
    pub ground_truth: usize,
    /// Ignore regions.
    pub ignored_ground_truth: usize,
    /// Detections evaluated (at most 100 per image).
    pub detections: usize,
    /// Detections dropped beyond the 100 best of an image.
    pub dropped_detections: usize,
    /// True positives at IoU 0.5.
    pub true_positives: usize,
    /// False positives at IoU 0.5.
    pub false_positives: usize,
    /// Detections on ignore regions at IoU 0.5 (neither true nor false positives).
    pub ignored_detections: usize,
}

/// What [`CocoEvaluator::summary`] returns. The means are over the classes with non-ignored
/// ground truth, as COCO's `stats` are (`None` when there is none).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectionMetrics {
    /// Mean AP at IoU 0.5 (COCO's `stats[1]`).
    pub ap50: Option<f64>,
    /// Mean AP at IoU 0.75 (COCO's `stats[2]`).
    pub ap75: Option<f64>,
    /// Mean AP over IoU 0.50:0.05:0.95 (COCO's `stats[0]`, "AP").
    pub ap50_95: Option<f64>,
    /// Number of images evaluated.
    pub images: usize,
    /// Every class seen in ground truth or detections, sorted by name.
    pub classes: Vec<ClassMetrics>,
}

impl DetectionMetrics {
    /// The results of `class`, if it was seen.
    pub fn class(&self, class: &str) -> Option<&ClassMetrics> {
        self.classes.iter().find(|c| c.class == class)
    }
}

#[cfg(test)]
#[allow(
    clippy::expect_used,
    reason = "tests: a failed expect is a failed test"
)]
mod tests {
    use super::*;

    fn gt(class: &str, b: [f64; 4]) -> GroundTruthObject {
        GroundTruthObject {
            class: class.into(),
            bbox: EvalBox::new(b[0], b[1], b[2], b[3]),
            ignore: false,
        }
    }

    fn crowd(class: &str, b: [f64; 4]) -> GroundTruthObject {
        GroundTruthObject {
            ignore: true,
            ..gt(class, b)
        }
    }

    fn det(class: &str, b: [f64; 4], score: f64) -> Detection {
        Detection {
            class: class.into(),
            bbox: EvalBox::new(b[0], b[1], b[2], b[3]),
            score,
        }
    }

    fn close(a: Option<f64>, b: f64) -> bool {
        a.is_some_and(|a| (a - b).abs() < 1e-12)
    }

    #[test]
    fn thresholds_are_numpy_linspace() {
        let step = (0.95 - 0.5) / 9.0;
        for (i, &t) in COCO_IOU_THRESHOLDS.iter().enumerate().take(9) {
            assert_eq!(t, i as f64 * step + 0.5);
        }
        assert_eq!(COCO_IOU_THRESHOLDS[T75], 0.75);
        assert_eq!(recall_point(50), 0.5);
        assert_eq!(recall_point(100), 1.0);
    }

    #[test]
    fn iou_and_crowd_overlap() {
        let a = EvalBox::new(0.0, 0.0, 10.0, 10.0);
        let b = EvalBox::new(5.0, 5.0, 15.0, 15.0);
        assert!((a.iou(&b) - 25.0 / 175.0).abs() < 1e-15);
        assert_eq!(a.iou(&EvalBox::new(10.0, 0.0, 20.0, 10.0)), 0.0);
        assert_eq!(a.area(), 100.0);
        // An ignore region covering the detection: intersection over the detection's area.
        assert_eq!(overlap(&a, &EvalBox::new(0.0, 0.0, 20.0, 20.0), true), 1.0);
    }

    #[test]
    fn perfect_detections_score_one() {
        let mut eval = CocoEvaluator::new();
        for i in 0..5 {
            let x = 10.0 * i as f64;
            let truth = [
                gt("car", [x, 0.0, x + 8.0, 6.0]),
                gt("dog", [x, 50.0, x + 4.0, 60.0]),
            ];
            let dets = [
                det("car", [x, 0.0, x + 8.0, 6.0], 0.9),
                det("dog", [x, 50.0, x + 4.0, 60.0], 0.3),
            ];
            eval.add_image(&truth, &dets);
        }
        let m = eval.summary();
        assert_eq!(m.images, 5);
        assert!(close(m.ap50, 1.0) && close(m.ap75, 1.0) && close(m.ap50_95, 1.0));
        assert_eq!(m.classes.len(), 2);
        let car = m.class("car").expect("car");
        assert!(close(car.precision, 1.0) && close(car.recall, 1.0) && close(car.mean_iou, 1.0));
        assert_eq!(
            (car.ground_truth, car.true_positives, car.false_positives),
            (5, 5, 0)
        );
    }

    #[test]
    fn false_positive_ranked_above_the_true_one_halves_ap() {
        let mut eval = CocoEvaluator::new();
        eval.add_image(
            &[gt("car", [0.0, 0.0, 10.0, 10.0])],
            &[
                det("car", [50.0, 50.0, 60.0, 60.0], 0.9),
                det("car", [0.0, 0.0, 10.0, 10.0], 0.8),
            ],
        );
        let m = eval.summary();
        // Precision 1/2 at the only recall reached (1.0), at every threshold.
        assert!(close(m.ap50_95, 0.5), "{m:?}");
        let car = m.class("car").expect("car");
        assert!(close(car.precision, 0.5) && close(car.recall, 1.0));

        // TP 0.9, FP 0.8, TP 0.7 on two objects: precision 1 up to recall 0.5 (51 points),
        // then 2/3 (50 points).
        let mut eval = CocoEvaluator::new();
        eval.add_image(
            &[
                gt("car", [0.0, 0.0, 10.0, 10.0]),
                gt("car", [20.0, 0.0, 30.0, 10.0]),
            ],
            &[
                det("car", [0.0, 0.0, 10.0, 10.0], 0.9),
                det("car", [50.0, 50.0, 60.0, 60.0], 0.8),
                det("car", [20.0, 0.0, 30.0, 10.0], 0.7),
            ],
        );
        assert!(close(eval.summary().ap50, 253.0 / 303.0));
    }

    #[test]
    fn detection_on_an_ignore_region_is_neither_tp_nor_fp() {
        let truth = [
            gt("person", [0.0, 0.0, 10.0, 20.0]),
            crowd("person", [100.0, 0.0, 200.0, 100.0]),
        ];
        let dets = [
            det("person", [120.0, 10.0, 130.0, 30.0], 0.95),
            det("person", [0.0, 0.0, 10.0, 20.0], 0.9),
            det("person", [150.0, 10.0, 160.0, 30.0], 0.5),
        ];
        let mut eval = CocoEvaluator::new();
        eval.add_image(&truth, &dets);
        let m = eval.summary();
        assert!(close(m.ap50_95, 1.0), "{m:?}");
        let p = m.class("person").expect("person");
        assert_eq!(
            (p.ground_truth, p.ignored_ground_truth, p.detections),
            (1, 1, 3)
        );
        assert_eq!(
            (p.true_positives, p.false_positives, p.ignored_detections),
            (1, 0, 2)
        );
        let frame = match_frame(&truth, &dets, 0.5);
        assert_eq!(frame.ignored, vec![0, 2]);
        assert!(frame.false_positives.is_empty() && frame.misses.is_empty());
    }

    #[test]
    fn match_frame_is_greedy_by_score_per_class() {
        let truth = [
            gt("car", [0.0, 0.0, 10.0, 10.0]),
            gt("car", [100.0, 0.0, 110.0, 10.0]),
            gt("dog", [0.0, 50.0, 10.0, 60.0]),
        ];
        let dets = [
            det("car", [1.0, 0.0, 11.0, 10.0], 0.6), // IoU 9/11, but lower score
            det("car", [0.0, 0.0, 10.0, 9.0], 0.8),  // IoU 0.9: takes the car first
            det("cat", [0.0, 50.0, 10.0, 60.0], 0.9), // wrong class
            det("car", [300.0, 0.0, 310.0, 10.0], 0.7),
        ];
        let frame = match_frame(&truth, &dets, 0.5);
        assert_eq!(frame.matches.len(), 1);
        assert_eq!(
            (frame.matches[0].detection, frame.matches[0].ground_truth),
            (1, 0)
        );
        assert!((frame.matches[0].iou - 0.9).abs() < 1e-12);
        assert_eq!(frame.false_positives, vec![0, 2, 3]);
        assert_eq!(frame.misses, vec![1, 2]);
        assert!(frame.ignored.is_empty());
        // At a looser threshold nothing changes; above 0.9 the car is missed too.
        assert_eq!(match_frame(&truth, &dets, 0.95).misses, vec![0, 1, 2]);
    }

    #[test]
    fn a_later_object_wins_an_iou_tie() {
        let truth = [
            gt("car", [0.0, 0.0, 10.0, 10.0]),
            gt("car", [2.0, 0.0, 12.0, 10.0]),
        ];
        let dets = [
            det("car", [1.0, 0.0, 11.0, 10.0], 0.9), // IoU 9/11 with both
            det("car", [0.0, 0.0, 9.5, 10.0], 0.8),  // IoU 0.95 and 0.625
        ];
        let frame = match_frame(&truth, &dets, 0.75);
        let pairs: Vec<(usize, usize)> = frame
            .matches
            .iter()
            .map(|m| (m.detection, m.ground_truth))
            .collect();
        assert_eq!(pairs, [(0, 1), (1, 0)]);
    }

    #[test]
    fn equal_scores_keep_input_order() {
        let truth = [gt("car", [0.0, 0.0, 10.0, 10.0])];
        let dets = [
            det("car", [0.0, 0.0, 10.0, 8.0], 0.5),
            det("car", [0.0, 0.0, 10.0, 10.0], 0.5),
        ];
        let frame = match_frame(&truth, &dets, 0.5);
        assert_eq!(frame.matches[0].detection, 0);
        assert_eq!(frame.false_positives, vec![1]);
    }

    #[test]
    fn only_the_best_hundred_detections_of_an_image_count() {
        let truth = [gt("car", [0.0, 0.0, 10.0, 10.0])];
        let mut dets: Vec<Detection> = (0..COCO_MAX_DETECTIONS)
            .map(|i| det("car", [500.0 + i as f64, 0.0, 505.0 + i as f64, 5.0], 0.5))
            .collect();
        dets.push(det("car", [0.0, 0.0, 10.0, 10.0], 0.5)); // tied, but last
        let mut eval = CocoEvaluator::new();
        eval.add_image(&truth, &dets);
        let car = eval.summary().classes.remove(0);
        assert_eq!((car.detections, car.dropped_detections), (100, 1));
        assert_eq!((car.true_positives, car.false_positives), (0, 100));
        assert!(close(car.ap50, 0.0));
    }

    #[test]
    fn classes_without_ground_truth_have_no_ap() {
        let mut eval = CocoEvaluator::new();
        eval.add_image(
            &[
                gt("car", [0.0, 0.0, 10.0, 10.0]),
                crowd("dog", [0.0, 0.0, 50.0, 50.0]),
            ],
            &[
                det("car", [0.0, 0.0, 10.0, 10.0], 0.9),
                det("kite", [0.0, 0.0, 10.0, 10.0], 0.9),
            ],
        );
        let m = eval.summary();
        let names: Vec<&str> = m.classes.iter().map(|c| c.class.as_str()).collect();
        assert_eq!(names, ["car", "dog", "kite"]);
        assert!(m.classes[1].ap50.is_none() && m.classes[2].ap50_95.is_none());
        assert_eq!(m.classes[2].false_positives, 1);
        assert!(close(m.ap50_95, 1.0));
        assert!(CocoEvaluator::new().summary().ap50.is_none());
    }
}
