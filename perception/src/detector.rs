//! The YOLO detector on tract-onnx: loaded and optimised once, reused for every frame.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use rayon::ThreadPoolBuilder;
use tract_linalg::multithread::{Executor, multithread_tract_scope};
use tract_onnx::prelude::*;

use crate::error::{PerceptionError, Result};
use crate::fetch;
use crate::graph;
use crate::head::{self, Candidate, Head};
use crate::labels::read_labels_file;
use crate::messages::{BoundingBox, BoundingBoxes, FrameStamp};
use crate::onnxruntime::{OrtSession, Runtime, find_onnxruntime_library};
use crate::preprocess::{LetterboxPlan, RgbView};
use rover_assets::COCO80;

/// Input size the default model runs at: the camera's 4:3 aspect, so camera frames need no
/// letterbox padding, at 0.8x scale: about half the work of the native 640x640 (measured on
/// 2 cores without GPU: ~8 Hz instead of ~3 Hz) while the test photos give the same objects.
/// Use `--input-size 640x480` for more range.
pub const DEFAULT_INPUT_SIZE: (usize, usize) = (512, 384);
/// darknet_ros's default confidence threshold.
pub const DEFAULT_THRESHOLD: f32 = 0.3;
/// darknet_ros's default NMS IoU threshold.
pub const DEFAULT_NMS_IOU: f32 = 0.4;

/// How to build a [`Detector`].
#[derive(Debug, Clone, PartialEq)]
pub struct DetectorConfig {
    /// ONNX model file; `None` = the default YOLOv12n (fetched on first use).
    pub model: Option<PathBuf>,
    /// Class names file (one per line); default: the model's `names` metadata, else COCO's 80.
    pub labels: Option<PathBuf>,
    /// Input size (width, height), multiples of 32; default: [`DEFAULT_INPUT_SIZE`] for the
    /// default model, the model's own size for others.
    pub input_size: Option<(usize, usize)>,
    /// Confidence threshold.
    pub threshold: f32,
    /// Class-wise NMS IoU threshold.
    pub nms_iou: f32,
    /// At most this many boxes per image.
    pub max_boxes: usize,
    /// `frame_id` stamped on results.
    pub frame_id: String,
    /// Threads for one detection: tract splits its matrix products across a pool of this many
    /// (1 = on the calling thread only). The results are bit-identical whatever the count: each
    /// output tile is computed whole by one thread, in the same order.
    pub threads: usize,
    /// The runtime: tract (default) or onnxruntime's shared library (`--runtime onnxruntime`).
    pub runtime: Runtime,
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self {
            model: None,
            labels: None,
            input_size: None,
            threshold: DEFAULT_THRESHOLD,
            nms_iou: DEFAULT_NMS_IOU,
            max_boxes: 100,
            frame_id: "camera_link_optical".to_owned(),
            threads: 1,
            runtime: Runtime::Tract,
        }
    }
}

fn f32_slice(t: &Tensor) -> Result<&[f32]> {
    t.try_as_plain_ram()
        .and_then(|v| v.as_slice::<f32>())
        .map_err(|e| PerceptionError::Inference(format!("model output is not f32: {e}")))
}

/// Time spent in each stage of the last detection (ms).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Letterbox and normalisation.
    pub preprocess_ms: f64,
    /// The network.
    pub inference_ms: f64,
    /// Head decoding and NMS.
    pub decode_ms: f64,
}

/// Where tract spends its time, for one ONNX op type ([`Detector::profile_ops`]).
#[derive(Debug, Clone, Default)]
pub struct OpProfile {
    /// The ONNX op type (`Conv`, `MatMul`, ...).
    pub onnx_op: String,
    /// Milliseconds per run in tract's nodes that came from it.
    pub ms: f64,
    /// How many tract nodes.
    pub nodes: usize,
    /// tract's own ops among them and their milliseconds, slowest first.
    pub tract_ops: Vec<(String, f64)>,
}

