//! The walk over a launch file's tags, with roslaunch's scoping: namespaces, args per file,
//! private (`~`) params collected for the nodes that follow, remaps and env inherited by
//! children, includes with their own args.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use rover_sim::ResourcePaths;
use roxmltree::{Document, Node};

use super::eval::EvalHost;
use super::model::{
    Launch, LaunchError, LaunchNode, LaunchOptions, Location, Output, PROVIDED_PACKAGES, Param,
    ParamSource, ProvidedInclude, absolute, canonical_name, files_named, ns_join,
    provided_placeholder,
};
use super::shell::shell_split;
use super::subst;
use super::value::{ParamValue, convert_value, parse_bool, parse_yaml};

/// Deepest chain of includes (a cycle is caught before this).
const MAX_INCLUDE_DEPTH: usize = 32;
/// Largest launch, YAML or text file read.
const MAX_FILE_BYTES: u64 = 64 << 20;

/// Reads the launch file `path` (and its includes) with `options`.
pub fn load(path: &Path, options: &LaunchOptions) -> Result<Launch, LaunchError> {
    let mut loader = Loader {
        options,
        out: Launch::default(),
        anon: HashMap::new(),
        stack: Vec::new(),
    };
    let mut top_args = BTreeMap::new();
    for (name, value) in &options.args {
        top_args.insert(name.clone(), value.clone());
    }
    let ctx = Ctx {
        ns: "/".to_owned(),
        file: path.to_path_buf(),
        args: top_args,
        arg_names: Vec::new(),
        include_args: None,
        private: Vec::new(),
        remaps: Vec::new(),
        env: Vec::new(),
        pass_all_args: false,
    };
    loader.file(
        path,
        ctx,
        Location {
            file: path.to_path_buf(),
            line: 0,
        },
    )?;
    Ok(loader.out)
}

/// The launch file `name` in package folder `package_dir` (searched a few folders deep, as
/// `roslaunch PKG FILE` finds it).
pub fn find_launch_file(package_dir: &Path, name: &str) -> Result<PathBuf, String> {
    let mut found = files_named(vec![(package_dir.to_path_buf(), 0)], name);
    found.sort();
    match found.len() {
        0 => Err(format!(
            "no file named \"{name}\" in package folder {}",
            package_dir.display()
        )),
        1 => Ok(found.remove(0)),
        _ => Err(format!(
            "more than one \"{name}\" in {}: {}; give the path instead",
            package_dir.display(),
            found
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// The scope a tag is read in (roslaunch's `LoaderContext`).
#[derive(Debug, Clone)]
struct Ctx {
    /// Namespace, global, with a trailing `/`.
    ns: String,
    /// The file being read (`$(dirname)`, messages, `$(find)` from here).
    file: PathBuf,
    /// Arg values visible here.
    args: BTreeMap<String, String>,
    /// Args declared in this file.
    arg_names: Vec<String>,
    /// While reading an `<include>`'s children: the args passed to the included file.
    include_args: Option<BTreeMap<String, String>>,
    /// `~name` params, for every node that follows in this scope.
    private: Vec<(String, Param)>,
    remaps: Vec<(String, String)>,
    env: Vec<(String, String)>,
    pass_all_args: bool,
}

impl Ctx {
    fn child(&self, ns: Option<&str>) -> Ctx {
        let mut c = self.clone();
        if let Some(ns) = ns {
            c.ns = if ns.starts_with('/') {
                global_ns(ns)
            } else if ns == "~" {
                "~".to_owned()
            } else {
                global_ns(&ns_join(&self.ns, ns))
            };
        }
        c
    }

    fn add_remap(&mut self, from: String, to: String) {
        self.remaps.retain(|(f, _)| *f != from);
        self.remaps.push((from, to));
    }
}

fn global_ns(ns: &str) -> String {
    let c = canonical_name(ns);
    let c = if c.starts_with('/') {
        c
    } else {
        format!("/{c}")
    };
    if c.ends_with('/') { c } else { format!("{c}/") }
}

struct Loader<'o> {
    options: &'o LaunchOptions,
    out: Launch,
    anon: HashMap<String, String>,
    /// Files being read, outermost first (for cycles).
    stack: Vec<PathBuf>,
}

/// Resolves substitutions against one scope.
struct Scope<'a> {
    args: &'a BTreeMap<String, String>,
    file: &'a Path,
    anon: &'a mut HashMap<String, String>,
    resources: &'a ResourcePaths,
}

impl EvalHost for Scope<'_> {
    fn arg(&mut self, name: &str) -> Result<String, String> {
        self.args.get(name).cloned().ok_or_else(|| {
            format!("arg \"{name}\" is not defined (declare it with <arg name=\"{name}\" default=\"...\"/> or pass {name}:=VALUE)")
        })
    }

    fn find(&mut self, package: &str) -> Result<String, String> {
        match self.resources.find_package(package, self.file) {
            Ok(dir) => Ok(absolute(&dir).to_string_lossy().into_owned()),
            Err(_) if PROVIDED_PACKAGES.contains(&package) => Ok(provided_placeholder(package)),
            Err(e) => Err(format!(
                "$(find {package}): {e} (add its folder to ROS_PACKAGE_PATH or pass --package-path {package}=DIR)"
            )),
        }
    }

    fn anon(&mut self, id: &str) -> String {
        if let Some(name) = self.anon.get(id) {
            return name.clone();
        }
        let host = std::fs::read_to_string("/proc/sys/kernel/hostname")
            .map(|h| h.trim().replace(['-', '.'], "_"))
            .unwrap_or_else(|_| "localhost".to_owned());
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let name = format!(
            "{id}_{host}_{}_{}",
            std::process::id(),
            u64::from(nanos).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 1
        );
        self.anon.insert(id.to_owned(), name.clone());
        name
    }

    fn dirname(&mut self) -> Result<String, String> {
        Ok(absolute(self.file)
            .parent()
            .map(|p| p.to_string_lossy().into_owned())
            .unwrap_or_default())
    }
}

fn line_of(doc: &Document<'_>, node: Node<'_, '_>) -> u32 {
    doc.text_pos_at(node.range().start).row
}

/// Attributes each tag knows (besides `if` and `unless`).
fn known_attributes(tag: &str) -> &'static [&'static str] {
    match tag {
        "arg" => &["name", "value", "default", "doc"],
        "param" => &["name", "value", "type", "textfile", "binfile", "command"],
        "rosparam" => &["command", "ns", "file", "param", "subst_value"],
        "node" => &[
            "pkg",
            "type",
            "name",
            "args",
            "machine",
            "respawn",
            "respawn_delay",
            "required",
            "ns",
            "clear_params",
            "output",
            "cwd",
            "launch-prefix",
        ],
        "remap" => &["from", "to"],
        "env" => &["name", "value"],
        "include" => &["file", "ns", "clear_params", "pass_all_args"],
        "group" => &["ns", "clear_params"],
        "launch" => &["deprecated"],
        _ => &[],
    }
}

