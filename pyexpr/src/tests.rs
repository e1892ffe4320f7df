//! The evaluator against Python's own results (the values Python 3 gives).

use super::*;
use crate::host::R;
use std::collections::HashMap;

struct Table(HashMap<&'static str, Value>);

impl Host for Table {
    fn name(&mut self, name: &str) -> R<Option<Value>> {
        Ok(self.0.get(name).cloned())
    }
    fn call(&mut self, name: &str, args: &[Value]) -> R<Option<Value>> {
        Ok(match (name, args) {
            ("twice", [Value::Int(i)]) => Some(Value::Int(2 * i)),
            _ => None,
        })
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
    assert_eq!(ev("missing * 2"), "error: name \"missing\" is not defined");
    assert_eq!(ev("1 +"), "error: unexpected end of expression");
    assert_eq!(ev("(1"), "error: expected ')'");
    assert!(ev(&"(".repeat(10_000)).contains("nested too deeply"));
}

#[test]
fn host_names_and_functions_come_first() {
    assert_eq!(ev("twice(n) + 1"), "7");
    assert_eq!(ev("twice(1.5)"), "error: name \"twice()\" is not defined");
    assert_eq!(ev("math.pi == pi"), "True");
}

#[test]
fn numbers_and_text_read_as_python_reads_them() {
    assert_eq!(ev("1_000 + 1"), "1001");
    assert_eq!(ev("int(' 42 ') + int('1_0')"), "52");
    assert_eq!(ev("float('1e3')"), "1000.0");
    assert_eq!(ev("str()"), "");
    assert_eq!(parse_int("_1"), None);
    assert_eq!(parse_int("1__0"), None);
    assert_eq!(parse_float("Infinity"), Some(f64::INFINITY));
    assert_eq!(parse_float("e5"), None);
    assert_eq!(float_repr(3.0), "3.0");
    assert_eq!(float_repr(-0.0), "-0.0");
    assert_eq!(float_repr(1e-7), "1e-07");
    assert_eq!(float_repr(1.5e20), "1.5e+20");
    assert_eq!(float_repr(1e16), "1e+16");
    assert_eq!(float_repr(123456789012345.6), "123456789012345.6");
}

#[test]
fn hostile_input_is_refused_not_allocated() {
    assert!(ev("'x' * 100000000").starts_with("error: the string grows too long"));
    assert!(ev("2 ** 99").starts_with("error: integer overflow"));
    assert!(ev("'abc").starts_with("error: unterminated string"));
    assert!(ev("").starts_with("error: empty expression"));
}