/// One detection of one image: what [`crate::DetectorWorker`] and [`crate::LockstepDetector`]
/// run. [`Detector`] is the real one; [`crate::FaultInjector`] wraps it to fail on purpose
/// (`--inject-fault`), so the detector's own path never checks for injected faults.
/// `Send`: a detector moves onto the worker's thread.
pub trait Detect: Send {
    /// Detects objects in an RGB8 image; the result carries `stamp` (the frame it came from).
    fn detect(&mut self, image: RgbView<'_>, stamp: FrameStamp) -> Result<BoundingBoxes>;
}

impl<D: Detect + ?Sized> Detect for Box<D> {
    fn detect(&mut self, image: RgbView<'_>, stamp: FrameStamp) -> Result<BoundingBoxes> {
        (**self).detect(image, stamp)
    }
}

impl Detect for Detector {
    fn detect(&mut self, image: RgbView<'_>, stamp: FrameStamp) -> Result<BoundingBoxes> {
        Detector::detect(self, image, stamp)
    }
}

/// A loaded YOLO model.
pub struct Detector {
    plan: Arc<TypedRunnableModel>,
    head: Head,
    labels: Vec<String>,
    num_classes: usize,
    input_w: usize,
    input_h: usize,
    input: Arc<Tensor>,
    letterbox: LetterboxPlan,
    candidates: Vec<Candidate>,
    kept: Vec<Candidate>,
    config: DetectorConfig,
    model_path: PathBuf,
    proto: tract_onnx::pb::ModelProto,
    last_times: StageTimes,
    /// tract's thread pool when [`DetectorConfig::threads`] > 1.
    executor: Option<Executor>,
    /// The onnxruntime session when [`DetectorConfig::runtime`] asks for it (tract's plan is
    /// still built: it gives the output shape and the per-op profile).
    ort: Option<OrtSession>,
    /// onnxruntime's output, copied into a reused buffer, and its shape.
    ort_output: (Vec<f32>, Vec<usize>),
}

impl std::fmt::Debug for Detector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Detector")
            .field("model", &self.model_path)
            .field("head", &self.head)
            .field("input", &(self.input_w, self.input_h))
            .field("classes", &self.num_classes)
            .finish_non_exhaustive()
    }
}

impl Detector {
    /// Loads, checks and optimises the model (once; detection reuses everything).
    pub fn load(config: DetectorConfig) -> Result<Self> {
        let (model_path, requested) = resolve_model(&config)?;
        // Before tract's plan is built (seconds): a missing library is said at once.
        let ort_library = match config.runtime {
            Runtime::Tract => None,
            Runtime::OnnxRuntime => Some(find_onnxruntime_library()?),
        };
        let prepared = graph::prepare(&model_path, requested)?;
        let (input_w, input_h) = prepared.input_size;
        let (plan, output_shape) = build_plan(&prepared, &model_path)?;
        let labels = match &config.labels {
            Some(file) => read_labels_file(file)?,
            None => prepared
                .metadata_names
                .clone()
                .unwrap_or_else(|| COCO80.iter().map(|s| (*s).to_owned()).collect()),
        };
        let (head, num_classes) = resolve_head(
            prepared.head.clone(),
            output_shape,
            labels.len(),
            &model_path,
        )?;
        check_label_count(&config, &prepared, &model_path, num_classes, labels.len())?;
        let executor = thread_pool(config.threads, config.runtime)?;
        let ort = match &ort_library {
            None => None,
            Some(library) => {
                use prost::Message as _;
                Some(OrtSession::new(
                    library,
                    &prepared.proto.encode_to_vec(),
                    [1, 3, input_h, input_w],
                    config.threads,
                    &model_path,
                )?)
            }
        };
        tracing::debug!(
            "detector: {} at {input_w}x{input_h}, head {}, {num_classes} classes",
            model_path.display(),
            head.name()
        );
        Ok(Self {
            plan,
            head,
            num_classes,
            labels,
            input_w,
            input_h,
            input: Arc::new(Tensor::zero::<f32>(&[1, 3, input_h, input_w]).map_err(|e| {
                PerceptionError::Inference(format!("allocating the input tensor: {e}"))
            })?),
            letterbox: LetterboxPlan::default(),
            candidates: Vec::with_capacity(1024),
            kept: Vec::with_capacity(128),
            config,
            model_path,
            proto: prepared.proto,
            last_times: StageTimes::default(),
            executor,
            ort,
            ort_output: (Vec::new(), Vec::new()),
        })
    }

    /// Class names, indexed by class id.
    pub fn labels(&self) -> &[String] {
        &self.labels
    }

    /// Model input size (width, height).
    pub fn input_size(&self) -> (usize, usize) {
        (self.input_w, self.input_h)
    }

    /// The head format being decoded.
    pub fn head(&self) -> &Head {
        &self.head
    }

    /// The model file.
    pub fn model_path(&self) -> &std::path::Path {
        &self.model_path
    }

    /// The configuration it was built with.
    pub fn config(&self) -> &DetectorConfig {
        &self.config
    }

    /// Stage timings of the last [`Detector::detect`].
    pub fn last_times(&self) -> StageTimes {
        self.last_times
    }

