//! Load-time surgery on Ultralytics ONNX exports, so tract runs them fast and at any input size:
//!
//! * the detect head is cut before its built-in decode (its distribution-focal softmax runs
//!   along a strided axis, which alone took 325 of tract's 690 ms per 640x640 frame here); rover
//!   decodes the raw head itself ([`crate::head::Head::Dfl`]);
//! * the input size can then change (e.g. 640x480 to match the camera instead of letterboxing
//!   into 640x640): Reshape shapes that bake the feature-map grids (YOLOv12's area attention)
//!   are rewritten for the new grids.
//! * softmax spelled out as five ops (YOLOv12's attention) becomes one `Softmax`;
//! * `Concat` nodes that feed only 1x1 convolutions are listed, so the detector keeps them whole
//!   in tract's plan (tract would split each such convolution into small products).

use std::collections::{HashMap, HashSet};
use std::path::Path;

use tract_onnx::pb::{
    ModelProto, NodeProto, TensorProto, TypeProto, ValueInfoProto, tensor_shape_proto, type_proto,
};

use crate::error::{PerceptionError, Result};
use crate::head::Head;

/// Strides of Ultralytics' P3-P5 detect heads.
const STRIDES: [usize; 3] = [8, 16, 32];
/// Distribution-focal bins per box side in Ultralytics heads.
const REG_MAX: usize = 16;

/// A model after surgery.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    pub proto: ModelProto,
    /// `Some` when the head was cut and rover decodes it.
    pub head: Option<Head>,
    /// Input size to run at (width, height).
    pub input_size: (usize, usize),
    /// Class names from the `names` metadata.
    pub metadata_names: Option<Vec<String>>,
    /// Names of the `Concat` nodes that feed only 1x1 convolutions
    /// ([`concats_before_1x1_convs`]).
    pub whole_concats: Vec<String>,
}

