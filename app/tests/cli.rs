//! The real `rover` binary, as users run it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use anyhow::Result;

fn repo(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn rover(args: &[&str], cwd: &Path) -> Result<Output> {
    Ok(Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(args)
        .current_dir(cwd)
        .env("RUST_LOG", "warn")
        .output()?)
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `rover ARGS` in `cwd` exits 1, its stderr saying `expected`.
fn assert_refused(args: &[&str], cwd: &Path, expected: &str) -> Result<()> {
    let out = rover(args, cwd)?;
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(expected), "{stderr}");
    Ok(())
}

/// `rover ... | head`: a reader that stops reading is no reason to panic. The run finishes
/// (its trace is written) and exits 0; it used to die with "failed printing to stdout".
#[test]
fn a_reader_that_stops_reading_stdout_does_not_make_rover_panic() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let mut child = Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(["--headless", "--duration", "0.5", "--trace"])
        .arg(&trace)
        .current_dir(dir.path())
        .env("RUST_LOG", "warn")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()?;
    // Close the reading end at once: every line rover prints meets a broken pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output()?;
    let stderr = text(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(std::fs::read_to_string(&trace)?.lines().count() > 10);
    Ok(())
}

#[test]
fn plain_headless_run_uses_the_default_world_and_robot_from_anywhere() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let out = rover(&["--headless", "--duration", "1"], dir.path())?;
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", text(&out.stderr));
    assert!(
        stdout.contains("world \"playground\", robot \"my_robot\""),
        "{stdout}"
    );
    assert!(stdout.contains("1.00 s sim time"), "{stdout}");
    Ok(())
}

#[test]
fn scripted_run_writes_the_trace() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let script = dir.path().join("drive.toml");
    std::fs::write(
        &script,
        "steps = [ { at = 0.0, cmd_vel = [0.5, 0.0] }, { at = 1.0, key = \"k\" } ]\n",
    )?;
    let trace = dir.path().join("out.csv");
    let args = [
        "--headless",
        "--world",
        &repo("worlds/playground.toml").display().to_string(),
        "--robot",
        &repo("assets/robots/my_robot.urdf").display().to_string(),
        "--script",
        &script.display().to_string(),
        "--trace",
        &trace.display().to_string(),
        "--seed",
        "3",
    ]
    .map(String::from);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = rover(&args, dir.path())?;
    assert!(out.status.success(), "{}", text(&out.stderr));
    // Duration defaults to the last step + 1 s: 2 s at 100 Hz control.
    let csv = std::fs::read_to_string(&trace)?;
    let rows = rover_core::parse_trace(&csv)?;
    assert_eq!(rows.len(), 200);
    let moved = rows.last().map(|r| r.x_m).unwrap_or_default();
    assert!(moved > 0.3, "the car drove forward, x = {moved}");
    assert!(text(&out.stdout).contains("(200 rows)"));
    Ok(())
}

#[test]
fn bad_input_exits_with_a_located_error() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let world = dir.path().join("w.toml");
    std::fs::write(
        &world,
        "[[box]]\nsize_m = [1.0, 1.0, 1.0]\nposition_m = [1.0, 0.0]\nmas_kg = 3.0\n",
    )?;
    let out = rover(
        &["--headless", "--world", &world.display().to_string()],
        dir.path(),
    )?;
    assert_eq!(out.status.code(), Some(1));
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("w.toml:4: at `box[0].mas_kg`: unknown field `mas_kg`"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");

    assert_refused(
        &["--headless", "--place", "0.5,0.2,inf"],
        dir.path(),
        "--place 0.5,0.2,inf: a point must be three finite numbers",
    )?;
    assert_refused(
        &["--headless", "--fetch", "0.27"],
        dir.path(),
        "--fetch 0.27: expected X,Y",
    )?;

    let out = rover(&["--headless", "--script", "missing.toml"], dir.path())?;
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("cannot read missing.toml"),
        "{}",
        text(&out.stderr)
    );
    Ok(())
}

#[test]
fn headless_rtf_paces_the_run_to_the_wall_clock() -> Result<()> {
    // Pacing can only slow a run down, so this holds on any machine: 2 sim seconds at 1x take
    // at least 2 wall seconds (unpaced, this run takes a small fraction of that).
    let out = rover(&["--headless", "--duration", "2", "--rtf", "1"], &repo(""))?;
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", text(&out.stderr));
    let wall_s = stdout
        .split(" s wall")
        .next()
        .and_then(|head| head.rsplit(' ').next())
        .and_then(|v| v.parse::<f64>().ok())
        .ok_or_else(|| anyhow::anyhow!("no wall time in {stdout}"))?;
    assert!(wall_s >= 1.99, "2 s of sim time at 1x took {wall_s} s");
    let out = rover(&["--headless", "--rtf", "0"], &repo(""))?;
    assert!(!out.status.success());
    assert!(text(&out.stderr).contains("--rtf must be a positive factor"));
    Ok(())
}

