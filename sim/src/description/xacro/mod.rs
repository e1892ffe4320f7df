//! xacro, in-process: expands `.xacro` robot descriptions to URDF without ROS or Python.
//!
//! Supported, with the reference xacro's (ROS Noetic, xacro 1.14 / 2.x) semantics:
//! `xacro:property` (value, default, block, lazily evaluated, `scope="parent|global"`),
//! `xacro:arg` and `$(arg)`, `xacro:macro` with plain, default (`a:=1`), inherited (`a:=^`,
//! `a:=^|1`) and block (`*a`, `**a`) parameters, `xacro:insert_block`, `xacro:include` (with `ns`),
//! `xacro:if` / `xacro:unless`, `xacro:element` / `xacro:attribute`, `xacro:call`, and the
//! substitution args `$(find)`, `$(arg)`, `$(env)`, `$(optenv)`, `$(eval)`, `$(dirname)`.
//! Expressions are described in [`expr`].
//!
//! Written in-tree because the one complete Rust xacro crate (xurdf 0.6.6) drops element text,
//! which loses every Gazebo plugin parameter; this builds on roxmltree, already a dependency.
//!
//! The expansion keeps, for every output line, the file and line it came from, so that errors
//! found later in the URDF still name the xacro file and line the user wrote.


use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use rover_pyexpr::{ExprError, Host, Value};

use crate::description::resource::ResourcePaths;
use crate::error::{Location, Result, SimError};

/// The xacro namespace URIs in use (the wiki moved from ros.org to www.ros.org).
const XACRO_NAMESPACES: [&str; 2] = ["http://ros.org/wiki/xacro", "http://www.ros.org/wiki/xacro"];

/// Deepest macro call nesting accepted (a macro that calls itself without end stops here).
const MAX_MACRO_DEPTH: usize = 100;
/// Most output elements accepted, so that runaway expansion fails instead of eating memory.
const MAX_OUTPUT_ELEMENTS: usize = 2_000_000;

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
    write_element(&out, 0, &ex.namespaces, &mut text, &mut lines);
    text.push('\n');
    Ok(Expanded {
        text,
        files: ex.files,
        lines,
    })
}

/// An input element, owned so that macros can keep their bodies.
#[derive(Debug)]
struct XElem {
    /// Qualified name as written (`link`, `sensor`, `gazebo:plugin`).
    name: String,
    /// The local name when the element is in the xacro namespace.
    xacro: Option<String>,
    attrs: Vec<(String, String)>,
    children: Vec<XNode>,
    file: usize,
    line: u32,
}

#[derive(Debug)]
enum XNode {
    Elem(Rc<XElem>),
    Text(String),
}

/// An output element.
#[derive(Debug, Clone)]
struct OElem {
    name: String,
    attrs: Vec<(String, String)>,
    children: Vec<ONode>,
    file: usize,
    line: u32,
}

#[derive(Debug, Clone)]
enum ONode {
    Elem(OElem),
    Text(String),
}

#[derive(Debug, Clone)]
enum Prop {
    /// Text not yet evaluated (xacro evaluates properties on first use).
    Lazy(String),
    Value(Value),
    Block(Vec<ONode>),
}

#[derive(Debug, Default)]
struct Scope {
    parent: Option<usize>,
    props: HashMap<String, Prop>,
    macros: HashMap<String, Rc<Macro>>,
}

#[derive(Debug)]
enum Param {
    Plain {
        name: String,
        default: Option<ParamDefault>,
    },
    /// `*name`: one element of the call's body.
    Block(String),
    /// `**name`: the children of one element of the call's body.
    BlockContents(String),
}

#[derive(Debug)]
enum ParamDefault {
    Text(String),
    /// `^` or `^|fallback`: the caller's property of the same name.
    Inherit(Option<String>),
}

#[derive(Debug)]
struct Macro {
    name: String,
    params: Vec<Param>,
    body: Rc<XElem>,
}

struct Expander<'a> {
    resources: &'a ResourcePaths,
    args: BTreeMap<String, String>,
    arg_defaults: BTreeMap<String, String>,
    files: Vec<PathBuf>,
    include_stack: Vec<usize>,
    scopes: Vec<Scope>,
    /// Namespace prefixes of non-xacro elements, declared on the output's root.
    namespaces: BTreeMap<String, String>,
    /// Lazy properties being evaluated, to report self-reference instead of overflowing.
    evaluating: Vec<(usize, String)>,
    macro_depth: usize,
    elements_out: usize,
    /// File and line of the element being expanded, for messages.
    at: (usize, u32),
}

