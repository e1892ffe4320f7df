//! The detector benchmark (`rover bench detect`): the detector's stages beside onnxruntime on
//! the same graph and input, and with `--profile` a per-op comparison.

use std::path::PathBuf;

use anyhow::Result;
use rover_perception::DetectorConfig;

use super::stats::median;

/// Result of the detector benchmark.
#[derive(Debug, Clone)]
pub struct DetectorBench {
    /// Model input size (width, height).
    pub input_size: (usize, usize),
    /// Median letterbox + normalisation (ms).
    pub preprocess_ms: f64,
    /// The runtime measured (`tract` or `onnxruntime`).
    pub runtime: &'static str,
    /// Median inference (ms).
    pub inference_ms: f64,
    /// Median decode + NMS (ms).
    pub decode_ms: f64,
    /// Median end to end (ms).
    pub total_ms: f64,
    /// onnxruntime's median (Python, as many threads) on the same graph and input, when it
    /// could run.
    pub onnxruntime_ms: Result<f64, String>,
}

/// Times the detector (`config.threads` threads, `runs` frames after one warm-up) on `image`,
/// then onnxruntime (Python, scripts/ort_reference.py) on exactly the same graph and input
/// tensor with as many intra-op threads.
pub fn detector(
    config: rover_perception::DetectorConfig,
    image: &std::path::Path,
    runs: usize,
) -> Result<DetectorBench> {
    use rover_perception::{Detector, FrameStamp, RgbView, load_rgb};

    let mut detector = Detector::load(config)?;
    let (w, h, pixels) = load_rgb(image)?;
    let view = RgbView::new(w, h, &pixels)?;
    detector.detect(view, FrameStamp::default())?;
    let (mut pre, mut inf, mut dec, mut total) = (vec![], vec![], vec![], vec![]);
    for frame in 0..runs.max(1) {
        let r = detector.detect(
            view,
            FrameStamp {
                sim_time_s: 0.0,
                frame: frame as u64,
            },
        )?;
        let t = detector.last_times();
        pre.push(t.preprocess_ms);
        inf.push(t.inference_ms);
        dec.push(t.decode_ms);
        total.push(r.latency_ms);
    }
    let input_size = detector.input_size();
    let onnxruntime_ms = onnxruntime_median(&mut detector, view, runs);
    Ok(DetectorBench {
        runtime: detector.config().runtime.name(),
        input_size,
        preprocess_ms: median(&mut pre),
        inference_ms: median(&mut inf),
        decode_ms: median(&mut dec),
        total_ms: median(&mut total),
        onnxruntime_ms,
    })
}

/// Per-op profile: tract's plan node by node beside onnxruntime's profiler, grouped by the
/// ONNX op type, on the same graph and input tensor (one thread each).
fn profile_detector(
    config: rover_perception::DetectorConfig,
    image: &std::path::Path,
    runs: usize,
) -> Result<()> {
    use rover_perception::{Detector, FrameStamp, RgbView, load_rgb};
    let mut detector = Detector::load(config)?;
    let (w, h, pixels) = load_rgb(image)?;
    let view = RgbView::new(w, h, &pixels)?;
    detector.detect(view, FrameStamp::default())?;
    detector.preprocess(view)?;
    let tract = detector.profile_ops(runs)?;
    let model = std::env::temp_dir().join(format!("rover-profile-{}.onnx", std::process::id()));
    let (iw, ih) = detector.input_size();
    let ort = detector
        .export_onnx(&model)
        .map_err(anyhow::Error::from)
        .and_then(|()| {
            let (input, _) = detector.preprocess(view)?;
            Ok(rover_perception::onnxruntime_reference_profiled(
                &model,
                input,
                &[1, 3, ih, iw],
                runs.max(1),
            )?)
        });
    let _ = std::fs::remove_file(&model);
    let ort_ops = match ort {
        Ok(run) => run.ops,
        Err(e) => {
            say!("onnxruntime: not profiled ({e:#})");
            Vec::new()
        }
    };
    let tract_total: f64 = tract.iter().map(|g| g.ms).sum();
    let ort_total: f64 = ort_ops.iter().map(|(_, ms)| ms).sum();
    say!("per-op profile, ms per run (sum of node times), one thread, {runs} runs:");
    say!(
        "{:<20} {:>6} {:>9} {:>9} {:>7}   tract's ops (ms)",
        "ONNX op",
        "nodes",
        "tract",
        "ort",
        "ratio"
    );
    for g in &tract {
        let ort_ms = ort_ops
            .iter()
            .find(|(op, _)| *op == g.onnx_op)
            .map(|(_, ms)| *ms);
        let top: Vec<String> = g
            .tract_ops
            .iter()
            .take(3)
            .map(|(op, ms)| format!("{op} {ms:.1}"))
            .collect();
        say!(
            "{:<20} {:>6} {:>9.2} {:>9} {:>7}   {}",
            g.onnx_op,
            g.nodes,
            g.ms,
            ort_ms.map_or_else(|| "-".to_owned(), |m| format!("{m:.2}")),
            ort_ms.map_or_else(|| "-".to_owned(), |m| format!("{:.2}x", g.ms / m)),
            top.join(", ")
        );
    }
    for (op, ms) in &ort_ops {
        if !tract.iter().any(|g| g.onnx_op == *op) {
            say!("{op:<20} {:>6} {:>9} {ms:>9.2}", "-", "-");
        }
    }
    say!(
        "{:<20} {:>6} {:>9.2} {:>9.2} {:>7.2}x",
        "total",
        "",
        tract_total,
        ort_total,
        tract_total / ort_total
    );
    say!();
    Ok(())
}

