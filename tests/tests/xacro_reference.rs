//! rover's in-process xacro against references: the URDF Hello Robot ships beside its Stretch
//! xacro sources, and PyPI's `xacro` 2.1.1 (the reference implementation, run here with Python)
//! on rtb-data's robot packages. Same links, same joints (type, parent, child, origin within
//! 1e-6). The packages come from PyPI at set-up (assets/registry.tsv); the test skips, counted
//! and listed (a failure in strict mode), where they are not in the cache.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rover_sim::description::{ResourcePaths, expand_xacro};
use rover_tests::pypi;

#[derive(Debug, Clone, PartialEq)]
struct JointRow {
    kind: String,
    parent: String,
    child: String,
    origin: [f64; 6],
}

#[derive(Debug)]
struct Description {
    links: BTreeSet<String>,
    joints: BTreeMap<String, JointRow>,
}

fn numbers(text: Option<&str>) -> Result<[f64; 3]> {
    let Some(text) = text else {
        return Ok([0.0; 3]);
    };
    let v: Vec<f64> = text
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .with_context(|| format!("not numbers: {text}"))?;
    v.try_into()
        .map_err(|v| anyhow::anyhow!("expected 3 numbers, found {v:?}"))
}

fn describe(urdf: &str) -> Result<Description> {
    let doc = roxmltree::Document::parse(urdf)?;
    let root = doc.root_element();
    let mut links = BTreeSet::new();
    let mut joints = BTreeMap::new();
    for node in root.children().filter(|n| n.is_element()) {
        let name = node.attribute("name").unwrap_or_default().to_owned();
        match node.tag_name().name() {
            "link" => {
                links.insert(name);
            }
            "joint" => {
                let child_attr = |tag: &str| {
                    node.children()
                        .find(|c| c.has_tag_name(tag))
                        .and_then(|c| c.attribute("link"))
                        .unwrap_or_default()
                        .to_owned()
                };
                let origin = node.children().find(|c| c.has_tag_name("origin"));
                let xyz = numbers(origin.and_then(|o| o.attribute("xyz")))?;
                let rpy = numbers(origin.and_then(|o| o.attribute("rpy")))?;
                joints.insert(
                    name,
                    JointRow {
                        kind: node.attribute("type").unwrap_or_default().to_owned(),
                        parent: child_attr("parent"),
                        child: child_attr("child"),
                        origin: [xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2]],
                    },
                );
            }
            _ => {}
        }
    }
    Ok(Description { links, joints })
}

fn assert_same(ours: &Description, reference: &Description, what: &str) {
    assert_eq!(ours.links, reference.links, "{what}: links differ");
    assert_eq!(
        ours.joints.keys().collect::<Vec<_>>(),
        reference.joints.keys().collect::<Vec<_>>(),
        "{what}: joint names differ"
    );
    for (name, theirs) in &reference.joints {
        let mine = &ours.joints[name];
        assert_eq!(
            (&mine.kind, &mine.parent, &mine.child),
            (&theirs.kind, &theirs.parent, &theirs.child),
            "{what}: joint {name}"
        );
        for (a, b) in mine.origin.iter().zip(theirs.origin) {
            assert!(
                (a - b).abs() <= 1e-6,
                "{what}: joint {name} origin {:?} vs reference {:?}",
                mine.origin,
                theirs.origin
            );
        }
    }
    assert!(!reference.joints.is_empty(), "{what}: no joints compared");
}

fn expand(path: &Path, packages: &[(&str, PathBuf)]) -> Result<String> {
    let mut resources = ResourcePaths::default();
    for (name, dir) in packages {
        resources = resources.with_package(*name, dir);
    }
    Ok(expand_xacro(path, &BTreeMap::new(), &resources)?.text)
}

