//! Reads the workspace's own Rust sources to check their shape: which file of a crate uses
//! which (`use crate::...`, `super::`, `self::`, child modules, and paths written inline),
//! with re-exports followed to the file that defines the item, and how long each function is.
//!
//! A small lexer (comments, strings, char literals and lifetimes told apart) is enough here:
//! the checks need paths and braces, not a syntax tree, and the workspace builds no parser
//! crate (syn) it could reuse.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One source file of a crate, as the checks see it.
#[derive(Debug, Clone)]
pub struct SourceFile {
    /// Path relative to the crate's `src/`.
    pub relative: PathBuf,
    /// Module path (`[]` for lib.rs/main.rs, `["render", "scene"]` for render/scene.rs).
    pub module: Vec<String>,
    /// The text with comments, string and char literals blanked (same length, same lines)
    /// and `#[cfg(test)]` items removed the same way.
    pub code: String,
}

/// A crate's source files by module path.
#[derive(Debug, Clone)]
pub struct CrateSources {
    /// The crate's `src/` folder.
    pub root: PathBuf,
    /// Files by module path.
    pub files: BTreeMap<Vec<String>, SourceFile>,
}

/// A function longer than the limit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LongFunction {
    /// File (relative to the crate's `src/`).
    pub file: PathBuf,
    /// Function name.
    pub name: String,
    /// First line (1-based).
    pub line: usize,
    /// Lines from `fn` to the closing brace.
    pub lines: usize,
}

impl CrateSources {
    /// Reads every `.rs` file under `src`.
    pub fn read(src: &Path) -> std::io::Result<Self> {
        let mut files = BTreeMap::new();
        for path in crate::files_under(src)? {
            // A binary's main.rs beside lib.rs is another crate (it uses the library).
            let other_crate = path.ends_with("main.rs")
                && path.parent() == Some(src)
                && src.join("lib.rs").exists();
            if path.extension().is_none_or(|e| e != "rs") || other_crate {
                continue;
            }
            let relative = path.strip_prefix(src).unwrap_or(&path).to_path_buf();
            let module = module_of(&relative);
            let text = std::fs::read_to_string(&path)?;
            let code = without_test_items(&blank_literals(&text));
            files.insert(
                module.clone(),
                SourceFile {
                    relative,
                    module,
                    code,
                },
            );
        }
        Ok(Self {
            root: src.to_path_buf(),
            files,
        })
    }

