//! A dataset split over machines. `rover dataset --shard I/N` makes the images whose number
//! modulo N is I into a folder of its own (a dataset folder whose manifest names the shard, so
//! it resumes like any other) and, once every one of them is complete, writes
//! [`SHARD_MANIFEST`] there: rover's version, the seed, the model's and the input files'
//! SHA-256 and I/N. A shard cancelled or killed before that has no shard manifest, so the
//! merge names it missing. [`merge_dataset`] checks the set, gathers every shard's images,
//! labels and records into one dataset folder (hard links where the file system allows, copies
//! otherwise) and writes its COCO JSON and data.yaml from the records, as a one-machine run
//! does: every image depends only on the seed and its number, so the result is the same.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::finish::{DatasetProgress, DatasetSpec, DatasetSummary, disk_error, finish};
use super::store::{MANIFEST, Manifest, Split, Store, write_whole};
use crate::error::{CoreError, Result};
use crate::shard::{ShardIndex, ShardManifest, check_shard_set, not_one_set};

/// The shard manifest's file name, in a shard's folder; written when the shard is complete.
pub const SHARD_MANIFEST: &str = "rover-shard.json";

/// The shard's item list: the whole dataset's image numbers.
fn items(images: u64) -> Vec<String> {
    vec![format!("images 0..{images}")]
}

/// Removes a shard manifest an earlier run left: the shard is complete again only when this
/// run has made every image it owns.
pub(super) fn forget_shard_manifest(store: &Store) -> Result<()> {
    let path = store.root().join(SHARD_MANIFEST);
    match std::fs::remove_file(&path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(CoreError::write(&path, e)),
    }
}

/// Writes the complete shard's manifest (the last file a shard writes): `inputs` are the world
/// and robot files, `model` the detector's (with `--detect`).
pub(super) fn write_shard_manifest(
    store: &Store,
    inputs: &[PathBuf],
    spec: &DatasetSpec,
    shard: ShardIndex,
    model: Option<&Path>,
) -> Result<()> {
    let manifest = ShardManifest::new(
        "dataset",
        shard,
        Some(spec.seed),
        model,
        inputs,
        items(spec.images),
    )?;
    let text = serde_json::to_string_pretty(&manifest)
        .map_err(|e| CoreError::Option(format!("shard manifest: {e}")))?;
    let path = store.root().join(SHARD_MANIFEST);
    write_whole(&path, text.as_bytes()).map_err(|e| disk_error(&path, e, store, spec.images))
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path, what: &str) -> Result<T> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CoreError::Option(format!("cannot read {}: {e}", path.display())))?;
    serde_json::from_str(&text)
        .map_err(|e| CoreError::Option(format!("{}: not {what} ({e})", path.display())))
}

/// The finished shards among `dirs` (folder, shard manifest, dataset manifest), and a line
/// for each folder whose shard did not finish.
type Shards = Vec<(PathBuf, ShardManifest, Manifest)>;

fn read_shards(dirs: &[PathBuf]) -> Result<(Shards, Vec<String>)> {
    let mut shards = Vec::new();
    let mut unfinished = Vec::new();
    for dir in dirs {
        let dataset_path = dir.join(MANIFEST);
        if !dataset_path.is_file() {
            return Err(CoreError::Option(format!(
                "{}: not a folder of `rover dataset --shard I/N` (no {MANIFEST})",
                dir.display()
            )));
        }
        let dataset: Manifest = read_json(&dataset_path, "a rover dataset manifest")?;
        let Some(index) = dataset.shard else {
            return Err(CoreError::Option(format!(
                "{}: a whole dataset, not a shard (made without --shard)",
                dir.display()
            )));
        };
        let shard_path = dir.join(SHARD_MANIFEST);
        if !shard_path.is_file() {
            unfinished.push(format!(
                "{}: shard {} of {} did not finish (no {SHARD_MANIFEST}); the same command resumes it",
                dir.display(),
                index.index,
                index.count
            ));
            continue;
        }
        let shard: ShardManifest = read_json(&shard_path, "a rover shard manifest")?;
        if shard.kind != "dataset" || shard.shard != index || shard.items != items(dataset.images) {
            return Err(CoreError::Option(format!(
                "{}: {SHARD_MANIFEST} ({} shard {}/{}, {:?}) does not match {MANIFEST} (dataset shard {}/{}, {} images); run the shard again",
                dir.display(),
                shard.kind,
                shard.shard.index,
                shard.shard.count,
                shard.items,
                index.index,
                index.count,
                dataset.images
            )));
        }
        shards.push((dir.clone(), shard, dataset));
    }
    Ok((shards, unfinished))
}

