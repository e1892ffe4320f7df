//! Substitution in attribute and text values: `${...}` expressions (through rover_pyexpr)
//! and `$(...)` substitution args.

use std::path::Path;

use rover_pyexpr::{ExprError, Value};

use super::expander::Expander;
use super::properties::Lookup;
use crate::error::Result;

impl Expander<'_> {
    pub(super) fn eval_text(&mut self, text: &str, scope: usize) -> Result<Value> {
        self.eval_text_inner(text, scope)
            .map_err(|e| self.expr_error(text, e))
    }

    /// Evaluates `${...}` and `$(...)` in `text`. A text that is exactly one `${}` keeps the
    /// expression's type.
    pub(super) fn eval_text_inner(
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