    /// File-level dependency edges: `a -> b` when code in file `a` names an item defined in
    /// file `b` (re-exports followed). Re-export declarations themselves (`pub use`,
    /// `pub(crate) use`) and `mod` declarations are not edges: they are a module's facade.
    pub fn edges(&self) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
        let reexports: BTreeMap<&Vec<String>, BTreeMap<String, Vec<String>>> = self
            .files
            .iter()
            .map(|(m, f)| (m, self.reexports_of(f)))
            .collect();
        let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
        for (module, file) in &self.files {
            let targets = edges.entry(module.clone()).or_default();
            for path in self.paths_used(file) {
                if let Some(target) = self.resolve(&path, &reexports, 0)
                    && &target != module
                {
                    targets.insert(target);
                }
            }
        }
        edges
    }

    /// A cycle in [`Self::edges`], as the files in order, if there is one.
    pub fn find_cycle(&self) -> Option<Vec<PathBuf>> {
        let edges = self.edges();
        let mut state: BTreeMap<&Vec<String>, u8> = BTreeMap::new();
        let mut stack: Vec<&Vec<String>> = Vec::new();
        fn visit<'a>(
            node: &'a Vec<String>,
            edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
            state: &mut BTreeMap<&'a Vec<String>, u8>,
            stack: &mut Vec<&'a Vec<String>>,
        ) -> Option<Vec<&'a Vec<String>>> {
            state.insert(node, 1);
            stack.push(node);
            for next in edges.get(node).into_iter().flatten() {
                match state.get(next).copied().unwrap_or(0) {
                    1 => {
                        let start = stack.iter().position(|n| *n == next).unwrap_or(0);
                        let mut cycle = stack[start..].to_vec();
                        cycle.push(next);
                        return Some(cycle);
                    }
                    0 => {
                        if let Some(c) = visit(next, edges, state, stack) {
                            return Some(c);
                        }
                    }
                    _ => {}
                }
            }
            stack.pop();
            state.insert(node, 2);
            None
        }
        for node in edges.keys() {
            if state.get(node).copied().unwrap_or(0) == 0
                && let Some(cycle) = visit(node, &edges, &mut state, &mut stack)
            {
                return Some(
                    cycle
                        .into_iter()
                        .map(|m| {
                            self.files
                                .get(m)
                                .map_or_else(|| PathBuf::from(m.join("::")), |f| f.relative.clone())
                        })
                        .collect(),
                );
            }
        }
        None
    }

    /// Functions (outside `#[cfg(test)]` items) longer than `max_lines`.
    pub fn long_functions(&self, max_lines: usize) -> Vec<LongFunction> {
        self.long_blocks("fn", max_lines, |code, at, open| {
            // A signature without a body ends at `;` before any `{`.
            let body = open.filter(|&o| !code[at..o].contains(';'))?;
            let name = code[at + 2..body]
                .trim_start()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            Some((body, name))
        })
    }

    /// Every `impl` block (inherent or of a trait) longer than `max_lines`, as
    /// [`LongFunction`]s named after the block's header (`impl Foo`, `impl Bar for Foo`).
    pub fn long_impls(&self, max_lines: usize) -> Vec<LongFunction> {
        self.long_blocks("impl", max_lines, |code, at, open| {
            // An item: nothing but indentation (or `unsafe`) before it on its line, which
            // leaves out `impl Trait` in argument and return types.
            let line_start = code[..at].rfind('\n').map_or(0, |n| n + 1);
            let before = code[line_start..at].trim();
            if !(before.is_empty() || before == "unsafe") {
                return None;
            }
            let body = open?;
            let header = code[at..body]
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ");
            Some((body, header))
        })
    }

    /// Every block that starts at the word `keyword` and is longer than `max_lines` (from the
    /// keyword's line to the closing brace's). `block(code, at, open)` is given the keyword's
    /// offset and the next `{` after it, and says where the block's body opens and its name,
    /// or `None` for an occurrence that is no such block.
    fn long_blocks(
        &self,
        keyword: &str,
        max_lines: usize,
        block: impl Fn(&str, usize, Option<usize>) -> Option<(usize, String)>,
    ) -> Vec<LongFunction> {
        let mut out = Vec::new();
        for file in self.files.values() {
            let code = file.code.as_bytes();
            let mut i = 0;
            while let Some(at) = find_word(&file.code, keyword, i) {
                i = at + keyword.len();
                let open = code[i..].iter().position(|&c| c == b'{').map(|p| p + i);
                let Some((body, name)) = block(&file.code, at, open) else {
                    continue;
                };
                let Some(close) = matching_brace(code, body) else {
                    continue;
                };
                let first = line_at(code, at);
                let lines = line_at(code, close) - first + 1;
                if lines > max_lines {
                    out.push(LongFunction {
                        file: file.relative.clone(),
                        name,
                        line: first,
                        lines,
                    });
                }
            }
        }
        out
    }

    /// Every file with more than `max_lines` lines, test-only files (`tests.rs`, and files
    /// under a `tests/` folder of `src/`) left out, with its line count.
    pub fn long_files(&self, max_lines: usize) -> Vec<(PathBuf, usize)> {
        self.files
            .values()
            .filter(|f| {
                !f.relative.ends_with("tests.rs")
                    && !f.relative.components().any(|c| c.as_os_str() == "tests")
            })
            .map(|f| (f.relative.clone(), f.code.lines().count()))
            .filter(|(_, lines)| *lines > max_lines)
            .collect()
    }

    /// `pub use` / `pub(crate) use` re-exports of a file: exported name -> full path.
    fn reexports_of(&self, file: &SourceFile) -> BTreeMap<String, Vec<String>> {
        let mut out = BTreeMap::new();
        for (is_pub, tree) in use_trees(&file.code) {
            if !is_pub {
                continue;
            }
            for (path, alias) in expand_tree(&tree) {
                if let Some(full) = self.absolute(file, &path) {
                    let name = alias.unwrap_or_else(|| full.last().cloned().unwrap_or_default());
                    out.insert(name, full);
                }
            }
        }
        out
    }

    /// Every path a file's code names (not counting its re-exports), made absolute.
    fn paths_used(&self, file: &SourceFile) -> Vec<Vec<String>> {
        let mut out = Vec::new();
        for (is_pub, tree) in use_trees(&file.code) {
            if is_pub {
                continue;
            }
            for (path, _) in expand_tree(&tree) {
                out.extend(self.absolute(file, &path));
            }
        }
        for path in inline_paths(&file.code) {
            out.extend(self.absolute(file, &path));
        }
        out
    }

    /// `path` as seen from `file`, from the crate root; `None` for other crates' paths.
    fn absolute(&self, file: &SourceFile, path: &[String]) -> Option<Vec<String>> {
        let (first, rest) = path.split_first()?;
        let mut base = file.module.clone();
        let mut rest = rest.to_vec();
        match first.as_str() {
            "crate" => base.clear(),
            "self" => {}
            "super" => {
                base.pop();
                while rest.first().is_some_and(|s| s == "super") {
                    rest.remove(0);
                    base.pop();
                }
            }
            child => {
                let mut candidate = file.module.clone();
                candidate.push(child.to_owned());
                if !self.files.contains_key(&candidate) {
                    return None;
                }
                rest.insert(0, child.to_owned());
            }
        }
        base.extend(rest);
        Some(base)
    }

    /// The file that defines the item at `path` (re-exports followed).
    fn resolve(
        &self,
        path: &[String],
        reexports: &BTreeMap<&Vec<String>, BTreeMap<String, Vec<String>>>,
        depth: usize,
    ) -> Option<Vec<String>> {
        let split = (0..=path.len())
            .rev()
            .find(|&n| self.files.contains_key(&path[..n]))?;
        let module = path[..split].to_vec();
        if depth < 16
            && let Some(name) = path.get(split)
            && let Some(target) = reexports.get(&module).and_then(|r| r.get(name))
        {
            let mut next = target.clone();
            next.extend(path[split + 1..].iter().cloned());
            if next != path {
                return self.resolve(&next, reexports, depth + 1).or(Some(module));
            }
        }
        Some(module)
    }
}

