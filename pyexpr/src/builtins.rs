//! The functions an expression may call: Python's conversions and `math` module, and what
//! the host adds (`arg()`, `find()`, ...).

use crate::compare::compare;
use crate::host::{ExprError, R, err};
use crate::{Value, parse_float, parse_int};

/// One call of a builtin function: the name as written (`math.sqrt`, for messages) and the
/// evaluated arguments, with the argument checks the builtins share.
struct Builtin<'a> {
    name: &'a str,
    args: Vec<Value>,
}

impl Builtin<'_> {
    /// Argument `i` (from 0) as a number.
    fn num(&self, i: usize) -> R<f64> {
        self.args.get(i).and_then(Value::number).ok_or_else(|| {
            ExprError::Other(format!(
                "{}() expects a number as argument {}",
                self.name,
                i + 1
            ))
        })
    }

    /// Fails unless exactly `n` arguments were given.
    fn arity(&self, n: usize) -> R<()> {
        if self.args.len() == n {
            Ok(())
        } else {
            err(format!(
                "{}() takes {n} argument(s), {} given",
                self.name,
                self.args.len()
            ))
        }
    }

    /// A float function of one number.
    fn float1(&self, f: fn(f64) -> f64) -> R<Value> {
        self.arity(1)?;
        Ok(Value::Float(f(self.num(0)?)))
    }

    /// `x`, or Python's math domain error when `ok` is false.
    fn domain(&self, x: f64, ok: bool) -> R<Value> {
        if ok {
            Ok(Value::Float(x))
        } else {
            err(format!("{}(): math domain error", self.name))
        }
    }
}

/// Calls the builtin `name` (`math.` and `xacro.` prefixes allowed) on `args`.
pub(crate) fn call(name: &str, args: Vec<Value>) -> R<Value> {
    let bare = name
        .strip_prefix("math.")
        .or_else(|| name.strip_prefix("xacro."))
        .unwrap_or(name);
    let builtin = Builtin { name, args };
    float_function(bare, &builtin)
        .or_else(|| integer_function(bare, &builtin))
        .or_else(|| conversion_function(bare, &builtin))
        .unwrap_or_else(|| Err(ExprError::Undefined(format!("{name}()"))))
}

/// The float functions of Python's `math` module (trigonometry, logarithms, powers), or `None`
/// when `bare` is none of them.
fn float_function(bare: &str, b: &Builtin<'_>) -> Option<R<Value>> {
    Some(match bare {
        "sin" => b.float1(f64::sin),
        "cos" => b.float1(f64::cos),
        "tan" => b.float1(f64::tan),
        "asin" => b.arity(1).and_then(|()| {
            let x = b.num(0)?;
            b.domain(x.asin(), (-1.0..=1.0).contains(&x))
        }),
        "acos" => b.arity(1).and_then(|()| {
            let x = b.num(0)?;
            b.domain(x.acos(), (-1.0..=1.0).contains(&x))
        }),
        "atan" => b.float1(f64::atan),
        "exp" => b.float1(f64::exp),
        "fabs" => b.float1(f64::abs),
        "radians" => b.float1(f64::to_radians),
        "degrees" => b.float1(f64::to_degrees),
        "sqrt" => b.arity(1).and_then(|()| {
            let x = b.num(0)?;
            b.domain(x.sqrt(), x >= 0.0)
        }),
        "log10" => b.arity(1).and_then(|()| {
            let x = b.num(0)?;
            b.domain(x.log10(), x > 0.0)
        }),
        "log" => log(b),
        "atan2" => b
            .arity(2)
            .and_then(|()| Ok(Value::Float(b.num(0)?.atan2(b.num(1)?)))),
        "hypot" => b
            .arity(2)
            .and_then(|()| Ok(Value::Float(b.num(0)?.hypot(b.num(1)?)))),
        "pow" => b
            .arity(2)
            .and_then(|()| Ok(Value::Float(b.num(0)?.powf(b.num(1)?)))),
        "fmod" => b.arity(2).and_then(|()| {
            let y = b.num(1)?;
            b.domain(b.num(0)? % y, y != 0.0)
        }),
        "copysign" => b
            .arity(2)
            .and_then(|()| Ok(Value::Float(b.num(0)?.copysign(b.num(1)?)))),
        _ => return None,
    })
}