impl Expander<'_> {
    fn error(&self, message: impl Into<String>) -> SimError {
        SimError::Invalid {
            location: Location::new(&self.files[self.at.0], Some(self.at.1)),
            message: message.into(),
        }
    }

    fn expr_error(&self, text: &str, e: ExprError) -> SimError {
        match e {
            ExprError::Undefined(name) => {
                self.error(format!("in \"{text}\": undefined property \"{name}\""))
            }
            ExprError::Other(message) => self.error(format!("in \"{text}\": {message}")),
        }
    }

    /// Reads and converts one file; returns its root element.
    fn read(&mut self, path: &Path) -> Result<Rc<XElem>> {
        let text = crate::io::read_text(path)?;
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        let doc = crate::description::xml::parse_xml(&text, path)?;
        let root = convert(&doc, doc.root_element(), file, &mut self.namespaces);
        Ok(root)
    }

    /// Expands `children` in `scope`, appending to `out`; `xacro:attribute`s land in `attrs`.
    fn process(
        &mut self,
        children: &[XNode],
        scope: usize,
        out: &mut Vec<ONode>,
        attrs: &mut Vec<(String, String)>,
    ) -> Result<()> {
        for child in children {
            match child {
                XNode::Text(text) => {
                    if text.trim().is_empty() {
                        continue;
                    }
                    let value = self.eval_text(text, scope)?.to_string();
                    out.push(ONode::Text(value));
                }
                XNode::Elem(e) => {
                    self.at = (e.file, e.line);
                    match &e.xacro {
                        Some(local) => self.xacro_element(e, local, scope, out, attrs)?,
                        None => {
                            self.count_element()?;
                            let mut elem_attrs = Vec::with_capacity(e.attrs.len());
                            for (name, value) in &e.attrs {
                                elem_attrs.push((
                                    name.clone(),
                                    self.eval_text(value, scope)?.to_string(),
                                ));
                            }
                            let mut children = Vec::new();
                            let mut extra = Vec::new();
                            self.process(&e.children, scope, &mut children, &mut extra)?;
                            set_attrs(&mut elem_attrs, extra);
                            out.push(ONode::Elem(OElem {
                                name: e.name.clone(),
                                attrs: elem_attrs,
                                children,
                                file: e.file,
                                line: e.line,
                            }));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn count_element(&mut self) -> Result<()> {
        self.elements_out += 1;
        if self.elements_out > MAX_OUTPUT_ELEMENTS {
            return Err(self.error(format!(
                "the expansion grew past {MAX_OUTPUT_ELEMENTS} elements; runaway macro?"
            )));
        }
        Ok(())
    }

    fn attr<'e>(&self, e: &'e XElem, name: &str) -> Option<&'e str> {
        e.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    fn required<'e>(&self, e: &'e XElem, name: &str) -> Result<&'e str> {
        self.attr(e, name)
            .ok_or_else(|| self.error(format!("<{}> needs a {name}=\"...\" attribute", e.name)))
    }

    fn xacro_element(
        &mut self,
        e: &Rc<XElem>,
        local: &str,
        scope: usize,
        out: &mut Vec<ONode>,
        attrs: &mut Vec<(String, String)>,
    ) -> Result<()> {
        match local {
            "property" => self.define_property(e, scope),
            "arg" => {
                let name = self.required(e, "name")?.to_owned();
                if !self.args.contains_key(&name)
                    && !self.arg_defaults.contains_key(&name)
                    && let Some(default) = self.attr(e, "default")
                {
                    let value = self.eval_text(default, scope)?.to_string();
                    self.arg_defaults.insert(name, value);
                }
                Ok(())
            }
            "include" => self.include(e, scope, out),
            "if" | "unless" => {
                let text = self.required(e, "value")?;
                let value = self.eval_text(text, scope)?;
                let truth = self.boolean(&value, text)?;
                if truth == (local == "if") {
                    self.process(&e.children, scope, out, attrs)?;
                }
                Ok(())
            }
            "macro" => {
                let name = self.required(e, "name")?.to_owned();
                let params = self.parse_params(self.attr(e, "params").unwrap_or(""))?;
                let m = Macro {
                    name: name.clone(),
                    params,
                    body: Rc::clone(e),
                };
                self.scopes[scope].macros.insert(name, Rc::new(m));
                Ok(())
            }
            "insert_block" => {
                let name = self
                    .eval_text(self.required(e, "name")?, scope)?
                    .to_string();
                match self.lookup(&name, scope) {
                    Some((_, Prop::Block(nodes))) => {
                        out.extend(nodes);
                        Ok(())
                    }
                    Some(_) => Err(self.error(format!(
                        "xacro:insert_block name=\"{name}\": \"{name}\" is a value, not a block; blocks are *params of a macro or <xacro:property> with child elements"
                    ))),
                    None => Err(self.error(format!(
                        "xacro:insert_block name=\"{name}\": undefined block \"{name}\""
                    ))),
                }
            }
            "element" => self.computed_element(e, scope, out),
            "attribute" => {
                let name = self
                    .eval_text(self.required(e, "name")?, scope)?
                    .to_string();
                let value = self
                    .eval_text(self.required(e, "value")?, scope)?
                    .to_string();
                attrs.push((name, value));
                Ok(())
            }
            "call" => {
                let name = self
                    .eval_text(self.required(e, "macro")?, scope)?
                    .to_string();
                let m = self.find_macro(&name, scope)?;
                self.call_macro(&m, e, scope, out, &["macro"])
            }
            _ => {
                let m = self.find_macro(local, scope)?;
                self.call_macro(&m, e, scope, out, &[])
            }
        }
    }

    /// `<xacro:element xacro:name="...">`: an element whose name is computed, with the other
    /// attributes and the children expanded in `scope`, appended to `out`.
    fn computed_element(&mut self, e: &XElem, scope: usize, out: &mut Vec<ONode>) -> Result<()> {
        self.count_element()?;
        let name_text = self.required(e, "xacro:name")?;
        let name = self.eval_text(name_text, scope)?.to_string();
        let mut elem_attrs = Vec::new();
        for (n, v) in &e.attrs {
            if n != "xacro:name" {
                elem_attrs.push((n.clone(), self.eval_text(v, scope)?.to_string()));
            }
        }
        let mut children = Vec::new();
        let mut extra = Vec::new();
        self.process(&e.children, scope, &mut children, &mut extra)?;
        set_attrs(&mut elem_attrs, extra);
        out.push(ONode::Elem(OElem {
            name,
            attrs: elem_attrs,
            children,
            file: e.file,
            line: e.line,
        }));
        Ok(())
    }

    fn find_macro(&self, name: &str, scope: usize) -> Result<Rc<Macro>> {
        let mut s = Some(scope);
        while let Some(i) = s {
            if let Some(m) = self.scopes[i].macros.get(name) {
                return Ok(Rc::clone(m));
            }
            s = self.scopes[i].parent;
        }
        let mut known: Vec<&str> = Vec::new();
        let mut s = Some(scope);
        while let Some(i) = s {
            known.extend(self.scopes[i].macros.keys().map(String::as_str));
            s = self.scopes[i].parent;
        }
        known.sort_unstable();
        Err(self.error(format!(
            "unknown macro \"xacro:{name}\" (not a xacro element and no <xacro:macro name=\"{name}\"> defined before this line); macros defined: {}",
            if known.is_empty() {
                "(none)".to_owned()
            } else {
                known.join(", ")
            }
        )))
    }

    fn define_property(&mut self, e: &XElem, scope: usize) -> Result<()> {
        let name = self.required(e, "name")?.to_owned();
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_alphanumeric() || c == '_' || c == '.')
            || name.starts_with(|c: char| c.is_ascii_digit())
        {
            return Err(self.error(format!(
                "<xacro:property name=\"{name}\">: expected a name made of letters, digits and _"
            )));
        }
        let target = match self.attr(e, "scope") {
            None | Some("local") => scope,
            Some("parent") => self.scopes[scope].parent.unwrap_or(scope),
            Some("global") => 0,
            Some(other) => {
                return Err(self.error(format!(
                    "<xacro:property scope=\"{other}\">: expected local, parent or global"
                )));
            }
        };
        let lazy = match self.attr(e, "lazy_eval") {
            Some(text) => {
                let v = self.eval_text(text, scope)?;
                self.boolean(&v, text)?
            }
            None => true,
        };
        let prop = if let Some(value) = self.attr(e, "value") {
            if lazy && target == scope {
                Prop::Lazy(value.to_owned())
            } else {
                Prop::Value(literal(self.eval_text(value, scope)?))
            }
        } else if let Some(default) = self.attr(e, "default") {
            if self.lookup_exists(&name, scope) {
                return Ok(());
            }
            Prop::Lazy(default.to_owned())
        } else {
            let mut nodes = Vec::new();
            let mut extra = Vec::new();
            self.process(&e.children, scope, &mut nodes, &mut extra)?;
            // A block property's text-only content is a value (as in xacro).
            if nodes.iter().all(|n| matches!(n, ONode::Text(_))) && !nodes.is_empty() {
                let text: String = nodes
                    .iter()
                    .map(|n| match n {
                        ONode::Text(t) => t.as_str(),
                        ONode::Elem(_) => "",
                    })
                    .collect();
                Prop::Value(literal_value(text.trim()))
            } else {
                Prop::Block(nodes)
            }
        };
        self.scopes[target].props.insert(name, prop);
        Ok(())
    }

    fn include(&mut self, e: &XElem, scope: usize, out: &mut Vec<ONode>) -> Result<()> {
        let spec = self
            .eval_text(self.required(e, "filename")?, scope)?
            .to_string();
        let here = self.files[e.file]
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let path = if Path::new(&spec).is_absolute() {
            PathBuf::from(&spec)
        } else {
            here.join(&spec)
        };
        if !path.is_file() {
            return Err(self.error(format!(
                "xacro:include filename=\"{spec}\": no such file ({})",
                path.display()
            )));
        }
        let canonical = path.canonicalize().unwrap_or_else(|_| path.clone());
        let cycle_start = self.include_stack.iter().position(|&f| {
            self.files[f]
                .canonicalize()
                .unwrap_or_else(|_| self.files[f].clone())
                == canonical
        });
        if let Some(start) = cycle_start {
            let mut chain: Vec<String> = self.include_stack[start..]
                .iter()
                .map(|&f| self.files[f].display().to_string())
                .collect();
            chain.push(path.display().to_string());
            return Err(self.error(format!("include cycle: {}", chain.join(" -> "))));
        }
        let at = self.at;
        let root = self.read(&path)?;
        self.include_stack.push(root.file);
        let ns = self.attr(e, "ns").map(str::to_owned);
        let target = if ns.is_some() {
            self.scopes.push(Scope {
                parent: Some(scope),
                ..Default::default()
            });
            self.scopes.len() - 1
        } else {
            scope
        };
        let mut ignored = Vec::new();
        let result = self.process(&root.children, target, out, &mut ignored);
        self.include_stack.pop();
        result?;
        self.at = at;
        if let Some(ns) = ns {
            let inner = std::mem::take(&mut self.scopes[target]);
            self.scopes[target].parent = inner.parent;
            for (name, prop) in inner.props {
                // Keep lazy text evaluable: values move, lazy text is evaluated now.
                let prop = match prop {
                    Prop::Lazy(text) => Prop::Value(literal(self.eval_text(&text, scope)?)),
                    other => other,
                };
                self.scopes[scope]
                    .props
                    .insert(format!("{ns}.{name}"), prop);
            }
            for (name, m) in inner.macros {
                self.scopes[scope].macros.insert(format!("{ns}.{name}"), m);
            }
        }
        Ok(())
    }

    fn parse_params(&self, text: &str) -> Result<Vec<Param>> {
        let mut params = Vec::new();
        for token in split_params(text) {
            if let Some(name) = token.strip_prefix("**") {
                params.push(Param::BlockContents(name.to_owned()));
            } else if let Some(name) = token.strip_prefix('*') {
                params.push(Param::Block(name.to_owned()));
            } else {
                let (name, default) = match token.split_once(":=").or_else(|| token.split_once('='))
                {
                    Some((name, d)) => {
                        let d = unquote(d);
                        let default = if let Some(rest) = d.strip_prefix('^') {
                            ParamDefault::Inherit(rest.strip_prefix('|').map(str::to_owned))
                        } else {
                            ParamDefault::Text(d.to_owned())
                        };
                        (name, Some(default))
                    }
                    None => (token.as_str(), None),
                };
                if name.is_empty() {
                    return Err(
                        self.error(format!("macro params=\"{text}\": empty parameter name"))
                    );
                }
                params.push(Param::Plain {
                    name: name.to_owned(),
                    default,
                });
            }
        }
        Ok(params)
    }

    /// Calls macro `m` for the element `call` written in `scope`: binds the parameters in a new
    /// scope and expands the macro's body there into `out`. `skip_attrs` are attributes of
    /// `call` that are no parameters (`macro` of `xacro:call`).
    fn call_macro(
        &mut self,
        m: &Macro,
        call: &XElem,
        scope: usize,
        out: &mut Vec<ONode>,
        skip_attrs: &[&str],
    ) -> Result<()> {
        if self.macro_depth >= MAX_MACRO_DEPTH {
            return Err(self.error(format!(
                "macro calls nested deeper than {MAX_MACRO_DEPTH} (does xacro:{} call itself?)",
                m.name
            )));
        }
        let (file, line) = (call.file, call.line);
        let mut inner = Scope {
            parent: Some(scope),
            ..Default::default()
        };
        self.bind_attribute_params(m, call, scope, skip_attrs, &mut inner)?;
        // Blocks: the call's child elements, expanded in the caller's scope, in order.
        let mut body = Vec::new();
        let mut ignored = Vec::new();
        self.process(&call.children, scope, &mut body, &mut ignored)?;
        self.at = (file, line);
        let mut blocks = body.into_iter().filter_map(|n| match n {
            ONode::Elem(e) => Some(e),
            ONode::Text(_) => None,
        });
        self.bind_other_params(m, scope, &mut blocks, &mut inner)?;
        if let Some(extra) = blocks.next() {
            return Err(self.error(format!(
                "xacro:{}: unused block <{}> (the macro takes {} block parameter(s))",
                m.name,
                extra.name,
                m.params
                    .iter()
                    .filter(|p| !matches!(p, Param::Plain { .. }))
                    .count()
            )));
        }
        self.expand_macro_body(m, inner, out)?;
        self.at = (file, line);
        Ok(())
    }

    /// Binds the parameters that `call` passes as attributes (evaluated in the caller's
    /// `scope`) into `inner`; an attribute that names no plain parameter is an error.
    fn bind_attribute_params(
        &mut self,
        m: &Macro,
        call: &XElem,
        scope: usize,
        skip_attrs: &[&str],
        inner: &mut Scope,
    ) -> Result<()> {
        for (name, value) in &call.attrs {
            if skip_attrs.contains(&name.as_str()) {
                continue;
            }
            let known = m
                .params
                .iter()
                .any(|p| matches!(p, Param::Plain { name: n, .. } if n == name));
            if !known {
                return Err(self.error(format!(
                    "xacro:{}: unknown parameter \"{name}\"; its parameters: {}",
                    m.name,
                    param_names(&m.params)
                )));
            }
            let v = literal(self.eval_text(value, scope)?);
            inner.props.insert(name.clone(), Prop::Value(v));
        }
        Ok(())
    }

    /// Binds, in the macro's order, the block parameters to the call's next `blocks` and the
    /// plain parameters the call left out to their defaults.
    fn bind_other_params(
        &mut self,
        m: &Macro,
        scope: usize,
        blocks: &mut impl Iterator<Item = OElem>,
        inner: &mut Scope,
    ) -> Result<()> {
        for p in &m.params {
            match p {
                Param::Block(name) | Param::BlockContents(name) => {
                    let Some(block) = blocks.next() else {
                        return Err(self.error(format!(
                            "xacro:{}: not enough blocks: parameter *{name} needs a child element in the call",
                            m.name
                        )));
                    };
                    let nodes = if matches!(p, Param::Block(_)) {
                        vec![ONode::Elem(block)]
                    } else {
                        block.children
                    };
                    inner.props.insert(name.clone(), Prop::Block(nodes));
                }
                Param::Plain { name, default } => {
                    if inner.props.contains_key(name) {
                        continue;
                    }
                    let prop = self.param_default(m, name, default.as_ref(), scope)?;
                    inner.props.insert(name.clone(), prop);
                }
            }
        }
        Ok(())
    }

    /// The value of plain parameter `name` of `m` that the call written in `scope` left out:
    /// its default, the caller's property for `^`, or an error when there is neither.
    fn param_default(
        &mut self,
        m: &Macro,
        name: &str,
        default: Option<&ParamDefault>,
        scope: usize,
    ) -> Result<Prop> {
        Ok(match default {
            Some(ParamDefault::Text(text)) => Prop::Lazy(text.clone()),
            Some(ParamDefault::Inherit(fallback)) => match self.lookup(name, scope) {
                Some((_, Prop::Lazy(text))) => Prop::Value(literal(self.eval_text(&text, scope)?)),
                Some((_, prop)) => prop,
                None => match fallback {
                    Some(text) => Prop::Lazy(text.clone()),
                    None => {
                        return Err(self.error(format!(
                            "xacro:{}: parameter \"{name}\" inherits (^) a property the caller does not have",
                            m.name
                        )));
                    }
                },
            },
            None => {
                return Err(self.error(format!(
                    "xacro:{}: missing parameter \"{name}\"; its parameters: {}",
                    m.name,
                    param_names(&m.params)
                )));
            }
        })
    }

    /// Expands the body of `m` into `out` in the new scope `inner`, one macro level deeper.
    fn expand_macro_body(&mut self, m: &Macro, inner: Scope, out: &mut Vec<ONode>) -> Result<()> {
        self.scopes.push(inner);
        let inner_scope = self.scopes.len() - 1;
        self.macro_depth += 1;
        let mut attrs = Vec::new();
        let result = self.process(&m.body.children, inner_scope, out, &mut attrs);
        self.macro_depth -= 1;
        // Scopes of finished calls are kept only while something still refers to them; the
        // arena is trimmed back when nothing newer exists.
        if self.scopes.len() == inner_scope + 1 {
            self.scopes.pop();
        }
        result
    }

    fn lookup_exists(&self, name: &str, scope: usize) -> bool {
        let mut s = Some(scope);
        while let Some(i) = s {
            if self.scopes[i].props.contains_key(name) {
                return true;
            }
            s = self.scopes[i].parent;
        }
        false
    }

    /// A property and the scope holding it.
    fn lookup(&self, name: &str, scope: usize) -> Option<(usize, Prop)> {
        let mut s = Some(scope);
        while let Some(i) = s {
            if let Some(p) = self.scopes[i].props.get(name) {
                return Some((i, p.clone()));
            }
            s = self.scopes[i].parent;
        }
        None
    }

    /// The value of a property, evaluating lazy text in the scope that defined it.
    fn property_value(
        &mut self,
        name: &str,
        scope: usize,
    ) -> std::result::Result<Option<Value>, ExprError> {
        let Some((holder, prop)) = self.lookup(name, scope) else {
            return Ok(None);
        };
        match prop {
            Prop::Value(v) => Ok(Some(v)),
            Prop::Block(_) => Err(ExprError::Other(format!(
                "\"{name}\" is a block (of elements), not a value"
            ))),
            Prop::Lazy(text) => {
                if self
                    .evaluating
                    .iter()
                    .any(|(s, n)| *s == holder && n == name)
                {
                    return Err(ExprError::Other(format!(
                        "property \"{name}\" is defined in terms of itself"
                    )));
                }
                self.evaluating.push((holder, name.to_owned()));
                let result = self.eval_text_inner(&text, holder);
                self.evaluating.pop();
                let value = literal(result?);
                self.scopes[holder]
                    .props
                    .insert(name.to_owned(), Prop::Value(value.clone()));
                Ok(Some(value))
            }
        }
    }

    fn boolean(&self, value: &Value, text: &str) -> Result<bool> {
        match value {
            Value::Bool(b) => Ok(*b),
            Value::Int(i) => Ok(*i != 0),
            Value::Float(x) => Ok(*x != 0.0),
            Value::Str(s) => match s.trim() {
                "true" | "True" => Ok(true),
                "false" | "False" => Ok(false),
                other => other.parse::<i64>().map(|i| i != 0).map_err(|_| {
                    self.error(format!(
                        "condition \"{text}\" evaluated to \"{other}\", which is not a boolean (expected true, false, 1 or 0)"
                    ))
                }),
            },
            other => Err(self.error(format!(
                "condition \"{text}\" evaluated to \"{other}\", which is not a boolean"
            ))),
        }
    }

    fn eval_text(&mut self, text: &str, scope: usize) -> Result<Value> {
        self.eval_text_inner(text, scope)
            .map_err(|e| self.expr_error(text, e))
    }

    /// Evaluates `${...}` and `$(...)` in `text`. A text that is exactly one `${}` keeps the
    /// expression's type.
    fn eval_text_inner(
        &mut self,
        text: &str,
        scope: usize,
    ) -> std::result::Result<Value, ExprError> {
        if !text.contains('$') {
            return Ok(Value::Str(text.to_owned()));
        }
        let mut parts: Vec<Value> = Vec::new();
        let mut literal_buf = String::new();
        let mut rest = text;
        while let Some(pos) = rest.find('$') {
            literal_buf.push_str(&rest[..pos]);
            let after = &rest[pos + 1..];
            if let Some(stripped) = after
                .strip_prefix("${")
                .or_else(|| after.strip_prefix("$("))
            {
                // `$${` and `$$(` escape to a literal `${` / `$(`.
                literal_buf.push('$');
                literal_buf.push_str(&after[..1]);
                rest = stripped;
            } else if let Some(body) = after.strip_prefix('{') {
                let end = matching(body, '{', '}')
                    .ok_or_else(|| ExprError::Other("unterminated ${".into()))?;
                if !literal_buf.is_empty() {
                    parts.push(Value::Str(std::mem::take(&mut literal_buf)));
                }
                let mut names = Lookup { ex: self, scope };
                parts.push(rover_pyexpr::evaluate(&body[..end], &mut names)?);
                rest = &body[end + 1..];
            } else if let Some(body) = after.strip_prefix('(') {
                let end = matching(body, '(', ')')
                    .ok_or_else(|| ExprError::Other("unterminated $(".into()))?;
                let inner = self.eval_text_inner(&body[..end], scope)?.to_string();
                literal_buf.push_str(&self.substitution(&inner, scope)?);
                rest = &body[end + 1..];
            } else {
                literal_buf.push('$');
                rest = after;
            }
        }
        literal_buf.push_str(rest);
        if !literal_buf.is_empty() {
            parts.push(Value::Str(literal_buf));
        }
        Ok(match parts.len() {
            0 => Value::Str(String::new()),
            1 => parts.pop().unwrap_or(Value::None),
            _ => Value::Str(parts.iter().map(Value::to_string).collect()),
        })
    }

    fn arg_value(&self, name: &str) -> std::result::Result<String, ExprError> {
        self.args
            .get(name)
            .or_else(|| self.arg_defaults.get(name))
            .cloned()
            .ok_or_else(|| {
                ExprError::Other(format!(
                    "undefined arg \"{name}\": declare <xacro:arg name=\"{name}\" default=\"...\"/> or pass --xacro-arg {name}:=VALUE"
                ))
            })
    }

    /// `$(command args)`.
    fn substitution(
        &mut self,
        inner: &str,
        scope: usize,
    ) -> std::result::Result<String, ExprError> {
        let inner = inner.trim();
        let (command, rest) = inner.split_once(char::is_whitespace).unwrap_or((inner, ""));
        let rest = rest.trim();
        let here = self.files[self.at.0]
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        match command {
            "find" => self
                .resources
                .find_package(rest, &here)
                .map(|p| p.display().to_string())
                .map_err(|e| ExprError::Other(format!("$(find {rest}): {e}"))),
            "arg" => self.arg_value(rest),
            "env" => std::env::var(rest).map_err(|_| {
                ExprError::Other(format!(
                    "$(env {rest}): environment variable {rest} is not set (use $(optenv {rest} default) for a fallback)"
                ))
            }),
            "optenv" => {
                let (var, default) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
                Ok(std::env::var(var).unwrap_or_else(|_| default.trim().to_owned()))
            }
            "dirname" => Ok(here.display().to_string()),
            "eval" => {
                let mut names = Lookup { ex: self, scope };
                Ok(rover_pyexpr::evaluate(rest, &mut names)?.to_string())
            }
            _ => Err(ExprError::Other(format!(
                "unsupported substitution $({command} ...); expected find, arg, env, optenv, eval or dirname"
            ))),
        }
    }
}

struct Lookup<'a, 'b> {
    ex: &'a mut Expander<'b>,
    scope: usize,
}

impl Host for Lookup<'_, '_> {
    fn name(&mut self, name: &str) -> std::result::Result<Option<Value>, ExprError> {
        self.ex.property_value(name, self.scope)
    }

    /// `arg('name')`, as `$(eval ...)` offers it.
    fn call(
        &mut self,
        name: &str,
        args: &[Value],
    ) -> std::result::Result<Option<Value>, ExprError> {
        match (name, args) {
            ("arg" | "xacro.arg", [Value::Str(arg)]) => {
                Ok(Some(Value::Str(self.ex.arg_value(arg)?)))
            }
            ("arg" | "xacro.arg", _) => Err(ExprError::Other(
                "arg() expects one string, the arg's name".into(),
            )),
            _ => Ok(None),
        }
    }
}

/// How xacro reads a property's text: an int, else a float, else a boolean word, else the text
/// itself (`'quoted'` text loses its quotes; text with `_` stays text).
fn literal_value(text: &str) -> Value {
    if text.len() >= 2 && text.starts_with('\'') && text.ends_with('\'') {
        return Value::Str(text[1..text.len() - 1].to_owned());
    }
    if text.contains('_') {
        return Value::Str(text.to_owned());
    }
    if let Some(i) = rover_pyexpr::parse_int(text) {
        return Value::Int(i);
    }
    if let Some(x) = rover_pyexpr::parse_float(text) {
        return Value::Float(x);
    }
    match text {
        "true" | "True" => Value::Bool(true),
        "false" | "False" => Value::Bool(false),
        _ => Value::Str(text.to_owned()),
    }
}

/// Values given as text become numbers or booleans where they read as one (xacro's rule).
fn literal(v: Value) -> Value {
    match v {
        Value::Str(s) => literal_value(&s),
        other => other,
    }
}

/// Index of the bracket closing an opening one just before `s`, honouring nesting and quotes.
fn matching(s: &str, open: char, close: char) -> Option<usize> {
    let mut depth = 0usize;
    let mut quote: Option<char> = None;
    for (i, c) in s.char_indices() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '\'' || c == '"' => quote = Some(c),
            None if c == open => depth += 1,
            None if c == close => {
                if depth == 0 {
                    return Some(i);
                }
                depth -= 1;
            }
            None => {}
        }
    }
    None
}

