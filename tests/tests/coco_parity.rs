//! rover-perception's `CocoEvaluator` against pycocotools' `COCOeval` (`bbox`) on the same
//! pseudo-random images: crowd regions, jittered and duplicate detections, false positives,
//! tied scores, an image with more than 100 detections of one class, a class without ground
//! truth. Skips, saying why, where python3 lacks pycocotools (./test installs it).

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result};
use rover_perception::{CocoEvaluator, Detection, DetectionMetrics, EvalBox, GroundTruthObject};

/// Class names; "kite" only ever appears as detections.
const CLASSES: [&str; 4] = ["bicycle", "car", "kite", "person"];
const WIDTH: f64 = 640.0;
const HEIGHT: f64 = 480.0;
/// Both compute the same floating-point values; only the order of the final sums differs
/// (about 1e-16). Much tighter than 1e-3 on purpose: ranking tied scores with an unstable sort
/// moves AP by only ~4e-5 on this fixture.
const TOLERANCE: f64 = 1e-9;

/// rover's SplitMix64: the same sequence everywhere.
struct Rng(rover_sim::SplitMix64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        self.0.unit()
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    /// A score on a coarse grid (0.05 .. 1.0), so that many are tied.
    fn score(&mut self) -> f64 {
        (1 + self.below(20)) as f64 / 20.0
    }

    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

struct Image {
    ground_truth: Vec<GroundTruthObject>,
    detections: Vec<Detection>,
}

fn random_box(rng: &mut Rng, min: f64, max: f64) -> EvalBox {
    let w = min + rng.unit() * (max - min);
    let h = min + rng.unit() * (max - min);
    let x = rng.unit() * (WIDTH - w);
    let y = rng.unit() * (HEIGHT - h);
    EvalBox::new(x, y, x + w, y + h)
}

/// `b` moved and resized by up to `amount` of its size: IoUs from about 0.3 to 1.
fn jitter(rng: &mut Rng, b: &EvalBox, amount: f64) -> EvalBox {
    let (w, h) = (b.width(), b.height());
    let mut d = |s: f64| (rng.unit() - 0.5) * amount * s;
    EvalBox::new(b.xmin + d(w), b.ymin + d(h), b.xmax + d(w), b.ymax + d(h))
}

fn det(class: &str, bbox: EvalBox, score: f64) -> Detection {
    Detection {
        class: class.to_owned(),
        bbox,
        score,
    }
}

fn fixture(seed: u64, images: usize) -> Vec<Image> {
    let mut rng = Rng(rover_sim::SplitMix64(seed));
    let mut out = Vec::with_capacity(images);
    for i in 0..images {
        let mut ground_truth = Vec::new();
        let mut detections = Vec::new();
        for class in ["bicycle", "car", "person"] {
            for _ in 0..rng.below(5) {
                let crowd = rng.chance(0.1);
                let bbox = if crowd {
                    random_box(&mut rng, 120.0, 300.0)
                } else {
                    random_box(&mut rng, 8.0, 160.0)
                };
                ground_truth.push(GroundTruthObject {
                    class: class.to_owned(),
                    bbox,
                    ignore: crowd,
                });
                if crowd {
                    // Detections inside the crowd (and one sticking out of it).
                    for _ in 0..rng.below(4) {
                        let w = 10.0 + rng.unit() * 40.0;
                        let x = bbox.xmin + rng.unit() * (bbox.width() - w * 0.6);
                        let y = bbox.ymin + rng.unit() * (bbox.height() - w * 0.6);
                        let score = rng.score();
                        detections.push(det(class, EvalBox::new(x, y, x + w, y + w), score));
                    }
                    continue;
                }
                if rng.chance(0.85) {
                    let amount = 0.05 + rng.unit() * 0.6;
                    let score = rng.score();
                    detections.push(det(class, jitter(&mut rng, &bbox, amount), score));
                }
                if rng.chance(0.25) {
                    let score = rng.score();
                    detections.push(det(class, jitter(&mut rng, &bbox, 0.3), score));
                }
                if rng.chance(0.1) {
                    let other = CLASSES[rng.below(4) as usize];
                    let score = rng.score();
                    detections.push(det(other, jitter(&mut rng, &bbox, 0.1), score));
                }
            }
        }
        for _ in 0..rng.below(5) {
            let class = CLASSES[rng.below(4) as usize];
            let bbox = random_box(&mut rng, 8.0, 200.0);
            let score = rng.score();
            detections.push(det(class, bbox, score));
        }
        match i {
            // An image with nothing, one with objects but no detections.
            3 => {
                ground_truth.clear();
                detections.clear();
            }
            5 => detections.clear(),
            // A degenerate detection (zero width) and an inverted one (negative area: COCO
            // ignores it unless it matches).
            8 => {
                detections.push(det("car", EvalBox::new(100.0, 100.0, 100.0, 150.0), 0.9));
                detections.push(det("car", EvalBox::new(200.0, 100.0, 150.0, 150.0), 0.95));
            }
            // A detection overlapping two cars exactly equally (0.818): COCO gives it the later
            // one, which leaves the first for the next detection (IoU 0.95, 0.625 with the
            // second).
            12 => {
                for b in [[0.0, 0.0, 10.0, 10.0], [2.0, 0.0, 12.0, 10.0]] {
                    ground_truth.push(GroundTruthObject {
                        class: "car".to_owned(),
                        bbox: EvalBox::new(b[0], b[1], b[2], b[3]),
                        ignore: false,
                    });
                }
                detections.push(det("car", EvalBox::new(1.0, 0.0, 11.0, 10.0), 1.0));
                detections.push(det("car", EvalBox::new(0.0, 0.0, 9.5, 10.0), 1.0));
            }
            // More than 100 detections of one class, many tied at the cut.
            9 => {
                for g in ground_truth.iter().filter(|g| g.class == "person") {
                    let score = rng.score();
                    detections.push(det("person", jitter(&mut rng, &g.bbox, 0.2), score));
                }
                for _ in 0..140 {
                    let bbox = random_box(&mut rng, 8.0, 120.0);
                    let score = rng.score();
                    detections.push(det("person", bbox, score));
                }
            }
            _ => {}
        }
        // Shuffle so that ties are not in generation order.
        for k in (1..detections.len()).rev() {
            let j = rng.below(k as u64 + 1) as usize;
            detections.swap(k, j);
        }
        out.push(Image {
            ground_truth,
            detections,
        });
    }
    out
}

fn category_id(class: &str) -> usize {
    CLASSES.iter().position(|c| *c == class).unwrap_or(0) + 1
}

fn xywh(b: &EvalBox) -> String {
    format!("[{}, {}, {}, {}]", b.xmin, b.ymin, b.width(), b.height())
}

/// The images as COCO ground truth and results JSON (image ids from 1, in order).
fn coco_json(images: &[Image]) -> Result<(String, String)> {
    let mut gt = String::from("{\"images\": [");
    for i in 0..images.len() {
        let sep = if i == 0 { "" } else { ", " };
        write!(gt, "{sep}{{\"id\": {}}}", i + 1)?;
    }
    gt.push_str("], \"categories\": [");
    for (k, class) in CLASSES.iter().enumerate() {
        let sep = if k == 0 { "" } else { ", " };
        write!(gt, "{sep}{{\"id\": {}, \"name\": \"{class}\"}}", k + 1)?;
    }
    gt.push_str("], \"annotations\": [");
    let mut results = String::from("[");
    let mut id = 0;
    for (i, image) in images.iter().enumerate() {
        for g in &image.ground_truth {
            id += 1;
            let sep = if id == 1 { "" } else { ", " };
            write!(
                gt,
                "{sep}{{\"id\": {id}, \"image_id\": {}, \"category_id\": {}, \"bbox\": {}, \
                 \"area\": {}, \"iscrowd\": {}}}",
                i + 1,
                category_id(&g.class),
                xywh(&g.bbox),
                g.bbox.width() * g.bbox.height(),
                u8::from(g.ignore)
            )?;
        }
        for d in &image.detections {
            let sep = if results.len() == 1 { "" } else { ", " };
            write!(
                results,
                "{sep}{{\"image_id\": {}, \"category_id\": {}, \"bbox\": {}, \"score\": {}}}",
                i + 1,
                category_id(&d.class),
                xywh(&d.bbox),
                d.score
            )?;
        }
    }
    gt.push_str("]}");
    results.push(']');
    Ok((gt, results))
}

/// COCOeval on the two files. Prints `stats AP AP50 AP75`, then per category
/// `class NAME AP50 AP TP FP MEAN_IOU` at IoU 0.5 (AP -1 without ground truth, mean IoU -1
/// without true positives).
const REFERENCE: &str = r#"
import contextlib, sys
import numpy as np
from pycocotools.coco import COCO
from pycocotools.cocoeval import COCOeval

with contextlib.redirect_stdout(sys.stderr):
    gt = COCO(sys.argv[1])
    ev = COCOeval(gt, gt.loadRes(sys.argv[2]), 'bbox')
    ev.evaluate()
    ev.accumulate()
    ev.summarize()
print('stats', *(repr(float(s)) for s in ev.stats[:3]))
precision = ev.eval['precision']  # [T, R, K, A, M]; area 'all' is 0, maxDets 100 is 2
for k, cat in enumerate(ev.params.catIds):
    p = precision[:, :, k, 0, 2]
    ap50, ap = (float(np.mean(p[0])), float(np.mean(p))) if (p > -1).any() else (-1.0, -1.0)
    tp, fp, ious = 0, 0, []
    for e in ev.evalImgs:
        if e is None or e['category_id'] != cat or e['aRng'] != ev.params.areaRng[0]:
            continue
        gt_ids = [g['id'] for g in ev._gts[e['image_id'], cat]]
        iou = ev.ious[e['image_id'], cat]
        for d, (m, ignored) in enumerate(zip(e['dtMatches'][0], e['dtIgnore'][0])):
            if ignored:
                continue
            if m > 0:
                tp += 1
                ious.append(iou[d, gt_ids.index(int(m))])
            else:
                fp += 1
    mean_iou = float(np.mean(ious)) if ious else -1.0
    print('class', gt.cats[cat]['name'], repr(ap50), repr(ap), tp, fp, repr(mean_iou))
"#;

struct ReferenceClass {
    name: String,
    ap50: f64,
    ap: f64,
    tp: usize,
    fp: usize,
    mean_iou: f64,
}

struct Reference {
    stats: [f64; 3],
    classes: Vec<ReferenceClass>,
}

fn parse_reference(out: &str) -> Result<Reference> {
    let mut stats = None;
    let mut classes = Vec::new();
    for line in out.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        match f.as_slice() {
            ["stats", a, b, c] => stats = Some([a.parse()?, b.parse()?, c.parse()?]),
            ["class", name, ap50, ap, tp, fp, iou] => classes.push(ReferenceClass {
                name: (*name).to_owned(),
                ap50: ap50.parse()?,
                ap: ap.parse()?,
                tp: tp.parse()?,
                fp: fp.parse()?,
                mean_iou: iou.parse()?,
            }),
            _ => anyhow::bail!("unexpected reference output line: {line}"),
        }
    }
    Ok(Reference {
        stats: stats.context("no stats line from the reference")?,
        classes,
    })
}

