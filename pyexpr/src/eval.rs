//! The evaluator: walks the tree with Python's semantics for each operator.

use crate::Value;
use crate::builtins::call;
use crate::compare::compare;
use crate::host::{ExprError, Host, R, err};
use crate::parse::Expr;

/// Longest string an expression may build (`'x' * 10**9` is refused, not allocated).
const MAX_STR: usize = 1 << 20;

/// The value of `e`, names and host functions from `host`.
pub(crate) fn eval(e: &Expr, host: &mut dyn Host) -> R<Value> {
    match e {
        Expr::Const(v) => Ok(v.clone()),
        Expr::Name(name) => {
            if let Some(v) = host.name(name)? {
                return Ok(v);
            }
            constant(name).ok_or_else(|| ExprError::Undefined(name.clone()))
        }
        Expr::Unary(op, inner) => {
            let v = eval(inner, host)?;
            match (*op, &v) {
                ("-", Value::Int(i)) => i
                    .checked_neg()
                    .map(Value::Int)
                    .ok_or_else(|| ExprError::Other("integer overflow".into())),
                ("-", Value::Bool(b)) => Ok(Value::Int(-i64::from(*b))),
                ("-", Value::Float(x)) => Ok(Value::Float(-x)),
                ("+", Value::Int(_) | Value::Float(_)) => Ok(v),
                ("+", Value::Bool(b)) => Ok(Value::Int(i64::from(*b))),
                _ => err(format!(
                    "bad operand type for unary {op}: '{}'",
                    v.type_name()
                )),
            }
        }
        Expr::Binary(op, a, b) => binary(op, eval(a, host)?, eval(b, host)?),
        Expr::Compare(first, rest) => {
            let mut left = eval(first, host)?;
            for (op, right) in rest {
                let right = eval(right, host)?;
                if !compare(op, &left, &right)? {
                    return Ok(Value::Bool(false));
                }
                left = right;
            }
            Ok(Value::Bool(true))
        }
        Expr::And(a, b) => {
            let left = eval(a, host)?;
            if left.truthy() {
                eval(b, host)
            } else {
                Ok(left)
            }
        }
        Expr::Or(a, b) => {
            let left = eval(a, host)?;
            if left.truthy() {
                Ok(left)
            } else {
                eval(b, host)
            }
        }
        Expr::Not(inner) => Ok(Value::Bool(!eval(inner, host)?.truthy())),
        Expr::IfElse {
            then,
            cond,
            otherwise,
        } => {
            if eval(cond, host)?.truthy() {
                eval(then, host)
            } else {
                eval(otherwise, host)
            }
        }
        Expr::List(items) => Ok(Value::List(
            items.iter().map(|i| eval(i, host)).collect::<R<Vec<_>>>()?,
        )),
        Expr::Index(target, index) => subscript(eval(target, host)?, &eval(index, host)?),
        Expr::Call(name, args) => {
            let values = args.iter().map(|a| eval(a, host)).collect::<R<Vec<_>>>()?;
            match host.call(name, &values)? {
                Some(v) => Ok(v),
                None => call(name, values),
            }
        }
    }
}

/// The `math` module's constants (`pi`, `math.pi`, `e`, `tau`, `inf`, `nan`).
fn constant(name: &str) -> Option<Value> {
    let bare = name.strip_prefix("math.").unwrap_or(name);
    Some(Value::Float(match bare {
        "pi" => std::f64::consts::PI,
        "e" => std::f64::consts::E,
        "tau" => std::f64::consts::TAU,
        "inf" => f64::INFINITY,
        "nan" => f64::NAN,
        _ => return None,
    }))
}

/// `target[index]` on a list or a string, negative indices counting from the end.
fn subscript(target: Value, index: &Value) -> R<Value> {
    let Some(i) = index.int() else {
        return err(format!(
            "indices must be integers, not {}",
            index.type_name()
        ));
    };
    let pick = |len: usize| -> R<usize> {
        let len = len as i64;
        let j = if i < 0 { i + len } else { i };
        if (0..len).contains(&j) {
            Ok(j as usize)
        } else {
            err(format!("index {i} out of range"))
        }
    };
    match target {
        Value::List(items) => Ok(items[pick(items.len())?].clone()),
        Value::Str(s) => {
            let chars: Vec<char> = s.chars().collect();
            Ok(Value::Str(chars[pick(chars.len())?].to_string()))
        }
        other => err(format!(
            "'{}' object is not subscriptable",
            other.type_name()
        )),
    }
}

fn binary(op: &str, a: Value, b: Value) -> R<Value> {
    use Value::{Float, Int, List, Str};
    match (op, &a, &b) {
        ("+", Str(x), Str(y)) => {
            if x.len() + y.len() > MAX_STR {
                return err("the string grows too long");
            }
            return Ok(Str(format!("{x}{y}")));
        }
        ("+", List(x), List(y)) => return Ok(List([x.clone(), y.clone()].concat())),
        ("*", Str(s), n) | ("*", n, Str(s)) if n.int().is_some() => {
            let count = usize::try_from(n.int().unwrap_or(0).max(0)).unwrap_or(usize::MAX);
            if s.len().saturating_mul(count) > MAX_STR {
                return err("the string grows too long");
            }
            return Ok(Str(s.repeat(count)));
        }
        _ => {}
    }
    let type_error = || {
        err(format!(
            "unsupported operand types for {op}: '{}' and '{}'",
            a.type_name(),
            b.type_name()
        ))
    };
    if let (Some(x), Some(y)) = (a.int(), b.int()) {
        let overflow = || ExprError::Other("integer overflow".into());
        return match op {
            "+" => x.checked_add(y).map(Int).ok_or_else(overflow),
            "-" => x.checked_sub(y).map(Int).ok_or_else(overflow),
            "*" => x.checked_mul(y).map(Int).ok_or_else(overflow),
            "/" if y == 0 => err("division by zero"),
            "/" => Ok(Float(x as f64 / y as f64)),
            "//" | "%" if y == 0 => err("integer division or modulo by zero"),
            "//" => Ok(Int(
                x.div_euclid(y) - i64::from(y < 0 && x.rem_euclid(y) != 0)
            )),
            "%" => {
                let r = x.rem_euclid(y);
                Ok(Int(if y < 0 && r != 0 { r + y } else { r }))
            }
            "**" if y >= 0 => u32::try_from(y)
                .ok()
                .and_then(|e| x.checked_pow(e))
                .map(Int)
                .ok_or_else(overflow),
            "**" => Ok(Float((x as f64).powf(y as f64))),
            _ => type_error(),
        };
    }
    let (Some(x), Some(y)) = (a.number(), b.number()) else {
        return type_error();
    };
    match op {
        "+" => Ok(Float(x + y)),
        "-" => Ok(Float(x - y)),
        "*" => Ok(Float(x * y)),
        "/" | "//" | "%" if y == 0.0 => err("float division by zero"),
        "/" => Ok(Float(x / y)),
        "//" => Ok(Float((x / y).floor())),
        "%" => Ok(Float(x - y * (x / y).floor())),
        "**" => Ok(Float(x.powf(y))),
        _ => type_error(),
    }
}
