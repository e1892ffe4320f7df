//! The dataset folder: its manifest (what made it), which images are complete, and files
//! written whole or not at all (a temporary file renamed into place), so that a run stopped
//! anywhere (Ctrl-C, a full disk, a crash) leaves only complete images and resumes.
//!
//! ```text
//! DIR/rover-dataset.json              the manifest
//! DIR/images/{train,val}/000012.png   the camera images
//! DIR/labels/{train,val}/000012.txt   YOLO labels (with YOLO output)
//! DIR/ground_truth/{train,val}/000012.json
//!                                     rover's record of the image, written last: an image is
//!                                     complete when its record exists
//! DIR/data.yaml, DIR/annotations/instances_{train,val}.json, DIR/detections/, DIR/metrics.json
//!                                     written at the end from the records
//! ```

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::dataset::format::{DatasetFormat, names};
use crate::dataset::randomize::Randomization;
use crate::error::{CoreError, Result};
use crate::shard::ShardIndex;

/// The manifest's file name.
pub const MANIFEST: &str = "rover-dataset.json";

/// Which split an image is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    /// Training images.
    Train,
    /// Validation images.
    Val,
}

impl Split {
    /// Both, in folder order.
    pub const ALL: [Split; 2] = [Split::Train, Split::Val];

    /// The folder name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Train => "train",
            Self::Val => "val",
        }
    }
}

/// How images are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImageFormat {
    /// Lossless PNG.
    Png,
    /// JPEG, quality 95.
    Jpg,
}

impl ImageFormat {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Png => "png",
            Self::Jpg => "jpg",
        }
    }
}

/// What made a dataset: a run resumes only a folder whose manifest says the same (the number
/// of images may grow).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// This file's format.
    pub format: String,
    /// The rover that made it (`CARGO_PKG_VERSION`).
    pub rover_version: String,
    /// The seed every image's layout and noise come from.
    pub seed: u64,
    /// How many images (numbered 0..images).
    pub images: u64,
    /// Fraction of images in the validation split.
    pub val_fraction: f64,
    /// How images are stored.
    pub image_format: ImageFormat,
    /// The annotation formats (before 0.1's format list: `yolo` and `coco` booleans, read
    /// into it by [`Manifest::read`]).
    #[serde(default)]
    pub formats: Vec<DatasetFormat>,
    /// The world file, as given.
    pub world: String,
    /// SHA-256 of the world file's bytes.
    pub world_sha256: String,
    /// The robot file, as given.
    pub robot: String,
    /// SHA-256 of the robot file's bytes.
    pub robot_sha256: String,
    /// The camera rendered.
    pub camera: String,
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// What is randomized.
    pub randomization: Randomization,
    /// The detector run on every image (`--detect`): model file name and SHA-256, threshold.
    pub detector: Option<String>,
    /// The shard this folder holds (`--shard I/N`), absent for a whole dataset (made on one
    /// machine or merged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardIndex>,
}

/// The manifest's current format.
pub const MANIFEST_FORMAT: &str = "rover-dataset 1";

impl Manifest {
    /// A manifest from its JSON; one written before the format list (a `yolo` and a `coco`
    /// boolean) reads as the list they say.
    pub fn read(text: &str) -> serde_json::Result<Self> {
        let mut value: serde_json::Value = serde_json::from_str(text)?;
        if let Some(fields) = value.as_object_mut()
            && !fields.contains_key("formats")
        {
            // Before the format list: one boolean per format.
            let formats: Vec<serde_json::Value> = DatasetFormat::ALL
                .into_iter()
                .filter(|f| fields.remove(f.name()) == Some(serde_json::Value::Bool(true)))
                .map(|f| f.name().into())
                .collect();
            fields.insert("formats".into(), formats.into());
        }
        serde_json::from_value(value)
    }

