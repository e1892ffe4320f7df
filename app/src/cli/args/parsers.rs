//! Value parsers more than one topic's options share (`--package-path`, `--shard`); a leaf:
//! it names nothing from the files beside it.

use std::path::PathBuf;

/// `NAME=DIR` for a ROS package folder.
pub(super) fn parse_package_path(s: &str) -> Result<(String, PathBuf), String> {
    let (name, dir) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=DIR, found \"{s}\""))?;
    let dir = PathBuf::from(dir);
    if name.is_empty() || !dir.is_dir() {
        return Err(format!(
            "expected NAME=DIR naming an existing folder, found \"{s}\""
        ));
    }
    Ok((name.to_owned(), dir))
}

/// `I/N`: shard I of N, counted from 0.
pub(super) fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let parsed = text.split_once('/').and_then(|(i, n)| {
        Some((
            i.trim().parse::<usize>().ok()?,
            n.trim().parse::<usize>().ok()?,
        ))
    });
    match parsed {
        Some((i, n)) if n > 0 && i < n => Ok((i, n)),
        _ => Err(format!(
            "expected I/N with 0 <= I < N (shard I of N, counted from 0), found '{text}'"
        )),
    }
}
