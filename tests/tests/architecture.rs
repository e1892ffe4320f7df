//! The workspace's shape, checked on its own sources: no import circle between the files of
//! any crate, sim/src's top level small, no long function, impl block or file outside tests. What the rules are
//! and why: docs/ARCHITECTURE.md.

use rover_tests::architecture::CrateSources;
use rover_tests::repo;

/// Crates whose files must not import each other in a circle.
const CRATES: [&str; 10] = [
    "assets",
    "pyexpr",
    "sim",
    "perception",
    "core",
    "msgs",
    "ros1",
    "ros2",
    "app",
    "tests",
];

/// Longest function allowed outside tests (lines from `fn` to its closing brace).
const MAX_FUNCTION_LINES: usize = 120;
/// Longest `impl` block allowed outside tests (lines from `impl` to its closing brace).
const MAX_IMPL_LINES: usize = 400;
/// Longest source file allowed outside tests: what a newcomer can read in one sitting.
const MAX_FILE_LINES: usize = 1000;

fn sources(krate: &str) -> anyhow::Result<CrateSources> {
    Ok(CrateSources::read(&repo(&format!("{krate}/src")))?)
}

#[test]
fn no_crate_has_an_import_circle_between_its_files() -> anyhow::Result<()> {
    let mut circles = Vec::new();
    for krate in CRATES {
        let sources = sources(krate)?;
        // rover-msgs is one file (lib.rs); every other crate has several.
        let least = if krate == "msgs" { 1 } else { 2 };
        assert!(
            sources.files.len() >= least,
            "{krate}: expected at least {least} source files, found {}",
            sources.files.len()
        );
        if let Some(cycle) = sources.find_cycle() {
            let files: Vec<String> = cycle.iter().map(|p| p.display().to_string()).collect();
            circles.push(format!("{krate}/src: {}", files.join(" -> ")));
        }
    }
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
    Ok(())
}

/// Writes `files` (path under `src`, text) and checks that the import circle found in the
/// crate at `src` takes in both `expected` files.
fn assert_circle(
    src: &std::path::Path,
    files: [(&str, &str); 2],
    expected: [&str; 2],
) -> anyhow::Result<()> {
    for (path, text) in files {
        std::fs::write(src.join(path), text)?;
    }
    let names: Vec<String> = CrateSources::read(src)?
        .find_cycle()
        .iter()
        .flatten()
        .map(|p| p.display().to_string())
        .collect();
    assert!(
        expected.iter().all(|e| names.iter().any(|n| n == e)),
        "expected {expected:?} in a circle, found {names:?}"
    );
    Ok(())
}

#[test]
fn the_circle_check_finds_a_known_circle_and_follows_reexports() -> anyhow::Result<()> {
    // A crate where a.rs uses b's item through the root's re-export, and b.rs uses a: a circle
    // only visible once the re-export is followed.
    let dir = tempfile::tempdir()?;
    let src = dir.path().join("src");
    std::fs::create_dir_all(src.join("b"))?;
    std::fs::write(
        src.join("lib.rs"),
        "mod a;\nmod b;\npub use b::inner::Thing;\npub use a::Other;\n",
    )?;
    std::fs::write(
        src.join("a.rs"),
        "use crate::Thing;\npub struct Other(Thing);\n",
    )?;
    let inner =
        "pub struct Thing;\nfn f() -> Option<crate::a::Other> { None }\n// crate::c::Ignored\n";
    assert_circle(
        &src,
        [
            ("b/mod.rs", "pub(crate) mod inner;\n"),
            ("b/inner.rs", inner),
        ],
        ["a.rs", "b/inner.rs"],
    )?;
    // Without the back edge there is none.
    std::fs::write(src.join("b/inner.rs"), "pub struct Thing;\n")?;
    assert_eq!(CrateSources::read(&src)?.find_cycle(), None);
    // A parent naming its child inline (`inner::f()`, no `use`) while the child uses the
    // parent: a circle too.
    assert_circle(
        &src,
        [
            (
                "b/mod.rs",
                "pub(crate) mod inner;\npub struct Shared;\nfn g() { inner::f(); }\n",
            ),
            (
                "b/inner.rs",
                "pub struct Thing;\npub fn f() -> Option<super::Shared> { None }\n",
            ),
        ],
        ["b/mod.rs", "b/inner.rs"],
    )?;
    Ok(())
}

/// sim/src's top level: one folder per layer (description, model, physics, planning, render,
/// sensors), the leaves every layer shares (error, geometry, io, noise) and lib.rs.
#[test]
fn sim_src_top_level_is_a_folder_per_layer_and_its_shared_leaves() -> anyhow::Result<()> {
    let mut entries: Vec<String> = std::fs::read_dir(repo("sim/src"))?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect::<Result<_, _>>()?;
    entries.sort();
    assert!(
        entries.len() <= 11,
        "sim/src has {} entries (expected at most 11: a folder per layer, the shared leaves, lib.rs): {entries:?}",
        entries.len()
    );
    Ok(())
}

