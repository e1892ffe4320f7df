//! The real default model on real photos, checked against onnxruntime on the same graph, input
//! and decoding.

use anyhow::Result;
use rover_perception::{
    Detector, DetectorConfig, DetectorWorker, Frame, FrameStamp, RgbView, Runtime, load_rgb,
    onnxruntime_reference,
};
use rover_tests::photo;

const CASES: [(&str, &[&str]); 3] = [
    ("astronaut", &["person"]),
    ("person", &["person", "horse", "dog"]),
    ("dog", &["bicycle", "dog", "car"]),
];

#[test]
fn default_model_finds_the_expected_objects_like_onnxruntime() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let mut detector = Detector::load(DetectorConfig::default())?;
    let model = dir.path().join("model.onnx");
    detector.export_onnx(&model)?;
    let (w, h) = detector.input_size();
    for (name, expected) in CASES {
        let path = photo(name, dir.path())?;
        let (width, height, pixels) = load_rgb(&path)?;
        let view = RgbView::new(width, height, &pixels)?;
        let stamp = FrameStamp {
            sim_time_s: 1.5,
            frame: 7,
        };
        let ours = detector.detect(view, stamp)?;
        assert_eq!(ours.image_stamp, stamp, "results carry their image's stamp");
        for class in expected {
            assert!(
                ours.bounding_boxes.iter().any(|b| b.class == *class),
                "{name}: expected a {class}, got {:?}",
                ours.bounding_boxes
            );
        }
        // onnxruntime on exactly the graph, input tensor and decoder rover uses.
        let (input, letterbox) = detector.preprocess(view)?;
        let input = input.to_vec();
        let reference = onnxruntime_reference(&model, &input, &[1, 3, h, w], 1, 1)?;
        let theirs = detector.decode_raw(&reference.output, &reference.shape, letterbox, stamp)?;
        assert!(
            !theirs.bounding_boxes.is_empty(),
            "{name}: reference found nothing"
        );
        for r in &theirs.bounding_boxes {
            let best = ours
                .bounding_boxes
                .iter()
                .filter(|b| b.class == r.class)
                .map(|b| b.iou(r))
                .fold(0.0, f64::max);
            assert!(
                best >= 0.9,
                "{name}: onnxruntime's {r:?} has no tract box with IoU >= 0.9 (best {best})"
            );
        }
        eprintln!(
            "{name}: {:?}",
            ours.bounding_boxes
                .iter()
                .map(|b| (&b.class, b.probability))
                .collect::<Vec<_>>()
        );
    }
    Ok(())
}

/// Determinism does not depend on `--detect-threads`: tract's matrix products split over a pool
/// give the very same numbers as on one thread (each output tile is computed whole by one
/// thread), so traces and goldens hold for any thread count.
#[test]
fn several_detector_threads_give_bit_identical_outputs() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let mut one = Detector::load(DetectorConfig::default())?;
    let mut three = Detector::load(DetectorConfig {
        threads: 3,
        ..DetectorConfig::default()
    })?;
    for name in ["person", "dog"] {
        let (width, height, pixels) = load_rgb(&photo(name, dir.path())?)?;
        let view = RgbView::new(width, height, &pixels)?;
        one.preprocess(view)?;
        three.preprocess(view)?;
        let (a, shape_a) = one.infer_raw()?;
        let (b, shape_b) = three.infer_raw()?;
        assert_eq!(shape_a, shape_b);
        let differing = a
            .iter()
            .zip(&b)
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(
            differing,
            0,
            "{name}: {differing} of {} outputs differ",
            a.len()
        );
        let stamp = FrameStamp::default();
        assert_eq!(
            one.detect(view, stamp)?.bounding_boxes,
            three.detect(view, stamp)?.bounding_boxes
        );
    }
    Ok(())
}

/// `--runtime onnxruntime`: the same graph run by the libonnxruntime.so of a pip install finds
/// the same objects as tract (every tract box matched by an onnxruntime box of its class with
/// IoU >= 0.9, and the other way round). Skips where no onnxruntime library is installed.
#[test]
fn the_onnxruntime_runtime_gives_the_same_boxes_as_tract() -> Result<()> {
    if let Err(e) = rover_perception::find_onnxruntime_library() {
        return rover_tests::skip(e);
    }
    let dir = tempfile::tempdir()?;
    let mut tract = Detector::load(DetectorConfig::default())?;
    let mut ort = Detector::load(DetectorConfig {
        runtime: Runtime::OnnxRuntime,
        threads: 2,
        ..DetectorConfig::default()
    })?;
    for (name, expected) in CASES {
        let (width, height, pixels) = load_rgb(&photo(name, dir.path())?)?;
        let view = RgbView::new(width, height, &pixels)?;
        let stamp = FrameStamp::default();
        let a = tract.detect(view, stamp)?.bounding_boxes;
        let b = ort.detect(view, stamp)?.bounding_boxes;
        for class in expected {
            assert!(
                b.iter().any(|x| x.class == *class),
                "{name}: onnxruntime found no {class}: {b:?}"
            );
        }
        for (from, to, what) in [
            (&a, &b, "tract -> onnxruntime"),
            (&b, &a, "onnxruntime -> tract"),
        ] {
            for x in from {
                let best = to
                    .iter()
                    .filter(|y| y.class == x.class)
                    .map(|y| y.iou(x))
                    .fold(0.0, f64::max);
                assert!(
                    best >= 0.9,
                    "{name} ({what}): {x:?} unmatched (best IoU {best})"
                );
            }
        }
    }
    Ok(())
}

