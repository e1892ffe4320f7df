//! Skinned COLLADA for Gazebo actors (`<actor><skin>` and `<animation>`): the skin
//! (`<library_controllers><controller><skin>`: bind shape matrix, joints and their inverse bind
//! matrices, vertex weights) on the joint hierarchy of the visual scene (the `<node>`s under the
//! `<instance_controller>`'s `<skeleton>`), and the animation (`<library_animations>` channels,
//! each a joint's `<matrix>` sampled over time), as Gazebo's walk.dae and its other actor files
//! write them. Vertex identity is kept (the weights address it), so this is separate from
//! `collada.rs`, which reads static meshes corner by corner; the two share its helpers.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec3};
use roxmltree::Node;

use super::collada::{
    NodeError, Primitive, child, children, file_basis, floats, index_lists, input_offset,
    material_of, node_transform, primitives, source,
};
use super::xml::{line_of, parse_xml};
use crate::error::{Result, SimError};
use crate::geometry::Rgba;
use crate::model::actor::{ActorSkin, Channel, Clip, SkinJoint};

/// Deepest joint nesting followed.
const MAX_DEPTH: usize = 128;
/// Most joints a vertex keeps (the strongest; their weights renormalised).
const MAX_INFLUENCES: usize = 4;
/// Colour of a skin material without a diffuse colour.
const DEFAULT_COLOR: Rgba = Rgba([0.7, 0.7, 0.7, 1.0]);

type NodeResult<'a, T> = std::result::Result<T, NodeError<'a>>;

/// A COLLADA matrix (16 numbers, row by row) as glam's column-major matrix.
fn matrix(v: &[f32]) -> Mat4 {
    Mat4::from_cols_array(&[
        v[0], v[4], v[8], v[12], v[1], v[5], v[9], v[13], v[2], v[6], v[10], v[14], v[3], v[7],
        v[11], v[15],
    ])
}

/// The name a joint node is known by: its `name`, else its `sid`, else its `id`.
fn joint_name<'a>(node: Node<'a, 'a>) -> &'a str {
    node.attribute("name")
        .or_else(|| node.attribute("sid"))
        .or_else(|| node.attribute("id"))
        .unwrap_or("")
}

/// Reads an actor's skin from a COLLADA file, `scale` times its size (`<skin><scale>`).
pub(crate) fn load_skin(path: &Path, scale: f32) -> Result<ActorSkin> {
    let text = crate::io::read_text(path)?;
    let doc = parse_xml(&text, path)?;
    let root = doc.root_element();
    let err = |(node, message): NodeError<'_>| {
        SimError::invalid(
            path,
            Some(line_of(&doc, node)),
            format!("actor <skin>: {message}"),
        )
    };
    let ids: HashMap<&str, Node<'_, '_>> = root
        .descendants()
        .filter_map(|n| n.attribute("id").map(|id| (id, n)))
        .collect();
    read_skin(root, &ids, scale).map_err(err)
}

