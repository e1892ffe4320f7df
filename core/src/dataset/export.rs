//! What a dataset says about each image, in rover's own record and in the two formats
//! trainers read: Ultralytics YOLO (`class cx cy w h`, normalised, COCO-80 class numbers) and
//! COCO JSON (boxes in pixels, COCO's own category ids, ignore regions as `iscrowd`).

use std::fmt::Write as _;

use rover_assets::COCO80;
use rover_perception::{BoundingBoxes, Detection, EvalBox, GroundTruthObject};
use rover_sim::sensors::{GroundTruthBox, PixelBox};
use serde::{Deserialize, Serialize};

use crate::dataset::randomize::Shot;
use crate::dataset::store::Split;

/// COCO's category id of each of the 80 classes, in [`COCO80`] order (COCO numbers 91
/// categories and annotates 80 of them).
pub const COCO_CATEGORY_IDS: [u32; 80] = [
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 27, 28,
    31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55,
    56, 57, 58, 59, 60, 61, 62, 63, 64, 65, 67, 70, 72, 73, 74, 75, 76, 77, 78, 79, 80, 81, 82, 84,
    85, 86, 87, 88, 89, 90,
];

/// The COCO-80 number (YOLO's class id) of `class`.
pub fn yolo_class(class: &str) -> Option<usize> {
    COCO80.iter().position(|c| *c == class)
}

/// COCO's category id of `class`.
pub fn coco_category(class: &str) -> Option<u32> {
    yolo_class(class).map(|i| COCO_CATEGORY_IDS[i])
}

/// One labelled thing of an image, as the dataset records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabelledBox {
    /// Its COCO class.
    pub class: String,
    /// Its name in the world.
    pub name: String,
    /// The box trainers get, `[x, y, w, h]` in pixels: the visible (tight) box; for a thing
    /// with no visible pixel, its full box.
    pub bbox: [f64; 4],
    /// The full (amodal) box, `[x, y, w, h]`, clipped to the image.
    pub full_bbox: [f64; 4],
    /// Pixels of the image that show it (COCO's `area`).
    pub visible_px: u32,
    /// Fraction of it not hidden by other things (0..1).
    pub visibility: f64,
    /// The image border cut it.
    pub truncated: bool,
    /// Fraction of its full box outside the image (0..1, KITTI's `truncated`; 1 when part of
    /// it was behind the camera). Records written before it existed read as 0.
    #[serde(default)]
    pub truncation: f64,
    /// Too small or too hidden to ask a detector for: COCO's `iscrowd`, left out of YOLO
    /// labels.
    pub ignore: bool,
}

impl LabelledBox {
    /// The record of one ground-truth box.
    pub fn from_truth(t: &GroundTruthBox) -> Self {
        Self {
            class: t.class.clone(),
            name: t.name.clone(),
            bbox: xywh(&t.visible.unwrap_or(t.full)),
            full_bbox: xywh(&t.full),
            visible_px: t.visible_px,
            visibility: t.visibility,
            truncated: t.truncated,
            truncation: t.truncation,
            ignore: t.ignore || t.visible.is_none(),
        }
    }
}

fn xywh(b: &PixelBox) -> [f64; 4] {
    [b.xmin, b.ymin, b.width(), b.height()]
}

/// One detection the detector made on an image (`--detect`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DetectedBox {
    /// Class name.
    pub class: String,
    /// Confidence.
    pub score: f64,
    /// `[x, y, w, h]` in pixels.
    pub bbox: [f64; 4],
}

impl DetectedBox {
    /// The detections of one result.
    pub fn from_result(result: &BoundingBoxes) -> Vec<Self> {
        result
            .bounding_boxes
            .iter()
            .map(|b| Self {
                class: b.class.clone(),
                score: b.probability,
                bbox: [
                    b.xmin as f64,
                    b.ymin as f64,
                    (b.xmax - b.xmin) as f64,
                    (b.ymax - b.ymin) as f64,
                ],
            })
            .collect()
    }
}

