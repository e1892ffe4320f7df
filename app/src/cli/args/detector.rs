//! The YOLO detector's options ([`DetectorArgs`]), shared by the commands that run it, and
//! the default thread counts.

use std::path::PathBuf;

use clap::Args;
use rover_perception::{
    DEFAULT_NMS_IOU, DEFAULT_THRESHOLD, DetectorConfig, FaultKind, InjectedFault, Runtime,
};

/// Detector options shared by the commands that run YOLO.
#[derive(Debug, Args)]
pub(crate) struct DetectorArgs {
    /// YOLO ONNX model [default: YOLOv12n from the crates.io package easy-yolo 0.1.3, fetched
    /// into ~/.cache/rover on first use; its weights are AGPL-3.0]. Heads: YOLOv5 [1,N,5+C],
    /// YOLOv8/11/12 [1,4+C,N], YOLOv10 [1,K,6]
    #[arg(long, value_name = "FILE")]
    pub(crate) model: Option<PathBuf>,

    /// Class names, one per line (darknet's coco.names format) [default: the model's `names`
    /// metadata, else COCO's 80]
    #[arg(long, value_name = "FILE")]
    pub(crate) labels: Option<PathBuf>,

    /// Confidence threshold (darknet_ros's default); under 0.25 it is the pick's too
    /// (`--threshold 0.15` lets pick take a can YOLO scores 0.2)
    #[arg(long, default_value_t = DEFAULT_THRESHOLD, value_name = "T")]
    pub(crate) threshold: f32,

    /// Class-wise NMS IoU threshold (darknet_ros's default)
    #[arg(long, default_value_t = DEFAULT_NMS_IOU, value_name = "IOU")]
    pub(crate) nms: f32,

    /// Network input size WIDTHxHEIGHT, multiples of 32 [default: 512x384 for the default model
    /// (the camera's 4:3 aspect), the model's own size otherwise]
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub(crate) input_size: Option<(usize, usize)>,

    /// Make the detector fail on purpose after N detections, to see (or test) how a run
    /// copes: KIND@N with KIND `panic` or `error`, e.g. `panic@10`
    #[arg(long, value_name = "KIND@N", value_parser = parse_fault)]
    pub(crate) inject_fault: Option<InjectedFault>,

    /// Threads for one detection: tract splits the network's matrix products across them, and
    /// the boxes are bit-identical whatever the count [default: 2 (1 on a one-core machine);
    /// 1 in `rover eval`'s workers, which already fill the cores]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=64))]
    pub(crate) detect_threads: Option<u16>,

    /// The network's runtime: `tract` (pure Rust, built in) or `onnxruntime`, the
    /// libonnxruntime.so of a `pip install onnxruntime` (found in $VIRTUAL_ENV, rover's
    /// ~/.cache/rover/venv, ~/.local or the system's Python; or set ORT_DYLIB_PATH), loaded at
    /// run time. Same graph, same boxes within float rounding; onnxruntime is ~1.6x faster here
    #[arg(long, value_enum, default_value_t = RuntimeArg::Tract, value_name = "RUNTIME")]
    pub(crate) runtime: RuntimeArg,
}

fn parse_fault(text: &str) -> Result<InjectedFault, String> {
    let (kind, n) = text
        .split_once('@')
        .ok_or_else(|| format!("expected KIND@N like panic@10, found '{text}'"))?;
    let kind = match kind {
        "panic" => FaultKind::Panic,
        "error" => FaultKind::Error,
        other => return Err(format!("'{other}' is not a fault: expected panic or error")),
    };
    let after_detections = n
        .parse()
        .map_err(|_| format!("'{n}' is not a whole number of detections"))?;
    Ok(InjectedFault {
        after_detections,
        kind,
    })
}

fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT like 640x480, found '{text}'"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{v}' is not a whole number of pixels"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// `--runtime`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum RuntimeArg {
    /// tract-onnx (default)
    Tract,
    /// onnxruntime's shared library from a pip install
    Onnxruntime,
}

impl From<RuntimeArg> for Runtime {
    fn from(arg: RuntimeArg) -> Self {
        match arg {
            RuntimeArg::Tract => Runtime::Tract,
            RuntimeArg::Onnxruntime => Runtime::OnnxRuntime,
        }
    }
}

/// The machine's CPU cores: the default of `--jobs` (eval, dataset).
pub(crate) fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Detector threads where the loop leaves a core free for them: 2, or 1 on a one-core machine.
/// Two measured here (2 vCPU, 512x384): one detection 76 -> 49 ms, the same boxes.
pub(crate) fn spare_detect_threads() -> usize {
    cores().min(2)
}

impl DetectorArgs {
    /// The same options as command-line arguments (to hand them to a child process).
    pub(crate) fn to_args(&self) -> Vec<std::ffi::OsString> {
        let mut args: Vec<std::ffi::OsString> = Vec::new();
        if let Some(m) = &self.model {
            args.push("--model".into());
            args.push(m.into());
        }
        if let Some(l) = &self.labels {
            args.push("--labels".into());
            args.push(l.into());
        }
        args.push(format!("--threshold={}", self.threshold).into());
        args.push(format!("--nms={}", self.nms).into());
        if let Some((w, h)) = self.input_size {
            args.push(format!("--input-size={w}x{h}").into());
        }
        if let Some(f) = self.inject_fault {
            let kind = match f.kind {
                FaultKind::Panic => "panic",
                FaultKind::Error => "error",
            };
            args.push(format!("--inject-fault={kind}@{}", f.after_detections).into());
        }
        if let Some(n) = self.detect_threads {
            args.push(format!("--detect-threads={n}").into());
        }
        if self.runtime != RuntimeArg::Tract {
            args.push(format!("--runtime={}", Runtime::from(self.runtime).name()).into());
        }
        args
    }

    /// The detector's settings for a command that runs no session (`rover detect`, `rover
    /// bench detect`), where `--inject-fault` has nothing to act on and is refused.
    pub(crate) fn tool_config(&self, default_threads: usize) -> anyhow::Result<DetectorConfig> {
        anyhow::ensure!(
            self.inject_fault.is_none(),
            "--inject-fault applies to runs (headless, the window, eval), not to this command"
        );
        self.config(default_threads)
    }

    /// The detector's settings; `default_threads` where `--detect-threads` was not given (see
    /// [`spare_detect_threads`]). `--inject-fault` is not among them: runs hand
    /// [`DetectorArgs::inject_fault`] to the session, which wraps the detector.
    pub(crate) fn config(&self, default_threads: usize) -> anyhow::Result<DetectorConfig> {
        anyhow::ensure!(
            (0.0..=1.0).contains(&self.threshold),
            "--threshold must be between 0 and 1, found {}",
            self.threshold
        );
        anyhow::ensure!(
            (0.0..=1.0).contains(&self.nms),
            "--nms must be between 0 and 1, found {}",
            self.nms
        );
        Ok(DetectorConfig {
            model: self.model.clone(),
            labels: self.labels.clone(),
            input_size: self.input_size,
            threshold: self.threshold,
            nms_iou: self.nms,
            threads: self.detect_threads.map_or(default_threads, usize::from),
            runtime: self.runtime.into(),
            ..DetectorConfig::default()
        })
    }
}
