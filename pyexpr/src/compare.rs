//! Python's comparisons: `==` across numbers of any type, orderings of numbers and of strings,
//! `in` on strings and lists.

use crate::Value;
use crate::host::{R, err};

/// `a OP b` for a comparison operator (`==`, `!=`, `<`, `<=`, `>`, `>=`, `in`, `not in`).
pub(crate) fn compare(op: &str, a: &Value, b: &Value) -> R<bool> {
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

/// Python's `==`: numbers by value (`1 == 1.0 == True`), anything else structurally.
fn values_equal(a: &Value, b: &Value) -> bool {
    match (a.number(), b.number()) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}
