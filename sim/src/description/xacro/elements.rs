//! Element expansion: walking children, dispatching the `xacro:` elements, and computed
//! (`xacro:element`) and plain elements.

use std::rc::Rc;

use super::expander::{Expander, Macro, OElem, ONode, Prop, XElem, XNode};
use crate::error::Result;

/// Most output elements accepted, so that runaway expansion fails instead of eating memory.
const MAX_OUTPUT_ELEMENTS: usize = 2_000_000;

impl Expander<'_> {
    /// Expands `children` in `scope`, appending to `out`; `xacro:attribute`s land in `attrs`.
    pub(super) fn process(
        &mut self,
        children: &[XNode],
        scope: usize,
        out: &mut Vec<ONode>,
        attrs: &mut Vec<(String, String)>,
    ) -> Result<()> {
        for child in children {
            match child {
                XNode::Text(text) => {
                    if text.trim().is_empty() {
                        continue;
                    }
                    let value = self.eval_text(text, scope)?.to_string();
                    out.push(ONode::Text(value));
                }
                XNode::Elem(e) => {
                    self.at = (e.file, e.line);
                    match &e.xacro {
                        Some(local) => self.xacro_element(e, local, scope, out, attrs)?,
                        None => {
                            self.count_element()?;
                            let mut elem_attrs = Vec::with_capacity(e.attrs.len());
                            for (name, value) in &e.attrs {
                                elem_attrs.push((
                                    name.clone(),
                                    self.eval_text(value, scope)?.to_string(),
                                ));
                            }
                            let mut children = Vec::new();
                            let mut extra = Vec::new();
                            self.process(&e.children, scope, &mut children, &mut extra)?;
                            set_attrs(&mut elem_attrs, extra);
                            out.push(ONode::Elem(OElem {
                                name: e.name.clone(),
                                attrs: elem_attrs,
                                children,
                                file: e.file,
                                line: e.line,
                            }));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn count_element(&mut self) -> Result<()> {
        self.elements_out += 1;
        if self.elements_out > MAX_OUTPUT_ELEMENTS {
            return Err(self.error(format!(
                "the expansion grew past {MAX_OUTPUT_ELEMENTS} elements; runaway macro?"
            )));
        }
        Ok(())
    }

    fn xacro_element(
        &mut self,
        e: &Rc<XElem>,
        local: &str,
        scope: usize,
        out: &mut Vec<ONode>,
        attrs: &mut Vec<(String, String)>,
    ) -> Result<()> {
        match local {
            "property" => self.define_property(e, scope),
            "arg" => {
                let name = self.required(e, "name")?.to_owned();
                if !self.args.contains_key(&name)
                    && !self.arg_defaults.contains_key(&name)
                    && let Some(default) = self.attr(e, "default")
                {
                    let value = self.eval_text(default, scope)?.to_string();
                    self.arg_defaults.insert(name, value);
                }
                Ok(())
            }
            "include" => self.include(e, scope, out),
            "if" | "unless" => {
                let text = self.required(e, "value")?;
                let value = self.eval_text(text, scope)?;
                let truth = self.boolean(&value, text)?;
                if truth == (local == "if") {
                    self.process(&e.children, scope, out, attrs)?;
                }
                Ok(())
            }
            "macro" => {
                let name = self.required(e, "name")?.to_owned();
                let params = self.parse_params(self.attr(e, "params").unwrap_or(""))?;
                let m = Macro {
                    name: name.clone(),
                    params,
                    body: Rc::clone(e),
                };
                self.scopes[scope].macros.insert(name, Rc::new(m));
                Ok(())
            }
            "insert_block" => {
                let name = self
                    .eval_text(self.required(e, "name")?, scope)?
                    .to_string();
                match self.lookup(&name, scope) {
                    Some((_, Prop::Block(nodes))) => {
                        out.extend(nodes);
                        Ok(())
                    }
                    Some(_) => Err(self.error(format!(
                        "xacro:insert_block name=\"{name}\": \"{name}\" is a value, not a block; blocks are *params of a macro or <xacro:property> with child elements"
                    ))),
                    None => Err(self.error(format!(
                        "xacro:insert_block name=\"{name}\": undefined block \"{name}\""
                    ))),
                }
            }
            "element" => self.computed_element(e, scope, out),
            "attribute" => {
                let name = self
                    .eval_text(self.required(e, "name")?, scope)?
                    .to_string();
                let value = self
                    .eval_text(self.required(e, "value")?, scope)?
                    .to_string();
                attrs.push((name, value));
                Ok(())
            }
            "call" => {
                let name = self
                    .eval_text(self.required(e, "macro")?, scope)?
                    .to_string();
                let m = self.find_macro(&name, scope)?;
                self.call_macro(&m, e, scope, out, &["macro"])
            }
            _ => {
                let m = self.find_macro(local, scope)?;
                self.call_macro(&m, e, scope, out, &[])
            }
        }
    }

    /// `<xacro:element xacro:name="...">`: an element whose name is computed, with the other
    /// attributes and the children expanded in `scope`, appended to `out`.
    fn computed_element(&mut self, e: &XElem, scope: usize, out: &mut Vec<ONode>) -> Result<()> {
        self.count_element()?;
        let name_text = self.required(e, "xacro:name")?;
        let name = self.eval_text(name_text, scope)?.to_string();
        let mut elem_attrs = Vec::new();
        for (n, v) in &e.attrs {
            if n != "xacro:name" {
                elem_attrs.push((n.clone(), self.eval_text(v, scope)?.to_string()));
            }
        }
        let mut children = Vec::new();
        let mut extra = Vec::new();
        self.process(&e.children, scope, &mut children, &mut extra)?;
        set_attrs(&mut elem_attrs, extra);
        out.push(ONode::Elem(OElem {
            name,
            attrs: elem_attrs,
            children,
            file: e.file,
            line: e.line,
        }));
        Ok(())
    }
}

/// `xacro:attribute`s override attributes of the same name.
fn set_attrs(attrs: &mut Vec<(String, String)>, extra: Vec<(String, String)>) {
    for (name, value) in extra {
        match attrs.iter_mut().find(|(n, _)| *n == name) {
            Some(slot) => slot.1 = value,
            None => attrs.push((name, value)),
        }
    }
}
