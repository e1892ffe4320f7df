//! Shards: one slice of a job split over machines (`--shard I/N`, e.g. a Slurm array task), and
//! the manifest every shard's output carries so that a merge can tell a complete, consistent
//! set from a broken one. A shard cancelled or killed before it finished writes no output, so
//! the merge names it missing; shards made by another rover, model, input file or seed are
//! named with the field that differs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};

/// The manifest's format.
pub const SHARD_FORMAT: &str = "rover-shard 1";

/// Shard `index` of `count` (counted from 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardIndex {
    /// This shard, 0..count.
    pub index: usize,
    /// How many shards the work is split into.
    pub count: usize,
}

impl ShardIndex {
    /// Whether item `i` (of the whole job, in its fixed order) belongs to this shard.
    pub fn owns(&self, i: u64) -> bool {
        self.count > 0 && i % self.count as u64 == self.index as u64
    }
}

/// What made one shard's output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardManifest {
    /// This manifest's format ([`SHARD_FORMAT`]).
    pub format: String,
    /// What was split: `eval` or `dataset`.
    pub kind: String,
    /// The rover that made it (`CARGO_PKG_VERSION`).
    pub rover_version: String,
    /// Which shard.
    pub shard: ShardIndex,
    /// The seed of the whole job, where it has one (a dataset's; an evaluation's seeds are in
    /// its scenario files, hashed in `inputs`).
    pub seed: Option<u64>,
    /// The detector model's file name and SHA-256, where a detector runs.
    pub model: Option<String>,
    /// Every input file of the whole job (not only this shard's): path as given -> SHA-256.
    pub inputs: BTreeMap<String, String>,
    /// The whole job's items in order (scenario labels; image numbers as `0..images`), of which
    /// this shard did those it owns.
    pub items: Vec<String>,
}

impl ShardManifest {
    /// A manifest of shard `shard` of a `kind` job over `items`, from the files `inputs`
    /// (hashed now) and the detector `model` (hashed now).
    pub fn new(
        kind: &str,
        shard: ShardIndex,
        seed: Option<u64>,
        model: Option<&Path>,
        inputs: &[PathBuf],
        items: Vec<String>,
    ) -> Result<Self> {
        let model = match model {
            Some(path) => Some(format!(
                "{} sha256 {}",
                path.file_name().unwrap_or_default().to_string_lossy(),
                sha256_of(path)?
            )),
            None => None,
        };
        let mut hashes = BTreeMap::new();
        for path in inputs {
            hashes.insert(path.display().to_string(), sha256_of(path)?);
        }
        Ok(Self {
            format: SHARD_FORMAT.into(),
            kind: kind.into(),
            rover_version: env!("CARGO_PKG_VERSION").into(),
            shard,
            seed,
            model,
            inputs: hashes,
            items,
        })
    }

    /// The fields (by name, with both values) in which `other` differs from `self`, the shard
    /// index aside.
    pub fn differences(&self, other: &ShardManifest) -> Vec<String> {
        let mut out = Vec::new();
        let mut check = |name: &str, a: String, b: String| {
            if a != b {
                out.push(format!("{name}: {a} vs {b}"));
            }
        };
        check("format", self.format.clone(), other.format.clone());
        check("kind", self.kind.clone(), other.kind.clone());
        check(
            "rover version",
            self.rover_version.clone(),
            other.rover_version.clone(),
        );
        check(
            "shard count",
            self.shard.count.to_string(),
            other.shard.count.to_string(),
        );
        check(
            "seed",
            format!("{:?}", self.seed),
            format!("{:?}", other.seed),
        );
        check(
            "model",
            format!("{:?}", self.model),
            format!("{:?}", other.model),
        );
        for (path, hash) in &self.inputs {
            match other.inputs.get(path) {
                Some(h) if h == hash => {}
                Some(h) => check(&format!("input {path}"), hash.clone(), h.clone()),
                None => check(&format!("input {path}"), hash.clone(), "absent".into()),
            }
        }
        for path in other.inputs.keys() {
            if !self.inputs.contains_key(path) {
                check(&format!("input {path}"), "absent".into(), "present".into());
            }
        }
        if self.items != other.items {
            check(
                "items",
                format!("{} items", self.items.len()),
                format!("{} items (another list)", other.items.len()),
            );
        }
        out
    }
}

