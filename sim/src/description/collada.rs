//! COLLADA (`.dae`) scenes as Gazebo draws them: every `<instance_geometry>` of the visual
//! scene placed by its node hierarchy (`<matrix>`, `<translate>`, `<rotate>`, `<scale>`,
//! `<instance_node>` into `<library_nodes>`), in the file's `<unit>`; triangles, polylists and
//! polygons; texture coordinates (set 0); each primitive's material with its diffuse colour or
//! image. `<up_axis>` is not applied: Gazebo's COLLADA loader does not read it
//! (gazebo-classic issue 1305, open) and models are drawn by it: osrf's coke_can and
//! plastic_cup and turtlebot3_world's walls say `Y_UP` while their height runs along the
//! file's z (the can's `<pose>` lowers it 0.18 m onto the ground on that reading).
//!
//! Written here rather than taken from mesh-loader (still used for STL and OBJ): mesh-loader
//! 0.1.13 applies `<unit>` to the scene's root only and does not follow `<instance_node>`, so
//! osrf's fire_hydrant (centimetres under a translated node) came out 16 m up and cafe_table
//! (inches, instanced nodes) 39 times too large. Malformed files are errors, never panics.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use roxmltree::Node;

use crate::description::trimesh::{TriMesh, TriMeshPart, find_texture};
use crate::error::{Result, SimError};
use crate::geometry::Rgba;

/// Deepest node nesting followed (instanced nodes included): a file whose nodes instance
/// each other in a loop stops here.
const MAX_DEPTH: usize = 64;

/// One placed primitive before it is merged: its triangles in the file's coordinates.
struct Placed<'a> {
    transform: Mat4,
    geometry: Node<'a, 'a>,
    /// Material symbol -> material id, from `<bind_material>`.
    bindings: HashMap<String, String>,
}

/// Reads a COLLADA file's triangles into a [`TriMesh`] (metres, z up, `scale` applied).
pub(crate) fn load_collada(path: &Path, text: &str, scale: Vec3) -> Result<TriMesh> {
    let doc = super::xml::parse_xml(text, path)?;
    let root = doc.root_element();
    let err = |node: Node<'_, '_>, message: String| {
        SimError::invalid(
            path,
            Some(super::xml::line_of(&doc, node)),
            format!("cannot read mesh: {message}"),
        )
    };
    let ids: HashMap<&str, Node<'_, '_>> = root
        .descendants()
        .filter_map(|n| n.attribute("id").map(|id| (id, n)))
        .collect();
    let base = Mat4::from_scale(scale) * file_basis(root);
    let scene = child(root, "scene")
        .and_then(|s| child(s, "instance_visual_scene"))
        .and_then(|i| i.attribute("url"))
        .and_then(|u| ids.get(u.trim_start_matches('#')))
        .copied()
        .or_else(|| child(root, "library_visual_scenes").and_then(|l| child(l, "visual_scene")))
        .ok_or_else(|| err(root, "no <visual_scene>: expected a scene to draw".into()))?;
    let mut placed = Vec::new();
    for node in children(scene, "node") {
        walk(node, base, &ids, &mut placed, 0).map_err(|(n, m)| err(n, m))?;
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut mesh = TriMesh::default();
    for p in &placed {
        add_geometry(&mut mesh, p, &ids, path, dir).map_err(|(n, m)| err(n, m))?;
    }
    mesh.finish(path)
}

/// A COLLADA file's units to rover's metres (its `<unit meter>`). Its `<up_axis>` is left
/// alone, as Gazebo (classic and gz-sim) leaves it: the file's z is up.
pub(super) fn file_basis(root: Node<'_, '_>) -> Mat4 {
    let unit = child(root, "asset")
        .and_then(|a| child(a, "unit"))
        .and_then(|u| u.attribute("meter"))
        .and_then(|m| m.trim().parse::<f32>().ok())
        .filter(|m| m.is_finite() && *m > 0.0)
        .unwrap_or(1.0);
    Mat4::from_scale(Vec3::splat(unit))
}

pub(super) type NodeError<'a> = (Node<'a, 'a>, String);

pub(super) fn child<'a>(node: Node<'a, 'a>, tag: &str) -> Option<Node<'a, 'a>> {
    node.children().find(|c| c.has_tag_name(tag))
}

