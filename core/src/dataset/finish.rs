//! What a dataset run is asked for and what it did ([`DatasetSpec`], [`DatasetSummary`]), and
//! how it ends: the records read back into data.yaml, COCO JSON and the detector's metrics, and
//! a failed write turned into an error that says what is kept. Shared by one-machine runs and
//! the merge of shards.

use std::path::{Path, PathBuf};
use std::time::Instant;

use rover_perception::{CocoEvaluator, DetectionMetrics};

use super::export::{ImageRecord, coco_json, coco_results, data_yaml};
use super::format::DatasetFormat;
use super::randomize::Randomization;
use super::store::{ImageFormat, Split, Store, write_whole};
use crate::error::{CoreError, Result};
use crate::shard::ShardIndex;

/// What dataset to make.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetSpec {
    /// The dataset's folder.
    pub out: PathBuf,
    /// How many images (numbered 0..images).
    pub images: u64,
    /// The seed of every image's layout and noise.
    pub seed: u64,
    /// Fraction of images in the validation split (each image's own draw).
    pub val_fraction: f64,
    /// How images are stored.
    pub image_format: ImageFormat,
    /// The annotation formats to write (at least one).
    pub formats: Vec<DatasetFormat>,
    /// What is randomized.
    pub randomization: Randomization,
    /// Run the detector on every image: its boxes in the records, COCO results files and
    /// rover's COCO metrics of it (`metrics.json`).
    pub detect: bool,
    /// Make only this shard's images (those whose number modulo N is I) into `out`, and
    /// instead of the COCO JSON and data.yaml write the shard's manifest ([`SHARD_MANIFEST`])
    /// for [`merge_dataset`].
    pub shard: Option<ShardIndex>,
    /// How many images to make at once, each lane with its own simulation, camera and
    /// detector on a thread of its own (0 or 1: one). The files do not depend on it.
    pub jobs: usize,
}

/// How far a dataset run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DatasetProgress {
    /// Images complete (kept from before and made now).
    pub done: u64,
    /// Images asked for.
    pub total: u64,
    /// Images that were already complete when the run started.
    pub kept: u64,
}

/// What a dataset run did.
#[derive(Debug, Clone)]
pub struct DatasetSummary {
    /// The folder.
    pub out: PathBuf,
    /// Images asked for.
    pub total: u64,
    /// Images made by this run.
    pub made: u64,
    /// Images that were already complete.
    pub kept: u64,
    /// Images per split (train, val), over the whole dataset.
    pub split_images: [u64; 2],
    /// Labelled boxes over the whole dataset (YOLO lines), and ignore regions.
    pub boxes: u64,
    /// Ignore regions (COCO `iscrowd`) over the whole dataset.
    pub ignored: u64,
    /// Images with no labelled box.
    pub backgrounds: u64,
    /// Wall time of the images made by this run (s).
    pub wall_s: f64,
    /// Ended early through [`RunConfig::stop`]: complete images kept, the rest to resume.
    pub interrupted: bool,
    /// With `detect`: rover's COCO metrics of the detector per split (train, val) and over all.
    pub metrics: Option<[DetectionMetrics; 3]>,
}

impl DatasetSummary {
    /// A summary of `[total, made, kept]` images in `out`, made since `start`, before the
    /// records are counted.
    pub(super) fn new(
        out: &Path,
        [total, made, kept]: [u64; 3],
        start: Instant,
        interrupted: bool,
    ) -> Self {
        Self {
            out: out.to_path_buf(),
            total,
            made,
            kept,
            split_images: [0; 2],
            boxes: 0,
            ignored: 0,
            backgrounds: 0,
            wall_s: start.elapsed().as_secs_f64(),
            interrupted,
            metrics: None,
        }
    }
}

/// A write that failed: a full disk says what is kept and how to go on.
pub(super) fn disk_error(path: &Path, e: std::io::Error, store: &Store, total: u64) -> CoreError {
    let complete = complete_count(store, total);
    if e.kind() == std::io::ErrorKind::StorageFull || e.raw_os_error() == Some(28) {
        CoreError::Option(format!(
            "{}: no space left on the device; stopped with {complete} of {total} images complete in {} (the image being written was removed). Free some space and run the same command again: it goes on from there",
            path.display(),
            store.root().display()
        ))
    } else {
        CoreError::Option(format!(
            "cannot write {}: {e}; {complete} of {total} images are complete in {} and the same command resumes",
            path.display(),
            store.root().display()
        ))
    }
}

