//! Python's tokens, as far as the expressions use them.

use crate::host::{ExprError, R, err};
use crate::{parse_float, parse_int};

/// One token.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Token {
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

/// Splits `src` into tokens.
pub(crate) fn tokenize(src: &str) -> R<Vec<Token>> {
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
            while i < bytes.len() && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'_'))
            {
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
                    while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'_') {
                        i += 1;
                    }
                }
            }
            let text = &src[start..i];
            let bad = || ExprError::Other(format!("bad number '{text}'"));
            tokens.push(if float {
                Token::Float(parse_float(text).ok_or_else(bad)?)
            } else {
                match parse_int(text) {
                    Some(v) => Token::Int(v),
                    // Python's ints grow; rover's are 64-bit, so a longer literal reads as the
                    // float it is nearest to.
                    None => Token::Float(parse_float(text).ok_or_else(bad)?),
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

impl Token {
    /// The token as an error message names it.
    pub(crate) fn describe(&self) -> String {
        match self {
            Token::Op(o) => format!("'{o}'"),
            Token::Name(n) => format!("'{n}'"),
            Token::Str(s) => format!("'{s}'"),
            Token::Int(i) => i.to_string(),
            Token::Float(x) => x.to_string(),
        }
    }
}
