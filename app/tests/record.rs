//! `--record`: a headless run of the default world writes an .rrd that Rerun's own decoder reads
//! back with the documented entity paths, data on `sim_time`, and row counts that match the run.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use anyhow::Result;
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

#[derive(Debug, Default)]
struct Entity {
    components: BTreeSet<String>,
    /// Rows on the `sim_time` timeline.
    timed_rows: usize,
    static_rows: usize,
}

fn read_rrd(path: &std::path::Path) -> Result<BTreeMap<String, Entity>> {
    let reader = std::io::BufReader::new(std::fs::File::open(path)?);
    let mut out: BTreeMap<String, Entity> = BTreeMap::new();
    for msg in DecoderApp::decode_eager(reader)? {
        if let LogMsg::ArrowMsg(store, arrow) = msg? {
            if !store.is_recording() {
                continue;
            }
            let chunk = Chunk::from_arrow_msg(&arrow)?;
            let e = out.entry(chunk.entity_path().to_string()).or_default();
            e.components.extend(
                chunk
                    .component_descriptors()
                    .map(|d| d.component.as_str().to_owned()),
            );
            if chunk.is_static() {
                e.static_rows += chunk.num_rows();
            } else if chunk.timelines().keys().any(|t| t.as_str() == "sim_time") {
                assert!(
                    chunk.timelines().keys().any(|t| t.as_str() == "frame"),
                    "{} has sim_time but no frame timeline",
                    chunk.entity_path()
                );
                e.timed_rows += chunk.num_rows();
            }
        }
    }
    Ok(out)
}

/// The recorded entity at `path`, or an error listing the entities there are.
fn entity<'a>(entities: &'a BTreeMap<String, Entity>, path: &str) -> Result<&'a Entity> {
    entities.get(path).ok_or_else(|| {
        let names: Vec<_> = entities.keys().collect();
        anyhow::anyhow!("{path} missing; entities: {names:?}")
    })
}

