//! The parser: Python's grammar for expressions, from `a if c else b` down to literals,
//! into a tree the evaluator walks.

use crate::Value;
use crate::host::{R, err};
use crate::lex::Token;

/// A parsed expression.
#[derive(Debug, Clone)]
pub(crate) enum Expr {
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

/// Recursive descent over the tokens.
pub(crate) struct Parser {
    pub(crate) tokens: Vec<Token>,
    pub(crate) pos: usize,
    pub(crate) depth: usize,
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

    /// One whole expression (`a if c else b` and everything below it).
    pub(crate) fn expr(&mut self) -> R<Expr> {
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