fn read_skin<'a>(
    root: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
    scale: f32,
) -> NodeResult<'a, ActorSkin> {
    let by_id = |url: Option<&str>| url.and_then(|u| ids.get(u.trim_start_matches('#')).copied());
    let (instance, skin) = root
        .descendants()
        .filter(|n| n.has_tag_name("instance_controller"))
        .find_map(|i| Some((i, child(by_id(i.attribute("url"))?, "skin")?)))
        .ok_or_else(|| {
            (
                root,
                "no <instance_controller> of a controller with a <skin>: an actor's skin is a \
                 mesh skinned to a skeleton (library_controllers/controller/skin)"
                    .to_owned(),
            )
        })?;
    let skeleton_root = child(instance, "skeleton")
        .and_then(|s| by_id(s.text().map(str::trim)))
        .or_else(|| {
            root.descendants().find(|n| {
                n.has_tag_name("node")
                    && n.attribute("type") == Some("JOINT")
                    && n.parent()
                        .is_none_or(|p| p.attribute("type") != Some("JOINT"))
            })
        })
        .ok_or_else(|| {
            (
                instance,
                "the skin has no skeleton: expected a <skeleton> naming the root joint's \
                 <node>, or <node type=\"JOINT\"> nodes in the scene"
                    .to_owned(),
            )
        })?;
    let (joints, nodes) = skeleton(skeleton_root)?;
    let mut above_root = Mat4::IDENTITY;
    for ancestor in skeleton_root
        .ancestors()
        .skip(1)
        .filter(|n| n.has_tag_name("node"))
    {
        above_root = node_transform(ancestor)? * above_root;
    }
    let bind = skin_joints(skin, ids, &nodes)?;
    let bind_shape = match child(skin, "bind_shape_matrix") {
        Some(m) => {
            let v = floats(m)?;
            if v.len() != 16 {
                return Err((m, "<bind_shape_matrix>: expected 16 numbers".into()));
            }
            matrix(&v)
        }
        None => Mat4::IDENTITY,
    };
    let geometry = by_id(skin.attribute("source"))
        .and_then(|g| child(g, "mesh"))
        .ok_or_else(|| {
            (
                skin,
                "<skin source> names no geometry with a <mesh>".to_owned(),
            )
        })?;
    let (positions, layers) = skin_mesh(geometry, instance, ids)?;
    let rest: Vec<Vec3> = positions
        .iter()
        .map(|p| bind_shape.transform_point3(*p))
        .collect();
    let weights = vertex_weights(skin, ids, rest.len(), bind.len())?;
    Ok(ActorSkin {
        rest,
        layers,
        joints,
        above_root,
        bind,
        weights,
        to_rover: Mat4::from_scale(Vec3::splat(scale)) * file_basis(root),
        clip: None,
    })
}

/// The joints under `root` (itself first, parents before children) and their nodes.
fn skeleton<'a>(root: Node<'a, 'a>) -> NodeResult<'a, (Vec<SkinJoint>, Vec<Node<'a, 'a>>)> {
    let mut joints = Vec::new();
    let mut nodes = Vec::new();
    let mut stack = vec![(root, None, 0usize)];
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > MAX_DEPTH {
            return Err((node, format!("joints nested deeper than {MAX_DEPTH}")));
        }
        let index = joints.len();
        joints.push(SkinJoint {
            name: joint_name(node).to_owned(),
            parent,
            rest_local: node_transform(node)?,
        });
        nodes.push(node);
        let kids: Vec<_> = children(node, "node").collect();
        for kid in kids.into_iter().rev() {
            stack.push((kid, Some(index), depth + 1));
        }
    }
    Ok((joints, nodes))
}

/// The skin's joints as skeleton joints, with their inverse bind matrices.
fn skin_joints<'a>(
    skin: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
    nodes: &[Node<'a, 'a>],
) -> NodeResult<'a, Vec<(usize, Mat4)>> {
    let joints_el =
        child(skin, "joints").ok_or_else(|| (skin, "<skin> without <joints>".to_owned()))?;
    let input = |semantic: &str| {
        children(joints_el, "input")
            .find(|i| i.attribute("semantic") == Some(semantic))
            .and_then(|i| i.attribute("source"))
            .and_then(|s| ids.get(s.trim_start_matches('#')).copied())
            .ok_or_else(|| {
                (
                    joints_el,
                    format!("<joints> without a {semantic} input source"),
                )
            })
    };
    let names_el = input("JOINT")?;
    let names: Vec<&str> = names_el
        .descendants()
        .find(|n| n.has_tag_name("Name_array") || n.has_tag_name("IDREF_array"))
        .and_then(|n| n.text())
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let inverse = floats(
        child(input("INV_BIND_MATRIX")?, "float_array").ok_or_else(|| {
            (
                joints_el,
                "INV_BIND_MATRIX source without numbers".to_owned(),
            )
        })?,
    )?;
    if inverse.len() != names.len() * 16 {
        return Err((
            joints_el,
            format!(
                "{} joints but {} inverse bind numbers: expected 16 per joint",
                names.len(),
                inverse.len()
            ),
        ));
    }
    names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let found = ["sid", "name", "id"]
                .iter()
                .find_map(|attr| nodes.iter().position(|n| n.attribute(*attr) == Some(*name)));
            match found {
                Some(j) => Ok((j, matrix(&inverse[k * 16..k * 16 + 16]))),
                None => Err((
                    names_el,
                    format!("skin joint \"{name}\" is not a node of the skeleton"),
                )),
            }
        })
        .collect()
}

