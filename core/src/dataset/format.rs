//! The annotation formats a dataset is written in, as one list: what each adds per image and
//! once the images are made. Images (`images/<split>/`) and rover's ground-truth records
//! (`ground_truth/<split>/`) are always written; a format adds its own files beside them.

use serde::{Deserialize, Serialize};

/// An annotation format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DatasetFormat {
    /// Ultralytics YOLO: a label file per image (`labels/<split>/N.txt`) and `data.yaml`.
    Yolo,
    /// COCO: `annotations/instances_<split>.json`, written once every image is made.
    Coco,
}

impl DatasetFormat {
    /// Every format.
    pub const ALL: [Self; 2] = [Self::Yolo, Self::Coco];

    /// Its name (`yolo`, `coco`), as the manifest and `--format` say it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Yolo => "yolo",
            Self::Coco => "coco",
        }
    }

    /// The folder of per-image files it adds (`labels`: `labels/<split>/N.txt`), if any. An
    /// image is complete when its file there exists too.
    pub fn image_dir(self) -> Option<&'static str> {
        match self {
            Self::Yolo => Some("labels"),
            Self::Coco => None,
        }
    }
}

/// `formats` as the manifest's differences and the summary say them: `yolo, coco`.
pub(crate) fn names(formats: &[DatasetFormat]) -> String {
    let names: Vec<&str> = formats.iter().map(|f| f.name()).collect();
    names.join(", ")
}
