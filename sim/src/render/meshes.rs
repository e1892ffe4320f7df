//! Triangle meshes for the renderer: primitives with their sizes baked in (so instance
//! transforms stay rigid and normals stay right), URDF mesh files, and the human figure.

use glam::{Quat, Vec3};

use crate::error::Result;
use crate::geometry::{Pose, Rgba, Shape};
use crate::mesh::load_mesh;
use crate::world::Person;

/// One vertex: position and normal.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// Position (m).
    pub position: [f32; 3],
    /// Unit normal.
    pub normal: [f32; 3],
}

/// An indexed triangle mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    /// Vertices.
    pub vertices: Vec<Vertex>,
    /// Triangle indices, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

impl MeshData {
    fn push(&mut self, position: Vec3, normal: Vec3) -> u32 {
        self.vertices.push(Vertex {
            position: position.to_array(),
            normal: normal.normalize_or_zero().to_array(),
        });
        (self.vertices.len() - 1) as u32
    }

    fn quad(&mut self, corners: [Vec3; 4], normal: Vec3) {
        let base = corners.map(|c| self.push(c, normal));
        self.indices
            .extend_from_slice(&[base[0], base[1], base[2], base[0], base[2], base[3]]);
    }

    /// Appends `other` transformed by `pose`.
    pub fn append(&mut self, other: &MeshData, pose: Pose) {
        let offset = self.vertices.len() as u32;
        for v in &other.vertices {
            self.vertices.push(Vertex {
                position: (pose * Vec3::from_array(v.position)).to_array(),
                normal: (pose.rotation * Vec3::from_array(v.normal)).to_array(),
            });
        }
        self.indices
            .extend(other.indices.iter().map(|i| i + offset));
    }
}