/// The skin mesh's positions (the file's, before the bind shape) and its triangles by
/// material, with the colour the `<instance_controller>` binds to each.
#[allow(
    clippy::type_complexity,
    reason = "one private function's result: the positions and each material's triangles"
)]
fn skin_mesh<'a>(
    mesh: Node<'a, 'a>,
    instance: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
) -> NodeResult<'a, (Vec<Vec3>, Vec<(Rgba, Vec<u32>)>)> {
    let bindings: HashMap<&str, &str> = instance
        .descendants()
        .filter(|n| n.has_tag_name("instance_material"))
        .filter_map(|m| Some((m.attribute("symbol")?, m.attribute("target")?)))
        .collect();
    let vertices = child(mesh, "vertices")
        .ok_or_else(|| (mesh, "skin <mesh> without <vertices>".to_owned()))?;
    let positions = source(vertices, ids)?;
    let stride = positions.stride.max(3);
    let points: Vec<Vec3> = positions
        .values
        .chunks_exact(stride)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect();
    let mut layers = Vec::new();
    for Primitive {
        node: prim,
        kind,
        inputs,
        stride: index_stride,
    } in primitives(mesh)
    {
        let vertex_offset = inputs
            .iter()
            .find(|i| i.attribute("semantic") == Some("VERTEX"))
            .map(input_offset)
            .ok_or_else(|| (prim, format!("<{kind}> without a VERTEX input")))?;
        let (indices, counts) = index_lists(prim, kind, index_stride)?;
        let mut triangles = Vec::new();
        let mut corner = 0usize;
        for &count in &counts {
            let mut polygon = Vec::with_capacity(count);
            for k in 0..count {
                let i = *indices
                    .get((corner + k) * index_stride + vertex_offset)
                    .ok_or_else(|| (prim, format!("<{kind}> has fewer indices than its counts")))?;
                if i >= points.len() {
                    return Err((
                        prim,
                        format!("index {i} is past the {} positions", points.len()),
                    ));
                }
                polygon.push(i as u32);
            }
            for k in 1..count.saturating_sub(1) {
                triangles.extend_from_slice(&[polygon[0], polygon[k], polygon[k + 1]]);
            }
            corner += count;
        }
        let color = prim
            .attribute("material")
            .map(|symbol| bindings.get(symbol).copied().unwrap_or(symbol))
            .and_then(|id| ids.get(id.trim_start_matches('#')))
            .and_then(|m| material_of(*m, ids).0)
            .unwrap_or(DEFAULT_COLOR);
        if !triangles.is_empty() {
            layers.push((color, triangles));
        }
    }
    if layers.is_empty() {
        return Err((mesh, "the skin's mesh has no triangles".to_owned()));
    }
    Ok((points, layers))
}

