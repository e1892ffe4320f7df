//! The loader's state (`Loader`), the scope a tag is read in (`Ctx`) and the document a tag is
//! located in (`FileReader`): the types every tag family's file shares.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use roxmltree::{Document, Node};

use crate::launch::model::{
    Launch, LaunchError, LaunchOptions, Location, Param, canonical_name, ns_join,
};

/// The scope a tag is read in (roslaunch's `LoaderContext`).
#[derive(Debug, Clone)]
pub(super) struct Ctx {
    /// Namespace, global, with a trailing `/`.
    pub(super) ns: String,
    /// The file being read (`$(dirname)`, messages, `$(find)` from here).
    pub(super) file: PathBuf,
    /// Arg values visible here.
    pub(super) args: BTreeMap<String, String>,
    /// Args declared in this file.
    pub(super) arg_names: Vec<String>,
    /// While reading an `<include>`'s children: the args passed to the included file.
    pub(super) include_args: Option<BTreeMap<String, String>>,
    /// `~name` params, for every node that follows in this scope.
    pub(super) private: Vec<(String, Param)>,
    pub(super) remaps: Vec<(String, String)>,
    pub(super) env: Vec<(String, String)>,
    pub(super) pass_all_args: bool,
}

impl Ctx {
    pub(super) fn child(&self, ns: Option<&str>) -> Ctx {
        let mut c = self.clone();
        if let Some(ns) = ns {
            c.ns = if ns.starts_with('/') {
                global_ns(ns)
            } else if ns == "~" {
                "~".to_owned()
            } else {
                global_ns(&ns_join(&self.ns, ns))
            };
        }
        c
    }

    pub(super) fn add_remap(&mut self, from: String, to: String) {
        self.remaps.retain(|(f, _)| *f != from);
        self.remaps.push((from, to));
    }
}

/// `ns` as a global namespace: canonical, with a leading and a trailing `/`.
pub(super) fn global_ns(ns: &str) -> String {
    let c = canonical_name(ns);
    let c = if c.starts_with('/') {
        c
    } else {
        format!("/{c}")
    };
    if c.ends_with('/') { c } else { format!("{c}/") }
}

/// What one `load` keeps while it walks the files.
pub(super) struct Loader<'o> {
    pub(super) options: &'o LaunchOptions,
    pub(super) out: Launch,
    pub(super) anon: HashMap<String, String>,
    /// Files being read, outermost first (for cycles).
    pub(super) stack: Vec<PathBuf>,
}

/// One file's document, for locating tags.
pub(super) struct FileReader<'d, 'i> {
    pub(super) doc: &'d Document<'i>,
    pub(super) path: &'d Path,
}

impl FileReader<'_, '_> {
    pub(super) fn at(&self, tag: Node<'_, '_>) -> Location {
        Location {
            file: self.path.to_path_buf(),
            line: line_of(self.doc, tag),
        }
    }

    pub(super) fn err(&self, tag: Node<'_, '_>, message: impl Into<String>) -> LaunchError {
        LaunchError::new(self.path, line_of(self.doc, tag), message)
    }
}

/// The line (1-based) `node` starts on.
pub(super) fn line_of(doc: &Document<'_>, node: Node<'_, '_>) -> u32 {
    doc.text_pos_at(node.range().start).row
}
