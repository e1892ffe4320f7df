//! The Python-like expressions of xacro's `${...}`: numbers, strings, property names,
//! arithmetic, comparisons, `and`/`or`/`not`, `a if c else b`, lists and the math functions.
//!
//! Written in-tree: the only Rust xacro crate drops element text (see docs/ROBOTS.md), and this
//! subset is small. Values follow Python 3 (`/` is true division, `//` floors, ints and floats
//! print as Python's `str()` does) so that expanded files match the reference xacro.

use std::fmt;

/// A value of a xacro expression.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    Int(i64),
    Float(f64),
    Bool(bool),
    Str(String),
    List(Vec<Value>),
    None,
}

impl fmt::Display for Value {
    /// Python's `str()`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{}", python_float(*x)),
            Value::Bool(true) => f.write_str("True"),
            Value::Bool(false) => f.write_str("False"),
            Value::Str(s) => f.write_str(s),
            Value::None => f.write_str("None"),
            Value::List(items) => {
                f.write_str("[")?;
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    match item {
                        Value::Str(s) => write!(f, "'{s}'")?,
                        other => write!(f, "{other}")?,
                    }
                }
                f.write_str("]")
            }
        }
    }
}

/// Python's `repr(float)`: shortest round-trip digits, `.0` on integral values, exponent form
/// outside 1e-4..1e16.
fn python_float(x: f64) -> String {
    if x.is_nan() {
        return "nan".to_owned();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.to_owned();
    }
    let magnitude = x.abs();
    if x != 0.0 && !(1e-4..1e16).contains(&magnitude) {
        // Rust's `{:e}` gives the shortest digits as 1.5e-5; Python writes 1.5e-05.
        let s = format!("{x:e}");
        if let Some((mantissa, exp)) = s.split_once('e') {
            let (sign, digits) = match exp.strip_prefix('-') {
                Some(d) => ('-', d),
                None => ('+', exp),
            };
            return format!("{mantissa}e{sign}{digits:0>2}");
        }
        return s;
    }
    let s = format!("{x}");
    if s.contains('.') { s } else { format!("{s}.0") }
}

impl Value {
    fn type_name(&self) -> &'static str {
        match self {
            Value::Int(_) => "int",
            Value::Float(_) => "float",
            Value::Bool(_) => "bool",
            Value::Str(_) => "str",
            Value::List(_) => "list",
            Value::None => "NoneType",
        }
    }

    /// Python truthiness.
    pub(crate) fn truthy(&self) -> bool {
        match self {
            Value::Int(i) => *i != 0,
            Value::Float(x) => *x != 0.0,
            Value::Bool(b) => *b,
            Value::Str(s) => !s.is_empty(),
            Value::List(l) => !l.is_empty(),
            Value::None => false,
        }
    }

    fn number(&self) -> Option<f64> {
        match self {
            Value::Int(i) => Some(*i as f64),
            Value::Float(x) => Some(*x),
            Value::Bool(b) => Some(f64::from(u8::from(*b))),
            _ => None,
        }
    }

    fn int(&self) -> Option<i64> {
        match self {
            Value::Int(i) => Some(*i),
            Value::Bool(b) => Some(i64::from(*b)),
            _ => None,
        }
    }

    /// How xacro reads a property's text: an int, else a float, else a boolean word, else the
    /// text itself (`'quoted'` text loses its quotes; text with `_` stays text).
    pub(crate) fn literal(text: &str) -> Value {
        if text.len() >= 2 && text.starts_with('\'') && text.ends_with('\'') {
            return Value::Str(text[1..text.len() - 1].to_owned());
        }
        if text.contains('_') {
            return Value::Str(text.to_owned());
        }
        let trimmed = text.trim();
        if let Some(i) = parse_python_int(trimmed) {
            return Value::Int(i);
        }
        if let Some(x) = parse_python_float(trimmed) {
            return Value::Float(x);
        }
        match text {
            "true" | "True" => Value::Bool(true),
            "false" | "False" => Value::Bool(false),
            _ => Value::Str(text.to_owned()),
        }
    }
}

fn parse_python_int(s: &str) -> Option<i64> {
    let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    s.parse().ok()
}

