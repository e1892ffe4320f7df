//! The expander's state and the types it works on (input and output elements, scopes,
//! properties, macros), with the error helpers every part of the expansion shares.

use std::collections::{BTreeMap, HashMap};
use std::path::PathBuf;
use std::rc::Rc;

use rover_pyexpr::{ExprError, Value};

use crate::description::resource::ResourcePaths;
use crate::error::{Location, Result, SimError};

/// The xacro namespace URIs in use (the wiki moved from ros.org to www.ros.org).
pub(super) const XACRO_NAMESPACES: [&str; 2] =
    ["http://ros.org/wiki/xacro", "http://www.ros.org/wiki/xacro"];

/// An input element, owned so that macros can keep their bodies.
#[derive(Debug)]
pub(super) struct XElem {
    /// Qualified name as written (`link`, `sensor`, `gazebo:plugin`).
    pub(super) name: String,
    /// The local name when the element is in the xacro namespace.
    pub(super) xacro: Option<String>,
    pub(super) attrs: Vec<(String, String)>,
    pub(super) children: Vec<XNode>,
    pub(super) file: usize,
    pub(super) line: u32,
}

#[derive(Debug)]
pub(super) enum XNode {
    Elem(Rc<XElem>),
    Text(String),
}

/// An output element.
#[derive(Debug, Clone)]
pub(super) struct OElem {
    pub(super) name: String,
    pub(super) attrs: Vec<(String, String)>,
    pub(super) children: Vec<ONode>,
    pub(super) file: usize,
    pub(super) line: u32,
}

#[derive(Debug, Clone)]
pub(super) enum ONode {
    Elem(OElem),
    Text(String),
}

#[derive(Debug, Clone)]
pub(super) enum Prop {
    /// Text not yet evaluated (xacro evaluates properties on first use).
    Lazy(String),
    Value(Value),
    Block(Vec<ONode>),
}

#[derive(Debug, Default)]
pub(super) struct Scope {
    pub(super) parent: Option<usize>,
    pub(super) props: HashMap<String, Prop>,
    pub(super) macros: HashMap<String, Rc<Macro>>,
}

#[derive(Debug)]
pub(super) enum Param {
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
pub(super) enum ParamDefault {
    Text(String),
    /// `^` or `^|fallback`: the caller's property of the same name.
    Inherit(Option<String>),
}

#[derive(Debug)]
pub(super) struct Macro {
    pub(super) name: String,
    pub(super) params: Vec<Param>,
    pub(super) body: Rc<XElem>,
}

pub(super) struct Expander<'a> {
    pub(super) resources: &'a ResourcePaths,
    pub(super) args: BTreeMap<String, String>,
    pub(super) arg_defaults: BTreeMap<String, String>,
    pub(super) files: Vec<PathBuf>,
    pub(super) include_stack: Vec<usize>,
    pub(super) scopes: Vec<Scope>,
    /// Namespace prefixes of non-xacro elements, declared on the output's root.
    pub(super) namespaces: BTreeMap<String, String>,
    /// Lazy properties being evaluated, to report self-reference instead of overflowing.
    pub(super) evaluating: Vec<(usize, String)>,
    pub(super) macro_depth: usize,
    pub(super) elements_out: usize,
    /// File and line of the element being expanded, for messages.
    pub(super) at: (usize, u32),
}

impl Expander<'_> {
    pub(super) fn error(&self, message: impl Into<String>) -> SimError {
        SimError::Invalid {
            location: Location::new(&self.files[self.at.0], Some(self.at.1)),
            message: message.into(),
        }
    }

    pub(super) fn expr_error(&self, text: &str, e: ExprError) -> SimError {
        match e {
            ExprError::Undefined(name) => {
                self.error(format!("in \"{text}\": undefined property \"{name}\""))
            }
            ExprError::Other(message) => self.error(format!("in \"{text}\": {message}")),
        }
    }

    pub(super) fn attr<'e>(&self, e: &'e XElem, name: &str) -> Option<&'e str> {
        e.attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    pub(super) fn required<'e>(&self, e: &'e XElem, name: &str) -> Result<&'e str> {
        self.attr(e, name)
            .ok_or_else(|| self.error(format!("<{}> needs a {name}=\"...\" attribute", e.name)))
    }

    pub(super) fn boolean(&self, value: &Value, text: &str) -> Result<bool> {
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
}
