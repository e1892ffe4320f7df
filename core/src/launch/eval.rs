//! `$(eval EXPR)`: the Python expressions roslaunch evaluates, as far as launch files use them.
//!
//! roslaunch hands the text to Python's `eval` with `arg()`, `env()`, `optenv()`, `find()`,
//! `anon()`, `dirname()`, `true`/`false`, `str`/`int`/`float` and the `math` module, and reads
//! bare names as args (converted like `<param>` values). rover has no Python, so this is a small
//! evaluator of that language: literals, names, calls, arithmetic (`+ - * / // % **`),
//! comparisons, `and`/`or`/`not`, `x if c else y`, with Python's result types, and the result
//! printed as Python's `str()` prints it.

use super::value::{ParamValue, convert_value, python_float, python_float_parse, python_int_parse};

/// What an expression may ask of the launch: its args and the substitution functions.
pub(crate) trait EvalHost {
    /// `$(arg NAME)`'s text.
    fn arg(&mut self, name: &str) -> Result<String, String>;
    /// `$(find PKG)`'s folder.
    fn find(&mut self, package: &str) -> Result<String, String>;
    /// `$(anon ID)`'s name.
    fn anon(&mut self, id: &str) -> String;
    /// `$(dirname)`: the launch file's folder.
    fn dirname(&mut self) -> Result<String, String>;
}

/// Longest string an expression may build (`'x' * 10**9` is refused, not allocated).
const MAX_STR: usize = 1 << 20;
/// Deepest nesting of parentheses and operators.
const MAX_DEPTH: usize = 64;

/// Evaluates `expr` and returns its value as Python's `str()` prints it.
pub(crate) fn eval(expr: &str, host: &mut dyn EvalHost) -> Result<String, String> {
    if expr.contains("__") {
        return Err("$(eval ...) may not contain double underscore expressions".to_owned());
    }
    let tokens = tokenize(expr)?;
    let mut p = Parser {
        tokens,
        pos: 0,
        host,
        depth: 0,
    };
    let value = p.ternary()?;
    if p.pos != p.tokens.len() {
        return Err(format!(
            "unexpected {} in \"{expr}\"",
            p.tokens[p.pos].describe()
        ));
    }
    Ok(value.text())
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Int(i64),
    Float(f64),
    Str(String),
    Name(String),
    Op(&'static str),
}

impl Tok {
    fn describe(&self) -> String {
        match self {
            Self::Int(i) => i.to_string(),
            Self::Float(f) => python_float(*f),
            Self::Str(s) => format!("'{s}'"),
            Self::Name(n) => n.clone(),
            Self::Op(o) => format!("\"{o}\""),
        }
    }
}

const OPS: [&str; 20] = [
    "**", "//", "==", "!=", "<=", ">=", "+", "-", "*", "/", "%", "<", ">", "(", ")", ",", "[", "]",
    ".", ":",
];

fn tokenize(s: &str) -> Result<Vec<Tok>, String> {
    let chars: Vec<char> = s.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit))
        {
            let start = i;
            while i < chars.len()
                && (chars[i].is_ascii_alphanumeric()
                    || chars[i] == '.'
                    || chars[i] == '_'
                    || ((chars[i] == '+' || chars[i] == '-') && matches!(chars[i - 1], 'e' | 'E')))
            {
                i += 1;
            }
            let text: String = chars[start..i].iter().collect();
            let is_float = text.contains(['.', 'e', 'E']);
            out.push(if is_float {
                Tok::Float(python_float_parse(&text).ok_or(format!("bad number {text}"))?)
            } else {
                Tok::Int(python_int_parse(&text).ok_or(format!("bad number {text}"))?)
            });
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Tok::Name(chars[start..i].iter().collect()));
        } else if c == '\'' || c == '"' {
            let mut text = String::new();
            i += 1;
            loop {
                match chars.get(i) {
                    None => return Err(format!("unterminated string in \"{s}\"")),
                    Some(&q) if q == c => break,
                    Some('\\') => {
                        i += 1;
                        match chars.get(i) {
                            Some('n') => text.push('\n'),
                            Some('t') => text.push('\t'),
                            Some(&other) => text.push(other),
                            None => return Err(format!("unterminated string in \"{s}\"")),
                        }
                    }
                    Some(&other) => text.push(other),
                }
                i += 1;
            }
            i += 1;
            out.push(Tok::Str(text));
        } else {
            let rest: String = chars[i..chars.len().min(i + 2)].iter().collect();
            let op = OPS
                .iter()
                .find(|op| rest.starts_with(*op))
                .ok_or_else(|| format!("unexpected \"{c}\" in \"{s}\""))?;
            out.push(Tok::Op(op));
            i += op.len();
        }
    }
    Ok(out)
}

