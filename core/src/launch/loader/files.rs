//! Reading the files a launch names (launch files, YAML, `textfile`, `binfile`), with a size
//! limit, and finding which package a file is in.

use std::path::Path;

/// Largest launch, YAML or text file read.
const MAX_FILE_BYTES: u64 = 64 << 20;

/// The package a file is in: the `<name>` of the nearest package.xml above it.
pub(super) fn package_of(path: &Path) -> Option<String> {
    let mut dir = path.parent();
    while let Some(d) = dir {
        let manifest = d.join("package.xml");
        if manifest.is_file() {
            let text = std::fs::read_to_string(&manifest).ok()?;
            let doc = roxmltree::Document::parse(&text).ok()?;
            return doc
                .root_element()
                .children()
                .find(|n| n.has_tag_name("name"))
                .and_then(|n| n.text())
                .map(|t| t.trim().to_owned());
        }
        dir = d.parent();
    }
    None
}

pub(super) fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

pub(super) fn read_bytes(path: &Path) -> Result<Vec<u8>, String> {
    use std::io::Read as _;
    let cannot = |e: std::io::Error| format!("cannot read {}: {e}", path.display());
    if path.is_dir() {
        return Err(format!("{} is a folder, not a file", path.display()));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(cannot)?
        // Not the file's length: /dev/zero and pipes have none.
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(format!(
            "{} is larger than {} MiB",
            path.display(),
            MAX_FILE_BYTES >> 20
        ));
    }
    Ok(bytes)
}

pub(super) fn read_text(path: &Path) -> Result<String, String> {
    String::from_utf8(read_bytes(path)?)
        .map_err(|_| format!("{} is not UTF-8 text", path.display()))
}