#[test]
fn help_explains_the_interface() -> Result<()> {
    let out = rover(&["--help"], &repo(""))?;
    let help = text(&out.stdout);
    for needle in [
        "--headless",
        "--world",
        "--robot",
        "--script",
        "--duration",
        "--trace",
        "--seed",
        "cmd_vel",
        "sim_time_s,x_m",
        "bench",
    ] {
        assert!(help.contains(needle), "--help lacks {needle}:\n{help}");
    }
    Ok(())
}

#[test]
fn bench_prints_a_real_time_factor() -> Result<()> {
    let out = rover(
        &["bench", "--sim-seconds", "0.5", "--repeats", "1"],
        &repo(""),
    )?;
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(stdout.contains("real-time x"), "{stdout}");
    let figure = stdout
        .lines()
        .last()
        .and_then(|l| l.split_whitespace().last())
        .and_then(|v| v.parse::<f64>().ok());
    assert!(figure.is_some_and(|rtf| rtf > 0.0), "{stdout}");
    Ok(())
}

/// `bench physics --hold`: the arm car drives its figure eight with the ball in its hand and
/// says it is still there; an object the world lacks is refused by name.
#[test]
fn bench_physics_holds_the_ball_in_the_arm_cars_hand() -> Result<()> {
    let args = [
        "bench",
        "physics",
        "--world",
        "worlds/arm_car_pick.toml",
        "--spawn=-3,-3",
        "--sim-seconds",
        "2",
        "--repeats",
        "1",
        "--hold",
    ];
    let out = rover(&[&args[..], &["ball"]].concat(), &repo(""))?;
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", text(&out.stderr));
    let held = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("ball: "))
        .ok_or_else(|| anyhow::anyhow!("no line on the ball in {stdout}"))?;
    assert!(held.starts_with("still in the hand"), "{stdout}");
    assert_refused(
        &[&args[..], &["teapot"]].concat(),
        &repo(""),
        "--hold teapot: the world has no object or model \"teapot\"",
    )
}

/// `bench physics --hold` on a model's link and a turning gripper: Stretch (PyPI
/// hello-robot-stretch-urdf) drives its figure eight with osrf's Coke can in its hand, the
/// grasp assist holding it (its world sets `grasp = "assist"`), and says it is still there.
/// The bench waits for the lift to reach its start pose and holds the can at the tool until
/// the fingers stop on it and the assist takes it.
#[test]
fn bench_physics_holds_the_can_in_stretchs_hand() -> Result<()> {
    let Some(models) = rover_tests::shared("corpus/gazebo_models") else {
        return Ok(());
    };
    let Some(wheel) = rover_tests::pypi("hello-robot-stretch-urdf", "0.1.2") else {
        return Ok(());
    };
    let (models, package) = (
        models.display().to_string(),
        format!("stretch_urdf={}", wheel.join("stretch_urdf").display()),
    );
    let args = [
        "bench",
        "physics",
        "--world",
        "tests/worlds/stretch_pick.toml",
        "--model-path",
        &models,
        "--package-path",
        &package,
        "--sim-seconds",
        "3",
        "--repeats",
        "1",
        "--hold",
        "can",
    ];
    let out = rover(&args, &repo(""))?;
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", text(&out.stderr));
    let held = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("can: "))
        .ok_or_else(|| anyhow::anyhow!("no line on the can in {stdout}"))?;
    assert!(held.starts_with("still in the hand"), "{stdout}");
    Ok(())
}

#[test]
fn detect_prints_boxes_json_and_draws_them() -> Result<()> {
    let photo = Path::new("/usr/share/darknet/data/person.jpg");
    anyhow::ensure!(
        photo.is_file(),
        "apt-get install darknet (its sample photos)"
    );
    let dir = tempfile::tempdir()?;
    let out_png = dir.path().join("boxes.png");
    let photo_arg = photo.display().to_string();
    let out_arg = out_png.display().to_string();
    let out = rover(&["detect", &photo_arg, "--out", &out_arg], dir.path())?;
    let stdout = text(&out.stdout);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let person = stdout
        .lines()
        .find(|l| l.starts_with("person "))
        .ok_or_else(|| anyhow::anyhow!("no person line in {stdout}"))?;
    let fields: Vec<&str> = person.split_whitespace().collect();
    assert_eq!(
        fields.len(),
        6,
        "class probability xmin ymin xmax ymax: {person}"
    );
    assert!(fields[1].parse::<f64>()? > 0.5);
    let drawn = image::open(&out_png)?.into_rgb8();
    let original = image::open(photo)?.into_rgb8();
    assert_eq!(drawn.dimensions(), original.dimensions());
    assert_ne!(drawn.as_raw(), original.as_raw(), "boxes were drawn");

    let out = rover(
        &["detect", &photo_arg, "--json", "--threshold", "0.5"],
        dir.path(),
    )?;
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_str(text(&out.stdout).trim())?;
    let boxes = json["bounding_boxes"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    assert!(boxes.iter().any(|b| b["Class"] == "horse"), "{json}");
    assert!(
        boxes
            .iter()
            .all(|b| b["probability"].as_f64().unwrap_or(0.0) >= 0.5)
    );
    assert_eq!(json["image_stamp"]["frame"], 0);

    let out = rover(&["detect", "missing.jpg"], dir.path())?;
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("missing.jpg"),
        "{}",
        text(&out.stderr)
    );
    Ok(())
}