/// A Python value.
#[derive(Debug, Clone, PartialEq)]
enum Val {
    None,
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(String),
    Func(String),
}

impl Val {
    fn text(&self) -> String {
        match self {
            Self::None => "None".to_owned(),
            Self::Bool(b) => if *b { "True" } else { "False" }.to_owned(),
            Self::Int(i) => i.to_string(),
            Self::Float(f) => python_float(*f),
            Self::Str(s) => s.clone(),
            Self::Func(name) => format!("<built-in function {name}>"),
        }
    }

    fn truthy(&self) -> bool {
        match self {
            Self::None => false,
            Self::Bool(b) => *b,
            Self::Int(i) => *i != 0,
            Self::Float(f) => *f != 0.0,
            Self::Str(s) => !s.is_empty(),
            Self::Func(_) => true,
        }
    }

    fn number(&self) -> Option<f64> {
        match self {
            Self::Bool(b) => Some(f64::from(u8::from(*b))),
            Self::Int(i) => Some(*i as f64),
            Self::Float(f) => Some(*f),
            _ => None,
        }
    }

    fn int(&self) -> Option<i64> {
        match self {
            Self::Bool(b) => Some(i64::from(*b)),
            Self::Int(i) => Some(*i),
            _ => None,
        }
    }

    fn type_name(&self) -> &'static str {
        match self {
            Self::None => "NoneType",
            Self::Bool(_) => "bool",
            Self::Int(_) => "int",
            Self::Float(_) => "float",
            Self::Str(_) => "str",
            Self::Func(_) => "builtin_function",
        }
    }

    fn from_param(value: ParamValue) -> Self {
        match value {
            ParamValue::Bool(b) => Self::Bool(b),
            ParamValue::Int(i) => Self::Int(i),
            ParamValue::Double(d) => Self::Float(d),
            ParamValue::Str(s) => Self::Str(s),
            other => Self::Str(other.as_text()),
        }
    }
}

struct Parser<'h> {
    tokens: Vec<Tok>,
    pos: usize,
    host: &'h mut dyn EvalHost,
    depth: usize,
}

const FUNCTIONS: [&str; 26] = [
    "arg", "env", "optenv", "find", "anon", "dirname", "str", "int", "float", "abs", "min", "max",
    "round", "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "radians", "degrees",
    "floor", "ceil", "pow",
];