    /// Writes the model as rover runs it (after surgery) to an ONNX file, so other runtimes can
    /// be compared on exactly the same graph.
    pub fn export_onnx(&self, path: &std::path::Path) -> Result<()> {
        use prost::Message as _;
        std::fs::write(path, self.proto.encode_to_vec()).map_err(|e| PerceptionError::io(path, e))
    }

    /// Letterboxes `image` into the reused input tensor and returns a view of it (for comparing
    /// runtimes on the same input).
    pub fn preprocess(
        &mut self,
        image: RgbView<'_>,
    ) -> Result<(&[f32], crate::preprocess::Letterbox)> {
        let (w, h) = (self.input_w, self.input_h);
        // The tensor is shared with tract only during a run; were it still shared here,
        // `make_mut` would silently copy 2.4 MB per frame. Refuse instead.
        let tensor = Arc::get_mut(&mut self.input).ok_or_else(|| {
            PerceptionError::Inference(
                "the input tensor is still held by the previous run (it would be copied every frame)"
                    .into(),
            )
        })?;
        let mut plain = tensor
            .try_as_plain_ram_mut()
            .map_err(|e| PerceptionError::Inference(e.to_string()))?;
        let slice = plain
            .as_slice_mut::<f32>()
            .map_err(|e| PerceptionError::Inference(e.to_string()))?;
        let lb = self.letterbox.letterbox_into(image, slice, w, h)?;
        Ok((f32_slice(&self.input)?, lb))
    }

    /// Runs the network on the current input tensor; returns the raw output and its shape.
    pub fn infer_raw(&mut self) -> Result<(Vec<f32>, Vec<usize>)> {
        if let Some(ort) = self.ort.as_mut() {
            let (mut output, mut shape) = (Vec::new(), Vec::new());
            ort.run(f32_slice(&self.input)?, &mut output, &mut shape)?;
            return Ok((output, shape));
        }
        let outputs = self.run_network()?;
        let out = &outputs[0];
        let data = f32_slice(out)?.to_vec();
        Ok((data, out.shape().to_vec()))
    }

    /// Times every node of tract's plan over `runs` runs of the current input tensor, grouped
    /// by the ONNX op type each node came from (tract's node names keep the ONNX node's name as
    /// a prefix; its own ops are listed beside). Milliseconds per run, slowest first.
    pub fn profile_ops(&mut self, runs: usize) -> Result<Vec<OpProfile>> {
        let onnx_ops: Vec<(&str, &str)> = self
            .proto
            .graph
            .as_ref()
            .map(|g| {
                g.node
                    .iter()
                    .map(|n| (n.name.as_str(), n.op_type.as_str()))
                    .collect()
            })
            .unwrap_or_default();
        let plan = self.plan.clone();
        let model = plan.model();
        let mut per_node = vec![std::time::Duration::ZERO; model.nodes().len()];
        let mut state = tract_onnx::tract_core::plan::SimpleState::new(&plan)
            .map_err(|e| PerceptionError::Inference(format!("{e:#}")))?;
        let runs = runs.max(1);
        for _ in 0..runs {
            state
                .run_plan_with_eval(
                    tvec!(TValue::from_const(self.input.clone())),
                    |ctx, op_state, node, inputs| {
                        let start = Instant::now();
                        let out = tract_onnx::tract_core::plan::eval(ctx, op_state, node, inputs);
                        if let Some(t) = per_node.get_mut(node.id) {
                            *t += start.elapsed();
                        }
                        out
                    },
                )
                .map_err(|e| PerceptionError::Inference(format!("{e:#}")))?;
        }
        let mut groups: std::collections::BTreeMap<String, OpProfile> = Default::default();
        for node in model.nodes() {
            let ms = per_node[node.id].as_secs_f64() * 1e3 / runs as f64;
            // The longest ONNX node name that prefixes this node's name.
            let onnx = onnx_ops
                .iter()
                .filter(|(name, _)| !name.is_empty() && node.name.starts_with(name))
                .max_by_key(|(name, _)| name.len())
                .map_or("(no ONNX node)", |(_, op)| op);
            let g = groups.entry(onnx.to_owned()).or_insert_with(|| OpProfile {
                onnx_op: onnx.to_owned(),
                ..OpProfile::default()
            });
            g.ms += ms;
            g.nodes += 1;
            let tract_op = node.op().name().to_string();
            match g.tract_ops.iter_mut().find(|(n, _)| *n == tract_op) {
                Some((_, t)) => *t += ms,
                None => g.tract_ops.push((tract_op, ms)),
            }
        }
        let mut out: Vec<OpProfile> = groups.into_values().collect();
        for g in &mut out {
            g.tract_ops.sort_by(|a, b| b.1.total_cmp(&a.1));
        }
        out.sort_by(|a, b| b.ms.total_cmp(&a.ms));
        Ok(out)
    }