pub(super) fn children<'a>(node: Node<'a, 'a>, tag: &'a str) -> impl Iterator<Item = Node<'a, 'a>> {
    node.children().filter(move |c| c.has_tag_name(tag))
}

/// The whitespace-separated numbers of `node`'s text.
pub(super) fn floats<'a>(node: Node<'a, 'a>) -> std::result::Result<Vec<f32>, NodeError<'a>> {
    node.text()
        .unwrap_or("")
        .split_whitespace()
        .map(|t| {
            t.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| (node, format!("\"{t}\" is not a finite number")))
        })
        .collect()
}

/// Follows a node and its children, accumulating their transforms.
fn walk<'a>(
    node: Node<'a, 'a>,
    parent: Mat4,
    ids: &HashMap<&str, Node<'a, 'a>>,
    out: &mut Vec<Placed<'a>>,
    depth: usize,
) -> std::result::Result<(), NodeError<'a>> {
    if depth > MAX_DEPTH {
        return Err((
            node,
            format!("<node> nested deeper than {MAX_DEPTH}: do nodes instance each other?"),
        ));
    }
    let transform = parent * node_transform(node)?;
    for item in node.children().filter(Node::is_element) {
        match item.tag_name().name() {
            "instance_geometry" => {
                let Some(geometry) = item
                    .attribute("url")
                    .and_then(|u| ids.get(u.trim_start_matches('#')))
                else {
                    continue;
                };
                let bindings = item
                    .descendants()
                    .filter(|n| n.has_tag_name("instance_material"))
                    .filter_map(|m| {
                        Some((
                            m.attribute("symbol")?.to_owned(),
                            m.attribute("target")?.trim_start_matches('#').to_owned(),
                        ))
                    })
                    .collect();
                out.push(Placed {
                    transform,
                    geometry: *geometry,
                    bindings,
                });
            }
            "instance_node" => {
                if let Some(target) = item
                    .attribute("url")
                    .and_then(|u| ids.get(u.trim_start_matches('#')))
                {
                    walk(*target, transform, ids, out, depth + 1)?;
                }
            }
            "node" => walk(item, transform, ids, out, depth + 1)?,
            _ => {}
        }
    }
    Ok(())
}

/// A node's own transform: its `<matrix>`, `<translate>`, `<rotate>` and `<scale>` in order.
pub(super) fn node_transform<'a>(node: Node<'a, 'a>) -> std::result::Result<Mat4, NodeError<'a>> {
    let mut transform = Mat4::IDENTITY;
    for t in node.children().filter(Node::is_element) {
        let v = || floats(t);
        let m = match t.tag_name().name() {
            "matrix" => match v()?[..] {
                [a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p] => {
                    // COLLADA writes matrices row by row.
                    Mat4::from_cols_array(&[a, e, i, m, b, f, j, n, c, g, k, o, d, h, l, p])
                }
                _ => return Err((t, "<matrix>: expected 16 numbers".into())),
            },
            "translate" => match v()?[..] {
                [x, y, z] => Mat4::from_translation(Vec3::new(x, y, z)),
                _ => return Err((t, "<translate>: expected 3 numbers".into())),
            },
            "rotate" => match v()?[..] {
                [x, y, z, deg] => {
                    let axis = Vec3::new(x, y, z);
                    match axis.try_normalize() {
                        Some(a) => Mat4::from_axis_angle(a, deg.to_radians()),
                        None => Mat4::IDENTITY,
                    }
                }
                _ => return Err((t, "<rotate>: expected 4 numbers".into())),
            },
            "scale" => match v()?[..] {
                [x, y, z] => Mat4::from_scale(Vec3::new(x, y, z)),
                _ => return Err((t, "<scale>: expected 3 numbers".into())),
            },
            _ => continue,
        };
        transform *= m;
    }
    Ok(transform)
}

/// A `<source>`'s values with their stride.
pub(super) struct Source {
    pub(super) values: Vec<f32>,
    pub(super) stride: usize,
}

