//! Attributes: which each tag knows, their substitutions resolved, required ones, booleans,
//! and `if`/`unless`.

use roxmltree::Node;

use super::scope::Scope;
use super::state::{Ctx, FileReader, Loader};
use crate::launch::model::LaunchError;
use crate::launch::subst;
use crate::launch::value::parse_bool;

/// Attributes each tag knows (besides `if` and `unless`).
fn known_attributes(tag: &str) -> &'static [&'static str] {
    match tag {
        "arg" => &["name", "value", "default", "doc"],
        "param" => &["name", "value", "type", "textfile", "binfile", "command"],
        "rosparam" => &["command", "ns", "file", "param", "subst_value"],
        "node" => &[
            "pkg",
            "type",
            "name",
            "args",
            "machine",
            "respawn",
            "respawn_delay",
            "required",
            "ns",
            "clear_params",
            "output",
            "cwd",
            "launch-prefix",
        ],
        "remap" => &["from", "to"],
        "env" => &["name", "value"],
        "include" => &["file", "ns", "clear_params", "pass_all_args"],
        "group" => &["ns", "clear_params"],
        "launch" => &["deprecated"],
        _ => &[],
    }
}

impl Loader<'_> {
    pub(super) fn check_attributes(&mut self, r: &FileReader<'_, '_>, tag: Node<'_, '_>) {
        let known = known_attributes(tag.tag_name().name());
        for a in tag.attributes() {
            let name = a.name();
            if !known.contains(&name) && name != "if" && name != "unless" && !known.is_empty() {
                self.out.warnings.push(format!(
                    "{}: unknown <{}> attribute '{name}'",
                    r.at(tag),
                    tag.tag_name().name()
                ));
            }
        }
    }

    pub(super) fn resolve(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        text: &str,
        ctx: &Ctx,
    ) -> Result<String, LaunchError> {
        let mut scope = Scope {
            args: &ctx.args,
            file: &ctx.file,
            anon: &mut self.anon,
            resources: &self.options.resources,
        };
        subst::resolve(text, &mut scope).map_err(|e| r.err(tag, e))
    }

    pub(super) fn opt(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        name: &str,
        ctx: &Ctx,
    ) -> Result<Option<String>, LaunchError> {
        match tag.attribute(name) {
            Some(text) => self.resolve(r, tag, text, ctx).map(Some),
            None => Ok(None),
        }
    }

    pub(super) fn req(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        name: &str,
        ctx: &Ctx,
    ) -> Result<String, LaunchError> {
        self.opt(r, tag, name, ctx)?.ok_or_else(|| {
            r.err(
                tag,
                format!(
                    "<{}> is missing its required attribute '{name}'",
                    tag.tag_name().name()
                ),
            )
        })
    }

    pub(super) fn flag(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        name: &str,
        ctx: &Ctx,
    ) -> Result<bool, LaunchError> {
        match self.opt(r, tag, name, ctx)? {
            None => Ok(false),
            Some(v) => match v.to_ascii_lowercase().as_str() {
                "true" => Ok(true),
                "false" => Ok(false),
                _ => Err(r.err(tag, format!("{name}=\"{v}\": expected true or false"))),
            },
        }
    }

    /// `if` / `unless`.
    pub(super) fn condition(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<bool, LaunchError> {
        let if_value = self.opt(r, tag, "if", ctx)?;
        let unless_value = self.opt(r, tag, "unless", ctx)?;
        let as_bool = |v: &str| {
            parse_bool(v).ok_or_else(|| {
                r.err(
                    tag,
                    format!("if/unless value \"{v}\": expected true, false, 1 or 0"),
                )
            })
        };
        match (if_value, unless_value) {
            (Some(_), Some(_)) => {
                Err(r.err(tag, "cannot set both 'if' and 'unless' on the same tag"))
            }
            (Some(v), None) => as_bool(&v),
            (None, Some(v)) => as_bool(&v).map(|b| !b),
            (None, None) => Ok(true),
        }
    }
}
