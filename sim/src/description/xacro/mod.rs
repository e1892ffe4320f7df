//! xacro, in-process: expands `.xacro` robot descriptions to URDF without ROS or Python.
//!
//! Supported, with the reference xacro's (ROS Noetic, xacro 1.14 / 2.x) semantics:
//! `xacro:property` (value, default, block, lazily evaluated, `scope="parent|global"`),
//! `xacro:arg` and `$(arg)`, `xacro:macro` with plain, default (`a:=1`), inherited (`a:=^`,
//! `a:=^|1`) and block (`*a`, `**a`) parameters, `xacro:insert_block`, `xacro:include` (with `ns`),
//! `xacro:if` / `xacro:unless`, `xacro:element` / `xacro:attribute`, `xacro:call`, and the
//! substitution args `$(find)`, `$(arg)`, `$(env)`, `$(optenv)`, `$(eval)`, `$(dirname)`.
//! Expressions are evaluated by [`rover_pyexpr`].
//!
//! Written in-tree because the one complete Rust xacro crate (xurdf 0.6.6) drops element text,
//! which loses every Gazebo plugin parameter; this builds on roxmltree, already a dependency.
//!
//! The expansion keeps, for every output line, the file and line it came from, so that errors
//! found later in the URDF still name the xacro file and line the user wrote.

mod elements;
mod expander;
mod include;
mod macros;
mod output;
mod properties;
mod substitute;
#[cfg(test)]
mod tests;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use expander::{Expander, OElem, Scope, XACRO_NAMESPACES};
use output::write_element;

use crate::description::resource::ResourcePaths;
use crate::error::{Location, Result};

/// A URDF produced by expanding a xacro file.
#[derive(Debug, Clone)]
pub struct Expanded {
    /// The URDF text.
    pub text: String,
    files: Vec<PathBuf>,
    /// Source (file index, line) of each output line.
    lines: Vec<(usize, u32)>,
}

impl Expanded {
    /// The xacro file and line an output line (1-based) came from.
    pub fn source_of(&self, line: u32) -> Option<Location> {
        let (file, src_line) = *self.lines.get((line as usize).checked_sub(1)?)?;
        Some(Location::new(&self.files[file], Some(src_line)))
    }

    /// Every file read (the top file and its includes).
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }
}

/// Whether `text` looks like xacro: it declares the xacro namespace.
pub fn uses_xacro(text: &str) -> bool {
    XACRO_NAMESPACES.iter().any(|ns| text.contains(ns))
}

/// Expands the xacro file `path`. `args` are `name:=value` arguments (`$(arg name)`);
/// `resources` finds `$(find pkg)`.
pub fn expand_file(
    path: &Path,
    args: &BTreeMap<String, String>,
    resources: &ResourcePaths,
) -> Result<Expanded> {
    let mut ex = Expander {
        resources,
        args: args.clone(),
        arg_defaults: BTreeMap::new(),
        files: Vec::new(),
        include_stack: Vec::new(),
        scopes: vec![Scope::default()],
        namespaces: BTreeMap::new(),
        evaluating: Vec::new(),
        macro_depth: 0,
        elements_out: 0,
        at: (0, 0),
    };
    let root = ex.read(path)?;
    let file = root.file;
    ex.include_stack.push(file);
    ex.at = (root.file, root.line);
    let mut attrs = Vec::with_capacity(root.attrs.len());
    for (name, value) in &root.attrs {
        attrs.push((name.clone(), ex.eval_text(value, 0)?.to_string()));
    }
    let mut children = Vec::new();
    let mut extra = Vec::new();
    ex.process(&root.children, 0, &mut children, &mut extra)?;
    attrs.extend(extra);
    let out = OElem {
        name: root.name.clone(),
        attrs,
        children,
        file: root.file,
        line: root.line,
    };
    let mut text = String::from("<?xml version=\"1.0\"?>");
    let mut lines = vec![(file, 1)];
    write_element(&out, 0, (&ex.namespaces, &ex.files), &mut text, &mut lines);
    text.push('\n');
    Ok(Expanded {
        text,
        files: ex.files,
        lines,
    })
}
