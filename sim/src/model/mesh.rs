//! Triangle meshes as plain data: what the renderer uploads and what viewers draw, in the
//! thing's own frame.

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
