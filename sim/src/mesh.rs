//! Triangle meshes from STL (binary or ASCII) and Wavefront OBJ files, as URDF `<mesh>` uses them.

use std::path::Path;

use glam::Vec3;

use crate::error::{Result, SimError};

/// An indexed triangle mesh in the file's own units, scaled.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// Loads an STL or OBJ file and applies a per-axis scale.
pub fn load_mesh(path: &Path, scale: Vec3) -> Result<TriMesh> {
    let bytes = std::fs::read(path).map_err(|source| SimError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let mut mesh = match ext.as_deref() {
        Some("stl") => parse_stl(&bytes, path)?,
        Some("obj") => parse_obj(&String::from_utf8_lossy(&bytes), path)?,
        _ => {
            return Err(SimError::invalid(
                path,
                None,
                "unsupported mesh format: expected .stl or .obj",
            ));
        }
    };
    if mesh.triangles.is_empty() {
        return Err(SimError::invalid(path, None, "mesh has no triangles"));
    }
    for p in &mut mesh.positions {
        *p *= scale;
    }
    Ok(mesh)
}

fn parse_stl(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    // Binary STL: 80-byte header, u32 count, 50 bytes per triangle. ASCII files start with
    // "solid" but so do some binary ones, so trust the size arithmetic first.
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if bytes.len() == 84 + count * 50 {
            let mut mesh = TriMesh::default();
            for t in 0..count {
                let base = 84 + t * 50 + 12;
                let mut tri = [0u32; 3];
                for (v, slot) in tri.iter_mut().enumerate() {
                    let mut xyz = [0f32; 3];
                    for (k, c) in xyz.iter_mut().enumerate() {
                        let o = base + v * 12 + k * 4;
                        *c = f32::from_le_bytes([
                            bytes[o],
                            bytes[o + 1],
                            bytes[o + 2],
                            bytes[o + 3],
                        ]);
                    }
                    *slot = mesh.positions.len() as u32;
                    mesh.positions.push(Vec3::from_array(xyz));
                }
                mesh.triangles.push(tri);
            }
            return Ok(mesh);
        }
    }
    let text = std::str::from_utf8(bytes).map_err(|_| {
        SimError::invalid(
            path,
            None,
            "not a valid STL file: binary size does not match its triangle count and it is not ASCII",
        )
    })?;
    let mut mesh = TriMesh::default();
    let mut pending = Vec::with_capacity(3);
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("vertex") {
            continue;
        }
        let xyz = parse_floats::<3>(words, path, n + 1, "vertex x y z")?;
        pending.push(mesh.positions.len() as u32);
        mesh.positions.push(Vec3::from_array(xyz));
        if pending.len() == 3 {
            mesh.triangles.push([pending[0], pending[1], pending[2]]);
            pending.clear();
        }
    }
    Ok(mesh)
}

fn parse_obj(text: &str, path: &Path) -> Result<TriMesh> {
    let mut mesh = TriMesh::default();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let xyz = parse_floats::<3>(words, path, n + 1, "v x y z")?;
                mesh.positions.push(Vec3::from_array(xyz));
            }
            Some("f") => {
                let mut corners = Vec::with_capacity(4);
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| {
                        SimError::invalid(
                            path,
                            Some(n as u32 + 1),
                            format!("face corner '{w}': expected a vertex index"),
                        )
                    })?;
                    // OBJ indices are 1-based; negative ones count back from the newest vertex.
                    let count = mesh.positions.len() as i64;
                    let resolved = if index < 0 { count + index } else { index - 1 };
                    if !(0..count).contains(&resolved) {
                        return Err(SimError::invalid(
                            path,
                            Some(n as u32 + 1),
                            format!(
                                "face refers to vertex {index}, but only {count} vertices are defined so far"
                            ),
                        ));
                    }
                    corners.push(resolved as u32);
                }
                if corners.len() < 3 {
                    return Err(SimError::invalid(
                        path,
                        Some(n as u32 + 1),
                        "face with fewer than 3 corners",
                    ));
                }
                for i in 1..corners.len() - 1 {
                    mesh.triangles
                        .push([corners[0], corners[i], corners[i + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(mesh)
}

fn parse_floats<'a, const N: usize>(
    mut words: impl Iterator<Item = &'a str>,
    path: &Path,
    line: usize,
    what: &str,
) -> Result<[f32; N]> {
    let mut out = [0f32; N];
    for slot in &mut out {
        let w = words.next().unwrap_or("");
        *slot = w
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                SimError::invalid(
                    path,
                    Some(line as u32),
                    format!("'{w}': expected {what} as numbers"),
                )
            })?;
    }
    Ok(out)
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
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.positions[2], Vec3::new(2.0, 2.0, 0.0));
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
        assert!(err.contains(":2: 'zero'"), "{err}");
        Ok(())
    }
}