fn dims_of(info: &ValueInfoProto) -> Vec<Option<usize>> {
    let Some(type_proto::Value::TensorType(t)) =
        info.r#type.as_ref().and_then(|t| t.value.as_ref())
    else {
        return Vec::new();
    };
    t.shape
        .as_ref()
        .map(|s| {
            s.dim
                .iter()
                .map(|d| match d.value {
                    Some(tensor_shape_proto::dimension::Value::DimValue(v)) if v > 0 => {
                        Some(v as usize)
                    }
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default()
}

/// Reads and prepares a model. `requested` forces an input size (width, height).
pub(crate) fn prepare(path: &Path, requested: Option<(usize, usize)>) -> Result<Prepared> {
    use tract_onnx::prelude::Framework;
    let mut proto = tract_onnx::onnx()
        .proto_model_for_path(path)
        .map_err(|e| PerceptionError::model(path, format!("not a readable ONNX model: {e:#}")))?;
    let metadata_names = proto
        .metadata_props
        .iter()
        .find(|p| p.key == "names")
        .and_then(|p| crate::labels::parse_metadata_names(&p.value));
    let graph = proto
        .graph
        .as_mut()
        .ok_or_else(|| PerceptionError::model(path, "the ONNX file has no graph"))?;
    let initializers: HashSet<String> = graph.initializer.iter().map(|t| t.name.clone()).collect();
    let inputs: Vec<&ValueInfoProto> = graph
        .input
        .iter()
        .filter(|i| !initializers.contains(&i.name))
        .collect();
    let [input] = inputs.as_slice() else {
        return Err(PerceptionError::model(
            path,
            format!("expected one image input, found {}", inputs.len()),
        ));
    };
    let native_size = match dims_of(input).as_slice() {
        [_, Some(3), Some(h), Some(w)] => Some((*w, *h)),
        [_, Some(3), _, _] => None,
        [_, Some(c), _, _] => {
            return Err(PerceptionError::model(
                path,
                format!("input has {c} channels; expected a [1, 3, H, W] RGB image input"),
            ));
        }
        other => {
            return Err(PerceptionError::model(
                path,
                format!("input shape {other:?}; expected [1, 3, H, W]"),
            ));
        }
    };
    let input_size = requested.or(native_size).unwrap_or((640, 640));
    if !input_size.0.is_multiple_of(32)
        || !input_size.1.is_multiple_of(32)
        || input_size.0 == 0
        || input_size.1 == 0
    {
        return Err(PerceptionError::model(
            path,
            format!(
                "input size {}x{}: expected width and height that are positive multiples of 32",
                input_size.0, input_size.1
            ),
        ));
    }

    let head = cut_ultralytics_head(graph, native_size);
    if head.is_some() {
        prune(graph);
    }
    if let Some(native) = native_size
        && native != input_size
    {
        if head.is_none() {
            return Err(PerceptionError::model(
                path,
                format!(
                    "this model is fixed at {}x{} and rover can resize only Ultralytics YOLOv8/11/12 detect exports; run it at its own size",
                    native.0, native.1
                ),
            ));
        }
        rewrite_grid_reshapes(graph, native, input_size).map_err(|m| {
            PerceptionError::model(
                path,
                format!("cannot run at {}x{}: {m}", input_size.0, input_size.1),
            )
        })?;
    }
    set_input_size(graph, &initializers, input_size);
    if fuse_manual_softmax(graph) > 0 {
        prune(graph);
    }
    let whole_concats = concats_before_1x1_convs(graph);
    Ok(Prepared {
        proto,
        head,
        input_size,
        metadata_names,
        whole_concats,
    })
}

/// Rewrites softmax spelled out over the last axis — `Div(Exp(Sub(x, ReduceMax(x))),
/// ReduceSum(Exp(...)))`, as YOLOv12's area attention is exported — into one `Softmax(axis=-1)`.
/// tract ran the five ops in 5.4 ms per 512x384 frame (its reductions take a scalar path; 8.9x
/// and 5.7x onnxruntime's); its own softmax is one vectorised pass. Returns how many were fused;
/// the orphaned nodes are left for [`prune`].
fn fuse_manual_softmax(graph: &mut tract_onnx::pb::GraphProto) -> usize {
    let producer: HashMap<String, usize> = graph
        .node
        .iter()
        .enumerate()
        .flat_map(|(i, n)| n.output.iter().map(move |o| (o.clone(), i)))
        .collect();
    let mut uses: HashMap<String, usize> = HashMap::new();
    for node in &graph.node {
        for input in &node.input {
            *uses.entry(input.clone()).or_default() += 1;
        }
    }
    for output in &graph.output {
        *uses.entry(output.name.clone()).or_default() += 1;
    }
    let last_axis: HashSet<String> = graph
        .initializer
        .iter()
        .filter(|t| tensor_i64(t).is_some_and(|v| v == [-1]))
        .map(|t| t.name.clone())
        .collect();
    let node_of = |name: &str, op: &str| {
        producer
            .get(name)
            .map(|&i| &graph.node[i])
            .filter(|n| n.op_type == op)
    };
    // A reduction over the last axis that keeps it (keepdims defaults to 1).
    let reduces_last = |n: &NodeProto| {
        n.input.get(1).is_some_and(|a| last_axis.contains(a))
            && n.attribute.iter().all(|a| a.name != "keepdims" || a.i == 1)
            && n.attribute.iter().all(|a| a.name != "noop_with_empty_axes")
    };
    let used = |name: &str, times: usize| uses.get(name).copied() == Some(times);
    let mut fused = Vec::new();
    for (i, div) in graph.node.iter().enumerate() {
        let [exp_out, sum_out] = div.input.as_slice() else {
            continue;
        };
        if div.op_type != "Div" {
            continue;
        }
        let Some(sum) = node_of(sum_out, "ReduceSum") else {
            continue;
        };
        let Some(exp) = node_of(exp_out, "Exp") else {
            continue;
        };
        let Some(sub) = exp.input.first().and_then(|x| node_of(x, "Sub")) else {
            continue;
        };
        let [x, max_out] = sub.input.as_slice() else {
            continue;
        };
        let Some(max) = node_of(max_out, "ReduceMax") else {
            continue;
        };
        let pattern = sum.input.first() == Some(exp_out)
            && max.input.first() == Some(x)
            && reduces_last(sum)
            && reduces_last(max)
            && used(exp_out, 2)
            && used(sum_out, 1)
            && used(max_out, 1)
            && exp.output.first().is_some_and(|o| o == exp_out)
            && sub.output.first().is_some_and(|o| used(o, 1));
        if pattern {
            fused.push((i, x.clone()));
        }
    }
    for (i, x) in &fused {
        let node = &mut graph.node[*i];
        node.op_type = "Softmax".into();
        node.input = vec![x.clone()];
        node.attribute = vec![tract_onnx::pb::AttributeProto {
            name: "axis".into(),
            r#type: 2, // INT
            i: -1,
            ..Default::default()
        }];
    }
    fused.len()
}

/// The names of the `Concat` nodes whose every consumer is a 1x1 `Conv` (the C2f/C3k2 blocks'
/// `cv2` of YOLOv8/11/12). tract splits such a convolution into one matrix product per
/// concatenated input, each with only 16-64 input channels, plus a sum: measured here, keeping
/// the concatenation whole and the product single is ~12% faster for the whole default model
/// (83-87 -> 73-74 ms at 512x384, one thread). tract skips that split for a `Concat` whose
/// output is also a model output, so the detector adds these as extra outputs of tract's plan
/// (never of the exported graph) and ignores them.
fn concats_before_1x1_convs(graph: &tract_onnx::pb::GraphProto) -> Vec<String> {
    let mut consumers: HashMap<&str, Vec<&NodeProto>> = HashMap::new();
    for node in &graph.node {
        for input in &node.input {
            consumers.entry(input.as_str()).or_default().push(node);
        }
    }
    let is_1x1_conv = |n: &NodeProto| {
        n.op_type == "Conv"
            && n.attribute
                .iter()
                .any(|a| a.name == "kernel_shape" && a.ints.iter().all(|&k| k == 1))
            && n.attribute.iter().all(|a| a.name != "group" || a.i == 1)
    };
    let outputs: HashSet<&str> = graph.output.iter().map(|o| o.name.as_str()).collect();
    graph
        .node
        .iter()
        .filter(|n| n.op_type == "Concat" && !n.name.is_empty())
        .filter(|n| {
            n.output.first().is_some_and(|out| {
                !outputs.contains(out.as_str())
                    && consumers
                        .get(out.as_str())
                        .is_some_and(|c| !c.is_empty() && c.iter().all(|n| is_1x1_conv(n)))
            })
        })
        .map(|n| n.name.clone())
        .collect()
}

/// Declares the image input as `[1, 3, height, width]`, so the exported graph is consistent for
/// other runtimes too.
fn set_input_size(
    graph: &mut tract_onnx::pb::GraphProto,
    initializers: &HashSet<String>,
    (w, h): (usize, usize),
) {
    for input in graph
        .input
        .iter_mut()
        .filter(|i| !initializers.contains(&i.name))
    {
        if let Some(type_proto::Value::TensorType(t)) =
            input.r#type.as_mut().and_then(|t| t.value.as_mut())
            && let Some(shape) = t.shape.as_mut()
            && shape.dim.len() == 4
        {
            for (dim, value) in shape.dim.iter_mut().zip([1, 3, h, w]) {
                dim.value = Some(tensor_shape_proto::dimension::Value::DimValue(value as i64));
            }
        }
    }
}

/// Finds Ultralytics' decode tail `output0 = Concat(boxes, Sigmoid(Split(raw)[1]))` and makes
/// `raw` the graph output. Returns the head to decode it with.
fn cut_ultralytics_head(
    graph: &mut tract_onnx::pb::GraphProto,
    native: Option<(usize, usize)>,
) -> Option<Head> {
    let (w, h) = native?;
    let [output] = graph.output.as_slice() else {
        return None;
    };
    let anchors: usize = STRIDES.iter().map(|s| (w / s) * (h / s)).sum();
    match dims_of(output).as_slice() {
        [_, Some(_), Some(n)] if *n == anchors => {}
        _ => return None,
    }
    let producer: HashMap<&str, &NodeProto> = graph
        .node
        .iter()
        .flat_map(|n| n.output.iter().map(move |o| (o.as_str(), n)))
        .collect();
    let concat = producer
        .get(output.name.as_str())
        .filter(|n| n.op_type == "Concat")?;
    let sigmoid = producer
        .get(concat.input.get(1)?.as_str())
        .filter(|n| n.op_type == "Sigmoid")?;
    let split = producer
        .get(sigmoid.input.first()?.as_str())
        .filter(|n| n.op_type == "Split")?;
    let raw = split.input.first()?.clone();
    graph.output = vec![ValueInfoProto {
        name: raw,
        r#type: Some(TypeProto {
            value: Some(type_proto::Value::TensorType(type_proto::Tensor {
                elem_type: 1, // FLOAT
                shape: None,
            })),
            ..TypeProto::default()
        }),
        ..ValueInfoProto::default()
    }];
    Some(Head::Dfl {
        reg_max: REG_MAX,
        strides: STRIDES.to_vec(),
    })
}

/// Drops nodes and initializers the outputs do not need.
fn prune(graph: &mut tract_onnx::pb::GraphProto) {
    let mut needed: HashSet<String> = graph.output.iter().map(|o| o.name.clone()).collect();
    let mut keep = vec![false; graph.node.len()];
    for (i, node) in graph.node.iter().enumerate().rev() {
        if node.output.iter().any(|o| needed.contains(o)) {
            keep[i] = true;
            needed.extend(node.input.iter().cloned());
        }
    }
    let mut i = 0;
    graph.node.retain(|_| {
        i += 1;
        keep[i - 1]
    });
    graph.initializer.retain(|t| needed.contains(&t.name));
    graph.value_info.clear();
}

fn tensor_i64(t: &TensorProto) -> Option<Vec<i64>> {
    // ONNX TensorProto data type 7 = INT64.
    if t.data_type != 7 {
        return None;
    }
    if !t.int64_data.is_empty() {
        return Some(t.int64_data.clone());
    }
    if !t.raw_data.len().is_multiple_of(8) {
        return None;
    }
    Some(
        t.raw_data
            .chunks_exact(8)
            .map(|c| i64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]))
            .collect(),
    )
}

