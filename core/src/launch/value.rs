//! Parameter values as roslaunch sets them: `<param>` text converted by its `type` (roslaunch's
//! `convert_value`), `<rosparam>` YAML, and the YAML `--dump-params` prints.

use rover_pyexpr::{float_repr, parse_float, parse_int};
use saphyr::{LoadableYamlNode, Scalar, Yaml};

/// A value on the ROS parameter server.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// `true` / `false`.
    Bool(bool),
    /// A whole number.
    Int(i64),
    /// A floating-point number.
    Double(f64),
    /// Text.
    Str(String),
    /// A YAML list.
    List(Vec<ParamValue>),
    /// A YAML mapping inside a list (mappings at the top are unrolled into one parameter per
    /// key, as roslaunch does).
    Map(Vec<(String, ParamValue)>),
    /// `<param binfile=...>`: the file's bytes.
    Binary(Vec<u8>),
}

impl ParamValue {
    /// The value's YAML text on one line (flow style, strings double-quoted), as
    /// `--dump-params` prints it: PyYAML reads it back as the same value.
    pub fn to_yaml(&self) -> String {
        let mut out = String::new();
        self.write_yaml(&mut out);
        out
    }

    fn write_yaml(&self, out: &mut String) {
        match self {
            Self::Bool(b) => out.push_str(if *b { "true" } else { "false" }),
            Self::Int(i) => out.push_str(&i.to_string()),
            Self::Double(d) => out.push_str(&yaml_float(*d)),
            Self::Str(s) => out.push_str(&quoted(s)),
            Self::Binary(bytes) => {
                out.push_str("!!binary ");
                out.push_str(&quoted(&base64(bytes)));
            }
            Self::List(items) => {
                out.push('[');
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    item.write_yaml(out);
                }
                out.push(']');
            }
            Self::Map(entries) => {
                out.push('{');
                for (i, (key, value)) in entries.iter().enumerate() {
                    if i > 0 {
                        out.push_str(", ");
                    }
                    out.push_str(&quoted(key));
                    out.push_str(": ");
                    value.write_yaml(out);
                }
                out.push('}');
            }
        }
    }

    /// The value as Python's `str()` would print it (for `$(eval)` and messages).
    pub fn as_text(&self) -> String {
        match self {
            Self::Bool(b) => if *b { "True" } else { "False" }.to_owned(),
            Self::Int(i) => i.to_string(),
            Self::Double(d) => float_repr(*d),
            Self::Str(s) => s.clone(),
            other => other.to_yaml(),
        }
    }
}

/// roslaunch's `convert_value`: `<param>` text by its `type` (`auto`, `str`/`string`, `int`,
/// `double`, `bool`/`boolean`, `yaml`). `auto` tries a number (a float when the text has a `.`,
/// an int without `_`), then `true`/`false`, then keeps the text.
pub fn convert_value(text: &str, ty: &str) -> Result<ParamValue, String> {
    match ty.to_ascii_lowercase().as_str() {
        "auto" => {
            if text.contains('.') {
                if let Some(f) = parse_float(text) {
                    return Ok(ParamValue::Double(f));
                }
            } else if !text.contains('_')
                && let Some(i) = parse_int(text)
            {
                return Ok(ParamValue::Int(i));
            }
            let lower = text.to_ascii_lowercase();
            if lower == "true" || lower == "false" {
                return Ok(ParamValue::Bool(lower == "true"));
            }
            Ok(ParamValue::Str(text.to_owned()))
        }
        "str" | "string" => Ok(ParamValue::Str(text.to_owned())),
        "int" => parse_int(text)
            .map(ParamValue::Int)
            .ok_or_else(|| format!("\"{text}\" is not an int")),
        "double" => parse_float(text)
            .map(ParamValue::Double)
            .ok_or_else(|| format!("\"{text}\" is not a double")),
        "bool" | "boolean" => parse_bool(text)
            .map(ParamValue::Bool)
            .ok_or_else(|| format!("\"{text}\" is not a bool (expected true, false, 1 or 0)")),
        "yaml" => parse_yaml(text),
        other => Err(format!(
            "unknown type \"{other}\" (expected auto, str, string, int, double, bool, boolean or yaml)"
        )),
    }
}

/// roslaunch's booleans (`if`, `unless`, `type="bool"`): `true`/`1` or `false`/`0`, any case,
/// spaces around ignored.
pub fn parse_bool(text: &str) -> Option<bool> {
    match text.trim().to_ascii_lowercase().as_str() {
        "true" | "1" => Some(true),
        "false" | "0" => Some(false),
        _ => None,
    }
}

