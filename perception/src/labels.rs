//! Class names: from the ONNX metadata (`names`), a darknet-style labels file, or COCO's 80
//! (`rover_assets::COCO80`).

use std::path::Path;

use crate::error::{PerceptionError, Result};

/// Parses Ultralytics' `names` metadata: a Python dict literal like `{0: 'person', 1: 'bicycle'}`.
pub fn parse_metadata_names(text: &str) -> Option<Vec<String>> {
    let body = text.trim().strip_prefix('{')?.strip_suffix('}')?;
    let mut names = Vec::new();
    let mut rest = body;
    while !rest.trim().is_empty() {
        let (key, after) = rest.split_once(':')?;
        let index: usize = key.trim().trim_start_matches(',').trim().parse().ok()?;
        let after = after.trim_start();
        let quote = after.chars().next().filter(|c| *c == '\'' || *c == '"')?;
        let value_and_rest = &after[1..];
        let end = value_and_rest.find(quote)?;
        if index != names.len() {
            return None;
        }
        names.push(value_and_rest[..end].to_owned());
        rest = value_and_rest[end + 1..]
            .trim_start()
            .trim_start_matches(',');
    }
    (!names.is_empty()).then_some(names)
}

/// Largest labels file read (darknet's 9k.names is 100 kB).
const MAX_LABELS_BYTES: u64 = 16 << 20;

/// Reads a labels file: one class name per line (darknet's coco.names format).
pub fn read_labels_file(path: &Path) -> Result<Vec<String>> {
    let meta = std::fs::metadata(path).map_err(|e| PerceptionError::io(path, e))?;
    if !meta.is_file() || meta.len() > MAX_LABELS_BYTES {
        return Err(PerceptionError::Labels(format!(
            "{}: expected a regular file of at most {MAX_LABELS_BYTES} bytes",
            path.display()
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| PerceptionError::io(path, e))?;
    let names: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(str::to_owned)
        .collect();
    if names.is_empty() {
        return Err(PerceptionError::Labels(format!(
            "{}: no class names; expected one name per line",
            path.display()
        )));
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_ultralytics_names() {
        let names = parse_metadata_names("{0: 'person', 1: \"bicycle\", 2: 'traffic light'}");
        assert_eq!(
            names,
            Some(vec![
                "person".into(),
                "bicycle".into(),
                "traffic light".into()
            ])
        );
        assert_eq!(parse_metadata_names("{1: 'a'}"), None, "must start at 0");
        assert_eq!(parse_metadata_names("person"), None);
    }
}
