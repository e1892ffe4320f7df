//! YAML files (ros_control controllers, ros_gz_bridge topic maps) read with saphyr into a small
//! tree that keeps every value's line, for located errors.

use std::path::Path;

use saphyr::{LoadableYamlNode, MarkedYaml, Scalar, YamlData};

use crate::error::{Result, SimError};

/// The first document of YAML `text` (`None`: an empty file); `path` names it in errors.
pub(crate) fn load(text: &str, path: &Path) -> Result<Option<Node>> {
    let docs = MarkedYaml::load_from_str(text).map_err(|e| {
        SimError::invalid(
            path,
            u32::try_from(e.marker().line()).ok(),
            format!("not valid YAML: {}", e.info()),
        )
    })?;
    docs.first().map(|d| convert(d, path)).transpose()
}

/// A YAML node reduced to what rover's YAML files use, with its line.
#[derive(Debug, Clone)]
pub(crate) struct Node {
    pub line: u32,
    pub value: Value,
}

#[derive(Debug, Clone)]
pub(crate) enum Value {
    Null,
    Bool(bool),
    Number(f64),
    Text(String),
    Map(Vec<(String, Node)>),
    List(Vec<Node>),
}

impl Node {
    pub(crate) fn get(&self, key: &str) -> Option<&Node> {
        match &self.value {
            Value::Map(entries) => entries.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    pub(crate) fn entries(&self) -> &[(String, Node)] {
        match &self.value {
            Value::Map(entries) => entries,
            _ => &[],
        }
    }

    pub(crate) fn is_map(&self) -> bool {
        matches!(self.value, Value::Map(_))
    }

    pub(crate) fn describe(&self) -> &'static str {
        match self.value {
            Value::Null => "nothing",
            Value::Bool(_) => "a boolean",
            Value::Number(_) => "a number",
            Value::Text(_) => "text",
            Value::Map(_) => "a mapping",
            Value::List(_) => "a list",
        }
    }
}

fn convert(node: &MarkedYaml<'_>, path: &Path) -> Result<Node> {
    let line = u32::try_from(node.span.start.line()).unwrap_or(u32::MAX);
    let value = match &node.data {
        YamlData::Value(Scalar::Null) => Value::Null,
        YamlData::Value(Scalar::Boolean(b)) => Value::Bool(*b),
        YamlData::Value(Scalar::Integer(i)) => Value::Number(*i as f64),
        YamlData::Value(Scalar::FloatingPoint(f)) => Value::Number(f.into_inner()),
        YamlData::Value(Scalar::String(s)) => Value::Text(s.to_string()),
        YamlData::Representation(s, _, _) => Value::Text(s.to_string()),
        YamlData::Sequence(items) => Value::List(
            items
                .iter()
                .map(|i| convert(i, path))
                .collect::<Result<_>>()?,
        ),
        YamlData::Mapping(map) => {
            let mut entries = Vec::with_capacity(map.len());
            for (k, v) in map {
                let key = match &k.data {
                    YamlData::Value(Scalar::String(s)) => s.to_string(),
                    YamlData::Value(Scalar::Integer(i)) => i.to_string(),
                    _ => {
                        return Err(SimError::invalid(
                            path,
                            u32::try_from(k.span.start.line()).ok(),
                            "expected a name as mapping key",
                        ));
                    }
                };
                let mut value = convert(v, path)?;
                if matches!(value.value, Value::Map(_) | Value::List(_)) {
                    // A block collection starts on the line after its key: point at the key.
                    value.line = u32::try_from(k.span.start.line()).unwrap_or(value.line);
                }
                entries.push((key, value));
            }
            Value::Map(entries)
        }
        YamlData::Tagged(_, inner) => return convert(inner, path),
        YamlData::Alias(_) | YamlData::BadValue => {
            return Err(SimError::invalid(
                path,
                Some(line),
                "aliases and malformed values are not supported here",
            ));
        }
    };
    Ok(Node { line, value })
}