impl Parser<'_> {
    fn peek_op(&self, op: &str) -> bool {
        matches!(self.tokens.get(self.pos), Some(Tok::Op(o)) if *o == op)
    }

    fn peek_name(&self, name: &str) -> bool {
        matches!(self.tokens.get(self.pos), Some(Tok::Name(n)) if n == name)
    }

    fn expect_op(&mut self, op: &str) -> Result<(), String> {
        if self.peek_op(op) {
            self.pos += 1;
            Ok(())
        } else {
            Err(match self.tokens.get(self.pos) {
                Some(t) => format!("expected \"{op}\", found {}", t.describe()),
                None => format!("expected \"{op}\" at the end"),
            })
        }
    }

    fn enter(&mut self) -> Result<(), String> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err("the expression nests too deeply".to_owned());
        }
        Ok(())
    }

    fn ternary(&mut self) -> Result<Val, String> {
        self.enter()?;
        let value = self.or()?;
        let out = if self.peek_name("if") {
            self.pos += 1;
            let cond = self.or()?;
            if !self.peek_name("else") {
                return Err("expected \"else\" after \"x if c\"".to_owned());
            }
            self.pos += 1;
            let other = self.ternary()?;
            if cond.truthy() { value } else { other }
        } else {
            value
        };
        self.depth -= 1;
        Ok(out)
    }

    fn or(&mut self) -> Result<Val, String> {
        let mut value = self.and()?;
        while self.peek_name("or") {
            self.pos += 1;
            let rhs = self.and()?;
            if !value.truthy() {
                value = rhs;
            }
        }
        Ok(value)
    }

    fn and(&mut self) -> Result<Val, String> {
        let mut value = self.not()?;
        while self.peek_name("and") {
            self.pos += 1;
            let rhs = self.not()?;
            if value.truthy() {
                value = rhs;
            }
        }
        Ok(value)
    }

    fn not(&mut self) -> Result<Val, String> {
        if self.peek_name("not") {
            self.pos += 1;
            self.enter()?;
            let v = self.not()?;
            self.depth -= 1;
            return Ok(Val::Bool(!v.truthy()));
        }
        self.comparison()
    }

    fn comparison(&mut self) -> Result<Val, String> {
        let mut left = self.arith()?;
        let mut result = None;
        loop {
            let op = match self.tokens.get(self.pos) {
                Some(Tok::Op(o)) if matches!(*o, "==" | "!=" | "<" | "<=" | ">" | ">=") => *o,
                _ => break,
            };
            self.pos += 1;
            let right = self.arith()?;
            let holds = compare(&left, op, &right)?;
            result = Some(result.unwrap_or(true) && holds);
            left = right;
        }
        Ok(match result {
            Some(b) => Val::Bool(b),
            None => left,
        })
    }

    fn arith(&mut self) -> Result<Val, String> {
        let mut value = self.term()?;
        while self.peek_op("+") || self.peek_op("-") {
            let plus = self.peek_op("+");
            self.pos += 1;
            let rhs = self.term()?;
            value = if plus {
                add(value, rhs)?
            } else {
                numeric(&value, &rhs, "-", i64::checked_sub, |a, b| a - b)?
            };
        }
        Ok(value)
    }

    fn term(&mut self) -> Result<Val, String> {
        let mut value = self.factor()?;
        loop {
            let op = match self.tokens.get(self.pos) {
                Some(Tok::Op(o)) if matches!(*o, "*" | "/" | "//" | "%") => *o,
                _ => break,
            };
            self.pos += 1;
            let rhs = self.factor()?;
            value = match op {
                "*" => multiply(value, rhs)?,
                "/" => {
                    let (a, b) = numbers(&value, &rhs, "/")?;
                    if b == 0.0 {
                        return Err("division by zero".to_owned());
                    }
                    Val::Float(a / b)
                }
                "//" => floor_div(&value, &rhs)?,
                _ => modulo(&value, &rhs)?,
            };
        }
        Ok(value)
    }

    fn factor(&mut self) -> Result<Val, String> {
        if self.peek_op("-") || self.peek_op("+") {
            let minus = self.peek_op("-");
            self.pos += 1;
            self.enter()?;
            let v = self.factor()?;
            self.depth -= 1;
            return match (&v, minus) {
                (Val::Int(i), true) => i
                    .checked_neg()
                    .map(Val::Int)
                    .ok_or_else(|| "integer overflow".to_owned()),
                (Val::Bool(b), true) => Ok(Val::Int(-i64::from(*b))),
                (Val::Float(f), true) => Ok(Val::Float(-f)),
                (Val::Int(_) | Val::Float(_), false) => Ok(v),
                (Val::Bool(b), false) => Ok(Val::Int(i64::from(*b))),
                _ => Err(format!("bad operand type for unary -: '{}'", v.type_name())),
            };
        }
        let base = self.primary()?;
        if self.peek_op("**") {
            self.pos += 1;
            self.enter()?;
            let exp = self.factor()?;
            self.depth -= 1;
            return power(&base, &exp);
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<Val, String> {
        let mut value = self.atom()?;
        while self.peek_op("(") {
            self.pos += 1;
            let mut args = Vec::new();
            while !self.peek_op(")") {
                args.push(self.ternary()?);
                if !self.peek_op(")") {
                    self.expect_op(",")?;
                }
            }
            self.expect_op(")")?;
            value = match value {
                Val::Func(name) => self.call(&name, &args)?,
                other => return Err(format!("'{}' object is not callable", other.type_name())),
            };
        }
        Ok(value)
    }

    fn atom(&mut self) -> Result<Val, String> {
        let tok = self
            .tokens
            .get(self.pos)
            .cloned()
            .ok_or_else(|| "the expression ends early".to_owned())?;
        self.pos += 1;
        match tok {
            Tok::Int(i) => Ok(Val::Int(i)),
            Tok::Float(f) => Ok(Val::Float(f)),
            Tok::Str(s) => Ok(Val::Str(s)),
            Tok::Op("(") => {
                let v = self.ternary()?;
                self.expect_op(")")?;
                Ok(v)
            }
            Tok::Op(o) => Err(format!("unexpected \"{o}\"")),
            Tok::Name(name) => self.name(&name),
        }
    }

    fn name(&mut self, name: &str) -> Result<Val, String> {
        Ok(match name {
            "True" | "true" => Val::Bool(true),
            "False" | "false" => Val::Bool(false),
            "None" => Val::None,
            "pi" => Val::Float(std::f64::consts::PI),
            "e" => Val::Float(std::f64::consts::E),
            "tau" => Val::Float(std::f64::consts::TAU),
            "inf" => Val::Float(f64::INFINITY),
            "nan" => Val::Float(f64::NAN),
            _ if FUNCTIONS.contains(&name) => Val::Func(name.to_owned()),
            _ => {
                let text = self
                    .host
                    .arg(name)
                    .map_err(|e| format!("name '{name}' is not defined: {e}"))?;
                Val::from_param(convert_value(&text, "auto")?)
            }
        })
    }

    fn call(&mut self, name: &str, args: &[Val]) -> Result<Val, String> {
        let text = |i: usize| -> Result<String, String> {
            match args.get(i) {
                Some(Val::Str(s)) => Ok(s.clone()),
                Some(other) => Err(format!(
                    "{name}() expects a string, found {}",
                    other.type_name()
                )),
                None => Err(format!("{name}() is missing an argument")),
            }
        };
        let count = |n: std::ops::RangeInclusive<usize>| -> Result<(), String> {
            if n.contains(&args.len()) {
                Ok(())
            } else {
                Err(format!(
                    "{name}() takes {n:?} arguments, {} given",
                    args.len()
                ))
            }
        };
        Ok(match name {
            "arg" => {
                count(1..=1)?;
                let t = self.host.arg(&text(0)?)?;
                Val::from_param(convert_value(&t, "auto")?)
            }
            "env" => {
                count(1..=1)?;
                let var = text(0)?;
                Val::Str(
                    std::env::var(&var)
                        .map_err(|_| format!("environment variable '{var}' is not set"))?,
                )
            }
            "optenv" => {
                count(1..=2)?;
                let default = if args.len() == 2 {
                    text(1)?
                } else {
                    String::new()
                };
                Val::Str(std::env::var(text(0)?).unwrap_or(default))
            }
            "find" => {
                count(1..=1)?;
                Val::Str(self.host.find(&text(0)?)?)
            }
            "anon" => {
                count(1..=1)?;
                Val::Str(self.host.anon(&text(0)?))
            }
            "dirname" => {
                count(0..=0)?;
                Val::Str(self.host.dirname()?)
            }
            "str" => {
                count(0..=1)?;
                Val::Str(args.first().map(Val::text).unwrap_or_default())
            }
            _ => builtin(name, args)?,
        })
    }
}

/// Python's conversions (`int`, `float`), `abs`, `min`, `max`, `round`, `pow` and the `math`
/// functions.
fn builtin(name: &str, args: &[Val]) -> Result<Val, String> {
    let num = |i: usize| -> Result<f64, String> {
        args.get(i)
            .and_then(Val::number)
            .ok_or_else(|| format!("{name}() expects a number"))
    };
    let one = || -> Result<&Val, String> {
        match args {
            [v] => Ok(v),
            _ => Err(format!("{name}() takes one argument, {} given", args.len())),
        }
    };
    Ok(match name {
        "int" => match one()? {
            Val::Str(s) => Val::Int(
                python_int_parse(s).ok_or_else(|| format!("invalid literal for int(): '{s}'"))?,
            ),
            Val::Float(f) => float_to_int(f.trunc())?,
            other => Val::Int(
                other
                    .int()
                    .ok_or_else(|| format!("int() of {}", other.type_name()))?,
            ),
        },
        "float" => match one()? {
            Val::Str(s) => Val::Float(
                python_float_parse(s)
                    .ok_or_else(|| format!("could not convert string to float: '{s}'"))?,
            ),
            _ => Val::Float(num(0)?),
        },
        "abs" => match one()? {
            Val::Int(i) => Val::Int(i.checked_abs().ok_or("integer overflow")?),
            _ => Val::Float(num(0)?.abs()),
        },
        "min" | "max" => {
            let (first, rest) = args
                .split_first()
                .ok_or_else(|| format!("{name}() needs arguments"))?;
            let mut best = first.clone();
            for a in rest {
                let op = if name == "min" { "<" } else { ">" };
                if compare(a, op, &best)? {
                    best = a.clone();
                }
            }
            best
        }
        // Python rounds half to even.
        "round" => float_to_int(one().and_then(|_| num(0))?.round_ties_even())?,
        "pow" | "atan2" => {
            let [a, b] = args else {
                return Err(format!(
                    "{name}() takes two arguments, {} given",
                    args.len()
                ));
            };
            if name == "pow" {
                power(a, b)?
            } else {
                Val::Float(num(0)?.atan2(num(1)?))
            }
        }
        _ => {
            let x = one().and_then(|_| num(0))?;
            Val::Float(match name {
                "sqrt" if x < 0.0 => return Err("math domain error".to_owned()),
                "sqrt" => x.sqrt(),
                "sin" => x.sin(),
                "cos" => x.cos(),
                "tan" => x.tan(),
                "asin" => x.asin(),
                "acos" => x.acos(),
                "atan" => x.atan(),
                "radians" => x.to_radians(),
                "degrees" => x.to_degrees(),
                "floor" => return float_to_int(x.floor()),
                "ceil" => return float_to_int(x.ceil()),
                _ => return Err(format!("{name}() is not supported")),
            })
        }
    })
}

fn float_to_int(f: f64) -> Result<Val, String> {
    if f.is_finite() && f.abs() < 9.2e18 {
        Ok(Val::Int(f as i64))
    } else {
        Err("cannot convert that float to an integer".to_owned())
    }
}

fn numbers(a: &Val, b: &Val, op: &str) -> Result<(f64, f64), String> {
    match (a.number(), b.number()) {
        (Some(x), Some(y)) => Ok((x, y)),
        _ => Err(format!(
            "unsupported operand type(s) for {op}: '{}' and '{}'",
            a.type_name(),
            b.type_name()
        )),
    }
}

fn numeric(
    a: &Val,
    b: &Val,
    op: &str,
    int_op: fn(i64, i64) -> Option<i64>,
    float_op: fn(f64, f64) -> f64,
) -> Result<Val, String> {
    if let (Some(x), Some(y)) = (a.int(), b.int()) {
        return int_op(x, y)
            .map(Val::Int)
            .ok_or_else(|| "integer overflow".to_owned());
    }
    let (x, y) = numbers(a, b, op)?;
    Ok(Val::Float(float_op(x, y)))
}

fn add(a: Val, b: Val) -> Result<Val, String> {
    match (a, b) {
        (Val::Str(x), Val::Str(y)) => {
            if x.len() + y.len() > MAX_STR {
                return Err("the string grows too long".to_owned());
            }
            Ok(Val::Str(x + &y))
        }
        (a, b) => numeric(&a, &b, "+", i64::checked_add, |x, y| x + y),
    }
}

fn multiply(a: Val, b: Val) -> Result<Val, String> {
    match (&a, &b) {
        (Val::Str(s), n) | (n, Val::Str(s)) if n.int().is_some() => {
            let times = usize::try_from(n.int().unwrap_or(0).max(0)).unwrap_or(0);
            if s.len().saturating_mul(times) > MAX_STR {
                return Err("the string grows too long".to_owned());
            }
            Ok(Val::Str(s.repeat(times)))
        }
        _ => numeric(&a, &b, "*", i64::checked_mul, |x, y| x * y),
    }
}

fn floor_div(a: &Val, b: &Val) -> Result<Val, String> {
    if let (Some(x), Some(y)) = (a.int(), b.int()) {
        if y == 0 {
            return Err("integer division by zero".to_owned());
        }
        let q = x.checked_div(y).ok_or("integer overflow")?;
        let q = if (x % y != 0) && ((x < 0) != (y < 0)) {
            q - 1
        } else {
            q
        };
        return Ok(Val::Int(q));
    }
    let (x, y) = numbers(a, b, "//")?;
    if y == 0.0 {
        return Err("float floor division by zero".to_owned());
    }
    Ok(Val::Float((x / y).floor()))
}

fn modulo(a: &Val, b: &Val) -> Result<Val, String> {
    if let (Some(x), Some(y)) = (a.int(), b.int()) {
        if y == 0 {
            return Err("integer modulo by zero".to_owned());
        }
        let r = x.checked_rem(y).ok_or("integer overflow")?;
        return Ok(Val::Int(if r != 0 && ((r < 0) != (y < 0)) {
            r + y
        } else {
            r
        }));
    }
    let (x, y) = numbers(a, b, "%")?;
    if y == 0.0 {
        return Err("float modulo".to_owned());
    }
    let r = x % y;
    Ok(Val::Float(if r != 0.0 && ((r < 0.0) != (y < 0.0)) {
        r + y
    } else {
        r
    }))
}

fn power(a: &Val, b: &Val) -> Result<Val, String> {
    if let (Some(x), Some(y)) = (a.int(), b.int())
        && y >= 0
    {
        let exp = u32::try_from(y).map_err(|_| "integer overflow".to_owned())?;
        return x
            .checked_pow(exp)
            .map(Val::Int)
            .ok_or_else(|| "integer overflow".to_owned());
    }
    let (x, y) = numbers(a, b, "**")?;
    Ok(Val::Float(x.powf(y)))
}

fn compare(a: &Val, op: &str, b: &Val) -> Result<bool, String> {
    use std::cmp::Ordering;
    let ordering = match (a, b) {
        (Val::Str(x), Val::Str(y)) => Some(x.cmp(y)),
        _ => match (a.number(), b.number()) {
            (Some(x), Some(y)) => x.partial_cmp(&y),
            _ => {
                return match op {
                    "==" => Ok(a == b),
                    "!=" => Ok(a != b),
                    _ => Err(format!(
                        "'{op}' not supported between '{}' and '{}'",
                        a.type_name(),
                        b.type_name()
                    )),
                };
            }
        },
    };
    Ok(match (op, ordering) {
        ("==", o) => o == Some(Ordering::Equal),
        ("!=", o) => o != Some(Ordering::Equal),
        ("<", o) => o == Some(Ordering::Less),
        ("<=", o) => matches!(o, Some(Ordering::Less | Ordering::Equal)),
        (">", o) => o == Some(Ordering::Greater),
        (_, o) => matches!(o, Some(Ordering::Greater | Ordering::Equal)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Args;

    impl EvalHost for Args {
        fn arg(&mut self, name: &str) -> Result<String, String> {
            match name {
                "radius" => Ok("0.5".into()),
                "robot" => Ok("tiago".into()),
                "flag" => Ok("true".into()),
                "n" => Ok("3".into()),
                _ => Err(format!("arg '{name}' is not defined")),
            }
        }
        fn find(&mut self, package: &str) -> Result<String, String> {
            Ok(format!("/pkgs/{package}"))
        }
        fn anon(&mut self, id: &str) -> String {
            format!("{id}_1")
        }
        fn dirname(&mut self) -> Result<String, String> {
            Ok("/here".into())
        }
    }

    fn ev(s: &str) -> Result<String, String> {
        eval(s, &mut Args)
    }

    #[test]
    fn python_results_and_their_text() {
        assert_eq!(ev("radius * 2").as_deref(), Ok("1.0"));
        assert_eq!(ev("n * 2").as_deref(), Ok("6"));
        assert_eq!(ev("n / 2").as_deref(), Ok("1.5"));
        assert_eq!(ev("-7 // 2").as_deref(), Ok("-4"));
        assert_eq!(ev("-7 % 3").as_deref(), Ok("2"));
        assert_eq!(ev("2 ** 10").as_deref(), Ok("1024"));
        assert_eq!(ev("robot == 'tiago'").as_deref(), Ok("True"));
        assert_eq!(
            ev("arg('robot') + '_description'").as_deref(),
            Ok("tiago_description")
        );
        assert_eq!(ev("flag and not False").as_deref(), Ok("True"));
        assert_eq!(ev("'a' if n > 2 else 'b'").as_deref(), Ok("a"));
        assert_eq!(ev("1 < n < 5").as_deref(), Ok("True"));
        assert_eq!(ev("find('pkg') + '/x'").as_deref(), Ok("/pkgs/pkg/x"));
        assert_eq!(ev("degrees(pi)").as_deref(), Ok("180.0"));
        assert_eq!(ev("0.1 + 0.2").as_deref(), Ok("0.30000000000000004"));
        assert_eq!(ev("optenv('ROVER_SURELY_UNSET', 'd')").as_deref(), Ok("d"));
    }

    #[test]
    fn bad_expressions_are_errors() {
        assert!(ev("undefined_name + 1").is_err());
        assert!(ev("1 +").is_err());
        assert!(ev("__import__('os')").is_err());
        assert!(ev("1 / 0").is_err());
        assert!(ev("'x' * 100000000").is_err());
        assert!(ev("2 ** 99").is_err());
        assert!(ev(&"(".repeat(500)).is_err());
        assert!(ev("'abc").is_err());
    }
}