/// A float as PyYAML reads it back as a float (it needs a `.` in the mantissa).
fn yaml_float(v: f64) -> String {
    if v.is_nan() {
        return ".nan".to_owned();
    }
    if v.is_infinite() {
        return if v > 0.0 { ".inf" } else { "-.inf" }.to_owned();
    }
    let text = float_repr(v);
    match text.split_once('e') {
        Some((m, e)) if !m.contains('.') => format!("{m}.0e{e}"),
        _ => text,
    }
}

/// A double-quoted YAML (and JSON) string.
fn quoted(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| format!("\"{}\"", s.escape_default()))
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> (18 - 6 * i)) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// YAML text (`<rosparam>`, `type="yaml"`) as a value; an empty document is an empty mapping,
/// as roslaunch reads it.
pub fn parse_yaml(text: &str) -> Result<ParamValue, String> {
    let docs = Yaml::load_from_str(text)
        .map_err(|e| format!("not valid YAML (line {}): {}", e.marker().line(), e.info()))?;
    match docs.first() {
        None => Ok(ParamValue::Map(Vec::new())),
        Some(doc) => from_yaml(doc),
    }
}

fn from_yaml(node: &Yaml<'_>) -> Result<ParamValue, String> {
    Ok(match node {
        Yaml::Value(scalar) => from_scalar(scalar)?,
        Yaml::Representation(text, _, _) => ParamValue::Str(text.to_string()),
        Yaml::Sequence(items) => {
            ParamValue::List(items.iter().map(from_yaml).collect::<Result<_, _>>()?)
        }
        Yaml::Mapping(map) => {
            let mut entries = Vec::with_capacity(map.len());
            for (key, value) in map {
                let key = match key {
                    Yaml::Value(scalar) => from_scalar(scalar)?.as_text(),
                    Yaml::Representation(text, _, _) => text.to_string(),
                    other => {
                        return Err(format!("a mapping key must be a scalar, found {other:?}"));
                    }
                };
                entries.push((key, from_yaml(value)?));
            }
            ParamValue::Map(entries)
        }
        Yaml::Tagged(_, inner) => from_yaml(inner)?,
        Yaml::Alias(_) | Yaml::BadValue => {
            return Err("a YAML alias or bad value rover cannot set as a parameter".to_owned());
        }
    })
}

fn from_scalar(scalar: &Scalar<'_>) -> Result<ParamValue, String> {
    Ok(match scalar {
        Scalar::Null => {
            return Err("a null value (the ROS parameter server has no null)".to_owned());
        }
        Scalar::Boolean(b) => ParamValue::Bool(*b),
        Scalar::Integer(i) => ParamValue::Int(*i),
        Scalar::FloatingPoint(f) => ParamValue::Double(f.into_inner()),
        Scalar::String(s) => ParamValue::Str(s.to_string()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_conversion_follows_roslaunch() {
        assert_eq!(convert_value("3", "auto"), Ok(ParamValue::Int(3)));
        assert_eq!(convert_value("3.5", "auto"), Ok(ParamValue::Double(3.5)));
        assert_eq!(
            convert_value("1_000", "auto"),
            Ok(ParamValue::Str("1_000".into()))
        );
        assert_eq!(convert_value("True", "auto"), Ok(ParamValue::Bool(true)));
        assert_eq!(
            convert_value("1.2.3", "auto"),
            Ok(ParamValue::Str("1.2.3".into()))
        );
        assert_eq!(convert_value("7", "str"), Ok(ParamValue::Str("7".into())));
        assert_eq!(convert_value("0", "bool"), Ok(ParamValue::Bool(false)));
        assert!(convert_value("maybe", "bool").is_err());
        assert!(convert_value("1", "float").is_err());
    }

    #[test]
    fn yaml_floats_read_back_as_floats() {
        assert_eq!(yaml_float(1e-7), "1.0e-07");
        assert_eq!(yaml_float(3.0), "3.0");
    }

    #[test]
    fn yaml_reads_nested_values() {
        let v = parse_yaml("a: 1\nb: {c: [1, 2.5], d: hello}\n");
        let expected = ParamValue::Map(vec![
            ("a".into(), ParamValue::Int(1)),
            (
                "b".into(),
                ParamValue::Map(vec![
                    (
                        "c".into(),
                        ParamValue::List(vec![ParamValue::Int(1), ParamValue::Double(2.5)]),
                    ),
                    ("d".into(), ParamValue::Str("hello".into())),
                ]),
            ),
        ]);
        assert_eq!(v, Ok(expected));
        assert_eq!(parse_yaml(""), Ok(ParamValue::Map(Vec::new())));
        assert!(parse_yaml("a: [1, 2").is_err());
        assert_eq!(base64(b"hi!?"), "aGkhPw==");
    }
}