/// Each vertex's strongest joints and weights (renormalised).
fn vertex_weights<'a>(
    skin: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
    vertex_count: usize,
    joint_count: usize,
) -> NodeResult<'a, Vec<[(u16, f32); MAX_INFLUENCES]>> {
    let vw = child(skin, "vertex_weights")
        .ok_or_else(|| (skin, "<skin> without <vertex_weights>".to_owned()))?;
    let inputs: Vec<Node<'_, '_>> = children(vw, "input").collect();
    let offset = |semantic: &str| {
        inputs
            .iter()
            .find(|i| i.attribute("semantic") == Some(semantic))
            .map(|i| {
                i.attribute("offset")
                    .and_then(|o| o.parse::<usize>().ok())
                    .unwrap_or(0)
            })
            .ok_or_else(|| (vw, format!("<vertex_weights> without a {semantic} input")))
    };
    let (joint_offset, weight_offset) = (offset("JOINT")?, offset("WEIGHT")?);
    let stride = joint_offset.max(weight_offset) + 1;
    let weight_values = inputs
        .iter()
        .find(|i| i.attribute("semantic") == Some("WEIGHT"))
        .and_then(|i| i.attribute("source"))
        .and_then(|s| ids.get(s.trim_start_matches('#')))
        .and_then(|s| child(*s, "float_array"))
        .map(floats)
        .transpose()?
        .ok_or_else(|| (vw, "the WEIGHT input names no numbers".to_owned()))?;
    let integers = |tag: &str| -> NodeResult<'a, Vec<i64>> {
        let Some(el) = child(vw, tag) else {
            return Ok(Vec::new());
        };
        el.text()
            .unwrap_or("")
            .split_whitespace()
            .map(|t| {
                t.parse::<i64>()
                    .map_err(|_| (el, format!("\"{t}\" is not an integer")))
            })
            .collect()
    };
    let (vcount, v) = (integers("vcount")?, integers("v")?);
    if vcount.len() != vertex_count {
        return Err((
            vw,
            format!(
                "weights for {} vertices but the mesh has {vertex_count}",
                vcount.len()
            ),
        ));
    }
    let mut out = Vec::with_capacity(vertex_count);
    let mut at = 0usize;
    for (vertex, &n) in vcount.iter().enumerate() {
        let n = usize::try_from(n).map_err(|_| (vw, format!("vcount {n} is negative")))?;
        let mut pairs: Vec<(u16, f32)> = Vec::with_capacity(n);
        for _ in 0..n {
            let pair = v
                .get(at..at + stride)
                .ok_or_else(|| (vw, "<v> is shorter than <vcount> says".to_owned()))?;
            at += stride;
            let (joint, weight) = (pair[joint_offset], pair[weight_offset]);
            if joint < 0 {
                continue; // -1: the bind shape itself; rover leaves it out.
            }
            let joint = usize::try_from(joint)
                .ok()
                .filter(|j| *j < joint_count)
                .ok_or_else(|| {
                    (
                        vw,
                        format!("joint index {joint} is past the {joint_count} joints"),
                    )
                })?;
            let w = usize::try_from(weight)
                .ok()
                .and_then(|w| weight_values.get(w))
                .ok_or_else(|| (vw, format!("weight index {weight} is past the weights")))?;
            pairs.push((joint as u16, *w));
        }
        pairs.sort_by(|a, b| b.1.total_cmp(&a.1));
        pairs.truncate(MAX_INFLUENCES);
        let total: f32 = pairs.iter().map(|p| p.1).sum();
        if total <= 0.0 {
            return Err((vw, format!("vertex {vertex} has no joint weight")));
        }
        let mut fixed = [(0u16, 0.0f32); MAX_INFLUENCES];
        for (slot, (joint, w)) in fixed.iter_mut().zip(pairs) {
            *slot = (joint, w / total);
        }
        out.push(fixed);
    }
    Ok(out)
}

/// Reads an animation for `skin` from a COLLADA file (`<animation><filename>`), its
/// translations `scale` times (`<animation><scale>`).
pub(crate) fn load_clip(
    path: &Path,
    scale: f32,
    interpolate_x: bool,
    skin: &ActorSkin,
) -> Result<Clip> {
    let text = crate::io::read_text(path)?;
    let doc = parse_xml(&text, path)?;
    let root = doc.root_element();
    let ids: HashMap<&str, Node<'_, '_>> = root
        .descendants()
        .filter_map(|n| n.attribute("id").map(|id| (id, n)))
        .collect();
    read_clip(root, &ids, scale, interpolate_x, skin).map_err(|(node, message)| {
        SimError::invalid(
            path,
            Some(line_of(&doc, node)),
            format!("actor <animation>: {message}"),
        )
    })
}

