//! The controllers file's named poses, with the real binary: `rover --headless` on the arm car
//! (worlds/arm_car.toml, assets/controllers/my_robot_arm.yaml) with a script of `pose = "..."`
//! steps, read back from the trace's joint columns. The pose values are read from the
//! controllers file itself, so the test follows the file. The station's `h` key sends the same
//! `pose = "home"` input; that the key gets there in a real window is
//! `h_in_the_real_window_brings_the_jogged_arm_home` in window.rs.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::Result;
use rover_core::{TraceRow, parse_trace, trace_joints};
use rover_sim::model::NamedPose;

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Every named pose of the arm car's controllers file, as rover reads it.
fn arm_car_poses() -> Result<Vec<NamedPose>> {
    let mut robot =
        rover_sim::model::RobotModel::load(&repo("assets/robots/my_robot_arm.urdf.xacro"))?;
    robot.load_controllers(&repo("assets/controllers/my_robot_arm.yaml"))?;
    let config = robot
        .controllers
        .ok_or_else(|| anyhow::anyhow!("the arm car's controllers file was not kept"))?;
    Ok(config.named_poses)
}

/// The joints and positions of the pose `name` of [`arm_car_poses`].
fn pose<'a>(poses: &'a [NamedPose], name: &str) -> Result<&'a [(String, f64)]> {
    poses
        .iter()
        .find(|p| p.name == name)
        .map(|p| p.joints.as_slice())
        .ok_or_else(|| anyhow::anyhow!("no pose \"{name}\" in the arm car's controllers file"))
}

/// What a headless run of the arm car left: rover's log, the trace's joint names and rows.
struct ArmRun {
    stderr: String,
    names: Vec<String>,
    rows: Vec<TraceRow>,
    _dir: tempfile::TempDir,
}

/// A headless run of the arm car with the script `steps` for `duration_s`.
fn run_arm_car(steps: &str, duration_s: &str) -> Result<ArmRun> {
    let dir = tempfile::tempdir()?;
    let script = dir.path().join("poses.toml");
    std::fs::write(&script, format!("steps = [\n{steps}\n]\n"))?;
    let trace = dir.path().join("trace.csv");
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .arg("--headless")
        .arg("--world")
        .arg(repo("worlds/arm_car.toml"))
        .args(["--duration", duration_s, "--no-detector", "--script"])
        .arg(&script)
        .arg("--trace")
        .arg(&trace)
        .current_dir(dir.path())
        .env("RUST_LOG", "warn")
        .output()?;
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "rover failed: {stderr}");
    let csv = std::fs::read_to_string(&trace)?;
    Ok(ArmRun {
        stderr,
        names: trace_joints(&csv),
        rows: parse_trace(&csv)?,
        _dir: dir,
    })
}

/// The trace's last row at or before sim time `t_s`.
fn row_at(rows: &[TraceRow], t_s: f64) -> Result<&TraceRow> {
    rows.iter()
        .rev()
        .find(|r| r.sim_time_s <= t_s + 1e-9)
        .ok_or_else(|| anyhow::anyhow!("no trace row by {t_s} s"))
}

/// The joint of `targets` furthest from its target in `row`, and how far (rad).
fn worst_error(
    names: &[String],
    row: &TraceRow,
    targets: &[(String, f64)],
) -> Result<(String, f64)> {
    let mut worst = (String::new(), 0.0f64);
    for (joint, target) in targets {
        let k = names
            .iter()
            .position(|n| n == joint)
            .ok_or_else(|| anyhow::anyhow!("no {joint} column in the trace: {names:?}"))?;
        let error = (row.joints[k].position - target).abs();
        if error >= worst.1 {
            worst = (joint.clone(), error);
        }
    }
    Ok(worst)
}

/// The largest difference between two poses over the joints of `a` (rad).
fn distance(a: &[(String, f64)], b: &[(String, f64)]) -> f64 {
    a.iter()
        .map(|(joint, qa)| {
            b.iter()
                .find(|(j, _)| j == joint)
                .map_or(f64::INFINITY, |(_, qb)| (qa - qb).abs())
        })
        .fold(0.0, f64::max)
}

/// A pose's joints and positions (rad).
type Pose = [(String, f64)];

/// Within this of a pose (rad): the effort PID controllers of my_robot_arm.yaml settle inside
/// it in 5 s.
const TOLERANCE_RAD: f64 = 0.05;