    fn run_network(&mut self) -> Result<TVec<TValue>> {
        let run = || self.plan.run(tvec!(TValue::from_const(self.input.clone())));
        match &self.executor {
            Some(pool) => multithread_tract_scope(pool.clone(), run),
            None => run(),
        }
        .map_err(|e| PerceptionError::Inference(format!("{e:#}")))
    }

    /// Decodes a raw output (as from [`Detector::infer_raw`], or another runtime given the same
    /// input) into boxes in source-image pixels.
    pub fn decode_raw(
        &mut self,
        output: &[f32],
        shape: &[usize],
        letterbox: crate::preprocess::Letterbox,
        stamp: FrameStamp,
    ) -> Result<BoundingBoxes> {
        let mut result = BoundingBoxes {
            image_stamp: stamp,
            frame_id: self.config.frame_id.clone(),
            ..BoundingBoxes::default()
        };
        self.decode_into(output, shape, letterbox, &mut result)?;
        Ok(result)
    }

    fn decode_into(
        &mut self,
        output: &[f32],
        shape: &[usize],
        lb: crate::preprocess::Letterbox,
        result: &mut BoundingBoxes,
    ) -> Result<()> {
        let spec = head::DecodeSpec {
            input_w: self.input_w,
            input_h: self.input_h,
            num_classes: self.num_classes,
            threshold: self.config.threshold,
        };
        head::decode(&self.head, output, shape, spec, &mut self.candidates)?;
        head::nms(
            &mut self.candidates,
            self.config.nms_iou,
            self.config.max_boxes,
            &mut self.kept,
        );
        result.bounding_boxes.clear();
        for c in &self.kept {
            let (x1, y1) = lb.to_source(c.x1, c.y1);
            let (x2, y2) = lb.to_source(c.x2, c.y2);
            if x2 - x1 < 1.0 || y2 - y1 < 1.0 {
                continue;
            }
            result.bounding_boxes.push(BoundingBox {
                class: self.labels[c.class].clone(),
                probability: f64::from(c.score),
                xmin: x1.round() as i64,
                ymin: y1.round() as i64,
                xmax: x2.round() as i64,
                ymax: y2.round() as i64,
                id: c.class as i16,
            });
        }
        Ok(())
    }

    /// Detects objects in an RGB8 image. Boxes are in the image's pixels; the result carries
    /// `stamp` (the frame it came from).
    pub fn detect(&mut self, image: RgbView<'_>, stamp: FrameStamp) -> Result<BoundingBoxes> {
        let start = Instant::now();
        let (_, lb) = self.preprocess(image)?;
        let preprocessed = Instant::now();
        let mut result = BoundingBoxes {
            image_stamp: stamp,
            frame_id: self.config.frame_id.clone(),
            ..BoundingBoxes::default()
        };
        let inferred;
        if let Some(ort) = self.ort.as_mut() {
            let (mut output, mut shape) = std::mem::take(&mut self.ort_output);
            let input = f32_slice(&self.input)?;
            let ran = ort.run(input, &mut output, &mut shape);
            inferred = Instant::now();
            let decoded = ran.and_then(|()| self.decode_into(&output, &shape, lb, &mut result));
            self.ort_output = (output, shape);
            decoded?;
        } else {
            let outputs = self.run_network()?;
            inferred = Instant::now();
            let out = &outputs[0];
            let data = f32_slice(out)?;
            let shape: TVec<usize> = out.shape().into();
            self.decode_into(data, &shape, lb, &mut result)?;
        }
        let done = Instant::now();
        self.last_times = StageTimes {
            preprocess_ms: (preprocessed - start).as_secs_f64() * 1e3,
            inference_ms: (inferred - preprocessed).as_secs_f64() * 1e3,
            decode_ms: (done - inferred).as_secs_f64() * 1e3,
        };
        result.latency_ms = (done - start).as_secs_f64() * 1e3;
        Ok(result)
    }
}

/// The model file a configuration names (the default model, fetched when needed) and the
/// input size asked for (the default model's [`DEFAULT_INPUT_SIZE`] unless given); refuses a
/// missing file and zero threads.
fn resolve_model(config: &DetectorConfig) -> Result<(PathBuf, Option<(usize, usize)>)> {
    let (model_path, requested) = match &config.model {
        Some(p) => (p.clone(), config.input_size),
        None => (
            fetch::ensure_default_model()?,
            Some(config.input_size.unwrap_or(DEFAULT_INPUT_SIZE)),
        ),
    };
    if !model_path.is_file() {
        return Err(PerceptionError::model(&model_path, "no such model file"));
    }
    if config.threads == 0 {
        return Err(PerceptionError::model(
            &model_path,
            "the detector needs at least one thread",
        ));
    }
    Ok((model_path, requested))
}

