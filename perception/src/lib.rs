//! rover-perception: YOLO object detection on tract-onnx with darknet_ros-shaped results.
//!
//! * [`Detector`] loads any YOLO ONNX export (YOLOv5 `[1,N,5+C]`, YOLOv8/11/12 `[1,4+C,N]`,
//!   YOLOv10 `[1,K,6]`), letterboxes RGB8 images into it, decodes the head ([`Head`]) and runs
//!   class-wise NMS. Ultralytics exports get load-time surgery that makes tract ~3x faster and
//!   lets them run at the camera's 640x480.
//! * [`DetectorWorker`] runs it on its own thread, always on the newest frame;
//!   [`LockstepDetector`] on the calling thread at a fixed sim-time rate. Both run anything
//!   that implements [`Detect`]: the [`Detector`], or a [`FaultInjector`] around it that fails
//!   on purpose (`--inject-fault`), so the detector itself never checks for injected faults.
//! * The default model is YOLOv12n from the crates.io package easy-yolo 0.1.3
//!   ([`ensure_default_model`]); its weights are AGPL-3.0 and are fetched at set-up, never
//!   shipped.
//! * [`CocoEvaluator`] scores detections against ground truth exactly as pycocotools' COCOeval
//!   (`bbox`): AP50, AP75, AP50:95, per-class precision, recall and counts; [`match_frame`]
//!   matches one frame live with the same rule.
//! * [`onnxruntime_reference`] runs onnxruntime (Python) on the same graph and input, for tests
//!   and benchmarks.
//!
//! No UI or viewer code: everything runs headless in tests. Modules are private; this is the
//! whole public surface.

mod detector;
mod draw;
mod error;
mod fault;
mod fetch;
mod graph;
mod head;
mod labels;
mod lockstep;
mod messages;
mod metrics;
mod onnxruntime;
mod preprocess;
mod reference;
mod worker;

pub use detector::{
    DEFAULT_INPUT_SIZE, DEFAULT_NMS_IOU, DEFAULT_THRESHOLD, Detect, Detector, DetectorConfig,
    OpProfile, StageTimes,
};
pub use draw::{PixelRect, box_outline, draw_box_rgb8};
pub use error::{PerceptionError, Result};
pub use fault::{FaultInjector, FaultKind, InjectedFault};
pub use fetch::{default_model_path, ensure_default_model};
pub use head::Head;
pub use labels::{parse_metadata_names, read_labels_file};
pub use lockstep::LockstepDetector;
pub use messages::{BoundingBox, BoundingBoxes, FrameStamp, ObjectCount};
pub use metrics::{
    COCO_IOU_THRESHOLDS, COCO_MAX_DETECTIONS, ClassMetrics, CocoEvaluator, Detection,
    DetectionMetrics, EvalBox, FrameMatch, GroundTruthObject, MatchedPair, match_frame,
};
pub use onnxruntime::{Runtime, find_onnxruntime_library};
pub use preprocess::{Letterbox, RgbView, load_rgb};
pub use reference::{OrtRun, onnxruntime_reference, onnxruntime_reference_profiled};
pub use worker::{DetectorWorker, Frame, WorkerStats};
