//! What an expression's host adds ([`Host`]) and what goes wrong ([`ExprError`]).

use std::fmt;

use crate::Value;

/// Why an expression could not be evaluated.
#[derive(Debug, Clone, PartialEq)]
pub enum ExprError {
    /// A name that is no host name, constant or function.
    Undefined(String),
    /// Anything else: syntax, types, domain.
    Other(String),
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExprError::Undefined(name) => write!(f, "name \"{name}\" is not defined"),
            ExprError::Other(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for ExprError {}

/// Results of the evaluator.
pub(crate) type R<T> = Result<T, ExprError>;

/// An [`ExprError::Other`] saying `message`.
pub(crate) fn err<T>(message: impl Into<String>) -> R<T> {
    Err(ExprError::Other(message.into()))
}

/// What the file an expression is in adds to the language.
pub trait Host {
    /// The value of the bare or dotted name `name`, or `Ok(None)` when the host has none by
    /// that name (the `math` constants are tried next, then it is undefined).
    fn name(&mut self, name: &str) -> Result<Option<Value>, ExprError>;

    /// Calls the host's function `name` (as written: `arg`, `xacro.arg`) on `args`, or returns
    /// `Ok(None)` when the host has no function by that name (Python's builtins are tried next).
    fn call(&mut self, name: &str, args: &[Value]) -> Result<Option<Value>, ExprError>;
}
