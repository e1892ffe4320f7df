//! The real window under a virtual X display (xvfb-run), driven with xdotool: holding `i` drives
//! forward, releasing stops, `f` switches to follow mode — as the trace records it. The keys
//! come on the wall clock, so nothing here assumes how much sim time passes between them (a
//! slow machine runs the window below real time).

use std::path::Path;
use std::process::Command;

use anyhow::Result;
use rover_core::parse_trace;

#[test]
fn keys_sent_to_the_real_window_drive_the_car_and_switch_mode() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let shot = dir.path().join("window.png");
    let script = dir.path().join("keys.sh");
    // Inside the virtual display: start rover, wait for its window, focus it, then keys.
    std::fs::write(
        &script,
        r#"set -eu
"$ROVER" --world "$WORLD" --duration 14 --trace "$TRACE" --screenshot "$SHOT" \
    --viewer none --no-detector 2> "$LOG" &
pid=$!
wid=$(timeout 120 xdotool search --sync --onlyvisible --name "driver's station" | head -n 1)
sleep 2
xdotool windowfocus --sync "$wid"
xdotool keydown i
sleep 2
xdotool keyup i
sleep 2
xdotool key f
wait "$pid"
"#,
    )?;
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", "bash"])
        .arg(&script)
        .env("ROVER", env!("CARGO_BIN_EXE_rover"))
        .env("WORLD", repo.join("worlds/playground.toml"))
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
    let rows = parse_trace(&std::fs::read_to_string(&trace)?)?;
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
    let shot = image::open(&shot)?;
    assert_eq!((shot.width(), shot.height()), (640, 592));
    Ok(())
}