/// Reads every record back and writes what is made from all of them: data.yaml, COCO JSON,
/// detections and metrics.
pub(super) fn finish(
    store: &Store,
    spec: &DatasetSpec,
    summary: &mut DatasetSummary,
) -> Result<()> {
    let records = read_records(store, 0..spec.images)?;
    count(&records, summary);
    let root = store.root();
    let write = |path: PathBuf, text: &str| -> Result<()> {
        write_whole(&path, text.as_bytes()).map_err(|e| disk_error(&path, e, store, spec.images))
    };
    let json_error = |e: serde_json::Error| CoreError::Option(format!("JSON: {e}"));
    for format in &spec.formats {
        match format {
            DatasetFormat::Yolo => write(root.join("data.yaml"), &data_yaml())?,
            DatasetFormat::Coco => {
                let dir = root.join("annotations");
                std::fs::create_dir_all(&dir).map_err(|e| CoreError::write(&dir, e))?;
                for split in Split::ALL {
                    let text = coco_json(&records, split).map_err(json_error)?;
                    write(dir.join(format!("instances_{}.json", split.name())), &text)?;
                }
            }
        }
    }
    if spec.detect {
        let dir = root.join("detections");
        std::fs::create_dir_all(&dir).map_err(|e| CoreError::write(&dir, e))?;
        let mut evaluators = [
            CocoEvaluator::new(),
            CocoEvaluator::new(),
            CocoEvaluator::new(),
        ];
        for r in &records {
            let (truth, found) = (r.eval_truth(), r.eval_detections());
            evaluators[usize::from(r.split == Split::Val)].add_image(&truth, &found);
            evaluators[2].add_image(&truth, &found);
        }
        for split in Split::ALL {
            let text = coco_results(&records, split).map_err(json_error)?;
            write(dir.join(format!("{}.json", split.name())), &text)?;
        }
        let metrics = evaluators.map(|e| e.summary());
        let text = serde_json::to_string_pretty(&serde_json::json!({
            "train": metrics[0], "val": metrics[1], "all": metrics[2],
        }))
        .map_err(json_error)?;
        write(root.join("metrics.json"), &text)?;
        summary.metrics = Some(metrics);
    }
    Ok(())
}

/// The records of images `indices`, read back from the store.
pub(super) fn read_records(
    store: &Store,
    indices: impl Iterator<Item = u64>,
) -> Result<Vec<ImageRecord>> {
    let mut records = Vec::new();
    for index in indices {
        let record = Split::ALL
            .iter()
            .map(|s| store.record_path(*s, index))
            .find(|p| p.is_file())
            .ok_or_else(|| CoreError::Option(format!("image {index}'s record is missing")))?;
        let text = std::fs::read_to_string(&record).map_err(|e| CoreError::write(&record, e))?;
        let r: ImageRecord = serde_json::from_str(&text).map_err(|e| {
            CoreError::Option(format!(
                "{}: not an image record ({e}); delete it and run again to remake that image",
                record.display()
            ))
        })?;
        records.push(r);
    }
    Ok(records)
}

/// Adds `records`' splits, boxes, ignore regions and background images to `summary`.
pub(super) fn count(records: &[ImageRecord], summary: &mut DatasetSummary) {
    for r in records {
        summary.split_images[usize::from(r.split == Split::Val)] += 1;
        let boxes = r.objects.iter().filter(|o| !o.ignore).count() as u64;
        summary.boxes += boxes;
        summary.ignored += r.objects.len() as u64 - boxes;
        summary.backgrounds += u64::from(boxes == 0);
    }
}

/// How many of the first `total` images have their record (are complete).
pub(super) fn complete_count(store: &Store, total: u64) -> u64 {
    (0..total)
        .filter(|&i| {
            Split::ALL
                .iter()
                .any(|s| store.record_path(*s, i).is_file())
        })
        .count() as u64
}
