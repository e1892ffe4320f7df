//! Writing the expanded URDF: escaped XML text, recording the source of every line written.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::expander::{OElem, ONode};

/// A `<mesh filename>` as written in an included file, as the consumer should read it: a
/// plain relative path that names no file beside the top file but one beside the file it was
/// written in (a URDF with `./meshes/...` included unchanged from its own folder) becomes that
/// file's path; anything else is left as it is.
fn mesh_file<'v>(e: &OElem, name: &str, value: &'v str, files: &[PathBuf]) -> Cow<'v, str> {
    let relative = !value.contains("://") && !value.is_empty() && Path::new(value).is_relative();
    if e.file == 0 || name != "filename" || !e.name.ends_with("mesh") || !relative {
        return Cow::Borrowed(value);
    }
    let dir = |file: usize| files.get(file).and_then(|f| f.parent());
    match (dir(0), dir(e.file)) {
        (Some(top), Some(own)) if !top.join(value).is_file() && own.join(value).is_file() => {
            Cow::Owned(own.join(value).display().to_string())
        }
        _ => Cow::Borrowed(value),
    }
}

fn escape(s: &str, attribute: bool, out: &mut String) {
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' if attribute => out.push_str("&quot;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' if attribute => out.push_str("&#9;"),
            c => out.push(c),
        }
    }
}

/// Writes an element starting on a new line, recording the source of every line written; an
/// included file's relative mesh files as [`mesh_file`] reads them.
pub(super) fn write_element(
    e: &OElem,
    depth: usize,
    (namespaces, files): (&BTreeMap<String, String>, &[PathBuf]),
    out: &mut String,
    lines: &mut Vec<(usize, u32)>,
) {
    out.push('\n');
    lines.push((e.file, e.line));
    for _ in 0..depth {
        out.push_str("  ");
    }
    out.push('<');
    out.push_str(&e.name);
    if depth == 0 {
        for (prefix, uri) in namespaces {
            out.push_str(" xmlns:");
            out.push_str(prefix);
            out.push_str("=\"");
            escape(uri, true, out);
            out.push('"');
        }
    }
    for (name, value) in &e.attrs {
        out.push(' ');
        out.push_str(name);
        out.push_str("=\"");
        escape(&mesh_file(e, name, value, files), true, out);
        out.push('"');
    }
    if e.children.is_empty() {
        out.push_str("/>");
        return;
    }
    out.push('>');
    let mut has_elements = false;
    for child in &e.children {
        match child {
            ONode::Text(t) => escape(t, false, out),
            ONode::Elem(c) => {
                has_elements = true;
                write_element(c, depth + 1, (namespaces, files), out, lines);
            }
        }
    }
    if has_elements {
        out.push('\n');
        lines.push((e.file, e.line));
        for _ in 0..depth {
            out.push_str("  ");
        }
    }
    out.push_str("</");
    out.push_str(&e.name);
    out.push('>');
}