/// rover's record of one image: everything the formats are made from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageRecord {
    /// The image's number (0..), its COCO id is `index + 1`.
    pub index: u64,
    /// Its split.
    pub split: Split,
    /// Its file name in `images/<split>/`.
    pub file_name: String,
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Every labelled thing in view (ignore regions included).
    pub objects: Vec<LabelledBox>,
    /// The detector's boxes, with `--detect`.
    pub detections: Option<Vec<DetectedBox>>,
    /// How the scene was laid out.
    pub shot: Shot,
}

impl ImageRecord {
    /// Its YOLO label file: one `class cx cy w h` line (normalised to the image, six decimals)
    /// per labelled thing that is not an ignore region.
    pub fn yolo_label(&self) -> String {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let mut out = String::new();
        for o in self.objects.iter().filter(|o| !o.ignore) {
            let Some(class) = yolo_class(&o.class) else {
                continue;
            };
            let [x, y, bw, bh] = o.bbox;
            let _ = writeln!(
                out,
                "{class} {:.6} {:.6} {:.6} {:.6}",
                (x + bw / 2.0) / w,
                (y + bh / 2.0) / h,
                bw / w,
                bh / h
            );
        }
        out
    }

    /// The ground truth as the evaluator takes it (the boxes COCO JSON holds).
    pub fn eval_truth(&self) -> Vec<GroundTruthObject> {
        self.objects
            .iter()
            .map(|o| GroundTruthObject {
                class: o.class.clone(),
                bbox: EvalBox::from_xywh(o.bbox[0], o.bbox[1], o.bbox[2], o.bbox[3]),
                ignore: o.ignore,
            })
            .collect()
    }

    /// The detections as the evaluator takes them.
    pub fn eval_detections(&self) -> Vec<Detection> {
        self.detections
            .iter()
            .flatten()
            .map(|d| Detection {
                class: d.class.clone(),
                bbox: EvalBox::from_xywh(d.bbox[0], d.bbox[1], d.bbox[2], d.bbox[3]),
                score: d.score,
            })
            .collect()
    }
}

/// Ultralytics' `data.yaml`: the folder as the dataset's root (no `path`: Ultralytics then
/// takes the yaml's own folder), the two splits, COCO's 80 names.
pub fn data_yaml() -> String {
    let mut out = String::from(
        "# Made by rover dataset: Ultralytics YOLO layout, COCO-80 class numbers.\n\
         # No `path`: Ultralytics takes this file's folder as the dataset's root.\n\
         train: images/train\nval: images/val\nnc: 80\nnames:\n",
    );
    for (i, name) in COCO80.iter().enumerate() {
        let _ = writeln!(out, "  {i}: {name}");
    }
    out
}

#[derive(Serialize)]
struct CocoImage<'a> {
    id: u64,
    file_name: &'a str,
    width: u32,
    height: u32,
}

#[derive(Serialize)]
struct CocoAnnotation<'a> {
    id: u64,
    image_id: u64,
    category_id: u32,
    bbox: [f64; 4],
    area: f64,
    iscrowd: u8,
    /// rover's extras (COCO readers skip unknown keys).
    name: &'a str,
    amodal_bbox: [f64; 4],
    visibility: f64,
    truncated: bool,
    truncation: f64,
}

#[derive(Serialize)]
struct CocoCategory {
    id: u32,
    name: &'static str,
    supercategory: &'static str,
}

#[derive(Serialize)]
struct CocoFile<'a> {
    info: CocoInfo,
    licenses: [(); 0],
    images: Vec<CocoImage<'a>>,
    annotations: Vec<CocoAnnotation<'a>>,
    categories: Vec<CocoCategory>,
}

#[derive(Serialize)]
struct CocoInfo {
    description: String,
    version: &'static str,
}