/// An error naming the fields in which shard `b` differs from shard `a` (of one `what`: a
/// job, a dataset), when there are any.
pub(crate) fn not_one_set(a: &Path, b: &Path, what: &str, differences: &[String]) -> Result<()> {
    if differences.is_empty() {
        return Ok(());
    }
    Err(CoreError::Option(format!(
        "{} and {} are not shards of one {what}:\n  {}",
        a.display(),
        b.display(),
        differences.join("\n  ")
    )))
}

/// Checks that `shards` (each with the file it came from) are one complete, consistent set:
/// the same job in every field, every index 0..count once. The error names the missing
/// shards, a shard given twice, or the fields in which a file differs from the first.
pub fn check_shard_set(shards: &[(PathBuf, ShardManifest)]) -> Result<()> {
    let Some((first_path, first)) = shards.first() else {
        return Err(CoreError::Option("no shards to merge".into()));
    };
    for (path, m) in &shards[1..] {
        not_one_set(first_path, path, "job", &first.differences(m))?;
    }
    let count = first.shard.count;
    let mut seen: Vec<Option<&Path>> = vec![None; count];
    for (path, m) in shards {
        let i = m.shard.index;
        let Some(slot) = seen.get_mut(i) else {
            return Err(CoreError::Option(format!(
                "{}: shard {i} of {count} is out of range",
                path.display()
            )));
        };
        if let Some(other) = slot {
            return Err(CoreError::Option(format!(
                "shard {i} of {count} is given twice: {} and {}",
                other.display(),
                path.display()
            )));
        }
        *slot = Some(path);
    }
    let missing: Vec<String> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(i, _)| i.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(CoreError::Option(format!(
            "incomplete: shard{} {} of {count} missing (not finished, cancelled or not given); run {} again with --shard I/{count} and merge once all are there",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", "),
            if missing.len() == 1 { "it" } else { "them" }
        )));
    }
    Ok(())
}

/// SHA-256 of a file's bytes, in hex.
pub fn sha256_of(path: &Path) -> Result<String> {
    rover_assets::registry::sha256_file(path).map_err(|e| CoreError::Option(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(index: usize, count: usize) -> ShardManifest {
        ShardManifest {
            format: SHARD_FORMAT.into(),
            kind: "eval".into(),
            rover_version: "1".into(),
            shard: ShardIndex { index, count },
            seed: None,
            model: Some("m.onnx sha256 ab".into()),
            inputs: BTreeMap::from([("a.toml".to_owned(), "11".to_owned())]),
            items: vec!["a".into(), "b".into(), "c".into()],
        }
    }

    fn set(manifests: Vec<ShardManifest>) -> Vec<(PathBuf, ShardManifest)> {
        manifests
            .into_iter()
            .map(|m| (PathBuf::from(format!("s{}.json", m.shard.index)), m))
            .collect()
    }

    #[test]
    fn a_complete_set_passes_and_a_missing_shard_is_named() {
        assert!(
            check_shard_set(&set(vec![manifest(1, 3), manifest(0, 3), manifest(2, 3)])).is_ok()
        );
        let e = check_shard_set(&set(vec![manifest(0, 4), manifest(2, 4)]))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("shards 1, 3 of 4 missing"), "{e}");
        let e = check_shard_set(&set(vec![manifest(0, 2), manifest(0, 2)]))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("given twice"), "{e}");
    }

    #[test]
    fn a_shard_of_another_job_names_the_field() {
        let mut other = manifest(1, 2);
        other.inputs.insert("a.toml".into(), "22".into());
        other.model = Some("m.onnx sha256 cd".into());
        let e = check_shard_set(&set(vec![manifest(0, 2), other]))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("input a.toml: 11 vs 22") && e.contains("model"),
            "{e}"
        );
        let e = check_shard_set(&set(vec![manifest(0, 2), manifest(1, 3)]))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("shard count: 2 vs 3"), "{e}");
    }

    #[test]
    fn shards_split_items_by_index() {
        let s = ShardIndex { index: 1, count: 3 };
        let owned: Vec<u64> = (0..8).filter(|&i| s.owns(i)).collect();
        assert_eq!(owned, [1, 4, 7]);
    }
}
