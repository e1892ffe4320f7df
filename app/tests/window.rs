//! The real window under a virtual X display (xvfb-run), driven with xdotool: holding `i` drives
//! forward, releasing stops, `f` switches to follow mode — as the trace records it. The keys
//! come on the wall clock, so nothing here assumes how much sim time passes between them (a
//! slow machine runs the window below real time).

use std::path::Path;
use std::process::Command;

use anyhow::Result;
use rover_core::{TraceRow, parse_trace, trace_joints};

/// The window tests run one at a time: each renders on the CPU in real time.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// What a window run left: the trace's rows and joint names, the screenshot, rover's log.
struct WindowRun {
    rows: Vec<TraceRow>,
    joints: Vec<String>,
    shot: image::DynamicImage,
    log: String,
    _dir: tempfile::TempDir,
}

/// Runs rover's window on `world` for `duration_s` under xvfb-run; once the window shows,
/// `keys` (xdotool lines, `$wid` is the window) runs, then rover's end is awaited. The image
/// the window shows last is kept (and copied to `keep_shot`, when given).
fn run_window(
    world: &str,
    duration_s: u32,
    keys: &str,
    keep_shot: Option<&Path>,
) -> Result<WindowRun> {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner());
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let shot = dir.path().join("window.png");
    let script = dir.path().join("keys.sh");
    // Inside the virtual display: start rover, wait for its window, focus it, then keys.
    std::fs::write(
        &script,
        format!(
            r#"set -eu
"$ROVER" --world "$WORLD" --duration {duration_s} --trace "$TRACE" --screenshot "$SHOT" \
    --viewer none --no-detector 2> "$LOG" &
pid=$!
wid=$(timeout 120 xdotool search --sync --onlyvisible --name "driver's station" | head -n 1)
sleep 2
xdotool windowfocus --sync "$wid"
{keys}
wait "$pid"
"#
        ),
    )?;
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", "bash"])
        .arg(&script)
        .env("ROVER", env!("CARGO_BIN_EXE_rover"))
        .env("WORLD", repo.join(world))
        .env("TRACE", &trace)
        .env("SHOT", &shot)
        .env("LOG", dir.path().join("rover.log"))
        .output()
        .map_err(|e| {
            anyhow::anyhow!("cannot run xvfb-run ({e}): apt-get install xvfb xauth xdotool")
        })?;
    let log = std::fs::read_to_string(dir.path().join("rover.log")).unwrap_or_default();
    assert!(
        out.status.success(),
        "window run failed: {}\n{}\nrover log:\n{log}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&trace)?;
    if let Some(keep) = keep_shot {
        std::fs::copy(&shot, keep)?;
    }
    Ok(WindowRun {
        rows: parse_trace(&text)?,
        joints: trace_joints(&text),
        shot: image::open(&shot)?,
        log,
        _dir: dir,
    })
}

#[test]
fn keys_sent_to_the_real_window_drive_the_car_and_switch_mode() -> Result<()> {
    let run = run_window(
        "worlds/playground.toml",
        14,
        "xdotool keydown i\nsleep 2\nxdotool keyup i\nsleep 2\nxdotool key f",
        None,
    )?;
    let (rows, log) = (&run.rows, &run.log);
    assert_eq!(rows.len(), 1400, "14 s of 100 Hz control updates");
    // While `i` was held the car drove forward at teleop's 0.5 m/s...
    let driving: Vec<_> = rows.iter().filter(|r| r.cmd_linear_mps == 0.5).collect();
    let (first, last) = (
        driving
            .first()
            .ok_or_else(|| anyhow::anyhow!("never drove; log:\n{log}"))?,
        driving
            .last()
            .ok_or_else(|| anyhow::anyhow!("never drove"))?,
    );
    assert!(
        last.sim_time_s > first.sim_time_s && last.x_m > first.x_m,
        "drove forward while held: t {:.2} -> {:.2} s, x {:.3} -> {:.3} m",
        first.sim_time_s,
        last.sim_time_s,
        first.x_m,
        last.x_m
    );
    // ...and releasing it stopped the car.
    let after: Vec<_> = rows
        .iter()
        .filter(|r| r.sim_time_s > last.sim_time_s + 0.05)
        .collect();
    assert!(after.iter().all(|r| r.cmd_linear_mps == 0.0));
    let end = rows.last().ok_or_else(|| anyhow::anyhow!("empty trace"))?;
    assert!(end.x_m - last.x_m < 0.1, "rolled on after release");
    // `f` switched to follow mode.
    assert_eq!(rows[0].mode, "manual");
    assert_eq!(end.mode, "follow");
    // The window's image was written at exit.
    assert_eq!((run.shot.width(), run.shot.height()), (640, 614));
    if let Some(path) = std::env::var_os("ROVER_KEEP_SCREENSHOT") {
        run.shot.save(path)?;
    }
    // The HUD's last line reads the playground car's laser, IMU, GPS and bumper: text there.
    assert!(
        text_pixels(&run.shot.to_rgb8(), 480 + 110..614) > 300,
        "no sensor line under the HUD"
    );
    Ok(())
}