/// Splits a macro's `params` on whitespace, keeping quoted defaults whole.
fn split_params(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current = String::new();
    let mut quote: Option<char> = None;
    for c in text.chars() {
        match quote {
            Some(q) => {
                current.push(c);
                if c == q {
                    quote = None;
                }
            }
            None if c.is_whitespace() => {
                if !current.is_empty() {
                    out.push(std::mem::take(&mut current));
                }
            }
            None => {
                if c == '\'' || c == '"' {
                    quote = Some(c);
                }
                current.push(c);
            }
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

fn unquote(s: &str) -> &str {
    for q in ['\'', '"'] {
        if s.len() >= 2 && s.starts_with(q) && s.ends_with(q) {
            return &s[1..s.len() - 1];
        }
    }
    s
}

fn param_names(params: &[Param]) -> String {
    let names: Vec<String> = params
        .iter()
        .map(|p| match p {
            Param::Plain { name, .. } => name.clone(),
            Param::Block(name) => format!("*{name}"),
            Param::BlockContents(name) => format!("**{name}"),
        })
        .collect();
    if names.is_empty() {
        "(none)".to_owned()
    } else {
        names.join(", ")
    }
}

/// `xacro:attribute`s override attributes of the same name.
fn set_attrs(attrs: &mut Vec<(String, String)>, extra: Vec<(String, String)>) {
    for (name, value) in extra {
        match attrs.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = value,
            None => attrs.push((name, value)),
        }
    }
}

fn is_xacro_ns(uri: Option<&str>) -> bool {
    uri.is_some_and(|u| XACRO_NAMESPACES.contains(&u))
}

fn convert(
    doc: &roxmltree::Document<'_>,
    node: roxmltree::Node<'_, '_>,
    file: usize,
    namespaces: &mut BTreeMap<String, String>,
) -> Rc<XElem> {
    let tag = node.tag_name();
    let xacro = is_xacro_ns(tag.namespace()).then(|| tag.name().to_owned());
    let qualify =
        |ns: Option<&str>, local: &str, namespaces: &mut BTreeMap<String, String>| match ns {
            Some(uri) if is_xacro_ns(Some(uri)) => format!("xacro:{local}"),
            Some(uri) => match node.lookup_prefix(uri) {
                Some(prefix) if !prefix.is_empty() => {
                    namespaces.insert(prefix.to_owned(), uri.to_owned());
                    format!("{prefix}:{local}")
                }
                _ => local.to_owned(),
            },
            None => local.to_owned(),
        };
    let name = qualify(tag.namespace(), tag.name(), namespaces);
    let attrs = node
        .attributes()
        .map(|a| {
            (
                qualify(a.namespace(), a.name(), namespaces),
                a.value().to_owned(),
            )
        })
        .collect();
    let mut children = Vec::new();
    for child in node.children() {
        if child.is_element() {
            children.push(XNode::Elem(convert(doc, child, file, namespaces)));
        } else if child.is_text()
            && let Some(text) = child.text()
        {
            children.push(XNode::Text(text.to_owned()));
        }
    }
    Rc::new(XElem {
        name,
        xacro,
        attrs,
        children,
        file,
        line: doc.text_pos_at(node.range().start).row,
    })
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

/// Writes an element starting on a new line, recording the source of every line written.
fn write_element(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_read_like_xacro() {
        assert_eq!(literal_value("3"), Value::Int(3));
        assert_eq!(literal_value("0.5"), Value::Float(0.5));
        assert_eq!(literal_value("true"), Value::Bool(true));
        assert_eq!(literal_value("1_000"), Value::Str("1_000".into()));
        assert_eq!(literal_value("'0.5'"), Value::Str("0.5".into()));
        assert_eq!(literal_value("base_link"), Value::Str("base_link".into()));
        assert_eq!(literal_value("infinity"), Value::Float(f64::INFINITY));
        assert_eq!(literal_value("1 2"), Value::Str("1 2".into()));
    }

    fn expand(files: &[(&str, &str)], args: &[(&str, &str)]) -> Result<String> {
        let dir = tempfile::tempdir().map_err(|source| SimError::Io {
            path: PathBuf::from("tempdir"),
            source,
        })?;
        for (name, text) in files {
            let p = dir.path().join(name);
            if let Some(parent) = p.parent() {
                let _ = std::fs::create_dir_all(parent);
            }
            std::fs::write(&p, text).map_err(|source| SimError::Io {
                path: p.clone(),
                source,
            })?;
        }
        let args = args
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect();
        let out = expand_file(
            &dir.path().join(files[0].0),
            &args,
            &ResourcePaths::default(),
        )?;
        Ok(out.text)
    }

    const HEAD: &str = r#"<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">"#;

    #[test]
    fn properties_macros_blocks_and_conditions() -> Result<()> {
        let text = format!(
            r#"{HEAD}
  <xacro:property name="r" value="0.033"/>
  <xacro:property name="d" value="${{2*r}}"/>
  <xacro:arg name="use_cam" default="true"/>
  <xacro:macro name="wheel" params="side reflect:=1 *origin **extra">
    <link name="${{side}}_wheel"><inertial><mass value="${{d*reflect}}"/></inertial></link>
    <joint name="${{side}}_joint" type="continuous"><xacro:insert_block name="origin"/></joint>
    <gazebo reference="${{side}}_wheel"><xacro:insert_block name="extra"/></gazebo>
  </xacro:macro>
  <xacro:wheel side="left">
    <origin xyz="0 ${{d}} 0"/>
    <gz><mu1>0.5</mu1></gz>
  </xacro:wheel>
  <xacro:wheel side="right" reflect="-1">
    <origin xyz="0 -${{d}} 0"/>
    <gz/>
  </xacro:wheel>
  <xacro:if value="$(arg use_cam)"><link name="camera"/></xacro:if>
  <xacro:unless value="${{r > 1}}"><link name="small"/></xacro:unless>
  <gazebo><wheelDiameter>${{d}}</wheelDiameter></gazebo>
</robot>"#
        );
        let out = expand(&[("r.urdf.xacro", &text)], &[])?;
        assert!(out.contains(r#"<link name="left_wheel">"#), "{out}");
        assert!(out.contains(r#"<mass value="0.066"/>"#), "{out}");
        assert!(out.contains(r#"<mass value="-0.066"/>"#), "{out}");
        assert!(out.contains(r#"<origin xyz="0 -0.066 0"/>"#), "{out}");
        assert!(out.contains("<mu1>0.5</mu1>"), "{out}");
        assert!(out.contains(r#"<link name="camera"/>"#), "{out}");
        assert!(out.contains(r#"<link name="small"/>"#), "{out}");
        assert!(
            out.contains("<wheelDiameter>0.066</wheelDiameter>"),
            "{out}"
        );
        assert!(!out.contains("xacro"), "{out}");
        let off = expand(&[("r.urdf.xacro", &text)], &[("use_cam", "false")])?;
        assert!(!off.contains("camera"), "{off}");
        Ok(())
    }

    #[test]
    fn includes_with_namespace_and_relative_paths() -> Result<()> {
        let main = format!(
            r#"{HEAD}
  <xacro:include filename="parts/common.xacro"/>
  <xacro:include filename="parts/common.xacro" ns="c"/>
  <link name="${{base}}"/><link name="${{c.base}}_2"/>
  <xacro:box_link name="b"/><xacro:c.box_link name="b2"/>
</robot>"#
        );
        let common = format!(
            r#"{HEAD}<xacro:property name="base" value="base_link"/>
<xacro:macro name="box_link" params="name"><link name="${{name}}"/></xacro:macro></robot>"#
        );
        let out = expand(
            &[("main.xacro", &main), ("parts/common.xacro", &common)],
            &[],
        )?;
        for name in ["base_link", "base_link_2", "b", "b2"] {
            assert!(out.contains(&format!(r#"<link name="{name}"/>"#)), "{out}");
        }
        Ok(())
    }

    fn message(result: Result<String>) -> String {
        match result {
            Ok(text) => format!("unexpectedly expanded: {text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn errors_name_file_line_and_what_is_undefined() {
        let undefined = format!("{HEAD}\n<link name=\"${{nope}}\"/></robot>");
        let m = message(expand(&[("a.xacro", &undefined)], &[]));
        assert!(
            m.contains("a.xacro:2") && m.contains("undefined property \"nope\""),
            "{m}"
        );

        let no_macro = format!("{HEAD}\n\n<xacro:wheel side=\"l\"/></robot>");
        let m = message(expand(&[("a.xacro", &no_macro)], &[]));
        assert!(
            m.contains("a.xacro:3") && m.contains("unknown macro \"xacro:wheel\""),
            "{m}"
        );

        let no_arg = format!("{HEAD}\n<link name=\"$(arg robot)\"/></robot>");
        let m = message(expand(&[("a.xacro", &no_arg)], &[]));
        assert!(
            m.contains("undefined arg \"robot\"") && m.contains("--xacro-arg"),
            "{m}"
        );

        let cycle_a = format!("{HEAD}<xacro:include filename=\"b.xacro\"/></robot>");
        let cycle_b = format!("{HEAD}\n<xacro:include filename=\"a.xacro\"/></robot>");
        let m = message(expand(&[("a.xacro", &cycle_a), ("b.xacro", &cycle_b)], &[]));
        assert!(
            m.contains("include cycle") && m.contains("b.xacro:2"),
            "{m}"
        );

        let recursive = format!(
            "{HEAD}<xacro:macro name=\"m\" params=\"\"><xacro:m/></xacro:macro><xacro:m/></robot>"
        );
        let m = message(expand(&[("a.xacro", &recursive)], &[]));
        assert!(m.contains("nested deeper"), "{m}");

        let selfref = format!(
            "{HEAD}<xacro:property name=\"a\" value=\"${{a+1}}\"/><link name=\"${{a}}\"/></robot>"
        );
        let m = message(expand(&[("a.xacro", &selfref)], &[]));
        assert!(m.contains("in terms of itself"), "{m}");

        let missing =
            format!("{HEAD}<xacro:macro name=\"m\" params=\"x\"/>\n<xacro:m y=\"1\"/></robot>");
        let m = message(expand(&[("a.xacro", &missing)], &[]));
        assert!(
            m.contains("unknown parameter \"y\"") && m.contains("a.xacro:2"),
            "{m}"
        );
    }

    #[test]
    fn output_lines_map_back_to_sources() -> Result<()> {
        let dir = tempfile::tempdir().map_err(|source| SimError::Io {
            path: PathBuf::from("tempdir"),
            source,
        })?;
        let p = dir.path().join("m.xacro");
        let text = format!(
            "{HEAD}\n<xacro:macro name=\"l\" params=\"n\">\n<link name=\"${{n}}\"/>\n</xacro:macro>\n<xacro:l n=\"a\"/>\n</robot>"
        );
        std::fs::write(&p, text).map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
        let out = expand_file(&p, &BTreeMap::new(), &ResourcePaths::default())?;
        let line = out
            .text
            .lines()
            .position(|l| l.contains("<link name=\"a\"/>"))
            .ok_or_else(|| SimError::Setup("link missing".into()))?;
        let loc = out
            .source_of(line as u32 + 1)
            .ok_or_else(|| SimError::Setup("no source".into()))?;
        assert_eq!(loc.line, Some(3));
        Ok(())
    }
}