/// A box with full side lengths, centred.
pub fn cuboid(size: Vec3) -> MeshData {
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

/// A cylinder along z, centred.
pub fn cylinder(radius: f32, length: f32, segments: u32) -> MeshData {
    let mut m = MeshData::default();
    let hz = length / 2.0;
    let ring = |i: u32| {
        let a = i as f32 / segments as f32 * std::f32::consts::TAU;
        Vec3::new(a.cos(), a.sin(), 0.0)
    };
    for i in 0..segments {
        let (a, b) = (ring(i), ring(i + 1));
        let p = [
            a * radius - Vec3::Z * hz,
            b * radius - Vec3::Z * hz,
            b * radius + Vec3::Z * hz,
            a * radius + Vec3::Z * hz,
        ];
        let idx = [
            m.push(p[0], a),
            m.push(p[1], b),
            m.push(p[2], b),
            m.push(p[3], a),
        ];
        m.indices
            .extend_from_slice(&[idx[0], idx[1], idx[2], idx[0], idx[2], idx[3]]);
        for (z, n) in [(hz, Vec3::Z), (-hz, Vec3::NEG_Z)] {
            let c = m.push(Vec3::Z * z, n);
            let pa = m.push(a * radius + Vec3::Z * z, n);
            let pb = m.push(b * radius + Vec3::Z * z, n);
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
pub fn ellipsoid(radius: f32, scale: Vec3, rings: u32, segments: u32) -> MeshData {
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
pub fn sphere(radius: f32) -> MeshData {
    ellipsoid(radius, Vec3::ONE, 12, 20)
}

/// A capsule along z: cylinder part `length`, caps of `radius`.
pub fn capsule(radius: f32, length: f32) -> MeshData {
    let mut m = cylinder(radius, length, 20);
    let cap = sphere(radius);
    m.append(&cap, Pose::from_translation(Vec3::Z * length / 2.0));
    m.append(&cap, Pose::from_translation(Vec3::NEG_Z * length / 2.0));
    m
}

/// The mesh of a URDF shape.
pub fn shape_mesh(shape: &Shape) -> Result<MeshData> {
    Ok(match shape {
        Shape::Box { size_m } => cuboid(*size_m),
        Shape::Cylinder { radius_m, length_m } => cylinder(*radius_m, *length_m, 24),
        Shape::Sphere { radius_m } => sphere(*radius_m),
        Shape::Capsule { radius_m, length_m } => capsule(*radius_m, *length_m),
        Shape::Mesh { path, scale } => {
            let tri = load_mesh(path, *scale)?;
            let mut m = MeshData::default();
            // Flat shading: one normal per face.
            for t in &tri.triangles {
                let [a, b, c] =
                    t.map(|i| tri.positions.get(i as usize).copied().unwrap_or(Vec3::ZERO));
                let n = (b - a).cross(c - a);
                for p in [a, b, c] {
                    let i = m.push(p, n);
                    m.indices.push(i);
                }
            }
            m
        }
    })
}

/// A coloured part of a figure, in the figure's frame.
#[derive(Debug, Clone)]
pub struct Part {
    /// The mesh, in the part's frame.
    pub mesh: MeshData,
    /// Where the part sits in the figure's frame.
    pub pose: Pose,
    /// Its colour.
    pub color: Rgba,
}

/// A standing person in its own frame: feet on z = 0, facing +x, proportioned to `height_m`
/// (a head about 1/7.5 of the height, shoulders about a quarter of it wide).
pub fn person_parts(person: &Person) -> Vec<Part> {
    let s = (person.height_m / 1.75) as f32;
    let at = |x: f32, y: f32, z: f32| Pose::from_translation(Vec3::new(x, y, z) * s);
    let tilt = |x: f32, y: f32, z: f32, roll: f32| {
        Pose::from_parts(Vec3::new(x, y, z) * s, Quat::from_rotation_x(roll))
    };
    let shoe = Rgba::rgb(0.1, 0.08, 0.07);
    let mut parts = Vec::new();
    let mut add = |mesh: MeshData, pose: Pose, color: Rgba| parts.push(Part { mesh, pose, color });
    for side in [-1.0f32, 1.0] {
        let y = 0.095 * side;
        add(
            ellipsoid(0.1 * s, Vec3::new(1.3, 0.5, 0.45), 8, 12),
            at(0.04, y, 0.04),
            shoe,
        );
        // Shin and thigh, a little thicker towards the hip.
        add(
            capsule(0.058 * s, 0.38 * s),
            at(0.0, y, 0.3),
            person.trousers_color,
        );
        add(
            capsule(0.075 * s, 0.33 * s),
            at(0.0, y * 0.95, 0.7),
            person.trousers_color,
        );
        // Arms hang close to the body: short sleeve, bare forearm, hand.
        let ay = 0.225 * side;
        add(
            capsule(0.048 * s, 0.2 * s),
            tilt(0.0, ay, 1.3, -0.12 * side),
            person.shirt_color,
        );
        add(
            capsule(0.036 * s, 0.24 * s),
            tilt(0.015, ay + 0.035 * side, 1.02, -0.06 * side),
            person.skin_color,
        );
        add(
            ellipsoid(0.045 * s, Vec3::new(0.7, 0.55, 1.3), 8, 12),
            at(0.02, ay + 0.045 * side, 0.83),
            person.skin_color,
        );
    }
    // Hips, then a torso that narrows from the shoulders to the waist.
    add(
        ellipsoid(0.2 * s, Vec3::new(0.5, 0.85, 0.5), 10, 16),
        at(0.0, 0.0, 0.93),
        person.trousers_color,
    );
    add(
        ellipsoid(0.2 * s, Vec3::new(0.6, 0.92, 1.25), 12, 18),
        at(0.0, 0.0, 1.2),
        person.shirt_color,
    );
    add(
        ellipsoid(0.2 * s, Vec3::new(0.58, 1.1, 0.5), 10, 18),
        at(0.0, 0.0, 1.38),
        person.shirt_color,
    );
    add(
        cylinder(0.045 * s, 0.12 * s, 12),
        at(0.0, 0.0, 1.5),
        person.skin_color,
    );
    // Eyes, brows and mouth on the face (the face's front is at x ~ 0.1).
    let dark = Rgba::rgb(0.08, 0.06, 0.05);
    for side in [-1.0f32, 1.0] {
        add(
            ellipsoid(0.012 * s, Vec3::new(0.6, 1.2, 0.8), 6, 8),
            at(0.093, 0.032 * side, 1.655),
            dark,
        );
        add(
            ellipsoid(0.016 * s, Vec3::new(0.4, 1.6, 0.35), 6, 8),
            at(0.092, 0.034 * side, 1.682),
            person.hair_color,
        );
    }
    add(
        ellipsoid(0.018 * s, Vec3::new(0.4, 1.5, 0.35), 6, 8),
        at(0.09, 0.0, 1.585),
        Rgba::rgb(0.55, 0.25, 0.22),
    );
    // Head: the face in skin, hair over the top and back.
    add(
        ellipsoid(0.1 * s, Vec3::new(0.95, 0.82, 1.15), 12, 18),
        at(0.005, 0.0, 1.635),
        person.skin_color,
    );
    add(
        ellipsoid(0.104 * s, Vec3::new(0.98, 0.88, 0.7), 10, 16),
        at(-0.006, 0.0, 1.7),
        person.hair_color,
    );
    add(
        ellipsoid(0.09 * s, Vec3::new(0.7, 0.9, 1.0), 8, 12),
        at(-0.045, 0.0, 1.62),
        person.hair_color,
    );
    parts
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
    }
}