/// tract's optimised, runnable plan of the prepared graph at its input size, and the shape of
/// its first output (the head).
fn build_plan(
    prepared: &graph::Prepared,
    model_path: &Path,
) -> Result<(Arc<TypedRunnableModel>, Vec<usize>)> {
    let (input_w, input_h) = prepared.input_size;
    let fail =
        |stage: &str, e: TractError| PerceptionError::model(model_path, format!("{stage}: {e:#}"));
    let mut model = tract_onnx::onnx()
        .model_for_proto_model(&prepared.proto)
        .map_err(|e| fail("tract cannot load it", e))?
        .with_input_fact(0, f32::fact([1, 3, input_h, input_w]).into())
        .map_err(|e| fail("setting the input shape", e))?;
    // Concatenations before 1x1 convolutions stay whole (see graph.rs): tract leaves them
    // alone when they are outputs. Output 0 stays the head; the extra ones are ignored.
    let mut outlets = model
        .output_outlets()
        .map_err(|e| fail("its outputs", e))?
        .to_vec();
    for name in &prepared.whole_concats {
        if let Some(node) = model.nodes().iter().find(|n| &n.name == name) {
            outlets.push(OutletId::new(node.id, 0));
        }
    }
    model
        .select_output_outlets(&outlets)
        .map_err(|e| fail("setting its outputs", e))?;
    let plan = model
        .into_optimized()
        .map_err(|e| fail("tract cannot optimise it", e))?
        .into_runnable()
        .map_err(|e| fail("tract cannot plan it", e))?;
    let output_shape: Vec<usize> = plan
        .model()
        .output_fact(0)
        .ok()
        .and_then(|f| f.shape.as_concrete().map(|s| s.to_vec()))
        .ok_or_else(|| {
            PerceptionError::model(model_path, "the model's output shape is not fixed")
        })?;
    Ok((plan, output_shape))
}

/// The head to decode and its class count: the one graph surgery found (a raw Ultralytics
/// head, classes from the output's channels), else the one the output shape says (classes
/// from the shape, or from the labels where the shape does not tell).
fn resolve_head(
    prepared: Option<Head>,
    output_shape: Vec<usize>,
    label_count: usize,
    model_path: &Path,
) -> Result<(Head, usize)> {
    Ok(match prepared {
        Some(Head::Dfl { reg_max, strides }) => {
            let classes = output_shape
                .get(1)
                .copied()
                .unwrap_or(0)
                .saturating_sub(4 * reg_max);
            (Head::Dfl { reg_max, strides }, classes)
        }
        Some(other) => (other, label_count),
        None => match Head::from_shape(&output_shape) {
            Some((head, Some(classes))) => (head, classes),
            Some((head, None)) => (head, label_count),
            None => {
                return Err(PerceptionError::UnknownHead {
                    path: model_path.to_path_buf(),
                    shape: output_shape,
                });
            }
        },
    })
}

/// Refuses class names that do not match the model's class count, saying where the names
/// came from.
fn check_label_count(
    config: &DetectorConfig,
    prepared: &graph::Prepared,
    model_path: &Path,
    num_classes: usize,
    label_count: usize,
) -> Result<()> {
    if label_count == num_classes {
        return Ok(());
    }
    Err(PerceptionError::Labels(format!(
        "{}: the model predicts {num_classes} classes but {label_count} class names were found ({}); pass --labels with one name per line",
        model_path.display(),
        match &config.labels {
            Some(f) => format!("from {}", f.display()),
            None if prepared.metadata_names.is_some() => "from the model's metadata".to_owned(),
            None => "COCO's default 80".to_owned(),
        }
    )))
}

/// tract's own thread pool for `threads` > 1 (none for one thread, or for onnxruntime, which
/// has its own).
fn thread_pool(threads: usize, runtime: Runtime) -> Result<Option<Executor>> {
    match (threads, runtime) {
        (0 | 1, _) | (_, Runtime::OnnxRuntime) => Ok(None),
        (n, Runtime::Tract) => ThreadPoolBuilder::new()
            .thread_name(|i| format!("rover-detect-{i}"))
            .num_threads(n)
            .build()
            .map(|pool| Some(Executor::MultiThread(Arc::new(pool))))
            .map_err(|e| PerceptionError::Inference(format!("starting {n} detector threads: {e}"))),
    }
}