fn parse_python_float(s: &str) -> Option<f64> {
    let lower = s.to_ascii_lowercase();
    let body = lower.strip_prefix(['+', '-']).unwrap_or(&lower);
    if matches!(body, "inf" | "infinity" | "nan") {
        return lower.parse().ok();
    }
    // Rust accepts a few spellings Python does not ("inf" handled above); require a digit.
    if !body.bytes().any(|b| b.is_ascii_digit())
        || !body
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'+' | b'-'))
    {
        return None;
    }
    s.parse().ok()
}

/// Why an expression could not be evaluated.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ExprError {
    /// A name that is no property, constant or function.
    Undefined(String),
    /// Anything else: syntax, types, domain.
    Other(String),
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExprError::Undefined(name) => write!(f, "undefined property \"{name}\""),
            ExprError::Other(message) => f.write_str(message),
        }
    }
}

type R<T> = Result<T, ExprError>;

fn err<T>(message: impl Into<String>) -> R<T> {
    Err(ExprError::Other(message.into()))
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Int(i64),
    Float(f64),
    Str(String),
    Name(String),
    Op(&'static str),
}

const OPS: [&str; 22] = [
    "**", "//", "==", "!=", "<=", ">=", "+", "-", "*", "/", "%", "<", ">", "(", ")", ",", "[", "]",
    ":", "{", "}", ".",
];

fn tokenize(src: &str) -> R<Vec<Token>> {
    let bytes = src.as_bytes();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let start = i;
            let mut float = false;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                float |= bytes[i] == b'.';
                i += 1;
            }
            if i < bytes.len() && matches!(bytes[i], b'e' | b'E') {
                let mut j = i + 1;
                if j < bytes.len() && matches!(bytes[j], b'+' | b'-') {
                    j += 1;
                }
                if j < bytes.len() && bytes[j].is_ascii_digit() {
                    float = true;
                    i = j;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text = &src[start..i];
            tokens.push(if float {
                Token::Float(
                    text.parse()
                        .map_err(|_| ExprError::Other(format!("bad number '{text}'")))?,
                )
            } else {
                match text.parse() {
                    Ok(v) => Token::Int(v),
                    Err(_) => Token::Float(
                        text.parse()
                            .map_err(|_| ExprError::Other(format!("bad number '{text}'")))?,
                    ),
                }
            });
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            tokens.push(Token::Name(src[start..i].to_owned()));
        } else if c == b'\'' || c == b'"' {
            let quote = c;
            let mut out = String::new();
            i += 1;
            let mut closed = false;
            while i < bytes.len() {
                let ch = src[i..].chars().next().unwrap_or('\0');
                if bytes[i] == quote {
                    closed = true;
                    i += 1;
                    break;
                }
                if bytes[i] == b'\\' && i + 1 < bytes.len() {
                    let next = src[i + 1..].chars().next().unwrap_or('\0');
                    out.push(match next {
                        'n' => '\n',
                        't' => '\t',
                        other => other,
                    });
                    i += 1 + next.len_utf8();
                    continue;
                }
                out.push(ch);
                i += ch.len_utf8();
            }
            if !closed {
                return err("unterminated string");
            }
            tokens.push(Token::Str(out));
        } else if let Some(op) = OPS.iter().find(|op| src[i..].starts_with(**op)) {
            tokens.push(Token::Op(op));
            i += op.len();
        } else {
            let ch = src[i..].chars().next().unwrap_or('?');
            return err(format!("unexpected character '{ch}'"));
        }
    }
    Ok(tokens)
}