/// Pixels that are not the HUD's background in rows `rows` of `shot`.
fn text_pixels(shot: &image::RgbImage, rows: std::ops::Range<u32>) -> usize {
    let background = image::Rgb([24u8, 26, 30]);
    rows.flat_map(|y| (0..shot.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| *shot.get_pixel(x, y) != background)
        .count()
}

/// The example car with an arm (worlds/arm_car.toml): the teleop keys drive it, `2` picks the
/// shoulder lift, five presses of `]` jog it 0.5 rad, `h` brings it home — the trace records
/// all of it. The window's last image is docs/arm-car-window.png when ROVER_UPDATE_DOCS is set.
#[test]
fn the_arm_car_drives_with_keys_and_its_arm_jogs() -> Result<()> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let keep = std::env::var_os("ROVER_UPDATE_DOCS").map(|_| repo.join("docs/arm-car-window.png"));
    let run = run_window(
        "worlds/arm_car.toml",
        16,
        "xdotool keydown i\nsleep 2\nxdotool keyup i\nsleep 1\nxdotool key 2\nfor n in 1 2 3 4 5; do xdotool key bracketright; sleep 0.3; done\nsleep 4\nxdotool key 3\nxdotool key bracketright\nsleep 2",
        keep.as_deref(),
    )?;
    let (rows, log) = (&run.rows, &run.log);
    let end = rows.last().ok_or_else(|| anyhow::anyhow!("empty trace"))?;
    assert!(
        end.x_m > 0.3,
        "the car did not drive: x {:.3} m; log:\n{log}",
        end.x_m
    );
    let k = run
        .joints
        .iter()
        .position(|j| j == "shoulder_lift_joint")
        .ok_or_else(|| anyhow::anyhow!("no shoulder_lift_joint in {:?}", run.joints))?;
    let lift: Vec<f64> = rows.iter().map(|r| r.joints[k].position).collect();
    let highest = lift.iter().copied().fold(f64::MIN, f64::max);
    let held = end.joints[k].position;
    assert!(
        (held - 0.5).abs() < 0.03 && highest < 0.6,
        "five jogs of 0.1 rad should bring the lift to 0.5 rad: it ends at {held:.3}, highest {highest:.3}; log:\n{log}"
    );
    let elbow = run
        .joints
        .iter()
        .position(|j| j == "elbow_joint")
        .ok_or_else(|| anyhow::anyhow!("no elbow_joint"))?;
    let elbow_end = end.joints[elbow].position;
    assert!(
        (elbow_end - 0.1).abs() < 0.03,
        "3 then ] should move the elbow to 0.1 rad: {elbow_end:.3}"
    );
    assert_eq!((run.shot.width(), run.shot.height()), (640, 614));
    Ok(())
}

