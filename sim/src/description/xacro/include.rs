//! Files: reading and converting a xacro file to owned elements (recording namespace
//! prefixes), and `xacro:include` with its cycle check and `ns` namespacing.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use super::expander::{Expander, ONode, Prop, Scope, XACRO_NAMESPACES, XElem, XNode};
use super::properties::literal;
use crate::error::Result;

impl Expander<'_> {
    /// Reads and converts one file; returns its root element.
    pub(super) fn read(&mut self, path: &Path) -> Result<Rc<XElem>> {
        let text = crate::io::read_text(path)?;
        let file = self.files.len();
        self.files.push(path.to_path_buf());
        let doc = crate::description::xml::parse_xml(&text, path)?;
        let root = convert(&doc, doc.root_element(), file, &mut self.namespaces);
        Ok(root)
    }

    pub(super) fn include(&mut self, e: &XElem, scope: usize, out: &mut Vec<ONode>) -> Result<()> {
        let spec = self
            .eval_text(self.required(e, "filename")?, scope)?
            .to_string();
        let here = self.files[e.file]
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let path = if Path::new(&spec).is_absolute() {
            PathBuf::from(&spec)
        } else {
            here.join(&spec)
        };
        if !path.is_file() {
            return Err(self.error(format!(
                "xacro:include filename=\"{spec}\": no such file ({})",
                path.display()
            )));
        }
        let canonical = path.canonicalize().unwrap_or_else(|_| path.clone());
        let cycle_start = self.include_stack.iter().position(|&f| {
            self.files[f]
                .canonicalize()
                .unwrap_or_else(|_| self.files[f].clone())
                == canonical
        });
        if let Some(start) = cycle_start {
            let mut chain: Vec<String> = self.include_stack[start..]
                .iter()
                .map(|&f| self.files[f].display().to_string())
                .collect();
            chain.push(path.display().to_string());
            return Err(self.error(format!("include cycle: {}", chain.join(" -> "))));
        }
        let at = self.at;
        let root = self.read(&path)?;
        self.include_stack.push(root.file);
        let ns = self.attr(e, "ns").map(str::to_owned);
        let target = if ns.is_some() {
            self.scopes.push(Scope {
                parent: Some(scope),
                ..Default::default()
            });
            self.scopes.len() - 1
        } else {
            scope
        };
        let mut ignored = Vec::new();
        let result = self.process(&root.children, target, out, &mut ignored);
        self.include_stack.pop();
        result?;
        self.at = at;
        if let Some(ns) = ns {
            let inner = std::mem::take(&mut self.scopes[target]);
            self.scopes[target].parent = inner.parent;
            for (name, prop) in inner.props {
                // Keep lazy text evaluable: values move, lazy text is evaluated now.
                let prop = match prop {
                    Prop::Lazy(text) => Prop::Value(literal(self.eval_text(&text, scope)?)),
                    other => other,
                };
                self.scopes[scope]
                    .props
                    .insert(format!("{ns}.{name}"), prop);
            }
            for (name, m) in inner.macros {
                self.scopes[scope].macros.insert(format!("{ns}.{name}"), m);
            }
        }
        Ok(())
    }
}

fn is_xacro_ns(uri: Option<&str>) -> bool {
    uri.is_some_and(|u| XACRO_NAMESPACES.contains(&u))
}

fn convert(
    doc: &roxmltree::Document<'_>,
    node: roxmltree::Node<'_, '_>,
    file: usize,
    namespaces: &mut BTreeMap<String, String>,
) -> Rc<XElem> {
    let tag = node.tag_name();
    let xacro = is_xacro_ns(tag.namespace()).then(|| tag.name().to_owned());
    let qualify =
        |ns: Option<&str>, local: &str, namespaces: &mut BTreeMap<String, String>| match ns {
            Some(uri) if is_xacro_ns(Some(uri)) => format!("xacro:{local}"),
            Some(uri) => match node.lookup_prefix(uri) {
                Some(prefix) if !prefix.is_empty() => {
                    namespaces.insert(prefix.to_owned(), uri.to_owned());
                    format!("{prefix}:{local}")
                }
                _ => local.to_owned(),
            },
            None => local.to_owned(),
        };
    let name = qualify(tag.namespace(), tag.name(), namespaces);
    let attrs = node
        .attributes()
        .map(|a| {
            (
                qualify(a.namespace(), a.name(), namespaces),
                a.value().to_owned(),
            )
        })
        .collect();
    let mut children = Vec::new();
    for child in node.children() {
        if child.is_element() {
            children.push(XNode::Elem(convert(doc, child, file, namespaces)));
        } else if child.is_text()
            && let Some(text) = child.text()
        {
            children.push(XNode::Text(text.to_owned()));
        }
    }
    Rc::new(XElem {
        name,
        xacro,
        attrs,
        children,
        file,
        line: doc.text_pos_at(node.range().start).row,
    })
}