/// Checks the shards in `dirs` and merges them into the dataset folder `out` (new, empty, or
/// an earlier merge of the same shards: it goes on, and merging twice gives the same files).
/// Returns what a one-machine run of the same dataset would have been asked, and the summary.
/// Errors name the missing shards, or the fields in which shards differ.
pub fn merge_dataset(
    dirs: &[PathBuf],
    out: &Path,
    progress: &mut dyn FnMut(DatasetProgress),
) -> Result<(DatasetSpec, DatasetSummary)> {
    let (shards, unfinished) = read_shards(dirs)?;
    let with_unfinished = |e: CoreError| {
        if unfinished.is_empty() {
            e
        } else {
            CoreError::Option(format!("{e}\n  {}", unfinished.join("\n  ")))
        }
    };
    let set: Vec<(PathBuf, ShardManifest)> = shards
        .iter()
        .map(|(dir, shard, _)| (dir.join(SHARD_MANIFEST), shard.clone()))
        .collect();
    check_shard_set(&set).map_err(with_unfinished)?;
    let (first_dir, _, first) = &shards[0];
    let whole = Manifest {
        shard: None,
        ..first.clone()
    };
    for (dir, _, dataset) in &shards[1..] {
        let differences = whole.differences(&Manifest {
            shard: None,
            ..dataset.clone()
        });
        not_one_set(first_dir, dir, "dataset", &differences)?;
    }
    // The shards by index: check_shard_set found each of 0..count once.
    let mut by_index: Vec<&Path> = vec![Path::new(""); shards[0].1.shard.count];
    for (dir, shard, _) in &shards {
        by_index[shard.shard.index] = dir;
    }
    let (store, done) = Store::open(out, &whole)?;
    let (total, kept) = (whole.images, done.len() as u64);
    progress(DatasetProgress {
        done: kept,
        total,
        kept,
    });
    let start = Instant::now();
    let mut made = 0;
    for index in (0..total).filter(|i| !done.contains(i)) {
        let dir = by_index[(index % by_index.len() as u64) as usize];
        gather(dir, &store, &whole, index)?;
        made += 1;
        progress(DatasetProgress {
            done: kept + made,
            total,
            kept,
        });
    }
    let spec = DatasetSpec {
        out: out.to_path_buf(),
        images: whole.images,
        seed: whole.seed,
        val_fraction: whole.val_fraction,
        image_format: whole.image_format,
        formats: whole.formats.clone(),
        randomization: whole.randomization.clone(),
        detect: whole.detector.is_some(),
        shard: None,
        jobs: 1,
    };
    let mut summary = DatasetSummary::new(out, [total, made, kept], start, false);
    finish(&store, &spec, &mut summary)?;
    Ok((spec, summary))
}

/// Brings image `index`'s files from the shard folder `dir` into `store`: the image, its label,
/// its record last (the record marks it complete).
fn gather(dir: &Path, store: &Store, whole: &Manifest, index: u64) -> Result<()> {
    let shard = Store::at(dir, whole);
    let split = Split::ALL
        .into_iter()
        .find(|s| shard.record_path(*s, index).is_file())
        .ok_or_else(|| {
            CoreError::Option(format!(
                "{}: image {index}'s record is missing although the shard finished (the folder was changed since); run that shard again",
                dir.display()
            ))
        })?;
    let mut files = vec![(
        shard.image_path(split, index),
        store.image_path(split, index),
    )];
    if whole.formats.iter().any(|f| f.image_dir().is_some()) {
        files.push((
            shard.label_path(split, index),
            store.label_path(split, index),
        ));
    }
    files.push((
        shard.record_path(split, index),
        store.record_path(split, index),
    ));
    for (from, to) in files {
        link_or_copy(&from, &to).map_err(|e| {
            if e.kind() == std::io::ErrorKind::NotFound && !from.exists() {
                CoreError::Option(format!(
                    "{} is missing although the shard finished; run that shard again",
                    from.display()
                ))
            } else {
                disk_error(&to, e, store, whole.images)
            }
        })?;
    }
    Ok(())
}

/// Puts `from`'s contents at `to`, whole or not at all: a hard link (no bytes copied, on the
/// same file system) or else a copy, made under a temporary name and renamed into place.
fn link_or_copy(from: &Path, to: &Path) -> std::io::Result<()> {
    let name = to.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let temporary = to.with_file_name(format!(".rover-{name}.tmp"));
    let _ = std::fs::remove_file(&temporary);
    let result = (|| {
        if std::fs::hard_link(from, &temporary).is_err() {
            std::fs::copy(from, &temporary)?;
        }
        std::fs::rename(&temporary, to)
    })();
    // A rename between two links of one file does nothing: the temporary is left behind.
    let _ = std::fs::remove_file(&temporary);
    result
}
