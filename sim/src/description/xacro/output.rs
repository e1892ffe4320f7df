//! Writing the expanded URDF: escaped XML text, recording the source of every line written.

use std::collections::BTreeMap;

use super::expander::{OElem, ONode};

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

/// Writes an element starting on a new line, recording the source of every line written.
pub(super) fn write_element(
    e: &OElem,
    depth: usize,
    namespaces: &BTreeMap<String, String>,
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
        escape(value, true, out);
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
                write_element(c, depth + 1, namespaces, out, lines);
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