fn run_reference(images: &[Image], dir: &Path) -> Result<Reference> {
    let (gt, results) = coco_json(images)?;
    let (gt_path, results_path) = (dir.join("gt.json"), dir.join("results.json"));
    std::fs::write(&gt_path, gt)?;
    std::fs::write(&results_path, results)?;
    let out = Command::new("python3")
        .args(["-c", REFERENCE])
        .arg(&gt_path)
        .arg(&results_path)
        .output()?;
    anyhow::ensure!(
        out.status.success(),
        "pycocotools failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    parse_reference(&String::from_utf8(out.stdout)?)
}

/// COCO's -1 for "no value".
fn or_minus_one(v: Option<f64>) -> f64 {
    v.unwrap_or(-1.0)
}

/// Asserts `ours` is within [`TOLERANCE`] of `theirs`; returns the difference.
fn assert_close(what: &str, ours: f64, theirs: f64) -> f64 {
    let difference = (ours - theirs).abs();
    assert!(
        difference <= TOLERANCE,
        "{what}: rover {ours} vs pycocotools {theirs}"
    );
    difference
}

/// Compares everything; returns the largest difference of an AP or mean IoU.
fn compare(seed: u64, ours: &DetectionMetrics, reference: &Reference) -> f64 {
    println!(
        "seed {seed:#x}: AP50:95 rover {:.12} pycocotools {:.12} | AP50 {:.12} {:.12} | AP75 {:.12} {:.12}",
        or_minus_one(ours.ap50_95),
        reference.stats[0],
        or_minus_one(ours.ap50),
        reference.stats[1],
        or_minus_one(ours.ap75),
        reference.stats[2]
    );
    let mut largest = [
        assert_close("AP50:95", or_minus_one(ours.ap50_95), reference.stats[0]),
        assert_close("AP50", or_minus_one(ours.ap50), reference.stats[1]),
        assert_close("AP75", or_minus_one(ours.ap75), reference.stats[2]),
    ]
    .into_iter()
    .fold(0.0, f64::max);
    let mut names: Vec<&str> = reference.classes.iter().map(|c| c.name.as_str()).collect();
    names.sort_unstable();
    let ours_names: Vec<&str> = ours.classes.iter().map(|c| c.class.as_str()).collect();
    assert_eq!(ours_names, names, "classes");
    for theirs in &reference.classes {
        let Some(c) = ours.class(&theirs.name) else {
            panic!("class {} missing", theirs.name);
        };
        println!(
            "  {:8} AP50 {:.6}/{:.6} AP {:.6}/{:.6} TP {}/{} FP {}/{} mean IoU {:.6}/{:.6} \
             (gt {}, ignored gt {}, dets {}, dropped {}, ignored dets {})",
            c.class,
            or_minus_one(c.ap50),
            theirs.ap50,
            or_minus_one(c.ap50_95),
            theirs.ap,
            c.true_positives,
            theirs.tp,
            c.false_positives,
            theirs.fp,
            or_minus_one(c.mean_iou),
            theirs.mean_iou,
            c.ground_truth,
            c.ignored_ground_truth,
            c.detections,
            c.dropped_detections,
            c.ignored_detections
        );
        let what = |m: &str| format!("seed {seed:#x} {} {m}", c.class);
        largest = largest
            .max(assert_close(
                &what("AP50"),
                or_minus_one(c.ap50),
                theirs.ap50,
            ))
            .max(assert_close(
                &what("AP50:95"),
                or_minus_one(c.ap50_95),
                theirs.ap,
            ))
            .max(assert_close(
                &what("mean IoU"),
                or_minus_one(c.mean_iou),
                theirs.mean_iou,
            ));
        assert_eq!(
            (c.true_positives, c.false_positives),
            (theirs.tp, theirs.fp),
            "{}",
            what("TP, FP at IoU 0.5")
        );
    }
    largest
}

fn has_pycocotools() -> bool {
    Command::new("python3")
        .args(["-c", "import numpy, pycocotools.cocoeval"])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn coco_evaluator_matches_pycocotools() -> Result<()> {
    if !has_pycocotools() {
        return rover_tests::skip(
            "python3 cannot import pycocotools and numpy (pip install pycocotools; ./test \
             installs it)",
        );
    }
    let dir = tempfile::tempdir()?;
    let mut largest: f64 = 0.0;
    for seed in [0x5EED, 0xC0C0, 7] {
        let images = fixture(seed, 30);
        let mut eval = CocoEvaluator::new();
        for image in &images {
            eval.add_image(&image.ground_truth, &image.detections);
        }
        let ours = eval.summary();
        assert_eq!(ours.images, 30);
        // The fixture exercises what it is meant to.
        let kite = ours.class("kite").context("kite")?;
        assert!(kite.ap50.is_none() && kite.detections > 0);
        assert!(ours.classes.iter().any(|c| c.dropped_detections > 0));
        assert!(ours.classes.iter().any(|c| c.ignored_detections > 0));
        assert!(ours.classes.iter().any(|c| c.ignored_ground_truth > 0));

        let reference = run_reference(&images, dir.path())?;
        largest = largest.max(compare(seed, &ours, &reference));
    }
    println!("largest difference from pycocotools: {largest:e} (tolerance {TOLERANCE:e})");
    Ok(())
}
