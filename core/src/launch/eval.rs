//! `$(eval EXPR)`: the Python expressions roslaunch evaluates, by the evaluator xacro uses too
//! (`rover_pyexpr`), with what roslaunch adds to Python's `eval`: bare names read as args
//! (converted like `<param>` values), `arg()`, `env()`, `optenv()`, `find()`, `anon()`,
//! `dirname()`, `true`/`false`, and the `math` module. The result prints as Python's `str()`.

use rover_pyexpr::{ExprError, Host, Value};

use super::value::{ParamValue, convert_value};

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

/// Evaluates `expr` and returns its value as Python's `str()` prints it.
pub(crate) fn eval(expr: &str, host: &mut dyn EvalHost) -> Result<String, String> {
    if expr.contains("__") {
        return Err("$(eval ...) may not contain double underscore expressions".to_owned());
    }
    match rover_pyexpr::evaluate(expr, &mut Launch(host)) {
        Ok(value) => Ok(value.to_string()),
        Err(ExprError::Undefined(name)) => Err(format!("name '{name}' is not defined")),
        Err(ExprError::Other(message)) => Err(format!("{message} (in \"{expr}\")")),
    }
}

/// roslaunch's names and functions over a launch's [`EvalHost`].
struct Launch<'h>(&'h mut dyn EvalHost);

/// The `math` module's constants, which roslaunch offers before the args.
const CONSTANTS: [&str; 5] = ["pi", "e", "tau", "inf", "nan"];

impl Host for Launch<'_> {
    fn name(&mut self, name: &str) -> Result<Option<Value>, ExprError> {
        match name {
            "true" => Ok(Some(Value::Bool(true))),
            "false" => Ok(Some(Value::Bool(false))),
            _ if CONSTANTS.contains(&name) || name.starts_with("math.") => Ok(None),
            _ => {
                let text = self
                    .0
                    .arg(name)
                    .map_err(|e| ExprError::Other(format!("name '{name}' is not defined: {e}")))?;
                arg_value(&text).map(Some)
            }
        }
    }

    fn call(&mut self, name: &str, args: &[Value]) -> Result<Option<Value>, ExprError> {
        let text = |i: usize| -> Result<&str, ExprError> {
            match args.get(i) {
                Some(Value::Str(s)) => Ok(s),
                Some(other) => Err(ExprError::Other(format!(
                    "{name}() expects a string, found {}",
                    other.type_name()
                ))),
                None => Err(ExprError::Other(format!("{name}() is missing an argument"))),
            }
        };
        let count = |n: std::ops::RangeInclusive<usize>| {
            if n.contains(&args.len()) {
                Ok(())
            } else {
                Err(ExprError::Other(format!(
                    "{name}() takes {n:?} arguments, {} given",
                    args.len()
                )))
            }
        };
        let other = ExprError::Other;
        Ok(Some(match name {
            "arg" => {
                count(1..=1)?;
                arg_value(&self.0.arg(text(0)?).map_err(other)?)?
            }
            "env" => {
                count(1..=1)?;
                let var = text(0)?;
                Value::Str(
                    std::env::var(var)
                        .map_err(|_| other(format!("environment variable '{var}' is not set")))?,
                )
            }
            "optenv" => {
                count(1..=2)?;
                let default = if args.len() == 2 { text(1)? } else { "" };
                Value::Str(std::env::var(text(0)?).unwrap_or_else(|_| default.to_owned()))
            }
            "find" => {
                count(1..=1)?;
                Value::Str(self.0.find(text(0)?).map_err(other)?)
            }
            "anon" => {
                count(1..=1)?;
                Value::Str(self.0.anon(text(0)?))
            }
            "dirname" => {
                count(0..=0)?;
                Value::Str(self.0.dirname().map_err(other)?)
            }
            _ => return Ok(None),
        }))
    }
}

/// An arg's text as roslaunch hands it to Python: converted like a `<param>` of type `auto`.
fn arg_value(text: &str) -> Result<Value, ExprError> {
    Ok(
        match convert_value(text, "auto").map_err(ExprError::Other)? {
            ParamValue::Bool(b) => Value::Bool(b),
            ParamValue::Int(i) => Value::Int(i),
            ParamValue::Double(d) => Value::Float(d),
            ParamValue::Str(s) => Value::Str(s),
            other => Value::Str(other.as_text()),
        },
    )
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