#[test]
fn stretch_re2v0_expands_to_the_urdf_shipped_beside_it() -> Result<()> {
    let Some(wheel) = pypi("hello-robot-stretch-urdf", "0.1.2") else {
        return Ok(());
    };
    let dir = wheel.join("stretch_urdf/RE2V0");
    let variants = [
        "tool_stretch_gripper",
        "tool_stretch_dex_wrist",
        "eoa_wrist_dw3_tool_sg3",
    ];
    let mut compared = 0;
    for variant in variants {
        let xacro = dir.join(format!("xacro/stretch_description_RE2V0_{variant}.xacro"));
        let urdf = dir.join(format!("stretch_description_RE2V0_{variant}.urdf"));
        anyhow::ensure!(
            urdf.is_file(),
            "{}: the wheel ships no URDF for {variant}",
            urdf.display()
        );
        let ours = describe(&expand(&xacro, &[])?)?;
        let shipped = describe(&std::fs::read_to_string(&urdf)?)?;
        println!(
            "stretch {variant}: {} links, {} joints",
            ours.links.len(),
            ours.joints.len()
        );
        assert_same(&ours, &shipped, variant);
        compared += 1;
    }
    assert_eq!(compared, variants.len(), "variants compared");
    Ok(())
}

/// PyPI xacro 2.1.1 on `path`, with `$(find)` answered from `packages` (xacro looks packages up
/// through ament_index_python; a stand-in module gives it the same folders rover uses).
fn reference_xacro(path: &Path, packages: &[(&str, PathBuf)]) -> Result<Option<String>> {
    let Some(xacro) = pypi("xacro", "2.1.1") else {
        return Ok(None);
    };
    let has_yaml = std::process::Command::new("python3")
        .args(["-c", "import yaml"])
        .status()
        .is_ok_and(|s| s.success());
    if !has_yaml {
        rover_tests::skip("the reference xacro needs python3 with PyYAML (./test installs it)")?;
        return Ok(None);
    }
    let shim = tempfile::tempdir()?;
    let ament = shim.path().join("ament_index_python");
    std::fs::create_dir_all(&ament)?;
    std::fs::write(ament.join("__init__.py"), "")?;
    std::fs::write(
        ament.join("packages.py"),
        "import os\n\
         class PackageNotFoundError(KeyError):\n    pass\n\
         def get_package_share_directory(name):\n\
         \x20   for entry in os.environ.get('ROVER_TEST_PACKAGES', '').split(';'):\n\
         \x20       if entry.partition('=')[0] == name:\n\
         \x20           return entry.partition('=')[2]\n\
         \x20   raise PackageNotFoundError(name)\n",
    )?;
    let python_path = std::env::join_paths([xacro.as_path(), shim.path()])?;
    let packages_env: Vec<String> = packages
        .iter()
        .map(|(n, d)| format!("{n}={}", d.display()))
        .collect();
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import sys, xacro; sys.argv = ['xacro', sys.argv[1]]; xacro.main()",
        ])
        .arg(path)
        .env("PYTHONPATH", python_path)
        .env("ROVER_TEST_PACKAGES", packages_env.join(";"))
        .output()?;
    anyhow::ensure!(
        out.status.success(),
        "reference xacro failed on {}: {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(Some(String::from_utf8(out.stdout)?))
}

#[test]
fn rtb_data_robots_expand_like_the_reference_xacro() -> Result<()> {
    let Some(wheel) = pypi("rtb-data", "2.0.0") else {
        return Ok(());
    };
    let root = wheel.join("rtbdata/xacro");
    // if/unless and arg (Trossen arms), insert_block (Clearpath Ridgeback), arg and $(find)
    // of a package without a package.xml (QUT's dual Panda).
    let cases: [(&str, Vec<(&str, PathBuf)>); 4] = [
        ("trossen_descriptions/urdf/wx250s.urdf.xacro", vec![]),
        ("trossen_descriptions/urdf/px100.urdf.xacro", vec![]),
        (
            "clearpath_ridgeback_description/urdf/ridgeback.urdf.xacro",
            vec![],
        ),
        (
            "qut_frankie_description/robots/dual_panda_example.urdf.xacro",
            vec![(
                "qut_frankie_description",
                root.join("qut_frankie_description"),
            )],
        ),
    ];
    for (file, packages) in cases {
        let path = root.join(file);
        let Some(reference) = reference_xacro(&path, &packages)? else {
            return Ok(());
        };
        let ours = describe(&expand(&path, &packages)?)?;
        let theirs = describe(&reference)?;
        println!(
            "{file}: {} links, {} joints",
            ours.links.len(),
            ours.joints.len()
        );
        assert_same(&ours, &theirs, file);
    }
    Ok(())
}
