//! Strict TOML loading shared by world files and (in the app) scripts: unknown keys are errors,
//! and every error names the file, the key path and, where TOML knows it, the line.

use std::path::Path;

use serde::de::DeserializeOwned;

use crate::error::{Result, SimError};

/// Reads and deserialises a TOML file into `T`.
pub fn load_toml<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text = crate::io::read_text(path)?;
    parse_toml(&text, path)
}

/// Deserialises TOML text into `T`; `path` is used in messages.
pub fn parse_toml<T: DeserializeOwned>(text: &str, path: &Path) -> Result<T> {
    let deserializer =
        toml::Deserializer::parse(text).map_err(|e| located(path, text, &e, None))?;
    serde_path_to_error::deserialize(deserializer).map_err(|e| {
        let key = e.path().to_string();
        located(path, text, e.inner(), (key != ".").then_some(key))
    })
}

fn located(path: &Path, text: &str, e: &toml::de::Error, key: Option<String>) -> SimError {
    let line = e
        .span()
        .map(|span| 1 + text[..span.start.min(text.len())].matches('\n').count() as u32);
    let message = match key {
        Some(key) => format!("at `{key}`: {}", e.message()),
        None => e.message().to_owned(),
    };
    SimError::invalid(path, line, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(
        dead_code,
        reason = "read only by the parser under test, never by the test"
    )]
    struct Outer {
        inner: Vec<Inner>,
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(
        dead_code,
        reason = "read only by the parser under test, never by the test"
    )]
    struct Inner {
        size: f64,
    }

    #[test]
    fn errors_carry_key_path_and_line() {
        let text = "[[inner]]\nsize = 1.0\n\n[[inner]]\nsize = \"big\"\n";
        let err = parse_toml::<Outer>(text, Path::new("w.toml"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(err.starts_with("w.toml:5: at `inner[1].size`"), "{err}");

        let text = "[[inner]]\nsize = 1.0\nsise = 2\n";
        let err = parse_toml::<Outer>(text, Path::new("w.toml"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(err.contains("unknown field `sise`"), "{err}");
        assert!(err.contains("w.toml:3"), "{err}");
    }
}