fn set_tensor_i64(t: &mut TensorProto, values: &[i64]) {
    t.int64_data.clear();
    t.raw_data = values.iter().flat_map(|v| v.to_le_bytes()).collect();
}

/// New Reshape target for a shape that bakes a feature-map grid, if it does.
fn regrid(
    dims: &[i64],
    native: (usize, usize),
    size: (usize, usize),
) -> Result<Option<Vec<i64>>, String> {
    let grids: Vec<(i64, i64, i64, i64)> = STRIDES
        .iter()
        .map(|s| {
            (
                (native.1 / s) as i64,
                (native.0 / s) as i64,
                (size.1 / s) as i64,
                (size.0 / s) as i64,
            )
        })
        .collect();
    // [.., gh, gw, ..]: a spatial grid.
    for &(gh, gw, h, w) in &grids {
        if let Some(i) = dims.windows(2).position(|p| p == [gh, gw]) {
            let mut out = dims.to_vec();
            out[i] = h;
            out[i + 1] = w;
            return Ok(Some(out));
        }
    }
    // [a, tokens, ..] where the leading dims multiply to gh * gw: flattened (area) tokens.
    let mut product = 1i64;
    for (i, &d) in dims.iter().enumerate() {
        if d <= 0 {
            break;
        }
        product *= d;
        if let Some(&(gh, gw, h, w)) = grids.iter().find(|g| g.0 * g.1 == product) {
            if (d * h * w) % (gh * gw) != 0 {
                return Err(format!(
                    "a reshape to {dims:?} splits the {gh}x{gw} grid into parts that a {h}x{w} grid cannot fill evenly; pick a size whose grids divide like the model's"
                ));
            }
            let mut out = dims.to_vec();
            out[i] = d * h * w / (gh * gw);
            return Ok(Some(out));
        }
    }
    Ok(None)
}

