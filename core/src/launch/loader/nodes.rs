//! `<node>` (with its `<remap>`, `<param>`, `<rosparam>` and `<env>` children and the private
//! params of its scope), and `<remap>` and `<env>`.

use roxmltree::Node;

use super::state::{Ctx, FileReader, Loader, global_ns};
use crate::launch::model::{LaunchError, LaunchNode, Output, Param, canonical_name, ns_join};

impl Loader<'_> {
    pub(super) fn remap(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(String, String), LaunchError> {
        let from = canonical_name(&self.req(r, tag, "from", ctx)?);
        let to = canonical_name(&self.req(r, tag, "to", ctx)?);
        if from.is_empty() || to.is_empty() {
            return Err(r.err(tag, "remap from/to attributes cannot be empty"));
        }
        Ok((from, to))
    }

    pub(super) fn env(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(String, String), LaunchError> {
        let name = self.req(r, tag, "name", ctx)?;
        let value = self.req(r, tag, "value", ctx)?;
        if name.is_empty() {
            return Err(r.err(tag, "<env> 'name' must be non-empty"));
        }
        Ok((name, value))
    }

    pub(super) fn node(
        &mut self,
        r: &FileReader<'_, '_>,
        tag: Node<'_, '_>,
        ctx: &Ctx,
    ) -> Result<(), LaunchError> {
        let name = self.req(r, tag, "name", ctx)?;
        if name.is_empty() || name.contains('/') {
            return Err(r.err(
                tag,
                format!("illegal <node> name \"{name}\" (a base name, without '/')"),
            ));
        }
        let ns = self.opt(r, tag, "ns", ctx)?;
        if ns.as_deref() == Some("") {
            return Err(r.err(tag, "<node> has an empty 'ns' attribute"));
        }
        let child = ctx.child(ns.as_deref());
        self.clear_params(r, tag, &child, Some(&name))?;
        let param_ns = global_ns(&ns_join(&child.ns, &name));
        let pkg = self.req(r, tag, "pkg", ctx)?;
        let node_type = self.req(r, tag, "type", ctx)?;
        let args = self.opt(r, tag, "args", ctx)?.unwrap_or_default();
        let output = match self.opt(r, tag, "output", ctx)?.as_deref() {
            None | Some("log") => Output::Log,
            Some("screen") => Output::Screen,
            Some(other) => {
                return Err(r.err(tag, format!("output=\"{other}\": expected log or screen")));
            }
        };
        let respawn = self.flag(r, tag, "respawn", ctx)?;
        let required = self.flag(r, tag, "required", ctx)?;
        let respawn_delay_s = match self.opt(r, tag, "respawn_delay", ctx)? {
            None => 0.0,
            Some(v) => v
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|d| d.is_finite() && *d >= 0.0)
                .ok_or_else(|| {
                    r.err(
                        tag,
                        format!("respawn_delay=\"{v}\": expected seconds (a number >= 0)"),
                    )
                })?,
        };
        let launch_prefix = self
            .opt(r, tag, "launch-prefix", ctx)?
            .filter(|p| !p.is_empty());
        let cwd = self.opt(r, tag, "cwd", ctx)?;
        let mut node_ctx = child.clone();
        node_ctx.ns = param_ns.clone();
        let mut local = Vec::new();
        for t in tag.children().filter(Node::is_element) {
            self.check_attributes(r, t);
            if !self.condition(r, t, ctx)? {
                continue;
            }
            match t.tag_name().name() {
                "remap" => {
                    let (from, to) = self.remap(r, t, ctx)?;
                    node_ctx.add_remap(from, to);
                }
                "param" => {
                    if let Some((name, param)) = self.param(r, t, &node_ctx, true)? {
                        local.retain(|(k, _): &(String, Param)| *k != name);
                        local.push((name, param));
                    }
                }
                "rosparam" => self.rosparam(r, t, &node_ctx)?,
                "env" => {
                    let pair = self.env(r, t, ctx)?;
                    node_ctx.env.push(pair);
                }
                other => self
                    .out
                    .warnings
                    .push(format!("{}: unrecognized <{other}> inside <node>", r.at(t))),
            }
        }
        for (key, param) in ctx.private.iter().chain(local.iter()) {
            let key = key.strip_prefix('~').unwrap_or(key);
            self.set(format!("{param_ns}{key}"), param.clone(), r, tag)?;
        }
        self.out.nodes.push(LaunchNode {
            pkg,
            node_type,
            name,
            namespace: child.ns.clone(),
            args,
            remaps: node_ctx.remaps,
            env: node_ctx.env,
            output,
            respawn,
            respawn_delay_s,
            required,
            launch_prefix,
            cwd,
            at: r.at(tag),
        });
        Ok(())
    }
}