pub(super) fn source<'a>(
    node: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
) -> std::result::Result<Source, NodeError<'a>> {
    // An input may name a <vertices> element, which names the position <source>.
    let node = if node.has_tag_name("vertices") {
        children(node, "input")
            .find(|i| i.attribute("semantic") == Some("POSITION"))
            .and_then(|i| i.attribute("source"))
            .and_then(|s| ids.get(s.trim_start_matches('#')))
            .copied()
            .ok_or_else(|| (node, "<vertices> without a POSITION input".to_owned()))?
    } else {
        node
    };
    let array = child(node, "float_array")
        .ok_or_else(|| (node, "<source> without a <float_array>".to_owned()))?;
    let stride = child(node, "technique_common")
        .and_then(|t| child(t, "accessor"))
        .and_then(|a| a.attribute("stride"))
        .and_then(|s| s.parse::<usize>().ok())
        .unwrap_or(3)
        .max(1);
    Ok(Source {
        values: floats(array)?,
        stride,
    })
}

/// One of a mesh's primitives rover reads (`<triangles>`, `<polylist>`, `<polygons>`).
pub(crate) struct Primitive<'a> {
    /// The element.
    pub(crate) node: Node<'a, 'a>,
    /// Its tag: `triangles`, `polylist` or `polygons`.
    pub(crate) kind: &'a str,
    /// Its `<input>`s.
    pub(crate) inputs: Vec<Node<'a, 'a>>,
    /// Indices per corner: the largest input offset + 1.
    pub(crate) stride: usize,
}

/// The primitives of `mesh` rover reads, in the file's order.
pub(crate) fn primitives<'a>(mesh: Node<'a, 'a>) -> impl Iterator<Item = Primitive<'a>> {
    mesh.children()
        .filter(Node::is_element)
        .filter(|p| matches!(p.tag_name().name(), "triangles" | "polylist" | "polygons"))
        .map(|node| {
            let inputs: Vec<Node<'a, 'a>> = children(node, "input").collect();
            let stride = inputs
                .iter()
                .map(|i| input_offset(i) + 1)
                .max()
                .unwrap_or(1);
            Primitive {
                node,
                kind: node.tag_name().name(),
                inputs,
                stride,
            }
        })
}

/// An `<input>`'s `offset` (0 when missing or malformed, as COLLADA's default).
pub(crate) fn input_offset(input: &Node<'_, '_>) -> usize {
    input
        .attribute("offset")
        .and_then(|o| o.parse::<usize>().ok())
        .unwrap_or(0)
}

