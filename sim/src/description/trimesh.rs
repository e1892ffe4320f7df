//! A mesh file's triangles as rover keeps them (`TriMesh`: positions, texture coordinates,
//! triangles, a part per material) and where a texture a file names is found: shared by the
//! mesh readers (`mesh_file.rs` for STL and OBJ, `collada.rs`).

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::error::{Result, SimError};
use crate::geometry::Rgba;

/// An indexed triangle mesh in metres (the file's unit and the URDF scale applied).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Texture coordinates per position (u right, v down the image), when the file has them
    /// (empty otherwise).
    pub uvs: Vec<[f32; 2]>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// The diffuse colour of the first part that has one.
    pub color: Option<Rgba>,
    /// The file's meshes in order, each a run of `triangles` with its own material.
    pub parts: Vec<TriMeshPart>,
}

impl TriMesh {
    /// The last step of every reader: the mesh's colour from its first part that has one,
    /// texture coordinates padded to one per position (when some part had them), and a mesh
    /// without triangles refused.
    pub(crate) fn finish(mut self, path: &Path) -> Result<Self> {
        self.color = self.parts.iter().find_map(|p| p.color);
        if !self.uvs.is_empty() {
            self.uvs.resize(self.positions.len(), [0.0, 0.0]);
        }
        if self.triangles.is_empty() {
            return Err(SimError::invalid(
                path,
                None,
                "mesh has no triangles: expected at least one",
            ));
        }
        Ok(self)
    }
}

/// A run of a [`TriMesh`]'s triangles that share one material.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMeshPart {
    /// First triangle (index into `triangles`).
    pub first_triangle: usize,
    /// Number of triangles.
    pub triangles: usize,
    /// The material's diffuse colour, if it has one.
    pub color: Option<Rgba>,
    /// The material's diffuse texture (COLLADA `<image><init_from>`, OBJ `map_Kd`) found on
    /// disk: next to the mesh, else in the model's `materials/textures` folder (where Gazebo
    /// looks); `None` when the part has no texture coordinates or no texture.
    pub texture: Option<PathBuf>,
}

/// Where a texture a mesh file names is: the path as written (relative to the mesh), else
/// its file name next to the mesh, in `../materials/textures` or `../materials` (Gazebo's
/// model layout; OBJ files often name `model://` paths or bare names that live there).
pub(crate) fn find_texture(mesh: &Path, named: &Path) -> Option<PathBuf> {
    let dir = mesh.parent()?;
    let as_written = dir.join(named);
    if as_written.is_file() {
        return Some(as_written);
    }
    let file = named.file_name()?;
    [
        dir.to_path_buf(),
        dir.join("../materials/textures"),
        dir.join("../materials"),
    ]
    .into_iter()
    .map(|d| d.join(file))
    .find(|p| p.is_file())
}