#[derive(Debug, Clone)]
enum Expr {
    Const(Value),
    Name(String),
    Unary(&'static str, Box<Expr>),
    Binary(&'static str, Box<Expr>, Box<Expr>),
    Compare(Box<Expr>, Vec<(&'static str, Expr)>),
    And(Box<Expr>, Box<Expr>),
    Or(Box<Expr>, Box<Expr>),
    Not(Box<Expr>),
    IfElse {
        then: Box<Expr>,
        cond: Box<Expr>,
        otherwise: Box<Expr>,
    },
    Call(String, Vec<Expr>),
    List(Vec<Expr>),
    Index(Box<Expr>, Box<Expr>),
}

/// Deepest nesting of brackets and unary operators accepted, so that hostile input cannot
/// overflow the stack.
const MAX_DEPTH: usize = 200;

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    depth: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.pos)
    }

    fn is_op(&self, op: &str) -> bool {
        matches!(self.peek(), Some(Token::Op(o)) if *o == op)
    }

    fn is_word(&self, word: &str) -> bool {
        matches!(self.peek(), Some(Token::Name(n)) if n == word)
    }

    fn expect_op(&mut self, op: &str) -> R<()> {
        if self.is_op(op) {
            self.pos += 1;
            Ok(())
        } else {
            err(format!("expected '{op}'"))
        }
    }

    fn enter(&mut self) -> R<()> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return err("expression nested too deeply");
        }
        Ok(())
    }

    fn expr(&mut self) -> R<Expr> {
        self.enter()?;
        let value = self.or_expr()?;
        let result = if self.is_word("if") {
            self.pos += 1;
            let cond = self.or_expr()?;
            if !self.is_word("else") {
                return err("expected 'else' in 'a if c else b'");
            }
            self.pos += 1;
            let otherwise = self.expr()?;
            Expr::IfElse {
                then: Box::new(value),
                cond: Box::new(cond),
                otherwise: Box::new(otherwise),
            }
        } else {
            value
        };
        self.depth -= 1;
        Ok(result)
    }

    fn or_expr(&mut self) -> R<Expr> {
        let mut left = self.and_expr()?;
        while self.is_word("or") {
            self.pos += 1;
            left = Expr::Or(Box::new(left), Box::new(self.and_expr()?));
        }
        Ok(left)
    }

    fn and_expr(&mut self) -> R<Expr> {
        let mut left = self.not_expr()?;
        while self.is_word("and") {
            self.pos += 1;
            left = Expr::And(Box::new(left), Box::new(self.not_expr()?));
        }
        Ok(left)
    }

    fn not_expr(&mut self) -> R<Expr> {
        if self.is_word("not") {
            self.pos += 1;
            self.enter()?;
            let inner = self.not_expr()?;
            self.depth -= 1;
            return Ok(Expr::Not(Box::new(inner)));
        }
        self.comparison()
    }

    fn comparison(&mut self) -> R<Expr> {
        let first = self.arith()?;
        let mut rest = Vec::new();
        loop {
            let op = match self.peek() {
                Some(Token::Op(o)) if matches!(*o, "==" | "!=" | "<" | "<=" | ">" | ">=") => *o,
                Some(Token::Name(n)) if n == "in" => "in",
                Some(Token::Name(n)) if n == "not" => {
                    if matches!(self.tokens.get(self.pos + 1), Some(Token::Name(m)) if m == "in") {
                        self.pos += 1;
                        "not in"
                    } else {
                        break;
                    }
                }
                _ => break,
            };
            self.pos += 1;
            rest.push((op, self.arith()?));
        }
        Ok(if rest.is_empty() {
            first
        } else {
            Expr::Compare(Box::new(first), rest)
        })
    }

    fn arith(&mut self) -> R<Expr> {
        let mut left = self.term()?;
        loop {
            let op = if self.is_op("+") {
                "+"
            } else if self.is_op("-") {
                "-"
            } else {
                break;
            };
            self.pos += 1;
            left = Expr::Binary(op, Box::new(left), Box::new(self.term()?));
        }
        Ok(left)
    }

    fn term(&mut self) -> R<Expr> {
        let mut left = self.factor()?;
        loop {
            let op = match self.peek() {
                Some(Token::Op(o)) if matches!(*o, "*" | "/" | "//" | "%") => *o,
                _ => break,
            };
            self.pos += 1;
            left = Expr::Binary(op, Box::new(left), Box::new(self.factor()?));
        }
        Ok(left)
    }

    fn factor(&mut self) -> R<Expr> {
        if self.is_op("-") || self.is_op("+") {
            let op = if self.is_op("-") { "-" } else { "+" };
            self.pos += 1;
            self.enter()?;
            let inner = self.factor()?;
            self.depth -= 1;
            return Ok(Expr::Unary(op, Box::new(inner)));
        }
        self.power()
    }

    fn power(&mut self) -> R<Expr> {
        let base = self.postfix()?;
        if self.is_op("**") {
            self.pos += 1;
            self.enter()?;
            let exponent = self.factor()?;
            self.depth -= 1;
            return Ok(Expr::Binary("**", Box::new(base), Box::new(exponent)));
        }
        Ok(base)
    }

    fn postfix(&mut self) -> R<Expr> {
        let mut e = self.primary()?;
        while self.is_op("[") {
            self.pos += 1;
            let index = self.expr()?;
            self.expect_op("]")?;
            e = Expr::Index(Box::new(e), Box::new(index));
        }
        Ok(e)
    }

    fn primary(&mut self) -> R<Expr> {
        let Some(token) = self.tokens.get(self.pos).cloned() else {
            return err("unexpected end of expression");
        };
        self.pos += 1;
        match token {
            Token::Int(i) => Ok(Expr::Const(Value::Int(i))),
            Token::Float(x) => Ok(Expr::Const(Value::Float(x))),
            Token::Str(s) => {
                // Adjacent string literals concatenate, as in Python.
                let mut s = s;
                while let Some(Token::Str(next)) = self.peek() {
                    s.push_str(next);
                    self.pos += 1;
                }
                Ok(Expr::Const(Value::Str(s)))
            }
            Token::Name(mut name) => {
                // Dotted names: math.pi, xacro.radians.
                while self.is_op(".") {
                    match self.tokens.get(self.pos + 1) {
                        Some(Token::Name(part)) => {
                            name = format!("{name}.{part}");
                            self.pos += 2;
                        }
                        _ => return err("expected a name after '.'"),
                    }
                }
                if self.is_op("(") {
                    self.pos += 1;
                    let mut args = Vec::new();
                    while !self.is_op(")") {
                        args.push(self.expr()?);
                        if !self.is_op(")") {
                            self.expect_op(",")?;
                        }
                    }
                    self.pos += 1;
                    return Ok(Expr::Call(name, args));
                }
                Ok(match name.as_str() {
                    "True" => Expr::Const(Value::Bool(true)),
                    "False" => Expr::Const(Value::Bool(false)),
                    "None" => Expr::Const(Value::None),
                    _ => Expr::Name(name),
                })
            }
            Token::Op("(") => {
                let inner = self.expr()?;
                if self.is_op(",") {
                    // A tuple: treat as a list.
                    let mut items = vec![inner];
                    while self.is_op(",") {
                        self.pos += 1;
                        if self.is_op(")") {
                            break;
                        }
                        items.push(self.expr()?);
                    }
                    self.expect_op(")")?;
                    return Ok(Expr::List(items));
                }
                self.expect_op(")")?;
                Ok(inner)
            }
            Token::Op("[") => {
                let mut items = Vec::new();
                while !self.is_op("]") {
                    items.push(self.expr()?);
                    if !self.is_op("]") {
                        self.expect_op(",")?;
                    }
                }
                self.pos += 1;
                Ok(Expr::List(items))
            }
            Token::Op(op) => err(format!("unexpected '{op}'")),
        }
    }
}

