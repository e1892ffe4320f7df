//! Triangle meshes from STL (binary or ASCII), Wavefront OBJ and COLLADA (`.dae`) files, as
//! URDF `<mesh>` and SDF `<mesh><uri>` use them.
//!
//! STL and OBJ parsing is OpenRR's `mesh-loader` (what urdf-viz uses): it tells binary STL files
//! that begin with "solid" from ASCII ones. COLLADA is rover's own reader (`collada.rs`: node
//! hierarchies, units and up axes as Gazebo draws them). rover adds the URDF `scale`, merges the
//! file's meshes and checks the result.

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::description::trimesh::{TriMesh, TriMeshPart, find_texture};
use crate::error::{Result, SimError};
use crate::geometry::Rgba;
use crate::model::mesh::TextureImage;

/// Largest mesh file accepted (a 231k-triangle COLLADA file is ~20 MB).
const MAX_MESH_BYTES: u64 = 512 << 20;

/// A material of an OBJ file's MTL library, as far as rover draws it.
#[derive(Debug, Clone, Default, PartialEq)]
struct ObjMaterial {
    name: String,
    diffuse: Option<[f32; 4]>,
    texture: Option<PathBuf>,
}

/// The materials of the MTL libraries an OBJ file names (`mtllib`), read leniently: `newmtl`,
/// `Kd` and `map_Kd` (its last word is the file; options before it are skipped), statements
/// indented or not. A library that cannot be read gives no materials (the mesh is drawn in
/// its colour).
fn obj_materials(obj: &Path, bytes: &[u8]) -> Vec<ObjMaterial> {
    let dir = obj.parent().unwrap_or(Path::new("."));
    let text = String::from_utf8_lossy(bytes);
    let mut materials: Vec<ObjMaterial> = Vec::new();
    for line in text.lines() {
        let Some(file) = line.trim().strip_prefix("mtllib ") else {
            continue;
        };
        let Ok(lib) = crate::io::read_bounded(&dir.join(file.trim()), MAX_MESH_BYTES) else {
            continue;
        };
        for statement in String::from_utf8_lossy(&lib).lines().map(str::trim) {
            let mut words = statement.split_whitespace();
            match (words.next(), materials.last_mut()) {
                (Some("newmtl"), _) => materials.push(ObjMaterial {
                    name: words.collect::<Vec<_>>().join(" "),
                    ..ObjMaterial::default()
                }),
                (Some("Kd"), Some(m)) => {
                    let rgb: Vec<f32> = words.filter_map(|w| w.parse().ok()).collect();
                    if let [r, g, b] = rgb[..] {
                        m.diffuse = Some([r, g, b, 1.0]);
                    }
                }
                (Some("map_Kd"), Some(m)) => m.texture = words.last().map(PathBuf::from),
                _ => {}
            }
        }
    }
    materials
}

/// Largest texture file accepted.
const MAX_TEXTURE_BYTES: u64 = 64 << 20;
/// Largest texture side accepted (px).
const MAX_TEXTURE_SIDE: u32 = 8192;

/// Decodes a texture image (PNG or JPEG) into RGBA8.
pub fn load_texture(path: &Path) -> Result<TextureImage> {
    let bytes = crate::io::read_bounded(path, MAX_TEXTURE_BYTES)?;
    let image = image::load_from_memory(&bytes)
        .map_err(|e| SimError::invalid(path, None, format!("cannot decode texture: {e}")))?;
    if image.width() > MAX_TEXTURE_SIDE || image.height() > MAX_TEXTURE_SIDE {
        return Err(SimError::invalid(
            path,
            None,
            format!(
                "texture is {}x{} px: expected at most {MAX_TEXTURE_SIDE} px a side",
                image.width(),
                image.height()
            ),
        ));
    }
    let rgba = image.into_rgba8();
    Ok(TextureImage {
        path: path.to_path_buf(),
        width: rgba.width(),
        height: rgba.height(),
        rgba: rgba.into_raw(),
    })
}

/// Loads an STL, OBJ or COLLADA file and applies a per-axis scale.
pub fn load_mesh(path: &Path, scale: Vec3) -> Result<TriMesh> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let loader = mesh_loader::Loader::default();
    let bytes = crate::io::read_bounded(path, MAX_MESH_BYTES)?;
    if ext.as_deref() == Some("dae") {
        let text = std::str::from_utf8(&bytes).map_err(|e| {
            SimError::invalid(
                path,
                None,
                format!("cannot read mesh: not UTF-8 text ({e})"),
            )
        })?;
        return super::collada::load_collada(path, text, scale);
    }
    let load: fn(&mesh_loader::Loader, &[u8], &Path) -> std::io::Result<mesh_loader::Scene> =
        match ext.as_deref() {
            Some("stl") => |l, b, p| l.load_stl_from_slice(b, p),
            Some("obj") => |l, b, p| l.load_obj_from_slice(b, p),
            _ => {
                return Err(SimError::invalid(
                    path,
                    None,
                    "unsupported mesh format: expected .stl, .obj or .dae (COLLADA)",
                ));
            }
        };
    // A panic in the parser becomes this file's error instead of taking rover down (mesh-loader
    // 0.1.13 indexed some malformed COLLADA files out of bounds; tests/tests/fuzz.rs).
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
    let mtl = if ext.as_deref() == Some("obj") {
        obj_materials(path, &bytes)
    } else {
        Vec::new()
    };
    from_scene(path, &scene, &mtl, scale)
}

/// mesh-loader's scene as a [`TriMesh`]: its meshes merged, a part per mesh with its material
/// (`mtl`: rover's own reading of an OBJ's MTL libraries), checked and scaled.
fn from_scene(
    path: &Path,
    scene: &mesh_loader::Scene,
    mtl: &[ObjMaterial],
    scale: Vec3,
) -> Result<TriMesh> {
    let mut mesh = TriMesh::default();
    // mesh-loader 0.1.13 skips indented MTL lines (3ds Max exports indent every statement):
    // `mtl` is rover's own reading of each OBJ's material library, for what it draws.
    for (index, part) in scene.meshes.iter().enumerate() {
        let material = scene.materials.get(index);
        let own = material.and_then(|m| mtl.iter().find(|o| o.name == m.name));
        let has_uvs = part.texcoords[0].len() == part.vertices.len() && !part.vertices.is_empty();
        let named_texture = material
            .and_then(|m| m.texture.diffuse.clone())
            .or_else(|| own.and_then(|o| o.texture.clone()));
        mesh.parts.push(TriMeshPart {
            first_triangle: mesh.triangles.len(),
            triangles: part.faces.len(),
            color: material
                .and_then(|m| m.color.diffuse)
                .or_else(|| own.and_then(|o| o.diffuse))
                .map(|c| Rgba(c.map(|v| v.clamp(0.0, 1.0)))),
            texture: named_texture
                .filter(|_| has_uvs)
                .and_then(|named| find_texture(path, &named)),
        });
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
        if has_uvs {
            // Pad meshes without coordinates so the table lines up with `positions`.
            mesh.uvs.resize(offset as usize, [0.0, 0.0]);
            // Files have v up the image; textures are stored top row first.
            mesh.uvs
                .extend(part.texcoords[0].iter().map(|t| [t[0], 1.0 - t[1]]));
        }
    }
    mesh.finish(path)
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