/// Appends one placed geometry's primitives to `mesh`, a part per primitive.
fn add_geometry<'a>(
    mesh: &mut TriMesh,
    placed: &Placed<'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
    path: &Path,
    dir: &Path,
) -> std::result::Result<(), NodeError<'a>> {
    let Some(geometry_mesh) = child(placed.geometry, "mesh") else {
        return Ok(());
    };
    for Primitive {
        node: prim,
        kind,
        inputs,
        stride,
    } in primitives(geometry_mesh)
    {
        let offset = input_offset;
        let find = |semantic: &str| {
            inputs
                .iter()
                .filter(|i| i.attribute("semantic") == Some(semantic))
                .find(|i| semantic != "TEXCOORD" || i.attribute("set").is_none_or(|s| s == "0"))
                .or_else(|| {
                    inputs
                        .iter()
                        .find(|i| i.attribute("semantic") == Some(semantic))
                })
        };
        let Some(vertex_input) = find("VERTEX") else {
            return Err((prim, format!("<{kind}> without a VERTEX input")));
        };
        let resolve = |i: &Node<'a, 'a>| {
            i.attribute("source")
                .and_then(|s| ids.get(s.trim_start_matches('#')))
                .copied()
                .ok_or_else(|| (*i, "an <input> names a missing source".to_owned()))
        };
        let positions = source(resolve(vertex_input)?, ids)?;
        let uv_input = find("TEXCOORD");
        let uvs = match uv_input {
            Some(i) => Some(source(resolve(i)?, ids)?),
            None => None,
        };
        let (vertex_offset, uv_offset) = (offset(vertex_input), uv_input.map(offset));
        let (indices, counts) = index_lists(prim, kind, stride)?;
        let material = prim
            .attribute("material")
            .and_then(|symbol| {
                placed
                    .bindings
                    .get(symbol)
                    .map(String::as_str)
                    .or(Some(symbol))
            })
            .and_then(|id| ids.get(id))
            .map(|m| material_of(*m, ids));
        let first_triangle = mesh.triangles.len();
        let mut corner = 0usize;
        for &count in &counts {
            let start_vertex = mesh.positions.len() as u32;
            for k in 0..count {
                let at = (corner + k) * stride;
                let pi = *indices
                    .get(at + vertex_offset)
                    .ok_or_else(|| (prim, format!("<{kind}> has fewer indices than its counts")))?;
                let p = positions
                    .values
                    .get(pi * positions.stride..pi * positions.stride + 3)
                    .ok_or_else(|| (prim, format!("index {pi} is past its positions")))?;
                let world = placed
                    .transform
                    .transform_point3(Vec3::new(p[0], p[1], p[2]));
                mesh.positions.push(world);
                if let (Some(uvs), Some(o)) = (&uvs, uv_offset) {
                    let ti = indices.get(at + o).copied().unwrap_or(0);
                    let t = uvs.values.get(ti * uvs.stride..ti * uvs.stride + 2);
                    mesh.uvs.resize(mesh.positions.len() - 1, [0.0, 0.0]);
                    mesh.uvs.push(t.map_or([0.0, 0.0], |t| [t[0], 1.0 - t[1]]));
                }
            }
            // Fan triangulation of the polygon.
            for k in 1..count.saturating_sub(1) as u32 {
                mesh.triangles
                    .push([start_vertex, start_vertex + k, start_vertex + k + 1]);
            }
            corner += count;
        }
        let (color, texture) = material.unwrap_or((None, None));
        mesh.parts.push(TriMeshPart {
            first_triangle,
            triangles: mesh.triangles.len() - first_triangle,
            color,
            texture: texture
                .filter(|_| uvs.is_some())
                .and_then(|t| find_texture(path, &dir.join(t))),
        });
    }
    Ok(())
}

/// A primitive's index lists and its polygons' corner counts: one `<p>` per polygon for
/// `<polygons>`, else one `<p>` with `<vcount>` (polylist) or threes (triangles).
pub(super) fn index_lists<'a>(
    prim: Node<'a, 'a>,
    kind: &str,
    stride: usize,
) -> std::result::Result<(Vec<usize>, Vec<usize>), NodeError<'a>> {
    let mut indices = Vec::new();
    let mut counts = Vec::new();
    for p in children(prim, "p") {
        let list: Vec<usize> = p
            .text()
            .unwrap_or("")
            .split_whitespace()
            .map(|t| {
                t.parse::<usize>()
                    .map_err(|_| (p, format!("\"{t}\" is not an index")))
            })
            .collect::<std::result::Result<_, _>>()?;
        if kind == "polygons" {
            counts.push(list.len() / stride);
        }
        indices.extend(list);
    }
    if kind == "polylist" {
        counts = child(prim, "vcount")
            .map(|v| {
                v.text()
                    .unwrap_or("")
                    .split_whitespace()
                    .filter_map(|t| t.parse::<usize>().ok())
                    .collect()
            })
            .unwrap_or_default();
    } else if kind == "triangles" {
        counts = vec![3; indices.len() / (3 * stride)];
    }
    Ok((indices, counts))
}

/// A material's diffuse colour and image file: material -> `<instance_effect>` -> effect ->
/// `<diffuse>` `<color>` or `<texture texture="...">` (a sampler -> surface -> image, or an
/// image directly) -> `<image><init_from>`.
pub(super) fn material_of<'a>(
    material: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
) -> (Option<Rgba>, Option<PathBuf>) {
    let Some(effect) = child(material, "instance_effect")
        .and_then(|i| i.attribute("url"))
        .and_then(|u| ids.get(u.trim_start_matches('#')))
    else {
        return (None, None);
    };
    let Some(diffuse) = effect.descendants().find(|n| n.has_tag_name("diffuse")) else {
        return (None, None);
    };
    let color = child(diffuse, "color")
        .and_then(|c| floats(c).ok())
        .and_then(|v| match v[..] {
            [r, g, b, a] => Some(Rgba([r, g, b, a].map(|c| c.clamp(0.0, 1.0)))),
            [r, g, b] => Some(Rgba::rgb(r, g, b)),
            _ => None,
        });
    let texture = child(diffuse, "texture")
        .and_then(|t| t.attribute("texture"))
        .and_then(|name| image_file(*effect, name, ids, 0));
    (color, texture)
}