/// Looks names up for an expression: properties first, then constants and functions.
pub(crate) trait Names {
    /// The value of property `name`, or `Ok(None)` when there is none.
    fn property(&mut self, name: &str) -> R<Option<Value>>;
    /// `arg('name')` as `$(eval ...)` offers it.
    fn arg(&mut self, name: &str) -> R<Value>;
}

/// Parses and evaluates `src`.
pub(crate) fn evaluate(src: &str, names: &mut dyn Names) -> R<Value> {
    let tokens = tokenize(src)?;
    if tokens.is_empty() {
        return err("empty expression");
    }
    let mut parser = Parser {
        tokens,
        pos: 0,
        depth: 0,
    };
    let expr = parser.expr()?;
    if parser.pos != parser.tokens.len() {
        return err(format!(
            "unexpected {} after the expression",
            match &parser.tokens[parser.pos] {
                Token::Op(o) => format!("'{o}'"),
                Token::Name(n) => format!("'{n}'"),
                Token::Str(s) => format!("'{s}'"),
                Token::Int(i) => i.to_string(),
                Token::Float(x) => x.to_string(),
            }
        ));
    }
    eval(&expr, names)
}

fn eval(e: &Expr, names: &mut dyn Names) -> R<Value> {
    match e {
        Expr::Const(v) => Ok(v.clone()),
        Expr::Name(name) => {
            if let Some(v) = names.property(name)? {
                return Ok(v);
            }
            let bare = name.strip_prefix("math.").unwrap_or(name);
            match bare {
                "pi" => Ok(Value::Float(std::f64::consts::PI)),
                "e" => Ok(Value::Float(std::f64::consts::E)),
                "tau" => Ok(Value::Float(std::f64::consts::TAU)),
                "inf" => Ok(Value::Float(f64::INFINITY)),
                "nan" => Ok(Value::Float(f64::NAN)),
                _ => Err(ExprError::Undefined(name.clone())),
            }
        }
        Expr::Unary(op, inner) => {
            let v = eval(inner, names)?;
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
        Expr::Binary(op, a, b) => binary(op, eval(a, names)?, eval(b, names)?),
        Expr::Compare(first, rest) => {
            let mut left = eval(first, names)?;
            for (op, right) in rest {
                let right = eval(right, names)?;
                if !compare(op, &left, &right)? {
                    return Ok(Value::Bool(false));
                }
                left = right;
            }
            Ok(Value::Bool(true))
        }
        Expr::And(a, b) => {
            let left = eval(a, names)?;
            if left.truthy() {
                eval(b, names)
            } else {
                Ok(left)
            }
        }
        Expr::Or(a, b) => {
            let left = eval(a, names)?;
            if left.truthy() {
                Ok(left)
            } else {
                eval(b, names)
            }
        }
        Expr::Not(inner) => Ok(Value::Bool(!eval(inner, names)?.truthy())),
        Expr::IfElse {
            then,
            cond,
            otherwise,
        } => {
            if eval(cond, names)?.truthy() {
                eval(then, names)
            } else {
                eval(otherwise, names)
            }
        }
        Expr::List(items) => Ok(Value::List(
            items
                .iter()
                .map(|i| eval(i, names))
                .collect::<R<Vec<_>>>()?,
        )),
        Expr::Index(target, index) => subscript(eval(target, names)?, &eval(index, names)?),
        Expr::Call(name, args) => {
            let values = args.iter().map(|a| eval(a, names)).collect::<R<Vec<_>>>()?;
            call(name, values, names)
        }
    }
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
        ("+", Str(x), Str(y)) => return Ok(Str(format!("{x}{y}"))),
        ("+", List(x), List(y)) => return Ok(List([x.clone(), y.clone()].concat())),
        ("*", Str(s), n) | ("*", n, Str(s)) if n.int().is_some() => {
            let count = n.int().unwrap_or(0).clamp(0, 10_000) as usize;
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

fn compare(op: &str, a: &Value, b: &Value) -> R<bool> {
    if op == "in" || op == "not in" {
        let found = match (a, b) {
            (Value::Str(x), Value::Str(y)) => y.contains(x.as_str()),
            (x, Value::List(items)) => items.iter().any(|i| values_equal(x, i)),
            _ => {
                return err(format!(
                    "'in' needs a string or list on the right, found '{}'",
                    b.type_name()
                ));
            }
        };
        return Ok(found == (op == "in"));
    }
    if op == "==" {
        return Ok(values_equal(a, b));
    }
    if op == "!=" {
        return Ok(!values_equal(a, b));
    }
    let ordering = match (a, b) {
        (Value::Str(x), Value::Str(y)) => x.partial_cmp(y),
        _ => match (a.number(), b.number()) {
            (Some(x), Some(y)) => x.partial_cmp(&y),
            _ => {
                return err(format!(
                    "'{op}' not supported between '{}' and '{}'",
                    a.type_name(),
                    b.type_name()
                ));
            }
        },
    };
    let Some(ordering) = ordering else {
        return Ok(false);
    };
    Ok(match op {
        "<" => ordering.is_lt(),
        "<=" => ordering.is_le(),
        ">" => ordering.is_gt(),
        _ => ordering.is_ge(),
    })
}

fn values_equal(a: &Value, b: &Value) -> bool {
    match (a.number(), b.number()) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

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
fn call(name: &str, args: Vec<Value>, names: &mut dyn Names) -> R<Value> {
    let bare = name
        .strip_prefix("math.")
        .or_else(|| name.strip_prefix("xacro."))
        .unwrap_or(name);
    let builtin = Builtin { name, args };
    float_function(bare, &builtin)
        .or_else(|| integer_function(bare, &builtin))
        .or_else(|| conversion_function(bare, &builtin, names))
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

/// Type conversions, `len` and `arg`, or `None` when `bare` is none of them.
fn conversion_function(bare: &str, b: &Builtin<'_>, names: &mut dyn Names) -> Option<R<Value>> {
    Some(match bare {
        "int" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => parse_python_int(s.trim())
                .map(Value::Int)
                .ok_or_else(|| ExprError::Other(format!("int(): invalid literal '{s}'"))),
            other => other
                .number()
                .ok_or_else(|| ExprError::Other("int() expects a number".into()))
                .and_then(|x| to_int(x.trunc(), b.name)),
        }),
        "float" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => parse_python_float(s.trim())
                .map(Value::Float)
                .ok_or_else(|| ExprError::Other(format!("float(): invalid literal '{s}'"))),
            other => other
                .number()
                .map(Value::Float)
                .ok_or_else(|| ExprError::Other("float() expects a number".into())),
        }),
        "str" => b.arity(1).map(|()| Value::Str(b.args[0].to_string())),
        "bool" => b.arity(1).map(|()| Value::Bool(b.args[0].truthy())),
        "len" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => Ok(Value::Int(s.chars().count() as i64)),
            Value::List(l) => Ok(Value::Int(l.len() as i64)),
            other => err(format!(
                "object of type '{}' has no len()",
                other.type_name()
            )),
        }),
        "arg" => b.arity(1).and_then(|()| match &b.args[0] {
            Value::Str(s) => names.arg(s),
            _ => err("arg() expects a string"),
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    struct Table(HashMap<&'static str, Value>);

    impl Names for Table {
        fn property(&mut self, name: &str) -> R<Option<Value>> {
            Ok(self.0.get(name).cloned())
        }
        fn arg(&mut self, name: &str) -> R<Value> {
            Err(ExprError::Undefined(format!("arg {name}")))
        }
    }

    fn ev(src: &str) -> String {
        let mut t = Table(HashMap::from([
            ("r", Value::Float(0.033)),
            ("n", Value::Int(3)),
            ("name", Value::Str("left".into())),
            ("flag", Value::Bool(true)),
        ]));
        match evaluate(src, &mut t) {
            Ok(v) => v.to_string(),
            Err(e) => format!("error: {e}"),
        }
    }

    #[test]
    fn arithmetic_follows_python() {
        assert_eq!(ev("255/255"), "1.0");
        assert_eq!(ev("7//2"), "3");
        assert_eq!(ev("-7//2"), "-4");
        assert_eq!(ev("-7%3"), "2");
        assert_eq!(ev("2**10"), "1024");
        assert_eq!(ev("2**-1"), "0.5");
        assert_eq!(ev("-2**2"), "-4");
        assert_eq!(ev("r*2"), "0.066");
        assert_eq!(ev("n*2+1"), "7");
        assert_eq!(ev("0.1+0.2"), "0.30000000000000004");
        assert_eq!(ev("1e-5"), "1e-05");
        assert_eq!(ev("1/0"), "error: division by zero");
        assert_eq!(ev("round(2.5)"), "2");
        assert_eq!(ev("round(0.125, 2)"), "0.12");
    }

    #[test]
    fn logic_strings_and_functions() {
        assert_eq!(ev("name + '_wheel'"), "left_wheel");
        assert_eq!(ev("1 if name == 'left' else -1"), "1");
        assert_eq!(ev("-1 if name == 'right' else 1"), "1");
        assert_eq!(ev("flag and n > 2"), "True");
        assert_eq!(ev("not flag or 0 < n <= 3"), "True");
        assert_eq!(ev("radians(180)"), ev("pi"));
        assert_eq!(ev("math.cos(0)"), "1.0");
        assert_eq!(ev("atan2(0, -1)"), ev("pi"));
        assert_eq!(ev("max(1, n, 2)"), "3");
        assert_eq!(ev("[1, 2, 3][-1]"), "3");
        assert_eq!(ev("'ef' in name"), "True");
        assert_eq!(ev("int('42') + float('0.5')"), "42.5");
        assert_eq!(ev("sqrt(-1)"), "error: sqrt(): math domain error");
        assert_eq!(ev("missing * 2"), "error: undefined property \"missing\"");
        assert_eq!(ev("1 +"), "error: unexpected end of expression");
        assert_eq!(ev("(1"), "error: expected ')'");
        assert!(ev(&"(".repeat(10_000)).contains("nested too deeply"));
    }

    #[test]
    fn literals_read_like_xacro() {
        assert_eq!(Value::literal("3"), Value::Int(3));
        assert_eq!(Value::literal("0.5"), Value::Float(0.5));
        assert_eq!(Value::literal("true"), Value::Bool(true));
        assert_eq!(Value::literal("1_000"), Value::Str("1_000".into()));
        assert_eq!(Value::literal("'0.5'"), Value::Str("0.5".into()));
        assert_eq!(Value::literal("base_link"), Value::Str("base_link".into()));
        assert_eq!(Value::literal("infinity"), Value::Float(f64::INFINITY));
        assert_eq!(Value::literal("1 2"), Value::Str("1 2".into()));
    }
}
