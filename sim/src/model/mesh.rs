//! Triangle meshes as plain data: what the renderer uploads and what viewers draw, in the
//! thing's own frame.

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;

use crate::geometry::{Pose, Rgba};

/// One vertex: position and normal, in the mesh's own frame. Plain data: the renderer copies
/// it into its own GPU layout when it uploads the mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshVertex {
    /// Position (m).
    pub position: [f32; 3],
    /// Unit normal.
    pub normal: [f32; 3],
}

/// An indexed triangle mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    /// Vertices.
    pub vertices: Vec<MeshVertex>,
    /// Triangle indices, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
    /// The colour a mesh file's material gives it, if any.
    pub color: Option<Rgba>,
    /// Texture coordinates per vertex (u right, v down, in 0..1 repeating), or empty.
    pub uvs: Vec<[f32; 2]>,
    /// Runs of `indices` drawn with a texture (the rest is drawn in the mesh's colour).
    pub textured: Vec<TexturedRun>,
}

/// A run of a mesh's indices drawn with a diffuse texture instead of its colour.
#[derive(Debug, Clone, PartialEq)]
pub struct TexturedRun {
    /// First index (into [`MeshData::indices`]).
    pub first_index: u32,
    /// Number of indices.
    pub count: u32,
    /// The decoded texture (shared by every mesh that uses the file).
    pub texture: Arc<TextureImage>,
}

/// A decoded texture image, RGBA8 rows top to bottom.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureImage {
    /// The file it came from.
    pub path: PathBuf,
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// RGBA8 pixels.
    pub rgba: Vec<u8>,
}

impl MeshData {
    pub(crate) fn push(&mut self, position: Vec3, normal: Vec3) -> u32 {
        self.vertices.push(MeshVertex {
            position: position.to_array(),
            normal: normal.normalize_or_zero().to_array(),
        });
        (self.vertices.len() - 1) as u32
    }

    pub(crate) fn quad(&mut self, corners: [Vec3; 4], normal: Vec3) {
        let base = corners.map(|c| self.push(c, normal));
        self.indices
            .extend_from_slice(&[base[0], base[1], base[2], base[0], base[2], base[3]]);
    }

    /// Appends `other` transformed by `pose`.
    pub fn append(&mut self, other: &MeshData, pose: Pose) {
        let offset = self.vertices.len() as u32;
        for v in &other.vertices {
            self.vertices.push(MeshVertex {
                position: (pose * Vec3::from_array(v.position)).to_array(),
                normal: (pose.rotation * Vec3::from_array(v.normal)).to_array(),
            });
        }
        self.indices
            .extend(other.indices.iter().map(|i| i + offset));
    }

    /// Splits the mesh at the height `z_m` of another frame, `frame_from_mesh` placing the mesh
    /// in it: the part at or above that height, then the part at or below it. Triangles the
    /// plane crosses are cut, positions, normals and texture coordinates interpolated along
    /// their edges; textured runs and the colour are kept. (A Gazebo model whose COCO box
    /// covers only part of it, such as a stop sign's face without its pole, is labelled by
    /// the upper part.)
    pub fn split_at_height(&self, frame_from_mesh: Pose, z_m: f32) -> (MeshData, MeshData) {
        // Height in the frame = normal . p + lift, for p in the mesh's frame.
        let normal = frame_from_mesh.rotation.inverse() * Vec3::Z;
        let lift = frame_from_mesh.translation.z;
        let mut above = Clipped::new(self);
        let mut below = Clipped::new(self);
        let mut runs: Vec<&TexturedRun> = self.textured.iter().collect();
        runs.sort_by_key(|r| r.first_index);
        for (t, corners) in self.indices.chunks_exact(3).enumerate() {
            let first = (3 * t) as u32;
            let texture = runs
                .iter()
                .find(|r| (r.first_index..r.first_index + r.count).contains(&first))
                .map(|r| &r.texture);
            let corners = [0, 1, 2].map(|k| self.corner(corners[k]));
            let height = corners.map(|c| normal.dot(c.position) + lift - z_m);
            above.add(&corners, height, texture);
            below.add(&corners, height.map(|h| -h), texture);
        }
        (above.mesh, below.mesh)
    }

    fn corner(&self, index: u32) -> Corner {
        let i = index as usize;
        let v = self.vertices.get(i).copied().unwrap_or(MeshVertex {
            position: [0.0; 3],
            normal: [0.0; 3],
        });
        Corner {
            position: Vec3::from_array(v.position),
            normal: Vec3::from_array(v.normal),
            uv: self.uvs.get(i).copied().unwrap_or_default(),
        }
    }
}

/// A vertex being clipped.
#[derive(Debug, Clone, Copy)]
struct Corner {
    position: Vec3,
    normal: Vec3,
    uv: [f32; 2],
}

impl Corner {
    fn lerp(&self, other: &Corner, t: f32) -> Corner {
        Corner {
            position: self.position.lerp(other.position, t),
            normal: self.normal.lerp(other.normal, t),
            uv: [
                self.uv[0] + (other.uv[0] - self.uv[0]) * t,
                self.uv[1] + (other.uv[1] - self.uv[1]) * t,
            ],
        }
    }
}

/// One side of [`MeshData::split_at_height`] being built.
struct Clipped {
    mesh: MeshData,
    with_uvs: bool,
}

impl Clipped {
    fn new(source: &MeshData) -> Self {
        Self {
            mesh: MeshData {
                color: source.color,
                ..MeshData::default()
            },
            with_uvs: !source.uvs.is_empty(),
        }
    }

