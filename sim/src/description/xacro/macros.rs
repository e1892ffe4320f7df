//! Macros: finding them, parsing their params, and calling them (binding plain, default,
//! inherited and block parameters, then expanding the body).

use std::rc::Rc;

use super::expander::{Expander, Macro, OElem, ONode, Param, ParamDefault, Prop, Scope, XElem};
use super::properties::literal;
use crate::error::Result;

/// Deepest macro call nesting accepted (a macro that calls itself without end stops here).
const MAX_MACRO_DEPTH: usize = 100;

impl Expander<'_> {
    pub(super) fn find_macro(&self, name: &str, scope: usize) -> Result<Rc<Macro>> {
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

    pub(super) fn parse_params(&self, text: &str) -> Result<Vec<Param>> {
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
    pub(super) fn call_macro(
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
