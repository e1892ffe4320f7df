//! Properties and args: definition, scope lookup, lazy evaluation, the name host that
//! expressions resolve names through, and how xacro reads literal text.

use rover_pyexpr::{ExprError, Host, Value};

use super::expander::{Expander, ONode, Prop, XElem};
use crate::error::Result;

impl Expander<'_> {
    pub(super) fn define_property(&mut self, e: &XElem, scope: usize) -> Result<()> {
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
    pub(super) fn lookup(&self, name: &str, scope: usize) -> Option<(usize, Prop)> {
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

    pub(super) fn arg_value(&self, name: &str) -> std::result::Result<String, ExprError> {
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
}

pub(super) struct Lookup<'a, 'b> {
    pub(super) ex: &'a mut Expander<'b>,
    pub(super) scope: usize,
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
pub(super) fn literal_value(text: &str) -> Value {
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
pub(super) fn literal(v: Value) -> Value {
    match v {
        Value::Str(s) => literal_value(&s),
        other => other,
    }
}
