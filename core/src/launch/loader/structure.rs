//! The tags that shape the walk: a file's `<launch>` and its children, `<group>`, `<arg>`,
//! `clear_params`, and `<include>` (cycles, include args, includes rover does itself).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use roxmltree::Node;

use super::files::{package_of, read_text, same_file};
use super::state::{Ctx, FileReader, Loader, global_ns, line_of};
use crate::launch::model::{
    LaunchError, Location, PROVIDED_PACKAGES, ProvidedInclude, ns_join, provided_placeholder,
};

/// Deepest chain of includes (a cycle is caught before this).
const MAX_INCLUDE_DEPTH: usize = 32;

impl Loader<'_> {
    /// Reads one launch file in `ctx` (the context an include made for it).
    pub(super) fn file(
        &mut self,
        path: &Path,
        ctx: Ctx,
        from: Location,
    ) -> Result<Ctx, LaunchError> {
        if let Some(i) = self.stack.iter().position(|p| same_file(p, path)) {
            let chain: Vec<String> = self.stack[i..]
                .iter()
                .chain(std::iter::once(&path.to_path_buf()))
                .map(|p| p.display().to_string())
                .collect();
            return Err(LaunchError::new(
                &from.file,
                from.line,
                format!("cyclic include: {}", chain.join(" -> ")),
            ));
        }
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            return Err(LaunchError::new(
                &from.file,
                from.line,
                format!("includes nest deeper than {MAX_INCLUDE_DEPTH}"),
            ));
        }
        let text = read_text(path).map_err(|e| LaunchError::new(&from.file, from.line, e))?;
        let doc = roxmltree::Document::parse_with_options(
            &text,
            roxmltree::ParsingOptions {
                allow_dtd: true,
                ..Default::default()
            },
        )
        .map_err(|e| LaunchError::new(path, e.pos().row, format!("not well-formed XML: {e}")))?;
        let root = doc.root_element();
        if root.tag_name().name() != "launch" {
            return Err(LaunchError::new(
                path,
                line_of(&doc, root),
                format!(
                    "expected a <launch> root element, found <{}>",
                    root.tag_name().name()
                ),
            ));
        }
        self.out.files.push(path.to_path_buf());
        self.stack.push(path.to_path_buf());
        let mut ctx = ctx;
        ctx.file = path.to_path_buf();
        let reader = FileReader { doc: &doc, path };
        let result = self.children(&reader, root, &mut ctx);
        self.stack.pop();
        result.map(|()| ctx)
    }

    fn children(
        &mut self,
        r: &FileReader<'_, '_>,
        parent: Node<'_, '_>,
        ctx: &mut Ctx,
    ) -> Result<(), LaunchError> {
        for tag in parent.children().filter(Node::is_element) {
            self.check_attributes(r, tag);
            if !self.condition(r, tag, ctx)? {
                continue;
            }
            match tag.tag_name().name() {
                "arg" => self.arg(r, tag, ctx)?,
                "group" => {
                    let ns = self.opt(r, tag, "ns", ctx)?;
                    if ns.as_deref() == Some("") {
                        return Err(r.err(tag, "<group> has an empty 'ns' attribute"));
                    }
                    let mut child = ctx.child(ns.as_deref());
                    self.clear_params(r, tag, &child, None)?;
                    self.children(r, tag, &mut child)?;
                }
                "node" => self.node(r, tag, ctx)?,
                "param" => {
                    if let Some((name, param)) = self.param(r, tag, ctx, false)? {
                        ctx.private.retain(|(k, _)| *k != name);
                        ctx.private.push((name, param));
                    }
                }
                "rosparam" => self.rosparam(r, tag, ctx)?,
                "remap" => {
                    let (from, to) = self.remap(r, tag, ctx)?;
                    ctx.add_remap(from, to);
                }
                "env" => {
                    let pair = self.env(r, tag, ctx)?;
                    ctx.env.push(pair);
                }
                "include" => self.include(r, tag, ctx)?,
                "machine" | "test" | "master" => self.out.warnings.push(format!(
                    "{}: <{}> is not used by rover launch; skipped",
                    r.at(tag),
                    tag.tag_name().name()
                )),
                other => self
                    .out
                    .warnings
                    .push(format!("{}: unrecognized tag <{other}>", r.at(tag))),
            }
        }
        Ok(())
    }

    fn arg(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &mut Ctx,
    ) -> Result<(), LaunchError> {
        let name = self.req(r, tag, "name", ctx)?;
        let value = self.opt(r, tag, "value", ctx)?;
        let default = self.opt(r, tag, "default", ctx)?;
        if value.is_some() && default.is_some() {
            return Err(r.err(tag, "<arg> must have only one of value and default"));
        }
        if ctx.arg_names.contains(&name) {
            if !ctx.pass_all_args {
                return Err(r.err(tag, format!("arg \"{name}\" has already been declared")));
            }
        } else {
            ctx.arg_names.push(name.clone());
        }
        let pass_all = ctx.pass_all_args;
        let dict = match ctx.include_args.as_mut() {
            Some(d) => d,
            None => &mut ctx.args,
        };
        if let Some(v) = value {
            if dict.contains_key(&name) && !pass_all {
                return Err(r.err(
                    tag,
                    format!("cannot override arg \"{name}\", which has already been set (an arg with value= is fixed; give it default= to let callers set it)"),
                ));
            }
            dict.insert(name, v);
        } else if let Some(d) = default {
            dict.entry(name).or_insert(d);
        }
        Ok(())
    }

    pub(super) fn clear_params(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
        node_name: Option<&str>,
    ) -> Result<(), LaunchError> {
        if self.flag(r, tag, "clear_params", ctx)? {
            let ns = match node_name {
                Some(name) => global_ns(&ns_join(&ctx.ns, name)),
                None if tag.attribute("ns").is_some() => ctx.ns.clone(),
                None => {
                    return Err(r.err(
                        tag,
                        "'ns' attribute must be set in order to use 'clear_params'",
                    ));
                }
            };
            self.out.clear_params.push(ns);
        }
        Ok(())
    }

    fn include(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &mut Ctx,
    ) -> Result<(), LaunchError> {
        let file = self.req(r, tag, "file", ctx)?;
        let pass_all_args = self.flag(r, tag, "pass_all_args", ctx)?;
        let ns = self.opt(r, tag, "ns", ctx)?;
        if ns.as_deref() == Some("") {
            return Err(r.err(tag, "<include> has an empty 'ns' attribute"));
        }
        let mut child = ctx.child(ns.as_deref());
        self.clear_params(r, tag, &child, None)?;
        child.arg_names = Vec::new();
        let mut passed = BTreeMap::new();
        if pass_all_args {
            passed = ctx.args.clone();
            child.arg_names = passed.keys().cloned().collect();
            child.pass_all_args = true;
        }
        child.include_args = Some(passed);
        for t in tag.children().filter(Node::is_element) {
            self.check_attributes(r, t);
            if !self.condition(r, t, &child)? {
                continue;
            }
            match t.tag_name().name() {
                "arg" => self.arg(r, t, &mut child)?,
                "env" => {
                    let pair = self.env(r, t, &child)?;
                    child.env.push(pair);
                }
                other => self.out.warnings.push(format!(
                    "{}: unrecognized <{other}> inside <include>",
                    r.at(t)
                )),
            }
        }
        let passed = child.include_args.take().unwrap_or_default();
        for name in &child.arg_names {
            if !passed.contains_key(name) {
                return Err(r.err(tag, format!("include arg \"{name}\" has no value")));
            }
        }
        let path = PathBuf::from(&file);
        if let Some(provided) = self.provided(&path, &passed, &child, r, tag) {
            self.out.provided.push(provided);
            return Ok(());
        }
        child.args = passed.clone();
        child.arg_names = Vec::new();
        let passed_names: Vec<String> = passed.keys().cloned().collect();
        let done = self.file(&path, child, r.at(tag))?;
        if !pass_all_args {
            let unused: Vec<&String> = passed_names
                .iter()
                .filter(|n| !done.arg_names.contains(n))
                .collect();
            if !unused.is_empty() {
                return Err(r.err(
                    tag,
                    format!(
                        "unused args [{}] for include of {} (it declares no such <arg>)",
                        unused
                            .iter()
                            .map(|s| s.as_str())
                            .collect::<Vec<_>>()
                            .join(", "),
                        path.display()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// An include rover does itself (rover's reading), or one of a provided package that is
    /// not installed: recorded, not read.
    fn provided(
        &mut self,
        path: &Path,
        args: &BTreeMap<String, String>,
        child: &Ctx,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
    ) -> Option<ProvidedInclude> {
        let file_name = path.file_name()?.to_string_lossy().into_owned();
        let text = path.to_string_lossy();
        let placeholder = PROVIDED_PACKAGES
            .iter()
            .find(|p| text.starts_with(&provided_placeholder(p)));
        let package = match placeholder {
            Some(p) => (*p).to_owned(),
            None if self.options.rover => {
                let package = package_of(path)?;
                if !matches!(
                    (package.as_str(), file_name.as_str()),
                    ("gazebo_ros", "empty_world.launch")
                        | ("darknet_ros", "darknet_ros.launch" | "yolo_v3.launch")
                ) {
                    return None;
                }
                package
            }
            None => return None,
        };
        if !self.options.rover {
            self.out.warnings.push(format!(
                "{}: {package} is not installed; {file_name} is not read (rover launch does its part itself)",
                r.at(tag)
            ));
        }
        Some(ProvidedInclude {
            package,
            file_name,
            args: args.clone(),
            namespace: child.ns.clone(),
            at: r.at(tag),
        })
    }
}