/// Runs `rover --headless --record` with `args` and a script of `steps`; returns the
/// recording's entities and the folder (which holds `run.rrd` and `trace.csv`).
fn record(args: &[&str], steps: &str) -> Result<(BTreeMap<String, Entity>, tempfile::TempDir)> {
    let dir = tempfile::tempdir()?;
    let rrd = dir.path().join("run.rrd");
    let script = dir.path().join("script.toml");
    std::fs::write(&script, format!("steps = [ {steps} ]\n"))?;
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .arg("--headless")
        .args(args)
        .arg("--record")
        .arg(&rrd)
        .arg("--trace")
        .arg(dir.path().join("trace.csv"))
        .arg("--script")
        .arg(&script)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()?;
    assert!(
        out.status.success(),
        "rover failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Ok((read_rrd(&rrd)?, dir))
}

#[test]
fn a_recorded_headless_run_reads_back_with_every_entity() -> Result<()> {
    let (entities, dir) = record(
        &["--duration", "2"],
        "{ at = 0.0, cmd_vel = [0.3, 0.2] }, { at = 1.0, toggle = \"follow\" }",
    )?;
    let trace = dir.path().join("trace.csv");
    println!("{:#?}", entities.keys().collect::<Vec<_>>());
    let get = |path: &str| entity(&entities, path);
    // Static scene.
    assert!(
        get("/world")?
            .components
            .iter()
            .any(|c| c.contains("ViewCoordinates"))
    );
    assert!(get("/world/people/alice/body")?.static_rows > 0);
    assert!(get("/world/objects/crate")?.static_rows > 0);
    assert!(get("/world/robot/base_link/visual_0")?.static_rows > 0);
    assert!(get("/world/robot/camera")?.static_rows > 0);
    let image = get("/world/robot/camera/image")?;
    assert!(
        image.components.iter().any(|c| c.starts_with("Pinhole:")),
        "{:?}",
        image.components
    );
    assert!(
        image
            .components
            .iter()
            .any(|c| c.starts_with("AnnotationContext:"))
    );
    // Per control update (100 Hz for 2 s): base pose, wheels, plots; rows match the trace.
    let control_rows = std::fs::read_to_string(&trace)?.lines().count() - 1;
    assert_eq!(control_rows, 200);
    assert_eq!(get("/world/robot")?.timed_rows, control_rows);
    assert_eq!(get("/world/robot/left_wheel")?.timed_rows, control_rows);
    assert_eq!(get("/plots/velocity/linear")?.timed_rows, control_rows);
    assert_eq!(get("/plots/mode")?.timed_rows, control_rows);
    assert_eq!(get("/world/odometry")?.timed_rows, control_rows);
    assert!(get("/world/odometry/trail")?.timed_rows >= 4);
    // Camera at 30 Hz: 60 images on sim_time; detections at 5 Hz on sim time, pipelined: the
    // images of 0.0-1.6 s are delivered by 1.8 s (the one of 1.8 s would arrive at 2.0 s, the end).
    assert!(image.components.iter().any(|c| c.starts_with("Image:")));
    assert_eq!(image.timed_rows, 60);
    let boxes = get("/world/robot/camera/image/detections")?;
    assert_eq!(boxes.timed_rows, 9);
    assert!(boxes.components.iter().any(|c| c.starts_with("Boxes2D:")));
    // The laser car's scans at 10 Hz after each physics step: at 0.005 s, then 0.1, 0.2, ...,
    // 2.0 s (21), as points in the laser's frame; the follower's state for the second in
    // follow mode.
    let scan = get("/world/robot/base_scan/scan")?;
    assert_eq!(scan.timed_rows, 21, "{:?}", scan.components);
    assert!(scan.components.iter().any(|c| c.starts_with("Points3D:")));
    assert_eq!(get("/plots/follower/state")?.timed_rows, 100);
    // The mode toggle is in the log.
    assert!(get("/log")?.timed_rows >= 1);
    Ok(())
}

/// The arm car (worlds/arm_car.toml): every arm link moves in 3D and every actuated joint's
/// position and target are plotted, once per control update.
#[test]
fn a_recorded_arm_moves_its_links_and_plots_its_joints() -> Result<()> {
    let (entities, _dir) = record(
        &[
            "--world",
            "worlds/arm_car.toml",
            "--duration",
            "2",
            "--no-detector",
        ],
        "{ at = 0.2, pose = \"reach\" }",
    )?;
    let timed = |path: &str| entity(&entities, path).map(|e| e.timed_rows);
    // 2 s of 100 Hz control updates.
    for joint in [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_pitch_joint",
        "wrist_roll_joint",
    ] {
        assert_eq!(timed(&format!("/plots/joints/{joint}"))?, 200, "{joint}");
    }
    assert_eq!(timed("/world/robot/upper_arm_link")?, 200);
    assert_eq!(timed("/world/robot/hand_link")?, 200);
    Ok(())
}

/// `--ground-truth`: every detection result is shown beside the ground truth of its own image
/// (the labelled person's visible box, "MISSED" when nothing found it), the false positives
/// apart, and the running per-class precision, recall and IoU plotted.
#[test]
fn a_recorded_run_with_ground_truth_shows_truth_beside_detections() -> Result<()> {
    let (entities, _dir) = record(
        &["--duration", "2", "--ground-truth"],
        "{ at = 0.0, toggle = \"follow\" }",
    )?;
    let get = |path: &str| entity(&entities, path);
    let detections = get("/world/robot/camera/image/detections")?.timed_rows;
    assert!(detections >= 9, "{detections} detection results");
    let truth = get("/world/robot/camera/image/ground_truth")?;
    assert_eq!(truth.timed_rows, detections, "one ground truth per result");
    assert!(truth.components.iter().any(|c| c.starts_with("Boxes2D:")));
    assert_eq!(
        get("/world/robot/camera/image/false_positives")?.timed_rows,
        detections
    );
    for what in ["precision", "recall", "iou"] {
        let plot = get(&format!("/plots/detector/person/{what}"))?;
        assert_eq!(plot.timed_rows, detections, "{what}");
    }
    Ok(())
}

/// A depth camera (TIAGo's xtion, `<sensor type="depth">`): each logged image has its depth
/// image beside it under the camera's pinhole, as a Rerun `DepthImage` in metres.
#[test]
fn a_recorded_depth_camera_logs_its_depth_image_with_each_image() -> Result<()> {
    let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
        return Ok(());
    };
    let urdf = urdf.to_string_lossy();
    let (entities, _dir) = record(
        &[
            "--robot",
            urdf.as_ref(),
            "--drive",
            "wheel_left_joint,wheel_right_joint",
            "--duration",
            "1",
        ],
        "",
    )?;
    let get = |path: &str| entity(&entities, path);
    let image = get("/world/robot/camera/image")?;
    let depth = get("/world/robot/camera/image/depth")?;
    println!(
        "images {}, depth images {}: {:?}",
        image.timed_rows, depth.timed_rows, depth.components
    );
    assert!(depth.timed_rows > 10, "{} depth images", depth.timed_rows);
    assert!(
        depth.components.iter().any(|c| c.contains("DepthImage")),
        "{:?}",
        depth.components
    );
    assert!(
        depth.components.iter().any(|c| c.contains("meter")),
        "{:?}",
        depth.components
    );
    Ok(())
}

/// A recording no live viewer watches re-poses a walking MakeHuman body once a sim second
/// (10 Hz made it 95 % of the file): 3 poses in 3 s, beside the person's 300 control updates.
#[test]
fn a_file_recording_reposes_a_walking_body_once_a_second() -> Result<()> {
    let (entities, _dir) = record(
        &["--world", "worlds/walking.toml", "--duration", "3"],
        "{ at = 0.0, toggle = \"follow\" }",
    )?;
    let people: Vec<&String> = (entities.keys())
        .filter(|k| k.starts_with("/world/people/") && k.ends_with("/body"))
        .collect();
    println!("{people:?}");
    let body = people
        .first()
        .ok_or_else(|| anyhow::anyhow!("no walking body recorded"))?;
    let rows = entity(&entities, body)?.timed_rows;
    assert!((3..=4).contains(&rows), "{body}: {rows} poses in 3 s");
    Ok(())
}