    /// The fields (by name) in which `self` and `other` differ, the image count aside.
    pub fn differences(&self, other: &Manifest) -> Vec<String> {
        let mut out = Vec::new();
        let mut check = |name: &str, a: String, b: String| {
            if a != b {
                out.push(format!("{name}: {a} (folder) vs {b} (now)"));
            }
        };
        check("format", self.format.clone(), other.format.clone());
        check(
            "rover version",
            self.rover_version.clone(),
            other.rover_version.clone(),
        );
        check("seed", self.seed.to_string(), other.seed.to_string());
        check(
            "val fraction",
            self.val_fraction.to_string(),
            other.val_fraction.to_string(),
        );
        check(
            "image format",
            format!("{:?}", self.image_format),
            format!("{:?}", other.image_format),
        );
        check("formats", names(&self.formats), names(&other.formats));
        check(
            "world file contents",
            self.world_sha256.clone(),
            other.world_sha256.clone(),
        );
        check(
            "robot file contents",
            self.robot_sha256.clone(),
            other.robot_sha256.clone(),
        );
        check("camera", self.camera.clone(), other.camera.clone());
        check(
            "image size",
            format!("{}x{}", self.width, self.height),
            format!("{}x{}", other.width, other.height),
        );
        check(
            "randomization",
            format!("{:?}", self.randomization),
            format!("{:?}", other.randomization),
        );
        check(
            "detector",
            format!("{:?}", self.detector),
            format!("{:?}", other.detector),
        );
        let shard = |s: Option<ShardIndex>| {
            s.map_or("none (a whole dataset)".to_owned(), |s| {
                format!("{}/{}", s.index, s.count)
            })
        };
        check("shard", shard(self.shard), shard(other.shard));
        out
    }
}

/// An open dataset folder.
#[derive(Debug, Clone)]
pub struct Store {
    root: PathBuf,
    image_format: ImageFormat,
    /// The formats' per-image folders (`labels`).
    image_dirs: Vec<&'static str>,
}

impl Store {
    /// Opens `root` for `manifest`: creates it (and its folders) when new or empty; resumes it
    /// when its manifest says the same; refuses a folder that holds something else, another
    /// run (naming what differs), or more images than asked for. Returns the store and the
    /// numbers of the images already complete.
    pub fn open(root: &Path, manifest: &Manifest) -> Result<(Self, BTreeSet<u64>)> {
        let manifest_path = root.join(MANIFEST);
        let refuse = |why: String| CoreError::Option(format!("{}: {why}", root.display()));
        if manifest_path.is_file() {
            let text = std::fs::read_to_string(&manifest_path)
                .map_err(|e| CoreError::write(&manifest_path, e))?;
            let old = Manifest::read(&text)
                .map_err(|e| refuse(format!("{MANIFEST} is not a rover dataset manifest ({e})")))?;
            let differences = old.differences(manifest);
            if !differences.is_empty() {
                return Err(refuse(format!(
                    "holds another dataset; to resume it, run with what made it. Differences:\n  {}\nChoose another folder for a new dataset",
                    differences.join("\n  ")
                )));
            }
            if old.images > manifest.images {
                return Err(refuse(format!(
                    "holds a dataset of {} images; ask for at least that many (resuming never deletes images)",
                    old.images
                )));
            }
        } else if root.exists() {
            let mut entries = std::fs::read_dir(root).map_err(|e| CoreError::write(root, e))?;
            if entries.next().is_some() {
                return Err(refuse(format!(
                    "exists and is not empty, and has no {MANIFEST}: choose a new or empty folder"
                )));
            }
        }
        let store = Self::at(root, manifest);
        for split in Split::ALL {
            for dir in store.split_dirs(split) {
                std::fs::create_dir_all(&dir).map_err(|e| CoreError::write(&dir, e))?;
                remove_temporaries(&dir)?;
            }
        }
        let text = serde_json::to_string_pretty(manifest)
            .map_err(|e| CoreError::Option(format!("manifest: {e}")))?;
        write_whole(&manifest_path, text.as_bytes())
            .map_err(|e| CoreError::write(&manifest_path, e))?;
        let done = store.complete(manifest.images)?;
        Ok((store, done))
    }

    /// The folder `root` made with `manifest`'s layout, to read from: nothing is checked or
    /// created.
    pub fn at(root: &Path, manifest: &Manifest) -> Self {
        Self {
            root: root.to_path_buf(),
            image_format: manifest.image_format,
            image_dirs: manifest
                .formats
                .iter()
                .filter_map(|f| f.image_dir())
                .collect(),
        }
    }

    fn split_dirs(&self, split: Split) -> Vec<PathBuf> {
        let mut dirs = vec![
            self.root.join("images").join(split.name()),
            self.root.join("ground_truth").join(split.name()),
        ];
        dirs.extend(
            self.image_dirs
                .iter()
                .map(|dir| self.root.join(dir).join(split.name())),
        );
        dirs
    }

