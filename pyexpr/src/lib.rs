//! The Python expressions of robot description and launch files: xacro's `${...}` and
//! roslaunch's `$(eval ...)`. One evaluator for both; each host adds its own names and
//! functions through [`Host`] (xacro: properties and `arg()`; roslaunch: args, `find()`,
//! `anon()`, `env()`, ...).
//!
//! The language: int, float, string, bool, `None` and list literals (tuples read as lists),
//! names and dotted names (`math.pi`), calls, subscripts, arithmetic (`+ - * / // % **`),
//! comparison chains, `in`/`not in`, `and`/`or`/`not`, `a if c else b`; Python's `math`
//! functions and constants and its conversions (`int`, `float`, `str`, `bool`, `len`, `abs`,
//! `round`, `min`, `max`). Values follow Python 3 (`/` is true division, `//` floors, `%` takes
//! the divisor's sign) and print as Python's `str()` prints them, so expanded files match the
//! reference tools' output byte for byte.
//!
//! Written in-tree: no Rust crate evaluates this subset of Python with Python's result types
//! (the only Rust xacro crate drops element text, docs/ROBOTS.md); it is small, fuzzed
//! (`tests/src/fuzz.rs`) and checked against ROS's own xacro and roslaunch.

mod builtins;
mod compare;
mod eval;
mod host;
mod lex;
mod parse;
mod value;

pub use host::{ExprError, Host};
pub use value::{Value, float_repr, parse_float, parse_int};

use host::err;

/// Parses and evaluates `src`, names and host functions from `host`.
pub fn evaluate(src: &str, host: &mut dyn Host) -> Result<Value, ExprError> {
    let tokens = lex::tokenize(src)?;
    if tokens.is_empty() {
        return err("empty expression");
    }
    let mut parser = parse::Parser {
        tokens,
        pos: 0,
        depth: 0,
    };
    let expr = parser.expr()?;
    if parser.pos != parser.tokens.len() {
        return err(format!(
            "unexpected {} after the expression",
            parser.tokens[parser.pos].describe()
        ));
    }
    eval::eval(&expr, host)
}

#[cfg(test)]
mod tests;
