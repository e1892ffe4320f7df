//! Substitution args in attribute values: `$(arg)`, `$(find)`, `$(env)`, `$(optenv)`,
//! `$(anon)`, `$(dirname)` and `$(eval)`, with roslaunch's rules: a value that is all one
//! `$(eval ...)` is a Python expression; otherwise `env`, `optenv`, `dirname`, `anon` and `arg`
//! are replaced first, then `find`; there are no escapes, and a `$` inside `$(...)` is an error.

use super::eval::{EvalHost, eval};

/// Resolves the substitution args in `text`.
pub(crate) fn resolve(text: &str, host: &mut dyn EvalHost) -> Result<String, String> {
    if !text.contains('$') {
        return Ok(text.to_owned());
    }
    if let Some(expr) = text
        .strip_prefix("$(eval ")
        .and_then(|rest| rest.strip_suffix(')'))
    {
        return eval(expr, host);
    }
    let mut resolved = text.to_owned();
    for pass in [Pass::Early, Pass::Find] {
        for inner in collect(&resolved, text)? {
            let words: Vec<&str> = inner.split(' ').filter(|w| !w.is_empty()).collect();
            let (command, args) = match words.split_first() {
                Some((c, a)) => (*c, a),
                None => return Err(format!("empty substitution $() in \"{text}\"")),
            };
            let value = match (pass, command) {
                (Pass::Early, "env") => {
                    let [name] = args else {
                        return Err(format!(
                            "$(env var) must specify one environment variable [{inner}]"
                        ));
                    };
                    std::env::var(name).map_err(|_| {
                        format!("environment variable '{name}' is not set (in $({inner}))")
                    })?
                }
                (Pass::Early, "optenv") => {
                    let Some((name, default)) = args.split_first() else {
                        return Err(format!(
                            "$(optenv var) must specify an environment variable [{inner}]"
                        ));
                    };
                    std::env::var(name).unwrap_or_else(|_| default.join(" "))
                }
                (Pass::Early, "dirname") => host.dirname()?,
                (Pass::Early, "anon") => {
                    let [id] = args else {
                        return Err(format!("$(anon var) must specify one name [{inner}]"));
                    };
                    host.anon(id)
                }
                (Pass::Early, "arg") => {
                    let [name] = args else {
                        return Err(format!("$(arg var) must specify one arg [{inner}]"));
                    };
                    host.arg(name)?
                }
                (Pass::Find, "find") => {
                    let [package] = args else {
                        return Err(format!("$(find pkg) accepts only one argument [{inner}]"));
                    };
                    host.find(package)?
                }
                (_, "env" | "optenv" | "dirname" | "anon" | "arg" | "find") => continue,
                (_, "eval") => {
                    return Err(format!(
                        "$(eval ...) must be the whole attribute value, found \"{text}\""
                    ));
                }
                (_, other) => {
                    return Err(format!(
                        "unknown substitution $({other} ...); expected one of find, env, optenv, dirname, anon, arg, eval"
                    ));
                }
            };
            resolved = resolved.replace(&format!("$({inner})"), &value);
        }
    }
    Ok(resolved)
}

#[derive(Clone, Copy)]
enum Pass {
    Early,
    Find,
}

/// The insides of the `$(...)` in `s`, in order (roslaunch's state machine).
fn collect(s: &str, original: &str) -> Result<Vec<String>, String> {
    #[derive(PartialEq)]
    enum State {
        Out,
        Dollar,
        LeftParen,
        In,
    }
    let mut state = State::Out;
    let mut buf = String::new();
    let mut out = Vec::new();
    for c in s.chars() {
        match c {
            '$' => match state {
                State::Out => state = State::Dollar,
                State::Dollar => {}
                _ => {
                    return Err(format!(
                        "dollar signs '$' cannot be inside of substitution args [{original}]"
                    ));
                }
            },
            '(' => match state {
                State::Dollar => state = State::LeftParen,
                State::Out => {}
                _ => {
                    return Err(format!(
                        "invalid left parenthesis '(' in substitution args [{original}]"
                    ));
                }
            },
            ')' => {
                if state == State::In {
                    out.push(std::mem::take(&mut buf));
                }
                state = State::Out;
            }
            _ if state == State::Dollar => state = State::Out,
            _ if state == State::LeftParen => state = State::In,
            _ => {}
        }
        if state == State::In {
            buf.push(c);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Host;

    impl EvalHost for Host {
        fn arg(&mut self, name: &str) -> Result<String, String> {
            match name {
                "x" => Ok("1.5".into()),
                "pkg" => Ok("mine".into()),
                _ => Err(format!("arg '{name}' is not defined")),
            }
        }
        fn find(&mut self, package: &str) -> Result<String, String> {
            Ok(format!("/ws/{package}"))
        }
        fn anon(&mut self, id: &str) -> String {
            format!("{id}_42")
        }
        fn dirname(&mut self) -> Result<String, String> {
            Ok("/ws/mine/launch".into())
        }
    }

    #[test]
    fn substitutions_resolve_in_roslaunch_order() {
        let r = |s: &str| resolve(s, &mut Host);
        assert_eq!(r("plain").as_deref(), Ok("plain"));
        assert_eq!(r("$(arg x)m").as_deref(), Ok("1.5m"));
        assert!(r("$(find $(arg pkg))/urdf").is_err());
        assert_eq!(
            r("$(find mine)/urdf/$(arg x)").as_deref(),
            Ok("/ws/mine/urdf/1.5")
        );
        assert_eq!(r("$(anon talker)").as_deref(), Ok("talker_42"));
        assert_eq!(
            r("$(dirname)/a.yaml").as_deref(),
            Ok("/ws/mine/launch/a.yaml")
        );
        assert_eq!(r("$(optenv ROVER_SURELY_UNSET a b)").as_deref(), Ok("a b"));
        assert_eq!(r("$(eval x * 2)").as_deref(), Ok("3.0"));
        assert!(r("$(arg nope)").is_err());
        assert!(r("$(frobnicate x)").is_err());
        assert!(r("a $(eval 1) b").is_err());
    }
}