fn read_clip<'a>(
    root: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
    scale: f32,
    interpolate_x: bool,
    skin: &ActorSkin,
) -> NodeResult<'a, Clip> {
    let mut channels = Vec::new();
    for channel in root.descendants().filter(|n| n.has_tag_name("channel")) {
        let target = channel.attribute("target").unwrap_or("");
        let (node_id, sid) = target.split_once('/').unwrap_or((target, ""));
        let node = ids
            .get(node_id)
            .filter(|n| n.has_tag_name("node"))
            .ok_or_else(|| (channel, format!("target \"{target}\" names no <node>")))?;
        let element = node
            .children()
            .find(|c| c.attribute("sid") == Some(sid))
            .ok_or_else(|| {
                (
                    channel,
                    format!("target \"{target}\": the node has no \"{sid}\""),
                )
            })?;
        if !element.has_tag_name("matrix") {
            return Err((
                channel,
                format!(
                    "target \"{target}\" animates a <{}>: rover reads animations of whole \
                     <matrix> transforms (as Gazebo's actor files have them)",
                    element.tag_name().name()
                ),
            ));
        }
        let name = joint_name(*node);
        let joint = skin.joints.iter().position(|j| j.name == name).ok_or_else(|| {
            (
                channel,
                format!(
                    "animates joint \"{name}\", which the skin's skeleton does not have: is the \
                     animation for another skeleton?"
                ),
            )
        })?;
        channels.push(sampled(channel, ids, joint, scale)?);
    }
    if channels.is_empty() {
        return Err((
            root,
            "no animation channels: expected <library_animations> moving the skin's joints"
                .to_owned(),
        ));
    }
    let duration_s = channels
        .iter()
        .filter_map(|c| c.times_s.last())
        .fold(0.0f32, |a, b| a.max(*b)) as f64;
    let metres_per_unit = f64::from(skin.to_rover.x_axis.truncate().length());
    let root_x: Vec<(f64, f64)> = channels
        .iter()
        .find(|c| c.joint == 0)
        .map(|c| {
            c.keys
                .iter()
                .zip(&c.times_s)
                .map(|(k, t)| (f64::from(k.2.x) * metres_per_unit, f64::from(*t)))
                .collect()
        })
        .unwrap_or_default();
    let cycle_x = match (root_x.first(), root_x.last()) {
        (Some(a), Some(b)) => (b.0 - a.0).max(0.0),
        _ => 0.0,
    };
    if interpolate_x && cycle_x <= 1e-6 {
        tracing::warn!(
            "actor <animation>: <interpolate_x> but the root joint does not move forward in the \
             clip; it plays by time"
        );
    }
    Ok(Clip {
        duration_s,
        interpolate_x,
        channels,
        cycle_x,
        root_x,
    })
}

/// One channel's keys: its sampler's INPUT times and OUTPUT matrices.
fn sampled<'a>(
    channel: Node<'a, 'a>,
    ids: &HashMap<&str, Node<'a, 'a>>,
    joint: usize,
    scale: f32,
) -> NodeResult<'a, Channel> {
    let by_id = |url: Option<&str>| url.and_then(|u| ids.get(u.trim_start_matches('#')).copied());
    let sampler = by_id(channel.attribute("source"))
        .filter(|s| s.has_tag_name("sampler"))
        .ok_or_else(|| (channel, "<channel source> names no <sampler>".to_owned()))?;
    let input = |semantic: &str| {
        children(sampler, "input")
            .find(|i| i.attribute("semantic") == Some(semantic))
            .and_then(|i| by_id(i.attribute("source")))
            .and_then(|s| child(s, "float_array"))
            .ok_or_else(|| (sampler, format!("<sampler> without a {semantic} source")))
    };
    let times_s = floats(input("INPUT")?)?;
    let values = floats(input("OUTPUT")?)?;
    if values.len() != times_s.len() * 16 {
        return Err((
            sampler,
            format!(
                "{} key times but {} numbers: expected 16 per key (a matrix)",
                times_s.len(),
                values.len()
            ),
        ));
    }
    if times_s.windows(2).any(|w| w[1] < w[0]) {
        return Err((sampler, "key times go backwards".to_owned()));
    }
    let keys = values
        .chunks_exact(16)
        .map(|v| {
            let (s, r, t) = matrix(v).to_scale_rotation_translation();
            (s, r.normalize(), t * scale)
        })
        .collect();
    Ok(Channel {
        joint,
        times_s,
        keys,
    })
}
