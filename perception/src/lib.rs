//! rover-perception: YOLO object detection on tract-onnx with darknet_ros-shaped results.
//!
//! * [`Detector`] loads any YOLO ONNX export (YOLOv5 `[1,N,5+C]`, YOLOv8/11/12 `[1,4+C,N]`,
//!   YOLOv10 `[1,K,6]`), letterboxes RGB8 images into it, decodes the head and runs class-wise
//!   NMS. Ultralytics exports get load-time surgery ([`graph`]) that makes tract ~3x faster and
//!   lets them run at the camera's 640x480.
//! * [`DetectorWorker`] runs it on its own thread, always on the newest frame.
//! * The default model is YOLOv12n from the crates.io package easy-yolo 0.1.3 ([`fetch`]); its
//!   weights are AGPL-3.0 and are fetched at set-up, never shipped.
//!
//! No UI or viewer code: everything runs headless in tests.

pub mod detector;
mod draw;
pub mod error;
pub mod fetch;
mod graph;
pub mod head;
pub mod labels;
pub mod lockstep;
pub mod messages;
pub mod onnxruntime;
pub mod preprocess;
pub mod reference;
pub mod worker;

pub use detector::{
    DEFAULT_INPUT_SIZE, DEFAULT_NMS_IOU, DEFAULT_THRESHOLD, Detector, DetectorConfig, FaultKind,
    InjectedFault, OpProfile, StageTimes,
};
pub use draw::{PixelRect, box_outline, draw_box_rgb8};
pub use error::{PerceptionError, Result};
pub use lockstep::LockstepDetector;
pub use messages::{BoundingBox, BoundingBoxes, FrameStamp, ObjectCount};
pub use onnxruntime::Runtime;
pub use preprocess::{Letterbox, LetterboxPlan, RgbView};
pub use worker::{DetectorWorker, Frame, WorkerStats};
