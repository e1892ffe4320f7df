//! Triangle meshes for the renderer: primitives with their sizes baked in (so instance
//! transforms stay rigid and normals stay right), URDF and SDF mesh files with their textures
//! (decoded once per file and mesh; one that will not decode is a warning and a flat colour),
//! and the human figure.

use std::sync::Arc;

use glam::{Quat, Vec3};

use crate::description::mesh_file::{load_mesh, load_texture};
use crate::description::trimesh::TriMesh;
use crate::error::Result;
use crate::geometry::{Pose, Rgba, Shape};
use crate::model::mesh::{MeshData, TextureImage, TexturedRun};
use crate::model::person::Person;
use crate::model::robot::Visual;

/// A box with full side lengths, centred.
pub(crate) fn cuboid(size: Vec3) -> MeshData {
    let h = size / 2.0;
    let mut m = MeshData::default();
    let faces = [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (Vec3::NEG_X, Vec3::NEG_Y, Vec3::Z),
        (Vec3::Y, Vec3::NEG_X, Vec3::Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    for (n, u, v) in faces {
        let c = n * h;
        let (du, dv) = (u * h, v * h);
        m.quad([c - du - dv, c + du - dv, c + du + dv, c - du + dv], n);
    }
    m
}

/// A cylinder along z, centred, with texture coordinates as Gazebo's cylinder has them: round
/// the side u from 0 to 1 (from +x, counter-clockwise seen from above), v from 0 at the top to
/// 1 at the bottom, so a label image wraps it once; the caps mapped flat (u along x, v against
/// y).
pub(crate) fn cylinder(radius: f32, length: f32, segments: u32) -> MeshData {
    let mut m = MeshData::default();
    let hz = length / 2.0;
    let ring = |i: u32| {
        let a = i as f32 / segments as f32 * std::f32::consts::TAU;
        Vec3::new(a.cos(), a.sin(), 0.0)
    };
    let push = |m: &mut MeshData, p: Vec3, n: Vec3, uv: [f32; 2]| {
        m.uvs.push(uv);
        m.push(p, n)
    };
    let cap_uv = |p: Vec3| [0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y];
    for i in 0..segments {
        let (a, b) = (ring(i), ring(i + 1));
        let (ua, ub) = (i as f32 / segments as f32, (i + 1) as f32 / segments as f32);
        let idx = [
            push(&mut m, a * radius - Vec3::Z * hz, a, [ua, 1.0]),
            push(&mut m, b * radius - Vec3::Z * hz, b, [ub, 1.0]),
            push(&mut m, b * radius + Vec3::Z * hz, b, [ub, 0.0]),
            push(&mut m, a * radius + Vec3::Z * hz, a, [ua, 0.0]),
        ];
        m.indices
            .extend_from_slice(&[idx[0], idx[1], idx[2], idx[0], idx[2], idx[3]]);
        for (z, n) in [(hz, Vec3::Z), (-hz, Vec3::NEG_Z)] {
            let c = push(&mut m, Vec3::Z * z, n, [0.5, 0.5]);
            let pa = push(&mut m, a * radius + Vec3::Z * z, n, cap_uv(a));
            let pb = push(&mut m, b * radius + Vec3::Z * z, n, cap_uv(b));
            if z > 0.0 {
                m.indices.extend_from_slice(&[c, pa, pb]);
            } else {
                m.indices.extend_from_slice(&[c, pb, pa]);
            }
        }
    }
    m
}

/// A UV sphere, centred, stretched by `scale` per axis (an ellipsoid when not uniform).
pub(crate) fn ellipsoid(radius: f32, scale: Vec3, rings: u32, segments: u32) -> MeshData {
    let mut m = MeshData::default();
    for r in 0..=rings {
        let phi = r as f32 / rings as f32 * std::f32::consts::PI;
        for s in 0..=segments {
            let theta = s as f32 / segments as f32 * std::f32::consts::TAU;
            let unit = Vec3::new(phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos());
            m.push(unit * radius * scale, unit / scale);
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            m.indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

/// A sphere, centred.
pub(crate) fn sphere(radius: f32) -> MeshData {
    ellipsoid(radius, Vec3::ONE, 12, 20)
}

/// A capsule along z: cylinder part `length`, caps of `radius`.
pub(crate) fn capsule(radius: f32, length: f32) -> MeshData {
    let mut m = cylinder(radius, length, 20);
    // No texture coordinates for the caps' spheres: none for the whole.
    m.uvs.clear();
    let cap = sphere(radius);
    m.append(&cap, Pose::from_translation(Vec3::Z * length / 2.0));
    m.append(&cap, Pose::from_translation(Vec3::NEG_Z * length / 2.0));
    m
}

/// Sides of a URDF cylinder's mesh.
const SHAPE_CYLINDER_SEGMENTS: u32 = 24;
/// Sides of a world object's cylinder (drawn finer: objects are bigger and seen closer).
const OBJECT_CYLINDER_SEGMENTS: u32 = 32;

/// The mesh of a robot's or a model's shape, in the shape's frame.
pub fn shape_mesh(shape: &Shape) -> Result<MeshData> {
    mesh_of(shape, SHAPE_CYLINDER_SEGMENTS)
}

/// The mesh of a world object, centred on its position: [`shape_mesh`] with finer cylinders.
pub fn object_mesh(shape: &Shape) -> Result<MeshData> {
    mesh_of(shape, OBJECT_CYLINDER_SEGMENTS)
}

fn mesh_of(shape: &Shape, cylinder_segments: u32) -> Result<MeshData> {
    Ok(match shape {
        Shape::Box { size_m } => cuboid(*size_m),
        Shape::Cylinder { radius_m, length_m } => cylinder(*radius_m, *length_m, cylinder_segments),
        Shape::Sphere { radius_m } => sphere(*radius_m),
        Shape::Capsule { radius_m, length_m } => capsule(*radius_m, *length_m),
        Shape::Mesh { path, scale } => file_mesh(&load_mesh(path, *scale)?),
    })
}

/// A mesh file's triangles flat shaded (one normal per face), with its textured parts.
fn file_mesh(tri: &TriMesh) -> MeshData {
    let mut m = MeshData {
        color: tri.color,
        ..MeshData::default()
    };
    for t in &tri.triangles {
        let [a, b, c] = t.map(|i| tri.positions.get(i as usize).copied().unwrap_or(Vec3::ZERO));
        let n = (b - a).cross(c - a);
        for (corner, p) in t.iter().zip([a, b, c]) {
            let i = m.push(p, n);
            m.indices.push(i);
            if !tri.uvs.is_empty() {
                m.uvs
                    .push(tri.uvs.get(*corner as usize).copied().unwrap_or_default());
            }
        }
    }
    let mut textures: Vec<Arc<TextureImage>> = Vec::new();
    for part in &tri.parts {
        let Some(path) = &part.texture else {
            continue;
        };
        let texture = match textures.iter().find(|t| &t.path == path) {
            Some(t) => Arc::clone(t),
            None => match load_texture(path) {
                Ok(t) => {
                    textures.push(Arc::new(t));
                    Arc::clone(&textures[textures.len() - 1])
                }
                Err(e) => {
                    tracing::warn!("{e}; drawing that part in its flat colour");
                    continue;
                }
            },
        };
        m.textured.push(TexturedRun {
            first_index: (part.first_triangle * 3) as u32,
            count: (part.triangles * 3) as u32,
            texture,
        });
    }
    m
}

/// A visual's mesh as the camera draws it: [`shape_mesh`], with the texture of the visual's
/// material script (Gazebo's OGRE `texture`) over the whole mesh when it has one and the mesh
/// has texture coordinates.
pub fn visual_mesh(visual: &Visual) -> Result<MeshData> {
    let mut mesh = shape_mesh(&visual.shape)?;
    if let Some(path) = &visual.texture
        && !mesh.uvs.is_empty()
    {
        match load_texture(path) {
            Ok(texture) => {
                mesh.textured = vec![TexturedRun {
                    first_index: 0,
                    count: mesh.indices.len() as u32,
                    texture: Arc::new(texture),
                }];
            }
            Err(e) => tracing::warn!("{e}; drawing the visual in its flat colour"),
        }
    }
    Ok(mesh)
}

/// A coloured part of a figure, in the figure's frame.
#[derive(Debug, Clone)]
pub struct PersonPart {
    /// The mesh, in the part's frame.
    pub mesh: MeshData,
    /// Where the part sits in the figure's frame, standing.
    pub pose: Pose,
    /// Its colour.
    pub color: Rgba,
    /// Where the colour comes from (re-dressing a person repaints the clothes).
    pub paint: Paint,
    /// How it moves as the person walks.
    pub swing: Swing,
}

impl PersonPart {
    /// Where the part sits in the figure's frame at gait phase `phase_rad`
    /// ([`Person::gait_phase_rad`]; 0: standing, `pose`).
    pub fn pose_at(&self, phase_rad: f64) -> Pose {
        self.swing.pose_at(self.pose, phase_rad)
    }
}

/// How far the legs swing forward and back from the hips as a person walks (rad, each way).
pub const LEG_SWING_RAD: f64 = 0.4;

/// How a figure part moves with the gait: it turns about `pivot` (the hip for a leg, the
/// shoulder for an arm) by `gain` times the legs' swing, and the whole figure sinks as far as
/// the swung legs (`leg_m` long) reach less far down, so both feet stay on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Swing {
    /// The joint it turns about (figure frame, m).
    pub pivot: Vec3,
    /// Its turn about the figure's y axis per radian of leg swing (0: carried along only).
    pub gain: f32,
    /// Hip height (m): how far the legs reach down.
    pub leg_m: f32,
    /// Carried round the pivot but kept level (a shoe stays flat on the ground).
    pub level: bool,
}

impl Swing {
    /// `pose` (figure frame, standing) at gait phase `phase_rad`: the legs swing
    /// `LEG_SWING_RAD * sin(phase)`, the figure sinks `leg_m * (1 - cos(swing))`.
    pub fn pose_at(&self, pose: Pose, phase_rad: f64) -> Pose {
        if phase_rad == 0.0 {
            return pose;
        }
        let swing = (LEG_SWING_RAD * phase_rad.sin()) as f32;
        let sink = Pose::from_translation(Vec3::new(0.0, 0.0, -self.leg_m * (1.0 - swing.cos())));
        if self.gain == 0.0 {
            return sink * pose;
        }
        let turn = Quat::from_rotation_y(self.gain * swing);
        if self.level {
            let origin = self.pivot + turn * (pose.translation - self.pivot);
            return sink * Pose::from_parts(origin, pose.rotation);
        }
        let turn = Pose::from_translation(self.pivot)
            * Pose::from_parts(Vec3::ZERO, turn)
            * Pose::from_translation(-self.pivot);
        sink * turn * pose
    }
}

/// Where a figure part's colour comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Paint {
    /// The person's shirt colour.
    Shirt,
    /// The person's trousers colour.
    Trousers,
    /// The person's skin colour.
    Skin,
    /// The person's hair colour.
    Hair,
    /// A colour of its own (shoes, lips).
    Fixed(Rgba),
}

impl Paint {
    /// The colour this paint has on `person`.
    pub fn of(self, person: &Person) -> Rgba {
        match self {
            Self::Shirt => person.shirt_color,
            Self::Trousers => person.trousers_color,
            Self::Skin => person.skin_color,
            Self::Hair => person.hair_color,
            Self::Fixed(color) => color,
        }
    }
}

/// One cross-section of a [`loft`]: at height `z`, a rounded rectangle with half sizes
/// `half_x` (front-back) and `half_y` (side to side), centred at (`x`, `y`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Section {
    /// Height (m).
    pub z: f32,
    /// Centre, front-back (m).
    pub x: f32,
    /// Centre, side to side (m).
    pub y: f32,
    /// Half depth (m).
    pub half_x: f32,
    /// Half width (m).
    pub half_y: f32,
}

impl Section {
    /// A section centred on the axis.
    pub const fn new(z: f32, half_x: f32, half_y: f32) -> Self {
        Self {
            z,
            x: 0.0,
            y: 0.0,
            half_x,
            half_y,
        }
    }

    /// The same section moved by (`x`, `y`).
    pub const fn at(self, x: f32, y: f32) -> Self {
        Self { x, y, ..self }
    }
}

/// A smooth closed body through `sections` (bottom to top): each section is a superellipse
/// with exponent `squareness` (2 = ellipse, larger = boxier); the ends are capped. Normals are
/// averaged over the faces around each vertex, so the surface shades smoothly.
pub(crate) fn loft(sections: &[Section], squareness: f32, segments: u32) -> MeshData {
    let mut m = MeshData::default();
    if sections.len() < 2 {
        return m;
    }
    let e = 2.0 / squareness.max(0.1);
    let ring_point = |s: &Section, i: u32| {
        let a = i as f32 / segments as f32 * std::f32::consts::TAU;
        let (c, sn) = (a.cos(), a.sin());
        let sx = c.signum() * c.abs().powf(e);
        let sy = sn.signum() * sn.abs().powf(e);
        Vec3::new(s.x + sx * s.half_x, s.y + sy * s.half_y, s.z)
    };
    let mut positions = Vec::new();
    for s in sections {
        for i in 0..segments {
            positions.push(ring_point(s, i));
        }
    }
    let first = sections[0];
    let last = sections[sections.len() - 1];
    let bottom = positions.len() as u32;
    positions.push(Vec3::new(first.x, first.y, first.z));
    let top = bottom + 1;
    positions.push(Vec3::new(last.x, last.y, last.z));
    let mut tris = Vec::new();
    for r in 0..sections.len() as u32 - 1 {
        for i in 0..segments {
            let j = (i + 1) % segments;
            let (a, b) = (r * segments + i, r * segments + j);
            let (c, d) = (a + segments, b + segments);
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
    }
    let top_ring = (sections.len() as u32 - 1) * segments;
    for i in 0..segments {
        let j = (i + 1) % segments;
        tris.push([bottom, j, i]);
        tris.push([top, top_ring + i, top_ring + j]);
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in &tris {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for i in t {
            normals[*i as usize] += n;
        }
    }
    // The caps get their own flat-ish normals so the ring edge stays rounded.
    normals[bottom as usize] = Vec3::NEG_Z;
    normals[top as usize] = Vec3::Z;
    for (p, n) in positions.iter().zip(&normals) {
        m.push(*p, *n);
    }
    for t in tris {
        m.indices.extend_from_slice(&t);
    }
    m
}

/// A limb from `from` to `to` (figure frame): a loft with radius `r_from` at `from` and `r_to`
/// at `to`, rounded ends.
fn limb(from: Vec3, to: Vec3, r_from: f32, r_to: f32) -> (MeshData, Pose) {
    let axis = to - from;
    let len = axis.length().max(1e-4);
    let mut sections = Vec::new();
    // Rounded ends: a few shrinking rings beyond each end.
    for k in [0.0f32, 0.5, 0.8, 1.0] {
        let r = r_from * (1.0 - k * k).sqrt().max(0.05);
        sections.push(Section::new(-r_from * k, r, r));
    }
    sections.reverse();
    for t in [0.25f32, 0.5, 0.75] {
        let r = r_from + (r_to - r_from) * t;
        sections.push(Section::new(len * t, r, r));
    }
    for k in [0.0f32, 0.5, 0.8, 1.0] {
        let r = r_to * (1.0 - k * k).sqrt().max(0.05);
        sections.push(Section::new(len + r_to * k, r, r));
    }
    let rotation = Quat::from_rotation_arc(Vec3::Z, axis / len);
    (loft(&sections, 2.0, 14), Pose::from_parts(from, rotation))
}

/// A standing person in its own frame: feet on z = 0, facing +x, proportioned to `height_m`
/// (a head about 1/7.5 of the height, shoulders about a quarter of it wide).
pub fn person_parts(person: &Person) -> Vec<PersonPart> {
    let mut f = Figure {
        s: (person.height_m / 1.75) as f32,
        person,
        parts: Vec::new(),
    };
    limbs(&mut f);
    trunk(&mut f);
    face(&mut f);
    f.parts
}

/// A figure being built: its scale against a 1.75 m person, whose colours it wears, and its
/// parts so far.
struct Figure<'p> {
    s: f32,
    person: &'p Person,
    parts: Vec<PersonPart>,
}

impl Figure<'_> {
    fn v(&self, x: f32, y: f32, z: f32) -> Vec3 {
        Vec3::new(x, y, z) * self.s
    }

    fn at(&self, x: f32, y: f32, z: f32) -> Pose {
        Pose::from_translation(self.v(x, y, z))
    }

    fn scaled(&self, sections: &[Section]) -> Vec<Section> {
        let s = self.s;
        sections
            .iter()
            .map(|c| Section {
                z: c.z * s,
                x: c.x * s,
                y: c.y * s,
                half_x: c.half_x * s,
                half_y: c.half_y * s,
            })
            .collect()
    }

    fn add(&mut self, mesh: MeshData, pose: Pose, paint: Paint) {
        self.add_swinging(mesh, pose, paint, Vec3::ZERO, 0.0);
    }

    /// A part that turns about `pivot` by `gain` times the legs' swing as the person walks.
    fn add_swinging(&mut self, mesh: MeshData, pose: Pose, paint: Paint, pivot: Vec3, gain: f32) {
        self.add_moving(mesh, pose, paint, pivot, gain, false);
    }

    /// A part that moves about `pivot` by `gain` times the legs' swing, turning with it or
    /// (`level`) kept level.
    fn add_moving(
        &mut self,
        mesh: MeshData,
        pose: Pose,
        paint: Paint,
        pivot: Vec3,
        gain: f32,
        level: bool,
    ) {
        let color = paint.of(self.person);
        let swing = Swing {
            pivot,
            gain,
            leg_m: HIP_Z * self.s,
            level,
        };
        self.parts.push(PersonPart {
            mesh,
            pose,
            color,
            paint,
            swing,
        });
    }
}

/// The hip joints' height on a 1.75 m figure (m): where the legs swing from.
const HIP_Z: f32 = 0.9;
/// How far the arms swing against the legs (each arm opposite its own side's leg).
const ARM_SWING_GAIN: f32 = 0.6;

/// Shoes, legs and arms.
fn limbs(f: &mut Figure) {
    let shoe = Rgba::rgb(0.1, 0.08, 0.07);
    for side in [-1.0f32, 1.0] {
        let y = 0.09 * side;
        // Walking, the left leg (side +1) swings forward (a turn about -y) as the left arm
        // swings back.
        let hip = f.v(0.0, 0.0, HIP_Z);
        let leg_gain = -side;
        // The shoes go with the legs but stay flat (a foot bends at the ankle).
        f.add_moving(
            ellipsoid(0.1 * f.s, Vec3::new(1.25, 0.48, 0.45), 8, 12),
            f.at(0.035, y * 1.3, 0.045),
            Paint::Fixed(shoe),
            hip,
            leg_gain,
            true,
        );
        // Leg: ankle, calf, knee, thigh, hip; loose trousers, feet a little apart. A low
        // camera at the follower's standoff sees no more than the legs and the shirt's hem:
        // drawn thin and parallel, YOLO called them a chair (docs/GROUND_TRUTH.md).
        let leg = f.scaled(&[
            Section::new(0.06, 0.055, 0.052).at(0.0, y * 1.3),
            Section::new(0.2, 0.058, 0.055).at(0.0, y * 1.22),
            Section::new(0.36, 0.064, 0.062).at(0.0, y * 1.13),
            Section::new(0.5, 0.062, 0.06).at(0.0, y * 1.05),
            Section::new(0.7, 0.078, 0.078).at(0.0, y * 0.95),
            Section::new(0.86, 0.085, 0.088).at(0.0, y * 0.9),
            Section::new(0.9, 0.075, 0.078).at(0.0, y * 0.85),
        ]);
        f.add_swinging(
            loft(&leg, 2.0, 16),
            Pose::IDENTITY,
            Paint::Trousers,
            hip,
            leg_gain,
        );
        // Arm: shoulder, elbow, wrist hanging just off the body.
        let shoulder = f.v(0.0, 0.185 * side, 1.42);
        let elbow = f.v(-0.03, 0.225 * side, 1.14);
        let wrist = f.v(0.07, 0.24 * side, 0.9);
        let arm_gain = -leg_gain * ARM_SWING_GAIN;
        let (mesh, pose) = limb(shoulder, elbow, 0.052 * f.s, 0.042 * f.s);
        f.add_swinging(mesh, pose, Paint::Shirt, shoulder, arm_gain);
        let (mesh, pose) = limb(elbow, wrist, 0.036 * f.s, 0.027 * f.s);
        f.add_swinging(mesh, pose, Paint::Skin, shoulder, arm_gain);
        f.add_swinging(
            ellipsoid(0.045 * f.s, Vec3::new(0.65, 0.5, 1.3), 8, 12),
            Pose::from_parts(f.v(0.09, 0.243 * side, 0.84), Quat::from_rotation_y(-0.35)),
            Paint::Skin,
            shoulder,
            arm_gain,
        );
    }
}

/// Pelvis, torso and neck.
fn trunk(f: &mut Figure) {
    // Pelvis in trousers, torso in the shirt (worn untucked, over the hips): shoulders broad,
    // waist narrower.
    let pelvis = f.scaled(&[
        Section::new(0.8, 0.06, 0.1),
        Section::new(0.86, 0.1, 0.165),
        Section::new(0.95, 0.11, 0.175),
        Section::new(1.03, 0.105, 0.165),
    ]);
    f.add(loft(&pelvis, 2.6, 24), Pose::IDENTITY, Paint::Trousers);
    let torso = f.scaled(&[
        Section::new(0.84, 0.118, 0.185),
        Section::new(0.9, 0.118, 0.185),
        Section::new(0.98, 0.112, 0.175),
        Section::new(1.1, 0.1, 0.155),
        Section::new(1.22, 0.11, 0.165),
        Section::new(1.33, 0.115, 0.18),
        Section::new(1.41, 0.1, 0.19),
        Section::new(1.46, 0.07, 0.14),
        Section::new(1.48, 0.04, 0.06),
    ]);
    f.add(loft(&torso, 2.6, 24), Pose::IDENTITY, Paint::Shirt);
    let neck = f.scaled(&[
        Section::new(1.42, 0.048, 0.048),
        Section::new(1.58, 0.045, 0.045),
    ]);
    f.add(loft(&neck, 2.0, 12), f.at(-0.01, 0.0, 0.0), Paint::Skin);
}

/// Eyes, brows, ears, mouth, nose, head and hair.
fn face(f: &mut Figure) {
    // Eyes, brows and mouth on the face (the face's front is at x ~ 0.1).
    let dark = Paint::Fixed(Rgba::rgb(0.08, 0.06, 0.05));
    for side in [-1.0f32, 1.0] {
        f.add(
            ellipsoid(0.012 * f.s, Vec3::new(0.6, 1.2, 0.8), 6, 8),
            f.at(0.093, 0.032 * side, 1.655),
            dark,
        );
        f.add(
            ellipsoid(0.016 * f.s, Vec3::new(0.4, 1.6, 0.35), 6, 8),
            f.at(0.092, 0.034 * side, 1.682),
            Paint::Hair,
        );
        // Ears.
        f.add(
            ellipsoid(0.03 * f.s, Vec3::new(0.6, 0.35, 1.0), 6, 8),
            f.at(0.0, 0.08 * side, 1.64),
            Paint::Skin,
        );
    }
    f.add(
        ellipsoid(0.018 * f.s, Vec3::new(0.4, 1.5, 0.35), 6, 8),
        f.at(0.09, 0.0, 1.585),
        Paint::Fixed(Rgba::rgb(0.55, 0.25, 0.22)),
    );
    // Nose.
    f.add(
        ellipsoid(0.016 * f.s, Vec3::new(0.9, 0.8, 1.3), 6, 8),
        f.at(0.1, 0.0, 1.625),
        Paint::Skin,
    );
    // Head: the face in skin, hair over the top and back.
    f.add(
        ellipsoid(0.1 * f.s, Vec3::new(0.95, 0.8, 1.15), 12, 18),
        f.at(0.005, 0.0, 1.635),
        Paint::Skin,
    );
    f.add(
        ellipsoid(0.104 * f.s, Vec3::new(0.98, 0.86, 0.7), 10, 16),
        f.at(-0.006, 0.0, 1.7),
        Paint::Hair,
    );
    f.add(
        ellipsoid(0.09 * f.s, Vec3::new(0.7, 0.88, 1.0), 8, 12),
        f.at(-0.045, 0.0, 1.62),
        Paint::Hair,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitive_bounds() {
        let b = cuboid(Vec3::new(1.0, 2.0, 3.0));
        let max = b
            .vertices
            .iter()
            .fold(Vec3::ZERO, |m, v| m.max(Vec3::from_array(v.position)));
        assert_eq!(max, Vec3::new(0.5, 1.0, 1.5));
        assert_eq!(b.indices.len(), 36);
        let c = cylinder(0.5, 2.0, 16);
        let max = c
            .vertices
            .iter()
            .fold(Vec3::ZERO, |m, v| m.max(Vec3::from_array(v.position)));
        assert!((max - Vec3::new(0.5, 0.5, 1.0)).length() < 1e-3);
        // Texture coordinates for every vertex: the side's top at v 0, its bottom at v 1.
        assert_eq!(c.uvs.len(), c.vertices.len());
        for (v, uv) in c.vertices.iter().zip(&c.uvs) {
            let side = v.normal[2] == 0.0;
            if side {
                assert_eq!(uv[1], if v.position[2] > 0.0 { 0.0 } else { 1.0 });
            }
        }
    }

    /// The lowest point and the furthest forward point of a person's feet on one side
    /// (y > 0: left; what of the swinging parts is within 0.2 m of the figure's lowest point),
    /// at gait phase `phase_rad`.
    fn reach(parts: &[PersonPart], left: bool, phase_rad: f64) -> (f32, f32) {
        let (mut low, mut ahead) = (f32::INFINITY, f32::NEG_INFINITY);
        for part in parts.iter().filter(|p| p.swing.gain != 0.0) {
            let pose = part.pose_at(phase_rad);
            for v in &part.mesh.vertices {
                let p = pose * Vec3::from_array(v.position);
                if (p.y > 0.0) == left && p.z < 0.2 {
                    low = low.min(p.z);
                    ahead = ahead.max(p.x);
                }
            }
        }
        (low, ahead)
    }

    #[test]
    fn a_walking_person_strides_with_both_feet_on_the_ground() {
        let parts = person_parts(&Person::standing("p", [0.0, 0.0], 0.0));
        let (standing_low, standing_ahead) = reach(&parts, true, 0.0);
        assert!(
            standing_low.abs() < 0.01,
            "standing feet at {standing_low} m"
        );
        // A quarter cycle in: the left leg forward, the right back, both feet down (the
        // figure sinks as far as the swung legs reach less far down).
        let quarter = std::f64::consts::FRAC_PI_2;
        let (left_low, left_ahead) = reach(&parts, true, quarter);
        let (right_low, right_ahead) = reach(&parts, false, quarter);
        assert!(
            left_ahead > standing_ahead + 0.25,
            "left foot at {left_ahead} m"
        );
        assert!(
            right_ahead < standing_ahead - 0.2,
            "right foot at {right_ahead} m"
        );
        for low in [left_low, right_low] {
            assert!(low.abs() < 0.03, "a foot at {low} m above the ground");
        }
        // The arms swing against the legs: the left hand goes back.
        let left_hand = |phase_rad: f64| {
            parts
                .iter()
                .filter(|p| p.swing.gain > 0.0)
                .flat_map(|p| {
                    let pose = p.pose_at(phase_rad);
                    p.mesh
                        .vertices
                        .iter()
                        .map(move |v| pose * Vec3::from_array(v.position))
                })
                .filter(|p| p.y > 0.0)
                .map(|p| p.x)
                .fold(f32::INFINITY, f32::min)
        };
        assert!(left_hand(quarter) < left_hand(0.0) - 0.05);
        // Standing (phase 0) every part sits where the figure was built.
        assert!(parts.iter().all(|p| p.pose_at(0.0) == p.pose));
    }
}
