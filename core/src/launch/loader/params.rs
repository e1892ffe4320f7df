//! `<param>` (`value`, `textfile`, `binfile`, `command`: xacro in-process, anything else as a
//! process) and `<rosparam>` (load, delete, dump), and setting parameters.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use roxmltree::Node;

use super::files::{read_bytes, read_text};
use super::state::{Ctx, FileReader, Loader};
use crate::launch::model::{LaunchError, Param, ParamSource, canonical_name, ns_join};
use crate::launch::shell::shell_split;
use crate::launch::value::{ParamValue, convert_value, parse_yaml};

impl Loader<'_> {
    /// `<param>`: into the launch's params, or (private, or inside a node) returned for the
    /// node(s) it belongs to.
    pub(super) fn param(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
        in_node: bool,
    ) -> Result<Option<(String, Param)>, LaunchError> {
        let ty = tag
            .attribute("type")
            .unwrap_or("auto")
            .trim()
            .to_ascii_lowercase();
        let value = self.opt(r, tag, "value", ctx)?;
        let textfile = self.opt(r, tag, "textfile", ctx)?;
        let binfile = self.opt(r, tag, "binfile", ctx)?;
        let command = self.opt(r, tag, "command", ctx)?;
        let given = [&value, &textfile, &binfile, &command]
            .iter()
            .filter(|v| v.is_some())
            .count();
        if given != 1 {
            return Err(r.err(
                tag,
                "<param> must have exactly one of value, textfile, binfile and command",
            ));
        }
        let name = self.req(r, tag, "name", ctx)?.trim().to_owned();
        let bad = |e: String| r.err(tag, format!("<param name=\"{name}\">: {e}"));
        let (value, source) = if let Some(v) = value {
            (
                convert_value(v.trim(), &ty).map_err(bad)?,
                ParamSource::Value,
            )
        } else if let Some(f) = textfile {
            let text = read_text(Path::new(&f)).map_err(bad)?;
            (
                convert_value(&text, &ty).map_err(bad)?,
                ParamSource::TextFile(f.into()),
            )
        } else if let Some(f) = binfile {
            let bytes = read_bytes(Path::new(&f)).map_err(bad)?;
            (ParamValue::Binary(bytes), ParamSource::BinFile(f.into()))
        } else {
            let command = command.unwrap_or_default();
            let (text, source) = self.command(&command, &ctx.file).map_err(bad)?;
            (convert_value(&text, &ty).map_err(bad)?, source)
        };
        let param = Param {
            value,
            source,
            at: r.at(tag),
        };
        if name.starts_with('~') || in_node {
            return Ok(Some((name, param)));
        }
        self.set(ns_join(&ctx.ns, &name), param, r, tag)?;
        Ok(None)
    }

    /// Sets a parameter; a mapping becomes one parameter per key.
    pub(super) fn set(
        &mut self,
        name: String,
        param: Param,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
    ) -> Result<(), LaunchError> {
        if name.starts_with('~') {
            return Err(r.err(tag, format!("private name \"{name}\" outside a node")));
        }
        let name = canonical_name(&name);
        if let ParamValue::Map(entries) = param.value {
            for (key, value) in entries {
                let p = Param {
                    value,
                    source: param.source.clone(),
                    at: param.at.clone(),
                };
                self.set(ns_join(&format!("{name}/"), &key), p, r, tag)?;
            }
            return Ok(());
        }
        if name == "/" {
            return Err(r.err(
                tag,
                "cannot set a non-mapping value on the root namespace '/'",
            ));
        }
        self.out.params.insert(name, param);
        Ok(())
    }

    /// Runs a `command` param: xacro in-process, anything else as a process.
    fn command(&self, command: &str, file: &Path) -> Result<(String, ParamSource), String> {
        let words = shell_split(command)?;
        let Some(first) = words.first() else {
            return Err("the command is empty".to_owned());
        };
        let program = Path::new(first)
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let xacro_args = if program == "xacro" || program == "xacro.py" {
            Some(&words[1..])
        } else if program == "rosrun" && words.get(1).map(String::as_str) == Some("xacro") {
            words.get(3..)
        } else {
            None
        };
        if let Some(args) = xacro_args {
            let (path, xargs) = xacro_command(args)?;
            let path = if path.is_relative() {
                file.parent().map(|d| d.join(&path)).unwrap_or(path)
            } else {
                path
            };
            let expanded =
                rover_sim::description::expand_xacro(&path, &xargs, &self.options.resources)
                    .map_err(|e| format!("xacro: {e}"))?;
            return Ok((
                expanded.text,
                ParamSource::Xacro {
                    file: path,
                    args: xargs,
                },
            ));
        }
        if !self.options.run_commands {
            return Err(format!("commands are not run here: \"{command}\""));
        }
        let output = std::process::Command::new(first)
            .args(&words[1..])
            .stdin(std::process::Stdio::null())
            .output()
            .map_err(|e| format!("cannot run \"{first}\": {e}"))?;
        if !output.status.success() {
            return Err(format!(
                "command \"{command}\" failed ({}): {}",
                output.status,
                String::from_utf8_lossy(&output.stderr).trim()
            ));
        }
        let text = String::from_utf8(output.stdout)
            .map_err(|_| format!("command \"{command}\" printed something that is not UTF-8"))?;
        Ok((text, ParamSource::Command(words)))
    }

    pub(super) fn rosparam(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(), LaunchError> {
        let command = self
            .opt(r, tag, "command", ctx)?
            .unwrap_or_else(|| "load".to_owned());
        let ns = self.opt(r, tag, "ns", ctx)?.unwrap_or_default();
        let file = self.opt(r, tag, "file", ctx)?;
        let param = self.opt(r, tag, "param", ctx)?.unwrap_or_default();
        let subst_value = self.flag(r, tag, "subst_value", ctx)?;
        let param = ns_join(&ns, &param);
        let full = if param.is_empty() {
            ctx.ns.clone()
        } else {
            ns_join(&ctx.ns, &param)
        };
        match command.as_str() {
            "load" => {
                let text = match &file {
                    Some(f) => read_text(Path::new(f)).map_err(|e| r.err(tag, e))?,
                    None => tag
                        .children()
                        .filter(Node::is_text)
                        .filter_map(|t| t.text())
                        .collect(),
                };
                let text = if subst_value {
                    self.resolve(r, tag, &text, ctx)?
                } else {
                    text
                };
                let value = parse_yaml(&text).map_err(|e| {
                    r.err(
                        tag,
                        match &file {
                            Some(f) => format!("{f}: {e}"),
                            None => format!("<rosparam>: {e}"),
                        },
                    )
                })?;
                if param.is_empty() && !matches!(value, ParamValue::Map(_)) {
                    return Err(r.err(
                        tag,
                        "<rosparam> needs a 'param' attribute for a value that is not a mapping",
                    ));
                }
                let p = Param {
                    value,
                    source: ParamSource::Yaml(file.map(PathBuf::from)),
                    at: r.at(tag),
                };
                self.set(full, p, r, tag)
            }
            "delete" => {
                if file.is_some() {
                    return Err(r.err(tag, "'file' attribute is invalid with the 'delete' command"));
                }
                self.out.deletes.push(canonical_name(&full));
                Ok(())
            }
            "dump" => {
                self.out.warnings.push(format!(
                    "{}: <rosparam command=\"dump\"> is not done by rover launch",
                    r.at(tag)
                ));
                Ok(())
            }
            other => Err(r.err(
                tag,
                format!("<rosparam command=\"{other}\">: expected load, dump or delete"),
            )),
        }
    }
}

/// xacro's command line: options, the file, and `name:=value` args.
fn xacro_command(words: &[String]) -> Result<(PathBuf, BTreeMap<String, String>), String> {
    let mut file = None;
    let mut args = BTreeMap::new();
    let mut i = 0;
    while i < words.len() {
        let w = &words[i];
        if let Some((name, value)) = w.split_once(":=") {
            args.insert(name.to_owned(), value.to_owned());
        } else if w == "-o" || w == "--output" {
            i += 1;
        } else if w.starts_with('-') {
            // --inorder, --xacro-ns, -v ...: nothing rover's xacro needs.
        } else if file.is_none() {
            file = Some(PathBuf::from(w));
        } else {
            return Err(format!(
                "xacro: a second file \"{w}\" (expected one input file)"
            ));
        }
        i += 1;
    }
    let file = file.ok_or_else(|| "xacro: no input file".to_owned())?;
    Ok((file, args))
}