/// The arm car's arm, first commanded away from every named pose joint by joint, then sent to
/// `pose = "reach"`, `"look_down"` and `"home"` 5 s apart: 5 s after each step (just before
/// the next; the file's PID gains overshoot a 1.1 rad step by 0.06 rad at 3 s) the trace's joint positions are the controllers file's values for that pose,
/// every joint within 0.05 rad. Each pose is more than 0.2 rad away from where the arm was
/// before, so a pose that moved nothing fails.
#[test]
fn scripted_named_poses_move_the_arm_car_to_the_controllers_files_values() -> Result<()> {
    let poses = arm_car_poses()?;
    // Away from every named pose: all five joints off their home values.
    let away: Vec<(String, f64)> = [
        ("shoulder_pan_joint", 0.6),
        ("shoulder_lift_joint", -0.4),
        ("elbow_joint", -0.5),
        ("wrist_pitch_joint", -0.5),
        ("wrist_roll_joint", 1.0),
    ]
    .into_iter()
    .map(|(j, q)| (j.to_owned(), q))
    .collect();
    let mut steps: Vec<String> = away
        .iter()
        .map(|(j, q)| format!("  {{ at = 0.0, joint = \"{j}\", position = {q:?} }},"))
        .collect();
    steps.push("  { at = 5.0, pose = \"reach\" },".into());
    steps.push("  { at = 10.0, pose = \"look_down\" },".into());
    steps.push("  { at = 15.0, pose = \"home\" },".into());
    let run = run_arm_car(&steps.join("\n"), "20")?;
    let (stderr, names, rows) = (&run.stderr, &run.names, &run.rows);
    assert!(
        !stderr.contains("command dropped"),
        "a step was dropped: {stderr}"
    );
    // (what the arm should hold, checked at this sim time)
    let checks: [(&str, &Pose, f64); 4] = [
        ("away", away.as_slice(), 4.95),
        ("reach", pose(&poses, "reach")?, 9.95),
        ("look_down", pose(&poses, "look_down")?, 14.95),
        ("home", pose(&poses, "home")?, 19.95),
    ];
    let mut before: &Pose = pose(&poses, "home")?;
    for (name, targets, t_s) in checks {
        assert!(
            distance(targets, before) > 0.2,
            "\"{name}\" is too close to the pose before it to show that it moved the arm"
        );
        let row = row_at(rows, t_s)?;
        let (joint, error) = worst_error(names, row, targets)?;
        println!(
            "{name} at {:.2} s: worst {joint} off by {error:.4} rad",
            row.sim_time_s
        );
        assert!(
            error < TOLERANCE_RAD,
            "at {:.2} s the arm should be at \"{name}\" {targets:?}: {joint} is {error:.4} rad off; \
             joints {names:?} at {:?}; log:\n{stderr}",
            row.sim_time_s,
            row.joints.iter().map(|s| s.position).collect::<Vec<_>>()
        );
        before = targets;
    }
    Ok(())
}

/// A pose the controllers file does not name (`pose = "wave"`): the run goes on, the step is
/// dropped with one warning that names the pose and lists the file's poses, and the arm stays
/// where it was (home, where it starts).
#[test]
fn an_unknown_pose_is_one_warning_listing_the_known_poses() -> Result<()> {
    let poses = arm_car_poses()?;
    let run = run_arm_car("  { at = 0.5, pose = \"wave\" },", "1.5")?;
    let (stderr, names, rows) = (&run.stderr, &run.names, &run.rows);
    assert_eq!(
        stderr.matches("no named pose \"wave\"").count(),
        1,
        "one warning naming the pose: {stderr}"
    );
    let known: Vec<String> = poses.iter().map(|p| format!("\"{}\"", p.name)).collect();
    assert!(
        stderr.contains(&format!("known: {}", known.join(", "))),
        "the warning lists the known poses {known:?}: {stderr}"
    );
    assert!(stderr.contains("command dropped"), "{stderr}");
    let end = rows.last().ok_or_else(|| anyhow::anyhow!("empty trace"))?;
    let (joint, error) = worst_error(names, end, pose(&poses, "home")?)?;
    assert!(
        error < TOLERANCE_RAD,
        "the arm moved on an unknown pose: {joint} {error:.4} rad from home"
    );
    Ok(())
}

/// A world whose `[robot] pose` names a pose the controllers file lacks is refused as it
/// loads, naming the key, the pose and the poses the file has.
#[test]
fn a_world_start_pose_the_controllers_file_lacks_is_refused() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let world = std::fs::read_to_string(repo("worlds/arm_car.toml"))?
        .replace("\"../", &format!("\"{}/", repo("").display()))
        .replace("[robot]\n", "[robot]\npose = \"nope\"\n");
    let path = dir.path().join("arm_car_pose.toml");
    std::fs::write(&path, world)?;
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(["--headless", "--duration", "0.5", "--world"])
        .arg(&path)
        .env("ROVER_OFFLINE", "1")
        .output()?;
    let stderr = text(&out.stderr);
    anyhow::ensure!(
        !out.status.success()
            && stderr.contains("[robot] pose = \"nope\"")
            && stderr.contains("no named pose \"nope\"")
            && stderr.contains("\"home\""),
        "{stderr}"
    );
    Ok(())
}