/// One split's COCO JSON (`instances_<split>.json`): images with id `index + 1`, annotations
/// numbered in image order, every COCO category.
pub fn coco_json(records: &[ImageRecord], split: Split) -> serde_json::Result<String> {
    let mut images = Vec::new();
    let mut annotations = Vec::new();
    for r in records.iter().filter(|r| r.split == split) {
        let image_id = r.index + 1;
        images.push(CocoImage {
            id: image_id,
            file_name: &r.file_name,
            width: r.width,
            height: r.height,
        });
        for o in &r.objects {
            let Some(category_id) = coco_category(&o.class) else {
                continue;
            };
            annotations.push(CocoAnnotation {
                id: annotations.len() as u64 + 1,
                image_id,
                category_id,
                bbox: o.bbox,
                area: f64::from(o.visible_px),
                iscrowd: u8::from(o.ignore),
                name: &o.name,
                amodal_bbox: o.full_bbox,
                visibility: o.visibility,
                truncated: o.truncated,
                truncation: o.truncation,
            });
        }
    }
    let file = CocoFile {
        info: CocoInfo {
            description: format!("rover dataset, {} split", split.name()),
            version: env!("CARGO_PKG_VERSION"),
        },
        licenses: [],
        images,
        annotations,
        categories: COCO80
            .iter()
            .zip(COCO_CATEGORY_IDS)
            .map(|(name, id)| CocoCategory {
                id,
                name,
                supercategory: "object",
            })
            .collect(),
    };
    serde_json::to_string(&file)
}

#[derive(Serialize)]
struct CocoResult {
    image_id: u64,
    category_id: u32,
    bbox: [f64; 4],
    score: f64,
}

/// One split's detections in COCO's results format (what `COCO.loadRes` reads); classes
/// outside COCO's 80 are left out.
pub fn coco_results(records: &[ImageRecord], split: Split) -> serde_json::Result<String> {
    let results: Vec<CocoResult> = records
        .iter()
        .filter(|r| r.split == split)
        .flat_map(|r| {
            r.detections.iter().flatten().filter_map(move |d| {
                Some(CocoResult {
                    image_id: r.index + 1,
                    category_id: coco_category(&d.class)?,
                    bbox: d.bbox,
                    score: d.score,
                })
            })
        })
        .collect();
    serde_json::to_string(&results)
}

#[cfg(test)]
#[allow(
    clippy::unwrap_used,
    reason = "tests: a failed unwrap is a failed test"
)]
mod tests {
    use super::*;

    #[test]
    fn coco_category_ids_follow_coco() {
        assert_eq!(coco_category("person"), Some(1));
        assert_eq!(coco_category("stop sign"), Some(13));
        assert_eq!(coco_category("dining table"), Some(67));
        assert_eq!(coco_category("toothbrush"), Some(90));
        assert_eq!(coco_category("unicorn"), None);
        let mut sorted = COCO_CATEGORY_IDS;
        sorted.sort_unstable();
        assert_eq!(sorted, COCO_CATEGORY_IDS);
    }

    #[test]
    fn yolo_lines_are_normalised_centres_and_skip_ignore_regions() {
        let labelled = |class: &str, bbox, ignore| LabelledBox {
            class: class.into(),
            name: "x".into(),
            bbox,
            full_bbox: bbox,
            visible_px: 100,
            visibility: 1.0,
            truncated: false,
            truncation: 0.0,
            ignore,
        };
        let record = ImageRecord {
            index: 0,
            split: Split::Train,
            file_name: "000000.png".into(),
            width: 640,
            height: 480,
            objects: vec![
                labelled("person", [320.0, 120.0, 64.0, 240.0], false),
                labelled("car", [0.0, 0.0, 10.0, 10.0], true),
                labelled("stop sign", [600.0, 0.0, 40.0, 48.0], false),
            ],
            detections: None,
            shot: Shot {
                robot: [0.0; 3],
                facing: None,
                sun_direction: [0.0, 0.0, -1.0],
                sun: 0.75,
                ambient: 1.0,
                noise_stddev: None,
                people: Vec::new(),
            },
        };
        assert_eq!(
            record.yolo_label(),
            "0 0.550000 0.500000 0.100000 0.500000\n11 0.968750 0.050000 0.062500 0.100000\n"
        );
        let json: serde_json::Value =
            serde_json::from_str(&coco_json(&[record], Split::Train).unwrap()).unwrap();
        assert_eq!(json["annotations"][1]["iscrowd"], 1);
        assert_eq!(json["annotations"][2]["category_id"], 13);
        assert_eq!(json["categories"].as_array().unwrap().len(), 80);
    }
}