/// `log(x)` or `log(x, base)`.
fn log(b: &Builtin<'_>) -> R<Value> {
    let x = b.num(0)?;
    match b.args.len() {
        1 => b.domain(x.ln(), x > 0.0),
        2 => {
            let base = b.num(1)?;
            b.domain(x.ln() / base.ln(), x > 0.0 && base > 0.0 && base != 1.0)
        }
        n => err(format!("log() takes 1 or 2 arguments, {n} given")),
    }
}

/// Rounding, `abs`, `min` and `max`, or `None` when `bare` is none of them.
fn integer_function(bare: &str, b: &Builtin<'_>) -> Option<R<Value>> {
    Some(match bare {
        "floor" | "ceil" | "trunc" => b.arity(1).and_then(|()| {
            let x = b.num(0)?;
            let y = match bare {
                "floor" => x.floor(),
                "ceil" => x.ceil(),
                _ => x.trunc(),
            };
            to_int(y, b.name)
        }),
        "abs" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Int(i) => Ok(Value::Int(i.saturating_abs())),
            other => Ok(Value::Float(
                other
                    .number()
                    .ok_or_else(|| ExprError::Other("abs() expects a number".into()))?
                    .abs(),
            )),
        }),
        "round" => round(b),
        "min" | "max" => extreme(bare == "min", b),
        _ => return None,
    })
}

/// `round(x)` (to an int, halves to even) or `round(x, digits)` (to a float).
fn round(b: &Builtin<'_>) -> R<Value> {
    let x = b.num(0)?;
    match b.args.len() {
        1 => to_int(round_half_even(x), b.name),
        2 => {
            let digits = b.args[1]
                .int()
                .ok_or_else(|| ExprError::Other("round() digits must be an int".into()))?
                .clamp(-300, 300) as i32;
            let scale = 10f64.powi(digits);
            Ok(Value::Float(round_half_even(x * scale) / scale))
        }
        n => err(format!("round() takes 1 or 2 arguments, {n} given")),
    }
}

/// `min(...)` when `smallest`, else `max(...)`: of the arguments, or of the items of a single
/// list argument.
fn extreme(smallest: bool, b: &Builtin<'_>) -> R<Value> {
    let items = match b.args.as_slice() {
        [Value::List(items)] => items.clone(),
        _ => b.args.clone(),
    };
    let mut best: Option<Value> = None;
    for item in items {
        best = Some(match best {
            None => item,
            Some(current) => {
                let better = if smallest {
                    compare("<", &item, &current)?
                } else {
                    compare(">", &item, &current)?
                };
                if better { item } else { current }
            }
        });
    }
    best.ok_or_else(|| ExprError::Other(format!("{}() of an empty sequence", b.name)))
}

/// Type conversions and `len`, or `None` when `bare` is none of them.
fn conversion_function(bare: &str, b: &Builtin<'_>) -> Option<R<Value>> {
    Some(match bare {
        "int" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => parse_int(s)
                .map(Value::Int)
                .ok_or_else(|| ExprError::Other(format!("int(): invalid literal '{s}'"))),
            other => other
                .number()
                .ok_or_else(|| ExprError::Other("int() expects a number".into()))
                .and_then(|x| to_int(x.trunc(), b.name)),
        }),
        "float" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => parse_float(s)
                .map(Value::Float)
                .ok_or_else(|| ExprError::Other(format!("float(): invalid literal '{s}'"))),
            other => other
                .number()
                .map(Value::Float)
                .ok_or_else(|| ExprError::Other("float() expects a number".into())),
        }),
        "str" => match b.args.as_slice() {
            [] => Ok(Value::Str(String::new())),
            [v] => Ok(Value::Str(v.to_string())),
            more => err(format!(
                "str() takes at most 1 argument, {} given",
                more.len()
            )),
        },
        "bool" => b.arity(1).map(|()| Value::Bool(b.args[0].truthy())),
        "len" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => Ok(Value::Int(s.chars().count() as i64)),
            Value::List(l) => Ok(Value::Int(l.len() as i64)),
            other => err(format!(
                "object of type '{}' has no len()",
                other.type_name()
            )),
        }),
        _ => return None,
    })
}

fn round_half_even(x: f64) -> f64 {
    let r = x.round();
    if (x - x.trunc()).abs() == 0.5 && r % 2.0 != 0.0 {
        r - x.signum()
    } else {
        r
    }
}

fn to_int(x: f64, name: &str) -> R<Value> {
    if x.is_finite() && x.abs() < 9.2e18 {
        Ok(Value::Int(x as i64))
    } else {
        err(format!("{name}(): cannot convert {x} to an integer"))
    }
}
