//! Headless scripted runs through the app library: traces, determinism, scripts with keys.

use anyhow::Result;
use rover_core::{RunConfig, headless};
use rover_core::{TRACE_HEADER, parse_trace};
use rover_sim::SimOptions;
use rover_tests::repo;

const SCRIPT: &str = r#"
steps = [
  { at = 0.0, cmd_vel = [0.5, 0.0] },
  { at = 1.0, key = "u" },
  { at = 2.0, key = "q" },
  { at = 2.5, key = "l" },
  { at = 3.0, key = "," },
  { at = 3.5, toggle = "follow" },
  { at = 4.5, key = "i" },
  { at = 5.0, key = "k" },
]
"#;

fn run_to(dir: &std::path::Path, name: &str, seed: u64) -> Result<String> {
    let script = dir.join("script.toml");
    std::fs::write(&script, SCRIPT)?;
    let trace = dir.join(name);
    let config = RunConfig {
        world: Some(repo("worlds/playground.toml")),
        script: Some(script),
        duration_s: Some(6.0),
        trace: Some(trace.clone()),
        options: SimOptions {
            seed,
            ..SimOptions::default()
        },
        ..RunConfig::default()
    };
    let summary = headless::run(&config)?;
    assert_eq!(summary.rows, 600, "100 Hz control for 6 s");
    Ok(std::fs::read_to_string(trace)?)
}

#[test]
fn same_inputs_give_a_byte_identical_trace() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let a = run_to(dir.path(), "a.csv", 7)?;
    let b = run_to(dir.path(), "b.csv", 7)?;
    assert!(a == b, "two identical runs produced different traces");
    assert!(a.starts_with(TRACE_HEADER));
    Ok(())
}

#[test]
fn script_keys_and_toggle_drive_the_robot() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let rows = parse_trace(&run_to(dir.path(), "t.csv", 0)?)?;
    let at = |t: f64| rows.iter().find(|r| r.sim_time_s >= t - 1e-9);
    let row = |t: f64| at(t).ok_or_else(|| anyhow::anyhow!("no row at {t}"));
    // cmd_vel step, then teleop keys with teleop_twist_keyboard's speeds.
    assert_eq!(row(0.5)?.cmd_linear_mps, 0.5);
    assert_eq!(
        (row(1.5)?.cmd_linear_mps, row(1.5)?.cmd_angular_radps),
        (0.5, 1.0)
    );
    let r = row(2.2)?;
    assert!(
        (r.cmd_linear_mps - 0.55).abs() < 1e-6 && (r.cmd_angular_radps - 1.1).abs() < 1e-6,
        "q scales both"
    );
    assert!(
        (row(2.7)?.cmd_angular_radps + 1.1).abs() < 1e-6,
        "l turns right in place"
    );
    assert!(
        (row(3.2)?.cmd_linear_mps + 0.55).abs() < 1e-6,
        ", drives back"
    );
    // Toggle to follow: the mode column changes and the follower takes over from the reverse
    // key (it never reverses faster than a third of its speed limit; tests/follow.rs checks
    // what it does).
    assert_eq!(row(3.2)?.mode, "manual");
    assert_eq!(row(4.0)?.mode, "follow");
    assert!(row(4.0)?.cmd_linear_mps > -0.2);
    // A manual key takes control back.
    assert_eq!(row(4.7)?.mode, "manual");
    assert!((row(4.7)?.cmd_linear_mps - 0.55).abs() < 1e-6);
    assert_eq!(row(5.5)?.cmd_linear_mps, 0.0);
    // The robot really moved: forward then around.
    assert!(row(1.0)?.x_m > 0.35, "moved forward in the first second");
    // Odometry (world source for my_robot) equals ground truth.
    assert!(
        rows.iter()
            .all(|r| r.odom_x_m == r.x_m && r.odom_yaw_rad == r.yaw_rad)
    );
    Ok(())
}