#[test]
fn the_worker_always_finishes_on_the_newest_frame() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let (width, height, pixels) = load_rgb(&photo("person", dir.path())?)?;
    let worker = DetectorWorker::spawn(Detector::load(DetectorConfig::default())?)?;
    let frames = 6u64;
    for frame in 0..frames {
        let mut buffer = worker.buffer();
        buffer.clear();
        buffer.extend_from_slice(&pixels);
        worker.submit(Frame {
            pixels: buffer,
            width,
            height,
            stamp: FrameStamp {
                sim_time_s: frame as f64 / 30.0,
                frame,
            },
        });
    }
    let mut last_seen = None;
    loop {
        let result = worker.wait()?;
        if let Some(prev) = last_seen {
            assert!(
                result.image_stamp.frame > prev,
                "results come in frame order"
            );
        }
        last_seen = Some(result.image_stamp.frame);
        assert!(result.bounding_boxes.iter().any(|b| b.class == "person"));
        if result.image_stamp.frame == frames - 1 {
            break;
        }
    }
    let stats = worker.stats();
    assert_eq!(stats.submitted, frames);
    assert_eq!(
        stats.processed + stats.dropped,
        frames,
        "every frame is either detected or dropped as stale: {stats:?}"
    );
    assert!(
        stats.dropped >= 1,
        "six frames submitted at once cannot all be detected: {stats:?}"
    );
    Ok(())
}

#[test]
fn bad_models_and_labels_are_clear_errors() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let junk = dir.path().join("junk.onnx");
    std::fs::write(&junk, b"definitely not protobuf")?;
    let err = load_error(DetectorConfig {
        model: Some(junk.clone()),
        ..DetectorConfig::default()
    });
    assert!(
        err.starts_with(&format!("{}: not a readable ONNX model", junk.display())),
        "{err}"
    );

    let missing = dir.path().join("missing.onnx");
    let err = load_error(DetectorConfig {
        model: Some(missing),
        ..DetectorConfig::default()
    });
    assert!(err.contains("no such model file"), "{err}");

    let labels = dir.path().join("three.names");
    std::fs::write(&labels, "cat\ndog\nbird\n")?;
    let err = load_error(DetectorConfig {
        labels: Some(labels),
        ..DetectorConfig::default()
    });
    assert!(
        err.contains("the model predicts 80 classes but 3 class names were found"),
        "{err}"
    );

    let err = load_error(DetectorConfig {
        input_size: Some((600, 480)),
        ..DetectorConfig::default()
    });
    assert!(err.contains("multiples of 32"), "{err}");

    let err = load_error(DetectorConfig {
        threads: 0,
        ..DetectorConfig::default()
    });
    assert!(err.contains("at least one thread"), "{err}");
    Ok(())
}

/// The error text of a detector that must not load.
fn load_error(config: DetectorConfig) -> String {
    Detector::load(config)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default()
}

#[test]
fn lockstep_detection_runs_at_its_sim_rate_and_repeats_exactly() -> Result<()> {
    use rover_perception::LockstepDetector;
    let dir = tempfile::tempdir()?;
    let (width, height, pixels) = load_rgb(&photo("person", dir.path())?)?;
    let view = RgbView::new(width, height, &pixels)?;
    let mut runs = Vec::new();
    for _ in 0..2 {
        let mut lockstep = LockstepDetector::new(Detector::load(DetectorConfig::default())?, 5.0)?;
        let mut results = Vec::new();
        // One second of 30 Hz camera frames.
        for frame in 0..30u64 {
            let stamp = FrameStamp {
                sim_time_s: frame as f64 / 30.0,
                frame,
            };
            if let Some(r) = lockstep.detect_if_due(view, stamp)? {
                results.push((r.image_stamp.frame, r.bounding_boxes));
            }
        }
        runs.push(results);
    }
    let frames: Vec<u64> = runs[0].iter().map(|(f, _)| *f).collect();
    assert_eq!(frames, vec![0, 6, 12, 18, 24], "5 Hz on sim time");
    assert_eq!(runs[0], runs[1], "same inputs, same boxes");
    assert!(LockstepDetector::new(Detector::load(DetectorConfig::default())?, 0.0).is_err());
    Ok(())
}