impl Loader<'_> {
    /// Reads one launch file in `ctx` (the context an include made for it).
    fn file(&mut self, path: &Path, ctx: Ctx, from: Location) -> Result<Ctx, LaunchError> {
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

    fn check_attributes(&mut self, r: &FileReader<'_, '_>, tag: Node<'_, '_>) {
        let known = known_attributes(tag.tag_name().name());
        for a in tag.attributes() {
            let name = a.name();
            if !known.contains(&name) && name != "if" && name != "unless" && !known.is_empty() {
                self.out.warnings.push(format!(
                    "{}: unknown <{}> attribute '{name}'",
                    r.at(tag),
                    tag.tag_name().name()
                ));
            }
        }
    }

    fn resolve(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        text: &str,
        ctx: &Ctx,
    ) -> Result<String, LaunchError> {
        let mut scope = Scope {
            args: &ctx.args,
            file: &ctx.file,
            anon: &mut self.anon,
            resources: &self.options.resources,
        };
        subst::resolve(text, &mut scope).map_err(|e| r.err(tag, e))
    }

    fn opt(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        name: &str,
        ctx: &Ctx,
    ) -> Result<Option<String>, LaunchError> {
        match tag.attribute(name) {
            Some(text) => self.resolve(r, tag, text, ctx).map(Some),
            None => Ok(None),
        }
    }

    fn req(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        name: &str,
        ctx: &Ctx,
    ) -> Result<String, LaunchError> {
        self.opt(r, tag, name, ctx)?.ok_or_else(|| {
            r.err(
                tag,
                format!(
                    "<{}> is missing its required attribute '{name}'",
                    tag.tag_name().name()
                ),
            )
        })
    }

    fn flag(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        name: &str,
        ctx: &Ctx,
    ) -> Result<bool, LaunchError> {
        match self.opt(r, tag, name, ctx)? {
            None => Ok(false),
            Some(v) => match v.to_ascii_lowercase().as_str() {
                "true" => Ok(true),
                "false" => Ok(false),
                _ => Err(r.err(tag, format!("{name}=\"{v}\": expected true or false"))),
            },
        }
    }

    /// `if` / `unless`.
    fn condition(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<bool, LaunchError> {
        let if_value = self.opt(r, tag, "if", ctx)?;
        let unless_value = self.opt(r, tag, "unless", ctx)?;
        let as_bool = |v: &str| {
            parse_bool(v).ok_or_else(|| {
                r.err(
                    tag,
                    format!("if/unless value \"{v}\": expected true, false, 1 or 0"),
                )
            })
        };
        match (if_value, unless_value) {
            (Some(_), Some(_)) => {
                Err(r.err(tag, "cannot set both 'if' and 'unless' on the same tag"))
            }
            (Some(v), None) => as_bool(&v),
            (None, Some(v)) => as_bool(&v).map(|b| !b),
            (None, None) => Ok(true),
        }
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

    fn clear_params(
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

    fn remap(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(String, String), LaunchError> {
        let from = canonical_name(&self.req(r, tag, "from", ctx)?);
        let to = canonical_name(&self.req(r, tag, "to", ctx)?);
        if from.is_empty() || to.is_empty() {
            return Err(r.err(tag, "remap from/to attributes cannot be empty"));
        }
        Ok((from, to))
    }

    fn env(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(String, String), LaunchError> {
        let name = self.req(r, tag, "name", ctx)?;
        let value = self.req(r, tag, "value", ctx)?;
        if name.is_empty() {
            return Err(r.err(tag, "<env> 'name' must be non-empty"));
        }
        Ok((name, value))
    }

    /// `<param>`: into the launch's params, or (private, or inside a node) returned for the
    /// node(s) it belongs to.
    fn param(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
        in_node: bool,
    ) -> Result<Option<(String, Param)>, LaunchError> {
        let ty = tag
            .attribute("type")
            .unwrap_or("auto")
            .trim()
            .to_ascii_lowercase();
        let value = self.opt(r, tag, "value", ctx)?;
        let textfile = self.opt(r, tag, "textfile", ctx)?;
        let binfile = self.opt(r, tag, "binfile", ctx)?;
        let command = self.opt(r, tag, "command", ctx)?;
        let given = [&value, &textfile, &binfile, &command]
            .iter()
            .filter(|v| v.is_some())
            .count();
        if given != 1 {
            return Err(r.err(
                tag,
                "<param> must have exactly one of value, textfile, binfile and command",
            ));
        }
        let name = self.req(r, tag, "name", ctx)?.trim().to_owned();
        let bad = |e: String| r.err(tag, format!("<param name=\"{name}\">: {e}"));
        let (value, source) = if let Some(v) = value {
            (
                convert_value(v.trim(), &ty).map_err(bad)?,
                ParamSource::Value,
            )
        } else if let Some(f) = textfile {
            let text = read_text(Path::new(&f)).map_err(bad)?;
            (
                convert_value(&text, &ty).map_err(bad)?,
                ParamSource::TextFile(f.into()),
            )
        } else if let Some(f) = binfile {
            let bytes = read_bytes(Path::new(&f)).map_err(bad)?;
            (ParamValue::Binary(bytes), ParamSource::BinFile(f.into()))
        } else {
            let command = command.unwrap_or_default();
            let (text, source) = self.command(&command, &ctx.file).map_err(bad)?;
            (convert_value(&text, &ty).map_err(bad)?, source)
        };
        let param = Param {
            value,
            source,
            at: r.at(tag),
        };
        if name.starts_with('~') || in_node {
            return Ok(Some((name, param)));
        }
        self.set(ns_join(&ctx.ns, &name), param, r, tag)?;
        Ok(None)
    }

    /// Sets a parameter; a mapping becomes one parameter per key.
    fn set(
        &mut self,
        name: String,
        param: Param,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
    ) -> Result<(), LaunchError> {
        if name.starts_with('~') {
            return Err(r.err(tag, format!("private name \"{name}\" outside a node")));
        }
        let name = canonical_name(&name);
        if let ParamValue::Map(entries) = param.value {
            for (key, value) in entries {
                let p = Param {
                    value,
                    source: param.source.clone(),
                    at: param.at.clone(),
                };
                self.set(ns_join(&format!("{name}/"), &key), p, r, tag)?;
            }
            return Ok(());
        }
        if name == "/" {
            return Err(r.err(
                tag,
                "cannot set a non-mapping value on the root namespace '/'",
            ));
        }
        self.out.params.insert(name, param);
        Ok(())
    }

    /// Runs a `command` param: xacro in-process, anything else as a process.
    fn command(&self, command: &str, file: &Path) -> Result<(String, ParamSource), String> {
        let words = shell_split(command)?;
        let Some(first) = words.first() else {
            return Err("the command is empty".to_owned());
        };
        let program = Path::new(first)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let xacro_args = if program == "xacro" || program == "xacro.py" {
            Some(&words[1..])
        } else if program == "rosrun" && words.get(1).map(String::as_str) == Some("xacro") {
            words.get(3..)
        } else {
            None
        };
        if let Some(args) = xacro_args {
            let (path, xargs) = xacro_command(args)?;
            let path = if path.is_relative() {
                file.parent().map(|d| d.join(&path)).unwrap_or(path)
            } else {
                path
            };
            let expanded = rover_sim::expand_xacro(&path, &xargs, &self.options.resources)
                .map_err(|e| format!("xacro: {e}"))?;
            return Ok((
                expanded.text,
                ParamSource::Xacro {
                    file: path,
                    args: xargs,
                },
            ));
        }
        if !self.options.run_commands {
            return Err(format!("commands are not run here: \"{command}\""));
        }
        let output = std::process::Command::new(first)
            .args(&words[1..])
            .stdin(std::process::Stdio::null())
            .output()
            .map_err(|e| format!("cannot run \"{first}\": {e}"))?;
        if !output.status.success() {
            return Err(format!(
                "command \"{command}\" failed ({}): {}",
                output.status,
                String::from_utf8_lossy(&output.stderr).trim()
            ));
        }
        let text = String::from_utf8(output.stdout)
            .map_err(|_| format!("command \"{command}\" printed something that is not UTF-8"))?;
        Ok((text, ParamSource::Command(words)))
    }

    fn rosparam(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(), LaunchError> {
        let command = self
            .opt(r, tag, "command", ctx)?
            .unwrap_or_else(|| "load".to_owned());
        let ns = self.opt(r, tag, "ns", ctx)?.unwrap_or_default();
        let file = self.opt(r, tag, "file", ctx)?;
        let param = self.opt(r, tag, "param", ctx)?.unwrap_or_default();
        let subst_value = self.flag(r, tag, "subst_value", ctx)?;
        let param = ns_join(&ns, &param);
        let full = if param.is_empty() {
            ctx.ns.clone()
        } else {
            ns_join(&ctx.ns, &param)
        };
        match command.as_str() {
            "load" => {
                let text = match &file {
                    Some(f) => read_text(Path::new(f)).map_err(|e| r.err(tag, e))?,
                    None => tag
                        .children()
                        .filter(Node::is_text)
                        .filter_map(|t| t.text())
                        .collect(),
                };
                let text = if subst_value {
                    self.resolve(r, tag, &text, ctx)?
                } else {
                    text
                };
                let value = parse_yaml(&text).map_err(|e| {
                    r.err(
                        tag,
                        match &file {
                            Some(f) => format!("{f}: {e}"),
                            None => format!("<rosparam>: {e}"),
                        },
                    )
                })?;
                if param.is_empty() && !matches!(value, ParamValue::Map(_)) {
                    return Err(r.err(
                        tag,
                        "<rosparam> needs a 'param' attribute for a value that is not a mapping",
                    ));
                }
                let p = Param {
                    value,
                    source: ParamSource::Yaml(file.map(PathBuf::from)),
                    at: r.at(tag),
                };
                self.set(full, p, r, tag)
            }
            "delete" => {
                if file.is_some() {
                    return Err(r.err(tag, "'file' attribute is invalid with the 'delete' command"));
                }
                self.out.deletes.push(canonical_name(&full));
                Ok(())
            }
            "dump" => {
                self.out.warnings.push(format!(
                    "{}: <rosparam command=\"dump\"> is not done by rover launch",
                    r.at(tag)
                ));
                Ok(())
            }
            other => Err(r.err(
                tag,
                format!("<rosparam command=\"{other}\">: expected load, dump or delete"),
            )),
        }
    }

    fn node(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(), LaunchError> {
        let name = self.req(r, tag, "name", ctx)?;
        if name.is_empty() || name.contains('/') {
            return Err(r.err(
                tag,
                format!("illegal <node> name \"{name}\" (a base name, without '/')"),
            ));
        }
        let ns = self.opt(r, tag, "ns", ctx)?;
        if ns.as_deref() == Some("") {
            return Err(r.err(tag, "<node> has an empty 'ns' attribute"));
        }
        let child = ctx.child(ns.as_deref());
        self.clear_params(r, tag, &child, Some(&name))?;
        let param_ns = global_ns(&ns_join(&child.ns, &name));
        let pkg = self.req(r, tag, "pkg", ctx)?;
        let node_type = self.req(r, tag, "type", ctx)?;
        let args = self.opt(r, tag, "args", ctx)?.unwrap_or_default();
        let output = match self.opt(r, tag, "output", ctx)?.as_deref() {
            None | Some("log") => Output::Log,
            Some("screen") => Output::Screen,
            Some(other) => {
                return Err(r.err(tag, format!("output=\"{other}\": expected log or screen")));
            }
        };
        let respawn = self.flag(r, tag, "respawn", ctx)?;
        let required = self.flag(r, tag, "required", ctx)?;
        let respawn_delay_s = match self.opt(r, tag, "respawn_delay", ctx)? {
            None => 0.0,
            Some(v) => v
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|d| d.is_finite() && *d >= 0.0)
                .ok_or_else(|| {
                    r.err(
                        tag,
                        format!("respawn_delay=\"{v}\": expected seconds (a number >= 0)"),
                    )
                })?,
        };
        let launch_prefix = self
            .opt(r, tag, "launch-prefix", ctx)?
            .filter(|p| !p.is_empty());
        let cwd = self.opt(r, tag, "cwd", ctx)?;
        let mut node_ctx = child.clone();
        node_ctx.ns = param_ns.clone();
        let mut local = Vec::new();
        for t in tag.children().filter(Node::is_element) {
            self.check_attributes(r, t);
            if !self.condition(r, t, ctx)? {
                continue;
            }
            match t.tag_name().name() {
                "remap" => {
                    let (from, to) = self.remap(r, t, ctx)?;
                    node_ctx.add_remap(from, to);
                }
                "param" => {
                    if let Some((name, param)) = self.param(r, t, &node_ctx, true)? {
                        local.retain(|(k, _): &(String, Param)| *k != name);
                        local.push((name, param));
                    }
                }
                "rosparam" => self.rosparam(r, t, &node_ctx)?,
                "env" => {
                    let pair = self.env(r, t, ctx)?;
                    node_ctx.env.push(pair);
                }
                other => self
                    .out
                    .warnings
                    .push(format!("{}: unrecognized <{other}> inside <node>", r.at(t))),
            }
        }
        for (key, param) in ctx.private.iter().chain(local.iter()) {
            let key = key.strip_prefix('~').unwrap_or(key);
            self.set(format!("{param_ns}{key}"), param.clone(), r, tag)?;
        }
        self.out.nodes.push(LaunchNode {
            pkg,
            node_type,
            name,
            namespace: child.ns.clone(),
            args,
            remaps: node_ctx.remaps,
            env: node_ctx.env,
            output,
            respawn,
            respawn_delay_s,
            required,
            launch_prefix,
            cwd,
            at: r.at(tag),
        });
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

/// The package a file is in: the `<name>` of the nearest package.xml above it.
fn package_of(path: &Path) -> Option<String> {
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

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// One file's document, for locating tags.
struct FileReader<'d, 'i> {
    doc: &'d Document<'i>,
    path: &'d Path,
}

impl FileReader<'_, '_> {
    fn at(&self, tag: Node<'_, '_>) -> Location {
        Location {
            file: self.path.to_path_buf(),
            line: line_of(self.doc, tag),
        }
    }

    fn err(&self, tag: Node<'_, '_>, message: impl Into<String>) -> LaunchError {
        LaunchError::new(self.path, line_of(self.doc, tag), message)
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, String> {
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

fn read_text(path: &Path) -> Result<String, String> {
    String::from_utf8(read_bytes(path)?)
        .map_err(|_| format!("{} is not UTF-8 text", path.display()))
}

/// xacro's command line: options, the file, and `name:=value` args.
fn xacro_command(words: &[String]) -> Result<(PathBuf, BTreeMap<String, String>), String> {
    let mut file = None;
    let mut args = BTreeMap::new();
    let mut i = 0;
    while i < words.len() {
        let w = &words[i];
        if let Some((name, value)) = w.split_once(":=") {
            args.insert(name.to_owned(), value.to_owned());
        } else if w == "-o" || w == "--output" {
            i += 1;
        } else if w.starts_with('-') {
            // --inorder, --xacro-ns, -v ...: nothing rover's xacro needs.
        } else if file.is_none() {
            file = Some(PathBuf::from(w));
        } else {
            return Err(format!(
                "xacro: a second file \"{w}\" (expected one input file)"
            ));
        }
        i += 1;
    }
    let file = file.ok_or_else(|| "xacro: no input file".to_owned())?;
    Ok((file, args))
}