/// `h` in the real window, end to end: on the arm car, `2` and five `]` jog the shoulder lift
/// to 0.5 rad and `3` and three `]` the elbow to 0.3 rad; the trace shows the arm holding
/// there, then, after `h`, every joint back at the controllers file's "home" pose
/// (assets/controllers/my_robot_arm.yaml, read with rover's own loader) within 0.03 rad. A
/// script cannot press `h` (scripts take teleop keys only; `pose = "home"` is what it sends,
/// tested in named_poses.rs), so this is the test that the key itself moves the arm.
#[test]
fn h_in_the_real_window_brings_the_jogged_arm_home() -> Result<()> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut robot =
        rover_sim::model::RobotModel::load(&repo.join("assets/robots/my_robot_arm.urdf.xacro"))?;
    robot.load_controllers(&repo.join("assets/controllers/my_robot_arm.yaml"))?;
    let home = robot
        .controllers
        .as_ref()
        .and_then(|c| c.named_pose("home"))
        .map(|p| p.joints.clone())
        .ok_or_else(|| anyhow::anyhow!("no \"home\" pose in my_robot_arm.yaml"))?;
    let run = run_window(
        "worlds/arm_car.toml",
        14,
        "xdotool key 2\nfor n in 1 2 3 4 5; do xdotool key bracketright; sleep 0.3; done\nxdotool key 3\nfor n in 1 2 3; do xdotool key bracketright; sleep 0.3; done\nsleep 3\nxdotool key h",
        None,
    )?;
    let (rows, log) = (&run.rows, &run.log);
    let column = |name: &str| {
        run.joints
            .iter()
            .position(|j| j == name)
            .ok_or_else(|| anyhow::anyhow!("no {name} column in {:?}", run.joints))
    };
    let (lift, elbow) = (column("shoulder_lift_joint")?, column("elbow_joint")?);
    // The jog took the arm well away from home first...
    for (joint, jogged) in [("shoulder_lift_joint", 0.5), ("elbow_joint", 0.3)] {
        let q = home
            .iter()
            .find(|(j, _)| j == joint)
            .map_or(f64::NAN, |(_, q)| *q);
        assert!(
            (q - jogged).abs() > 0.2,
            "home's {joint} ({q}) is too close to the jogged {jogged} rad to show `h` moved it"
        );
    }
    let jogged = rows
        .iter()
        .rev()
        .find(|r| {
            (r.joints[lift].position - 0.5).abs() < 0.05
                && (r.joints[elbow].position - 0.3).abs() < 0.05
        })
        .ok_or_else(|| {
            let end = rows.last().map(|r| r.joints.clone()).unwrap_or_default();
            anyhow::anyhow!(
                "the arm never held the jogged pose (lift 0.5, elbow 0.3 rad); joints {:?} end at {end:?}; log:\n{log}",
                run.joints
            )
        })?;
    // ...and after `h` every joint of the pose is back there.
    let end = rows.last().ok_or_else(|| anyhow::anyhow!("empty trace"))?;
    for (joint, q) in &home {
        let k = column(joint)?;
        let at = end.joints[k].position;
        assert!(
            (at - q).abs() < 0.03,
            "after `h` {joint} should be at home's {q} rad: it ends at {at:.3} ({:.2} s; the jogged \
             pose last held at {:.2} s); log:\n{log}",
            end.sim_time_s,
            jogged.sim_time_s
        );
    }
    assert!(
        end.sim_time_s > jogged.sim_time_s + 1.0,
        "home was reached only {:.2} s after the jogged pose",
        end.sim_time_s - jogged.sim_time_s
    );
    Ok(())
}

/// A camera narrower than the HUD (worlds/arm_car_reach.toml's workspace camera: 320 x 240)
/// gets a window as wide as the HUD's lines (640 px), the image centred above: the HUD's
/// lines are whole (text beyond the image's right edge), not cut at 320 px.
#[test]
fn a_narrow_camera_gets_a_hud_whose_lines_fit() -> Result<()> {
    let run = run_window("worlds/arm_car_reach.toml", 3, "sleep 1", None)?;
    let shot = run.shot.to_rgb8();
    assert_eq!(
        (shot.width(), shot.height()),
        (640, 240 + 134),
        "{}",
        run.log
    );
    let background = image::Rgb([24u8, 26, 30]);
    // The HUD strip, right of where a 320 px canvas would have ended.
    let text_beyond = (240..374)
        .flat_map(|y| (330..630).map(move |x| (x, y)))
        .filter(|&(x, y)| *shot.get_pixel(x, y) != background)
        .count();
    assert!(
        text_beyond > 200,
        "no HUD text right of 330 px ({text_beyond} pixels): lines are cut; log:\n{}",
        run.log
    );
    // The arm car carries no sensor but its cameras: no sensor line.
    assert_eq!(
        text_pixels(&shot, 240 + 110..374),
        0,
        "a sensor line without sensors"
    );
    // The image is centred: background at the left margin, the render in the middle.
    assert_eq!(*shot.get_pixel(100, 120), background);
    assert_ne!(*shot.get_pixel(320, 120), background);
    Ok(())
}