#[test]
fn no_function_outside_tests_is_longer_than_the_limit() -> anyhow::Result<()> {
    let mut long = Vec::new();
    // The tests crate is test code itself.
    for krate in CRATES.iter().filter(|k| **k != "tests") {
        for f in sources(krate)?.long_functions(MAX_FUNCTION_LINES) {
            long.push(format!(
                "{krate}/src/{}:{} fn {} is {} lines",
                f.file.display(),
                f.line,
                f.name,
                f.lines
            ));
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MAX_FUNCTION_LINES} lines (split them):\n{}",
        long.join("\n")
    );
    Ok(())
}

#[test]
fn no_impl_block_or_file_outside_tests_is_longer_than_the_limits() -> anyhow::Result<()> {
    let mut long = Vec::new();
    // The tests crate is test code itself.
    for krate in CRATES.iter().filter(|k| **k != "tests") {
        let sources = sources(krate)?;
        for f in sources.long_impls(MAX_IMPL_LINES) {
            long.push(format!(
                "{krate}/src/{}:{} `{}` is {} lines (at most {MAX_IMPL_LINES})",
                f.file.display(),
                f.line,
                f.name,
                f.lines
            ));
        }
        for (file, lines) in sources.long_files(MAX_FILE_LINES) {
            long.push(format!(
                "{krate}/src/{} is {lines} lines (at most {MAX_FILE_LINES})",
                file.display()
            ));
        }
    }
    assert!(
        long.is_empty(),
        "too long to read (split them):\n{}",
        long.join("\n")
    );
    Ok(())
}

/// The limits find what they are for: a 401-line impl block and a 1,001-line file, each
/// beside short ones and an `impl Trait` argument.
#[test]
fn the_length_limits_catch_a_long_impl_and_a_long_file() -> anyhow::Result<()> {
    let dir = tempfile::tempdir()?;
    let src = dir.path();
    let body = "    fn f(&self) {}\n".repeat(399);
    std::fs::write(
        src.join("lib.rs"),
        format!(
            "mod long;\npub struct S;\nimpl S {{\n{body}}}\nimpl Clone for S {{\n    fn clone(&self) -> S {{ S }}\n}}\nfn g(_: impl Fn()) {{}}\n"
        ),
    )?;
    std::fs::write(src.join("long.rs"), "// a line\n".repeat(1001))?;
    let sources = rover_tests::architecture::CrateSources::read(src)?;
    let impls = sources.long_impls(MAX_IMPL_LINES);
    assert_eq!(impls.len(), 1, "{impls:?}");
    assert_eq!((impls[0].name.as_str(), impls[0].lines), ("impl S", 401));
    let files = sources.long_files(MAX_FILE_LINES);
    assert_eq!(files, vec![(std::path::PathBuf::from("long.rs"), 1001)]);
    Ok(())
}

/// Public modules each library may have (a namespace whose items are not re-exported at the
/// root, so nothing is reachable by two paths).
const PUBLIC_MODULES: &[(&str, &[&str])] = &[
    // The pinned list and its fetch, apart from the cache folder and COCO's names at the root.
    ("assets", &["registry"]),
    ("pyexpr", &[]),
    // Grouped by module as rapier groups its API: one module a layer.
    (
        "sim",
        &[
            "description",
            "geometry",
            "model",
            "physics",
            "planning",
            "render",
            "sensors",
        ],
    ),
    ("perception", &[]),
    ("core", &[]),
    ("msgs", &[]),
    ("ros1", &["msgs"]),
    // ROS 2's wire: namespaces as a ROS 2 stack has them (messages, discovery, services,
    // parameters, actions), none re-exported at the root.
    (
        "ros2",
        &[
            "acked",
            "action_msgs",
            "bulk",
            "dds",
            "definitions",
            "discovery",
            "msgs",
            "parameters",
            "services",
        ],
    ),
];

#[test]
fn libraries_keep_modules_private_behind_one_curated_surface() -> anyhow::Result<()> {
    let mut found = Vec::new();
    for (krate, allowed) in PUBLIC_MODULES {
        let lib = std::fs::read_to_string(repo(&format!("{krate}/src/lib.rs")))?;
        for line in lib.lines() {
            let Some(name) = line.trim().strip_prefix("pub mod ") else {
                continue;
            };
            let name = name.trim_end_matches(';').trim();
            if !allowed.contains(&name) {
                found.push(format!("{krate}/src/lib.rs: pub mod {name}"));
            }
        }
    }
    assert!(
        found.is_empty(),
        "public modules (make them private and re-export the API from lib.rs):\n{}",
        found.join("\n")
    );
    Ok(())
}