/// `--inject-fault`'s wrapper around the real detector: good detections first, then a panic
/// on the worker's thread becomes `Panicked`, one on the lockstep's (calling) thread is caught
/// the same way, and an error is returned as it is.
#[test]
fn an_injected_fault_fails_where_a_real_one_would() -> Result<()> {
    use rover_perception::{
        FaultInjector, FaultKind, InjectedFault, LockstepDetector, PerceptionError,
    };
    let dir = tempfile::tempdir()?;
    let (width, height, pixels) = load_rgb(&photo("person", dir.path())?)?;
    let faulty = |after_detections, kind| -> Result<FaultInjector> {
        let fault = InjectedFault {
            after_detections,
            kind,
        };
        Ok(FaultInjector::new(
            Detector::load(DetectorConfig::default())?,
            fault,
        ))
    };
    let frame = |n: u64| Frame {
        pixels: pixels.clone(),
        width,
        height,
        stamp: FrameStamp {
            sim_time_s: n as f64,
            frame: n,
        },
    };
    let worker = DetectorWorker::spawn(faulty(1, FaultKind::Panic)?)?;
    worker.submit_queued(frame(0));
    worker.submit_queued(frame(1));
    assert_eq!(worker.wait()?.image_stamp.frame, 0);
    match worker.wait() {
        Err(PerceptionError::Panicked(text)) => {
            assert!(text.contains("injected fault after 1 detections"), "{text}")
        }
        other => panic!("expected Panicked, got {other:?}"),
    }

    let view = RgbView::new(width, height, &pixels)?;
    let stamp = |n: u64| FrameStamp {
        sim_time_s: n as f64,
        frame: n,
    };
    let mut lockstep = LockstepDetector::new(faulty(0, FaultKind::Panic)?, 1.0)?;
    assert!(matches!(
        lockstep.detect_if_due(view, stamp(0)),
        Err(PerceptionError::Panicked(_))
    ));
    let mut lockstep = LockstepDetector::new(faulty(1, FaultKind::Error)?, 1.0)?;
    assert!(lockstep.detect_if_due(view, stamp(0))?.is_some());
    let err = lockstep
        .detect_if_due(view, stamp(1))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("injected fault after 1 detections (--inject-fault)"),
        "{err}"
    );
    Ok(())
}

/// `rover bench detect --profile`'s two halves on the real model: every tract node is timed and
/// attributed to an ONNX op type (convolutions dominate, as they do in onnxruntime's own
/// profile), and onnxruntime's profiler reports the same graph's op types.
#[test]
fn the_per_op_profile_attributes_tract_and_onnxruntime_time_to_onnx_ops() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let mut detector = Detector::load(DetectorConfig::default())?;
    let path = photo("person", dir.path())?;
    let (width, height, pixels) = load_rgb(&path)?;
    let view = RgbView::new(width, height, &pixels)?;
    detector.preprocess(view)?;
    let tract = detector.profile_ops(1)?;
    let total: f64 = tract.iter().map(|g| g.ms).sum();
    assert!(total > 0.0);
    let conv = tract
        .iter()
        .find(|g| g.onnx_op == "Conv")
        .ok_or_else(|| anyhow::anyhow!("no Conv group in {tract:?}"))?;
    assert_eq!(tract[0].onnx_op, "Conv", "slowest first: {tract:?}");
    assert!(
        conv.nodes > 100 && conv.ms > 0.5 * total,
        "{conv:?} of {total} ms"
    );
    // Nearly everything comes from an ONNX node (the graph's input is the exception).
    let unmatched = tract
        .iter()
        .filter(|g| g.onnx_op == "(no ONNX node)")
        .map(|g| g.ms)
        .sum::<f64>();
    assert!(
        unmatched < 0.05 * total,
        "{unmatched} of {total} ms unattributed"
    );

    let model = dir.path().join("model.onnx");
    detector.export_onnx(&model)?;
    let (w, h) = detector.input_size();
    let (input, _) = detector.preprocess(view)?;
    let input = input.to_vec();
    let run = rover_perception::onnxruntime_reference_profiled(&model, &input, &[1, 3, h, w], 1)?;
    let ort_conv = run
        .ops
        .iter()
        .find(|(op, _)| op == "Conv")
        .map(|(_, ms)| *ms)
        .ok_or_else(|| anyhow::anyhow!("onnxruntime's profile has no Conv: {:?}", run.ops))?;
    let ort_total: f64 = run.ops.iter().map(|(_, ms)| ms).sum();
    assert!(ort_conv > 0.5 * ort_total, "{:?}", run.ops);
    Ok(())
}
