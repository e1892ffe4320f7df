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
}
