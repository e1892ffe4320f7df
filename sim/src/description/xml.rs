//! XML helpers shared by the URDF, `<gazebo>`, xacro and SDF readers: parsing with located
//! errors, element lines, child lookup.

use std::path::Path;

use roxmltree::Node;

use crate::error::{Result, SimError};

/// Parses XML (URDF, xacro, SDF; DTDs allowed), reporting malformed input with its line.
pub(crate) fn parse_xml<'a>(text: &'a str, path: &Path) -> Result<roxmltree::Document<'a>> {
    roxmltree::Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .map_err(|e| {
        let pos = e.pos();
        SimError::invalid(
            path,
            Some(pos.row),
            format!("malformed XML (column {}): {e}", pos.col),
        )
    })
}

/// 1-based line of an element.
pub(crate) fn line_of(doc: &roxmltree::Document<'_>, node: Node<'_, '_>) -> u32 {
    doc.text_pos_at(node.range().start).row
}

/// The first child element called `name`.
pub(crate) fn child<'a, 'input>(node: Node<'a, 'input>, name: &str) -> Option<Node<'a, 'input>> {
    node.children().find(|n| n.has_tag_name(name))
}

/// Every child element called `name`.
pub(crate) fn children<'a, 'input>(
    node: Node<'a, 'input>,
    name: &'static str,
) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children().filter(move |n| n.has_tag_name(name))
}

/// Every child element.
pub(crate) fn elements<'a, 'input>(
    node: Node<'a, 'input>,
) -> impl Iterator<Item = Node<'a, 'input>> {
    node.children().filter(|n| n.is_element())
}
