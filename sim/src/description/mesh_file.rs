//! Triangle meshes from STL (binary or ASCII), Wavefront OBJ and COLLADA (`.dae`) files, as
//! URDF `<mesh>` and SDF `<mesh><uri>` use them.
//!
//! Parsing is OpenRR's `mesh-loader` (what urdf-viz uses): it applies COLLADA's `<unit>` and node
//! transforms and tells binary STL files that begin with "solid" from ASCII ones. rover adds the
//! URDF `scale`, merges the file's meshes and checks the result.

use std::path::Path;

use glam::Vec3;

use crate::error::{Result, SimError};
use crate::geometry::Rgba;

/// Largest mesh file accepted (a 231k-triangle COLLADA file is ~20 MB).
const MAX_MESH_BYTES: u64 = 512 << 20;

/// An indexed triangle mesh in metres (the file's unit and the URDF scale applied).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// The diffuse colour of the file's first material, when it names one.
    pub color: Option<Rgba>,
}

/// Loads an STL, OBJ or COLLADA file and applies a per-axis scale.
pub fn load_mesh(path: &Path, scale: Vec3) -> Result<TriMesh> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let loader = mesh_loader::Loader::default();
    let bytes = crate::io::read_bounded(path, MAX_MESH_BYTES)?;
    let load: fn(&mesh_loader::Loader, &[u8], &Path) -> std::io::Result<mesh_loader::Scene> =
        match ext.as_deref() {
            Some("stl") => |l, b, p| l.load_stl_from_slice(b, p),
            Some("obj") => |l, b, p| l.load_obj_from_slice(b, p),
            Some("dae") => |l, b, p| l.load_collada_from_slice(b, p),
            _ => {
                return Err(SimError::invalid(
                    path,
                    None,
                    "unsupported mesh format: expected .stl, .obj or .dae (COLLADA)",
                ));
            }
        };
    // mesh-loader 0.1.13 indexes some malformed COLLADA files out of bounds (found by
    // tests/tests/fuzz.rs); its panic becomes this file's error instead of taking rover down.
    let scene =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| load(&loader, &bytes, path)))
            .map_err(|payload| {
                SimError::invalid(
                    path,
                    None,
                    format!(
                        "cannot read mesh: the mesh parser failed ({})",
                        crate::error::panic_message(payload.as_ref())
                    ),
                )
            })?
            .map_err(|e| SimError::invalid(path, None, format!("cannot read mesh: {e}")))?;

    let mut mesh = TriMesh {
        color: scene
            .materials
            .iter()
            .find_map(|m| m.color.diffuse)
            .map(|c| Rgba(c.map(|v| v.clamp(0.0, 1.0)))),
        ..TriMesh::default()
    };
    for part in &scene.meshes {
        let offset = u32::try_from(mesh.positions.len())
            .map_err(|_| SimError::invalid(path, None, "mesh has more than 2^32 vertices"))?;
        let count = part.vertices.len() as u32;
        for f in &part.faces {
            if f.iter().any(|&i| i >= count) {
                return Err(SimError::invalid(
                    path,
                    None,
                    format!(
                        "mesh \"{}\" has a face index past its {count} vertices",
                        part.name
                    ),
                ));
            }
            mesh.triangles.push(f.map(|i| i + offset));
        }
        for v in &part.vertices {
            let p = Vec3::from_array(*v) * scale;
            if !p.is_finite() {
                return Err(SimError::invalid(
                    path,
                    None,
                    format!(
                        "mesh \"{}\" has a vertex that is not a finite number",
                        part.name
                    ),
                ));
            }
            mesh.positions.push(p);
        }
    }
    if mesh.triangles.is_empty() {
        return Err(SimError::invalid(
            path,
            None,
            "mesh has no triangles: expected at least one",
        ));
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_quads_are_triangulated_and_scaled() -> Result<()> {
        let dir = tempfile::tempdir().map_err(|source| SimError::Io {
            path: "tmp".into(),
            source,
        })?;
        let p = dir.path().join("quad.obj");
        std::fs::write(
            &p,
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\n",
        )
        .map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
        let m = load_mesh(&p, Vec3::splat(2.0))?;
        assert_eq!(m.triangles.len(), 2);
        let max = m.positions.iter().fold(Vec3::ZERO, |a, p| a.max(*p));
        assert_eq!(max, Vec3::new(2.0, 2.0, 0.0));
        Ok(())
    }

    #[test]
    fn binary_and_ascii_stl() -> Result<()> {
        let dir = tempfile::tempdir().map_err(|source| SimError::Io {
            path: "tmp".into(),
            source,
        })?;
        let mut bin = vec![0u8; 80];
        bin.extend_from_slice(&1u32.to_le_bytes());
        bin.extend_from_slice(&[0u8; 12]);
        for v in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
            for c in v {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        bin.extend_from_slice(&[0u8; 2]);
        let p = dir.path().join("t.stl");
        std::fs::write(&p, &bin).map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
        assert_eq!(load_mesh(&p, Vec3::ONE)?.positions[1], Vec3::X);

        let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let p = dir.path().join("a.stl");
        std::fs::write(&p, ascii).map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
        assert_eq!(load_mesh(&p, Vec3::ONE)?.triangles.len(), 1);

        std::fs::write(&p, "solid t\nvertex 0 zero 0\n").map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
        let err = load_mesh(&p, Vec3::ONE)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            err.contains("a.stl") && err.contains("cannot read mesh"),
            "{err}"
        );

        // A binary file whose 80-byte header begins with "solid" is still binary.
        bin[..6].copy_from_slice(b"solid ");
        let p = dir.path().join("solid_binary.stl");
        std::fs::write(&p, &bin).map_err(|source| SimError::Io {
            path: p.clone(),
            source,
        })?;
        assert_eq!(load_mesh(&p, Vec3::ONE)?.triangles.len(), 1);
        Ok(())
    }
}