/// The file of the image a `<texture texture="NAME">` means inside `effect`: NAME is a
/// sampler's sid (whose source is a surface's sid, whose init_from is an image id) or an image
/// id itself.
fn image_file<'a>(
    effect: Node<'a, 'a>,
    name: &str,
    ids: &HashMap<&str, Node<'a, 'a>>,
    depth: usize,
) -> Option<PathBuf> {
    if depth > 4 {
        return None;
    }
    let param = effect
        .descendants()
        .find(|n| n.has_tag_name("newparam") && n.attribute("sid") == Some(name));
    if let Some(param) = param {
        if let Some(source) = param
            .descendants()
            .find(|n| n.has_tag_name("sampler2D"))
            .and_then(|s| child(s, "source"))
            .and_then(|s| s.text())
        {
            return image_file(effect, source.trim(), ids, depth + 1);
        }
        if let Some(image) = param
            .descendants()
            .find(|n| n.has_tag_name("surface"))
            .and_then(|s| child(s, "init_from"))
            .and_then(|i| i.text())
        {
            return image_file(effect, image.trim(), ids, depth + 1);
        }
    }
    let image = ids.get(name).filter(|n| n.has_tag_name("image"))?;
    let init = child(*image, "init_from")?;
    // COLLADA 1.5 nests the file in <ref>.
    let file = child(init, "ref").and_then(|r| r.text()).or(init.text())?;
    let file = file.trim().trim_start_matches("file://");
    (!file.is_empty()).then(|| PathBuf::from(file))
}

#[cfg(test)]
mod tests {
    use super::*;

    const NESTED: &str = r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="g"><mesh>
      <source id="p"><float_array id="pa" count="9">0 0 0 100 0 0 0 100 0</float_array>
        <technique_common><accessor source="#pa" count="3" stride="3"/></technique_common></source>
      <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
      <polylist count="1"><input semantic="VERTEX" source="#v" offset="0"/><vcount>3</vcount><p>0 1 2</p></polylist>
    </mesh></geometry>
  </library_geometries>
  <library_nodes><node id="lib"><translate>0 0 50</translate><instance_geometry url="#g"/></node></library_nodes>
  <library_visual_scenes><visual_scene id="s">
    <node><translate>10 0 0</translate><instance_node url="#lib"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##;

    #[test]
    fn units_apply_through_nested_and_instanced_nodes() -> Result<()> {
        let m = load_collada(Path::new("nested.dae"), NESTED, Vec3::ONE)?;
        assert_eq!(m.triangles.len(), 1);
        // (0,0,0) -> translate (10,0,0) then (0,0,50) -> cm to m.
        assert!((m.positions[0] - Vec3::new(0.1, 0.0, 0.5)).length() < 1e-6);
        assert!((m.positions[1] - Vec3::new(1.1, 0.0, 0.5)).length() < 1e-6);
        Ok(())
    }

    #[test]
    fn y_up_files_keep_their_z_up_as_gazebo_draws_them_and_loops_are_refused() -> Result<()> {
        let y_up = NESTED.replace("Z_UP", "Y_UP");
        let m = load_collada(Path::new("y.dae"), &y_up, Vec3::ONE)?;
        // The file's +y (0,1,0 at 100 cm) stays +y.
        assert!(
            (m.positions[2] - Vec3::new(0.1, 1.0, 0.5)).length() < 1e-5,
            "{:?}",
            m.positions[2]
        );
        let looped = NESTED.replace(
            r##"<instance_geometry url="#g"/></node></library_nodes>"##,
            r##"<instance_node url="#lib"/></node></library_nodes>"##,
        );
        let e = load_collada(Path::new("loop.dae"), &looped, Vec3::ONE)
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("loop.dae") && e.contains("nested deeper"), "{e}");
        Ok(())
    }
}