    /// Adds the part of a triangle where `height >= 0` (Sutherland-Hodgman against one plane:
    /// a triangle, a quad as two triangles, or nothing).
    fn add(
        &mut self,
        corners: &[Corner; 3],
        height: [f32; 3],
        texture: Option<&Arc<TextureImage>>,
    ) {
        // At most four: each edge gives its start if kept and the point where it crosses.
        let mut kept = [corners[0]; 4];
        let mut n = 0;
        for k in 0..3 {
            let (a, b) = (k, (k + 1) % 3);
            if height[a] >= 0.0 {
                kept[n] = corners[a];
                n += 1;
            }
            if (height[a] < 0.0) != (height[b] < 0.0) {
                let t = height[a] / (height[a] - height[b]);
                kept[n] = corners[a].lerp(&corners[b], t);
                n += 1;
            }
        }
        for k in 1..n.saturating_sub(1) {
            self.triangle([kept[0], kept[k], kept[k + 1]], texture);
        }
    }

    fn triangle(&mut self, corners: [Corner; 3], texture: Option<&Arc<TextureImage>>) {
        let first = self.mesh.indices.len() as u32;
        for c in corners {
            let index = self.mesh.push(c.position, c.normal);
            if self.with_uvs {
                self.mesh.uvs.push(c.uv);
            }
            self.mesh.indices.push(index);
        }
        let Some(texture) = texture else {
            return;
        };
        match self.mesh.textured.last_mut() {
            Some(run)
                if Arc::ptr_eq(&run.texture, texture) && run.first_index + run.count == first =>
            {
                run.count += 3;
            }
            _ => self.mesh.textured.push(TexturedRun {
                first_index: first,
                count: 3,
                texture: texture.clone(),
            }),
        }
    }
}

#[cfg(test)]
#[allow(
    clippy::unwrap_used,
    reason = "tests: a failed unwrap is a failed test"
)]
mod tests {
    use super::*;
    use glam::Quat;

    /// A 1 m wide, 2 m tall quad standing in the x-z plane, textured, v running down from the
    /// top (v = 0 at z = 2, v = 1 at z = 0).
    fn board() -> MeshData {
        let mut m = MeshData::default();
        m.quad(
            [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 2.0),
                Vec3::new(0.0, 0.0, 2.0),
            ],
            -Vec3::Y,
        );
        m.uvs = vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
        m.textured.push(TexturedRun {
            first_index: 0,
            count: 6,
            texture: Arc::new(TextureImage {
                path: PathBuf::from("board.png"),
                width: 1,
                height: 1,
                rgba: vec![255; 4],
            }),
        });
        m.color = Some(Rgba::rgb(0.5, 0.5, 0.5));
        m
    }

    fn area(m: &MeshData) -> f32 {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let p: Vec<Vec3> = t
                    .iter()
                    .map(|&i| Vec3::from_array(m.vertices[i as usize].position))
                    .collect();
                0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
            })
            .sum()
    }

    fn z_range(m: &MeshData) -> (f32, f32) {
        m.vertices.iter().fold((f32::MAX, f32::MIN), |(lo, hi), v| {
            (lo.min(v.position[2]), hi.max(v.position[2]))
        })
    }

    #[test]
    fn a_mesh_splits_at_a_height_with_its_texture_coordinates_and_runs() {
        let (above, below) = board().split_at_height(Pose::IDENTITY, 1.5);
        assert!((area(&above) - 0.5).abs() < 1e-5, "{}", area(&above));
        assert!((area(&below) - 1.5).abs() < 1e-5, "{}", area(&below));
        assert_eq!(z_range(&above), (1.5, 2.0));
        assert_eq!(z_range(&below), (0.0, 1.5));
        for part in [&above, &below] {
            assert_eq!(part.uvs.len(), part.vertices.len());
            // v follows height on the cut edges too.
            for (v, uv) in part.vertices.iter().zip(&part.uvs) {
                assert!(
                    (uv[1] - (1.0 - v.position[2] / 2.0)).abs() < 1e-6,
                    "{v:?} {uv:?}"
                );
            }
            assert_eq!(part.textured.len(), 1, "one run kept whole");
            assert_eq!(part.textured[0].first_index, 0);
            assert_eq!(part.textured[0].count as usize, part.indices.len());
            assert_eq!(part.color, Some(Rgba::rgb(0.5, 0.5, 0.5)));
            assert!(
                part.vertices
                    .iter()
                    .all(|v| (v.normal[1] + 1.0).abs() < 1e-6)
            );
        }
    }

    #[test]
    fn the_height_is_measured_in_the_frame_the_mesh_is_placed_in() {
        // Raised 1 m and laid flat (turned 90 degrees about x): the board's mesh z becomes
        // the frame's -y and its mesh y (0 everywhere) the frame's z, so all of it lies at
        // 1 m: none above 1.5 m, all above 0.5 m.
        let lying = Pose::from_parts(
            Vec3::new(0.0, 0.0, 1.0),
            Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
        );
        let (above, below) = board().split_at_height(lying, 1.5);
        assert!(above.indices.is_empty() && (area(&below) - 2.0).abs() < 1e-5);
        let (above, below) = board().split_at_height(lying, 0.5);
        assert!(below.indices.is_empty() && (area(&above) - 2.0).abs() < 1e-5);
        // Standing, raised 1 m: the cut at 1.5 m is at the mesh's 0.5 m.
        let raised = Pose::from_parts(Vec3::new(0.0, 0.0, 1.0), Quat::IDENTITY);
        let (above, _) = board().split_at_height(raised, 1.5);
        assert_eq!(z_range(&above), (0.5, 2.0));
    }
}