fn rewrite_grid_reshapes(
    graph: &mut tract_onnx::pb::GraphProto,
    native: (usize, usize),
    size: (usize, usize),
) -> Result<(), String> {
    let shape_inputs: HashSet<String> = graph
        .node
        .iter()
        .filter(|n| n.op_type == "Reshape")
        .filter_map(|n| n.input.get(1).cloned())
        .collect();
    let mut rewritten = 0;
    let mut fix = |t: &mut TensorProto| -> Result<(), String> {
        if let Some(dims) = tensor_i64(t)
            && let Some(new) = regrid(&dims, native, size)?
        {
            set_tensor_i64(t, &new);
            rewritten += 1;
        }
        Ok(())
    };
    for t in graph
        .initializer
        .iter_mut()
        .filter(|t| shape_inputs.contains(&t.name))
    {
        fix(t)?;
    }
    for node in graph.node.iter_mut().filter(|n| n.op_type == "Constant") {
        if node
            .output
            .first()
            .is_some_and(|o| shape_inputs.contains(o))
        {
            for attr in node.attribute.iter_mut().filter(|a| a.name == "value") {
                if let Some(t) = attr.t.as_mut() {
                    fix(t)?;
                }
            }
        }
    }
    tracing::debug!(
        "input resized from {native:?} to {size:?}: {rewritten} reshape shapes rewritten"
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(name: &str, op: &str, inputs: &[&str], output: &str, kernel: Option<i64>) -> NodeProto {
        NodeProto {
            name: name.into(),
            op_type: op.into(),
            input: inputs.iter().map(|s| (*s).to_owned()).collect(),
            output: vec![output.into()],
            attribute: kernel
                .map(|k| tract_onnx::pb::AttributeProto {
                    name: "kernel_shape".into(),
                    ints: vec![k, k],
                    ..Default::default()
                })
                .into_iter()
                .collect(),
            ..Default::default()
        }
    }

    fn softmax_graph(extra_exp_use: bool) -> tract_onnx::pb::GraphProto {
        let mut axes = TensorProto {
            name: "axes".into(),
            data_type: 7,
            dims: vec![1],
            ..Default::default()
        };
        set_tensor_i64(&mut axes, &[-1]);
        let mut nodes = vec![
            node("max", "ReduceMax", &["x", "axes"], "m", None),
            node("sub", "Sub", &["x", "m"], "d", None),
            node("exp", "Exp", &["d"], "e", None),
            node("sum", "ReduceSum", &["e", "axes"], "s", None),
            node("div", "Div", &["e", "s"], "y", None),
        ];
        let mut output = vec![ValueInfoProto {
            name: "y".into(),
            ..Default::default()
        }];
        if extra_exp_use {
            nodes.push(node("other", "Relu", &["e"], "z", None));
            output.push(ValueInfoProto {
                name: "z".into(),
                ..Default::default()
            });
        }
        tract_onnx::pb::GraphProto {
            node: nodes,
            output,
            initializer: vec![axes],
            ..Default::default()
        }
    }

    #[test]
    fn spelled_out_softmax_becomes_one_softmax_unless_its_parts_are_used_elsewhere() {
        let mut graph = softmax_graph(false);
        assert_eq!(fuse_manual_softmax(&mut graph), 1);
        prune(&mut graph);
        let ops: Vec<(&str, &[String])> = graph
            .node
            .iter()
            .map(|n| (n.op_type.as_str(), n.input.as_slice()))
            .collect();
        assert_eq!(ops, vec![("Softmax", &["x".to_owned()][..])]);
        assert_eq!(graph.node[0].output, vec!["y".to_owned()]);
        assert!(
            graph.node[0]
                .attribute
                .iter()
                .any(|a| a.name == "axis" && a.i == -1)
        );

        let mut graph = softmax_graph(true);
        assert_eq!(
            fuse_manual_softmax(&mut graph),
            0,
            "Exp's output is used elsewhere"
        );
    }

    #[test]
    fn only_concats_that_feed_1x1_convolutions_alone_are_kept_whole() {
        let graph = tract_onnx::pb::GraphProto {
            node: vec![
                node("c1", "Concat", &["a", "b"], "c1_out", None),
                node("conv1", "Conv", &["c1_out", "w1"], "y1", Some(1)),
                node("c2", "Concat", &["a", "b"], "c2_out", None),
                node("conv3", "Conv", &["c2_out", "w3"], "y3", Some(3)),
                node("c3", "Concat", &["a", "b"], "c3_out", None),
                node("conv1b", "Conv", &["c3_out", "w1"], "y4", Some(1)),
                node("add", "Add", &["c3_out", "y4"], "y5", None),
                node("c4", "Concat", &["y1", "y3"], "out", None),
            ],
            output: vec![ValueInfoProto {
                name: "out".into(),
                ..Default::default()
            }],
            ..Default::default()
        };
        assert_eq!(concats_before_1x1_convs(&graph), vec!["c1".to_owned()]);
    }

    #[test]
    fn regrid_rewrites_grids_and_area_tokens() -> Result<(), String> {
        let native = (640, 640);
        let size = (640, 480);
        // YOLOv12 area attention at stride 16: 4 areas of 400 tokens of the 40x40 grid.
        assert_eq!(
            regrid(&[4, 400, 2, 96], native, size)?,
            Some(vec![4, 300, 2, 96])
        );
        // At stride 32 one area of the 20x20 grid.
        assert_eq!(
            regrid(&[1, 400, 4, 96], native, size)?,
            Some(vec![1, 300, 4, 96])
        );
        assert_eq!(
            regrid(&[1, 40, 40, 64], native, size)?,
            Some(vec![1, 30, 40, 64])
        );
        assert_eq!(
            regrid(&[1, 20, 20, 128], native, size)?,
            Some(vec![1, 15, 20, 128])
        );
        // Shapes with -1 or unrelated sizes stay.
        assert_eq!(regrid(&[1, 192, -1], native, size)?, None);
        assert_eq!(regrid(&[1, 144, 7], native, size)?, None);
        // A split the new grid cannot fill evenly is refused (3 areas of a 20x20 grid at 96x96).
        assert!(
            regrid(&[3, 400, 2, 96], (1200, 1200), (96, 96)).is_err()
                || regrid(&[3, 400, 2, 96], (1200, 1200), (96, 96))?.is_none()
        );
        Ok(())
    }
}