fn onnxruntime_median(
    detector: &mut rover_perception::Detector,
    view: rover_perception::RgbView<'_>,
    runs: usize,
) -> Result<f64, String> {
    let model = std::env::temp_dir().join(format!("rover-bench-{}.onnx", std::process::id()));
    let (w, h) = detector.input_size();
    let threads = detector.config().threads;
    let result = detector
        .export_onnx(&model)
        .map_err(|e| e.to_string())
        .and_then(|()| {
            let (input, _) = detector.preprocess(view).map_err(|e| e.to_string())?;
            rover_perception::onnxruntime_reference(
                &model,
                input,
                &[1, 3, h, w],
                threads,
                runs.max(1) + 1,
            )
            .map(|r| r.median_ms)
            .map_err(|e| format!("{e:#}"))
        });
    let _ = std::fs::remove_file(&model);
    result
}

pub(crate) fn bench_detect(
    config: DetectorConfig,
    image: Option<PathBuf>,
    runs: usize,
    profile: bool,
) -> Result<()> {
    let image = match image {
        Some(path) => path,
        None => {
            let darknet = PathBuf::from("/usr/share/darknet/data/person.jpg");
            if darknet.is_file() {
                darknet
            } else {
                let path = std::env::temp_dir().join("rover-bench-pattern.png");
                let pattern = image::RgbImage::from_fn(640, 480, |x, y| {
                    image::Rgb([(x % 256) as u8, (y % 256) as u8, ((x + y) % 256) as u8])
                });
                pattern.save(&path)?;
                path
            }
        }
    };
    say!(
        "detector benchmark on {}: {runs} runs after a warm-up, {} thread(s) for both runtimes (--detect-threads)",
        image.display(),
        config.threads
    );
    if profile {
        // Node by node, one thread: the times add up to the run.
        profile_detector(
            DetectorConfig {
                threads: 1,
                runtime: rover_perception::Runtime::Tract,
                ..config.clone()
            },
            &image,
            runs,
        )?;
    }
    let b = detector(config, &image, runs)?;
    say!("input {}x{}", b.input_size.0, b.input_size.1);
    say!("{:<28} {:>10}", "stage (median)", "ms");
    say!("{:<28} {:>10.1}", "preprocess (letterbox)", b.preprocess_ms);
    say!(
        "{:<28} {:>10.1}",
        format!("{} inference", b.runtime),
        b.inference_ms
    );
    say!("{:<28} {:>10.1}", "decode + NMS", b.decode_ms);
    say!(
        "{:<28} {:>10.1}   ({:.1} Hz)",
        "end to end",
        b.total_ms,
        1000.0 / b.total_ms
    );
    match b.onnxruntime_ms {
        Ok(ort) => {
            say!("{:<28} {:>10.1}", "onnxruntime inference", ort);
            say!(
                "{:<28} {:>10.2}x",
                format!("{} / onnxruntime (Python)", b.runtime),
                b.inference_ms / ort
            );
        }
        Err(e) => say!("onnxruntime: not measured ({e}); pip install onnxruntime"),
    }
    Ok(())
}