    /// The images (numbers below `images`) whose record and image file both exist.
    fn complete(&self, images: u64) -> Result<BTreeSet<u64>> {
        let mut done = BTreeSet::new();
        for split in Split::ALL {
            let dir = self.root.join("ground_truth").join(split.name());
            for entry in std::fs::read_dir(&dir).map_err(|e| CoreError::write(&dir, e))? {
                let entry = entry.map_err(|e| CoreError::write(&dir, e))?;
                let name = entry.file_name();
                let Some(index) = name
                    .to_str()
                    .and_then(|n| n.strip_suffix(".json"))
                    .and_then(|n| n.parse::<u64>().ok())
                else {
                    continue;
                };
                let has_label =
                    !self.image_dirs.contains(&"labels") || self.label_path(split, index).is_file();
                if index < images && self.image_path(split, index).is_file() && has_label {
                    done.insert(index);
                }
            }
        }
        Ok(done)
    }

    /// The dataset's folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Image `index`'s file name (without folder).
    pub fn file_name(&self, index: u64) -> String {
        format!("{index:06}.{}", self.image_format.extension())
    }

    /// Where image `index` goes.
    pub fn image_path(&self, split: Split, index: u64) -> PathBuf {
        self.root
            .join("images")
            .join(split.name())
            .join(self.file_name(index))
    }

    /// Where image `index`'s YOLO label goes.
    pub fn label_path(&self, split: Split, index: u64) -> PathBuf {
        self.root
            .join("labels")
            .join(split.name())
            .join(format!("{index:06}.txt"))
    }

    /// Where image `index`'s record goes.
    pub fn record_path(&self, split: Split, index: u64) -> PathBuf {
        self.root
            .join("ground_truth")
            .join(split.name())
            .join(format!("{index:06}.json"))
    }
}

/// Removes `rover-*.tmp` files a stopped run left in `dir`.
fn remove_temporaries(dir: &Path) -> Result<()> {
    for entry in std::fs::read_dir(dir).map_err(|e| CoreError::write(dir, e))? {
        let entry = entry.map_err(|e| CoreError::write(dir, e))?;
        let name = entry.file_name();
        if name
            .to_str()
            .is_some_and(|n| n.starts_with(".rover-") && n.ends_with(".tmp"))
        {
            std::fs::remove_file(entry.path()).map_err(|e| CoreError::write(&entry.path(), e))?;
        }
    }
    Ok(())
}

/// Writes `path` whole or not at all: into a temporary file beside it, renamed into place.
pub fn write_whole(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    write_whole_with(path, |w| w.write_all(bytes))
}

/// As [`write_whole`], the contents written by `fill`.
pub fn write_whole_with(
    path: &Path,
    fill: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let temporary = path.with_file_name(format!(".rover-{name}.tmp"));
    let result = (|| {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&temporary)?);
        fill(&mut w)?;
        // Flushed, not synced: a killed process leaves whole files or temporaries (the kernel
        // has the bytes); syncing every file would halve the image rate on some disks.
        w.into_inner().map_err(|e| e.into_error())?;
        std::fs::rename(&temporary, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_manifest_from_before_the_format_list_reads_as_its_list() -> serde_json::Result<()> {
        let manifest = Manifest {
            format: MANIFEST_FORMAT.into(),
            rover_version: "0.1.0".into(),
            seed: 7,
            images: 3,
            val_fraction: 0.1,
            image_format: ImageFormat::Png,
            formats: vec![DatasetFormat::Yolo],
            world: "w.toml".into(),
            world_sha256: String::new(),
            robot: "r.urdf".into(),
            robot_sha256: String::new(),
            camera: "camera".into(),
            width: 640,
            height: 480,
            randomization: Randomization::default(),
            detector: None,
            shard: None,
        };
        let mut old = serde_json::to_value(&manifest)?;
        if let Some(fields) = old.as_object_mut() {
            fields.remove("formats");
            fields.insert("yolo".into(), true.into());
            fields.insert("coco".into(), false.into());
        }
        let read = Manifest::read(&old.to_string())?;
        assert_eq!(read, manifest);
        assert!(read.differences(&manifest).is_empty());
        let mut both = manifest.clone();
        both.formats = DatasetFormat::ALL.to_vec();
        assert_eq!(
            read.differences(&both),
            ["formats: yolo (folder) vs yolo, coco (now)"]
        );
        Ok(())
    }
}