fn module_of(relative: &Path) -> Vec<String> {
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap_or_default();
    match last.as_str() {
        "mod.rs" => {}
        "lib.rs" | "main.rs" if parts.is_empty() => {}
        other => parts.push(other.trim_end_matches(".rs").to_owned()),
    }
    parts
}

/// Comments, string literals and char literals replaced by spaces (newlines kept).
pub fn blank_literals(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let blank = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in &mut out[from..to.min(b.len())] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    let mut i = 0;
    while i < b.len() {
        let ident_before = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if b[i..].starts_with(b"//") {
            let end = b[i..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |p| i + p);
            blank(&mut out, i, end);
            i = end;
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0;
            let mut j = i;
            while j < b.len() {
                if b[j..].starts_with(b"/*") {
                    depth += 1;
                    j += 2;
                } else if b[j..].starts_with(b"*/") {
                    depth -= 1;
                    j += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            blank(&mut out, i, j);
            i = j;
        } else if let Some(end) = (!ident_before).then(|| raw_string_at(b, i)).flatten() {
            blank(&mut out, i, end);
            i = end;
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            blank(&mut out, i, j + 1);
            i = j + 1;
        } else if b[i] == b'\'' {
            // A char literal ('a', '\n', '\u{..}') or a lifetime ('a).
            let end = if b.get(i + 1) == Some(&b'\\') {
                b[i + 2..]
                    .iter()
                    .position(|&c| c == b'\'')
                    .map(|p| i + 2 + p + 1)
            } else {
                let ch_len = text[i + 1..].chars().next().map_or(1, char::len_utf8);
                (b.get(i + 1 + ch_len) == Some(&b'\'')).then_some(i + 2 + ch_len)
            };
            match end {
                Some(end) => {
                    blank(&mut out, i, end);
                    i = end;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// End of a raw string (`r"..."`, `r#"..."#`, `br"..."`) starting at `i`.
fn raw_string_at(b: &[u8], i: usize) -> Option<usize> {
    let mut j = i;
    if b.get(j) == Some(&b'b') {
        j += 1;
    }
    if b.get(j) != Some(&b'r') {
        return None;
    }
    j += 1;
    let hashes = b[j..].iter().take_while(|&&c| c == b'#').count();
    j += hashes;
    if b.get(j) != Some(&b'"') {
        return None;
    }
    let mut closing = vec![b'"'];
    closing.extend(std::iter::repeat_n(b'#', hashes));
    b[j + 1..]
        .windows(closing.len())
        .position(|w| w == closing.as_slice())
        .map(|p| j + 1 + p + closing.len())
}

/// `#[cfg(test)]` items blanked (they may use anything: tests are not part of the layering).
fn without_test_items(code: &str) -> String {
    let b = code.as_bytes();
    let mut out = b.to_vec();
    let mut from = 0;
    while let Some(p) = code[from..].find("#[cfg(test)]") {
        let at = from + p;
        let item_end = b[at..]
            .iter()
            .position(|&c| c == b'{' || c == b';')
            .map(|q| at + q)
            .and_then(|q| {
                if b[q] == b'{' {
                    matching_brace(b, q)
                } else {
                    Some(q)
                }
            })
            .unwrap_or(b.len() - 1);
        for c in &mut out[at..=item_end] {
            if *c != b'\n' {
                *c = b' ';
            }
        }
        from = item_end + 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn matching_brace(code: &[u8], open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (k, &c) in code.iter().enumerate().skip(open) {
        match c {
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(k);
                }
            }
            _ => {}
        }
    }
    None
}

fn line_at(code: &[u8], at: usize) -> usize {
    code[..at].iter().filter(|&&c| c == b'\n').count() + 1
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// Next occurrence of `word` as a whole word at or after `from`.
fn find_word(code: &str, word: &str, from: usize) -> Option<usize> {
    let b = code.as_bytes();
    let mut i = from;
    while let Some(p) = code.get(i..)?.find(word) {
        let at = i + p;
        let end = at + word.len();
        let before_ok = at == 0 || !is_ident(b[at - 1]);
        let after_ok = end >= b.len() || !is_ident(b[end]);
        if before_ok && after_ok {
            return Some(at);
        }
        i = at + word.len();
    }
    None
}

/// Every `use` declaration: (is a re-export, the tree's text).
fn use_trees(code: &str) -> Vec<(bool, String)> {
    let mut out = Vec::new();
    let mut i = 0;
    while let Some(at) = find_word(code, "use", i) {
        let Some(end) = code[at..].find(';').map(|p| at + p) else {
            break;
        };
        // A re-export: `pub use` or `pub(crate) use` (`pub(super)`, `pub(in ...)`).
        let before = code[..at].trim_end();
        let is_pub = before.ends_with("pub")
            || before.ends_with(')')
                && before
                    .rfind("pub(")
                    .is_some_and(|p| !before[p..].contains([';', '{', '}']));
        out.push((
            is_pub,
            code[at + 3..end]
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" "),
        ));
        i = end + 1;
    }
    out
}

/// `a::{b::C, d as E, f::*}` -> [(a::b::C, None), (a::d, Some(E)), (a::f, None)].
fn expand_tree(tree: &str) -> Vec<(Vec<String>, Option<String>)> {
    fn walk(text: &str, prefix: &[String], out: &mut Vec<(Vec<String>, Option<String>)>) {
        let text = text.trim();
        if text.is_empty() {
            return;
        }
        if let Some(open) = text.find('{') {
            let mut prefix = prefix.to_vec();
            prefix.extend(
                text[..open]
                    .split("::")
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .map(str::to_owned),
            );
            let inner = &text[open + 1..text.rfind('}').unwrap_or(text.len())];
            let mut depth = 0;
            let mut start = 0;
            for (k, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        walk(&inner[start..k], &prefix, out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            walk(&inner[start..], &prefix, out);
            return;
        }
        // Words are separated by single spaces here, so `as` is a word of its own.
        let (path, alias) = match text.split_once(" as ") {
            Some((p, a)) => (p, Some(a.trim().to_owned())),
            None => (text, None),
        };
        let mut full = prefix.to_vec();
        for seg in path
            .split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty() && *s != "*")
        {
            if seg == "self" && !full.is_empty() {
                continue;
            }
            full.push(seg.to_owned());
        }
        out.push((full, alias));
    }
    let mut out = Vec::new();
    walk(tree, &[], &mut out);
    out
}

/// Paths written in code outside `use` declarations that start with `crate::`, `super::`,
/// `self::`, or any other lower-case name followed by `::` (`merge::f()` names the child module
/// `merge`; [`CrateSources::absolute`] keeps only those that are the file's child modules).
fn inline_paths(code: &str) -> Vec<Vec<String>> {
    let b = code.as_bytes();
    let mut use_spans = Vec::new();
    let mut i = 0;
    while let Some(at) = find_word(code, "use", i) {
        let end = code[at..].find(';').map_or(code.len(), |p| at + p);
        use_spans.push(at..end);
        i = end;
    }
    let mut out = Vec::new();
    let mut at = 0;
    while at < b.len() {
        let starts_word = (b[at].is_ascii_lowercase() || b[at] == b'_')
            && (at == 0 || !is_ident(b[at - 1]))
            && !(at >= 2 && &b[at - 2..at] == b"::");
        if !starts_word || use_spans.iter().any(|s| s.contains(&at)) {
            at += 1;
            continue;
        }
        let first: String = code[at..]
            .chars()
            .take_while(|c| is_ident(*c as u8))
            .collect();
        let mut j = at + first.len();
        at = j;
        if !code[j..].starts_with("::") {
            continue;
        }
        let mut path = vec![first];
        while code[j..].starts_with("::") {
            j += 2;
            let seg: String = code[j..]
                .chars()
                .take_while(|c| is_ident(*c as u8))
                .collect();
            if seg.is_empty() {
                break;
            }
            j += seg.len();
            path.push(seg);
        }
        at = j;
        out.push(path);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_and_comments_are_blanked_and_lifetimes_kept() {
        let code =
            blank_literals("fn f<'a>(x: &'a str) { let c = '}'; \"use crate::x;\" } // crate::y");
        assert!(code.contains("'a"), "{code}");
        assert!(!code.contains("crate::"), "{code}");
        assert!(!code.contains("'}'"), "{code}");
    }

    #[test]
    fn use_trees_expand_to_paths() {
        let paths = expand_tree("crate::{a::{B, c::D}, e as F, g::*}");
        let flat: Vec<String> = paths.iter().map(|(p, _)| p.join("::")).collect();
        assert_eq!(
            flat,
            ["crate::a::B", "crate::a::c::D", "crate::e", "crate::g"]
        );
        assert_eq!(paths[2].1.as_deref(), Some("F"));
        // "as" inside a name is not a rename.
        let laser = expand_tree("crate::sensors::{LaserScan, passes::Base}");
        assert_eq!(
            laser[0],
            (
                vec!["crate".into(), "sensors".into(), "LaserScan".into()],
                None
            )
        );
        assert_eq!(laser[1].0.join("::"), "crate::sensors::passes::Base");
    }
}