/// `--runtime onnxruntime` where its library is not where ORT_DYLIB_PATH says: one clear error
/// naming the variable and the file, nothing loaded.
#[test]
fn a_missing_onnxruntime_library_is_a_clear_error() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let missing = dir.path().join("libonnxruntime.so.1.99.0");
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .args([
            "detect",
            "/usr/share/darknet/data/person.jpg",
            "--runtime",
            "onnxruntime",
        ])
        .env("ORT_DYLIB_PATH", &missing)
        .env("RUST_LOG", "warn")
        .current_dir(dir.path())
        .output()?;
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("ORT_DYLIB_PATH")
            && stderr.contains("libonnxruntime.so.1.99.0")
            && stderr.contains("not a file"),
        "{stderr}"
    );

    // Nowhere to be found: the error says what to install and lists the folders searched.
    let model = rover_perception::ensure_default_model()?;
    let home = dir.path().join("home");
    std::fs::create_dir_all(home.join(".local/lib/python3.11/site-packages"))?;
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .arg("detect")
        .arg("/usr/share/darknet/data/person.jpg")
        .arg("--model")
        .arg(&model)
        .args(["--runtime", "onnxruntime"])
        .env_remove("ORT_DYLIB_PATH")
        .env_remove("VIRTUAL_ENV")
        .env_remove("ROVER_CACHE_DIR")
        .env("HOME", &home)
        .env("XDG_CACHE_HOME", home.join(".cache"))
        .env("RUST_LOG", "warn")
        .current_dir(dir.path())
        .output()?;
    let stderr = text(&out.stderr);
    if out.status.success() {
        return rover_tests::skip(
            "the not-found case: this machine's system Python has onnxruntime",
        );
    }
    assert!(
        stderr.contains("pip install onnxruntime")
            && stderr.contains("Searched:")
            && stderr.contains(".local/lib/python3.11/site-packages/onnxruntime/capi"),
        "{stderr}"
    );
    Ok(())
}

#[test]
fn save_frames_writes_the_camera_images() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let frames = dir.path().join("frames");
    let frames_arg = frames.display().to_string();
    // 0.5 s at 30 Hz = 15 images; every 5th is written: 0, 5, 10.
    let out = rover(
        &[
            "--headless",
            "--duration",
            "0.5",
            "--save-frames",
            &frames_arg,
            "--frame-every",
            "5",
        ],
        dir.path(),
    )?;
    assert!(out.status.success(), "{}", text(&out.stderr));
    let mut names: Vec<String> = std::fs::read_dir(&frames)?
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["frame_000000.png", "frame_000005.png", "frame_000010.png"]
    );
    let image = image::open(frames.join("frame_000000.png"))?.into_rgb8();
    assert_eq!(image.dimensions(), (640, 480));
    // Sky above, ground below: the image is not blank.
    let sky = image.get_pixel(320, 10);
    let ground = image.get_pixel(320, 470);
    assert!(
        sky[2] > sky[0] && sky != ground,
        "sky {sky:?} ground {ground:?}"
    );
    Ok(())
}

#[test]
fn a_missing_model_warns_and_manual_driving_still_works() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let script = dir.path().join("s.toml");
    std::fs::write(
        &script,
        "steps = [ { at = 0.0, toggle = \"follow\" }, { at = 0.5, cmd_vel = [0.5, 0.0] } ]\n",
    )?;
    let trace = dir.path().join("t.csv");
    let out = rover(
        &[
            "--headless",
            "--duration",
            "1.5",
            "--model",
            "/nonexistent/model.onnx",
            "--script",
            &script.display().to_string(),
            "--trace",
            &trace.display().to_string(),
        ],
        dir.path(),
    )?;
    let stderr = text(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("no detector"), "{stderr}");
    assert!(stderr.contains("/nonexistent/model.onnx"), "{stderr}");
    let rows = rover_core::parse_trace(&std::fs::read_to_string(&trace)?)?;
    // Follow mode without a detector holds still; the manual command then drives.
    assert!(
        rows.iter()
            .take(50)
            .all(|r| r.cmd_linear_mps == 0.0 && r.mode == "follow")
    );
    let last = rows.last().ok_or_else(|| anyhow::anyhow!("empty trace"))?;
    assert_eq!((last.mode.as_str(), last.cmd_linear_mps), ("manual", 0.5));
    assert!(last.x_m > 0.3);
    Ok(())
}

#[test]
fn no_display_is_said_plainly() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(["--duration", "1"])
        .current_dir(dir.path())
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()?;
    let stderr = text(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("no display"), "{stderr}");
    assert!(stderr.contains("--headless"), "{stderr}");
    Ok(())
}
