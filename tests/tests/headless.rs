//! Headless scripted runs through the app library: traces, determinism, scripts with keys.

use anyhow::Result;
use rover_core::{RunConfig, run_headless, run_headless_observed};
use rover_core::{TRACE_HEADER, parse_trace};
use rover_sim::physics::SimOptions;
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
    let summary = run_headless(&config)?;
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

/// Records when each detection reached the session (the last control update's sim time) and
/// which image it came from.
#[derive(Default)]
struct Deliveries {
    now_s: f64,
    seen: Vec<(f64, f64)>,
}

impl rover_core::Observer for Deliveries {
    fn control(
        &mut self,
        _sim: &rover_sim::physics::Simulation,
        sample: &rover_sim::physics::ControlSample,
        _stats: &rover_core::LoopStats,
    ) {
        self.now_s = sample.sim_time_s;
    }
    fn detections(&mut self, boxes: &rover_perception::BoundingBoxes, _labels: &[String]) {
        self.seen.push((self.now_s, boxes.image_stamp.sim_time_s));
    }
}

fn deliveries(serial_detection: bool) -> Result<Vec<(f64, f64)>> {
    let mut seen = Deliveries::default();
    run_headless_observed(
        &RunConfig {
            world: Some(repo("worlds/playground.toml")),
            duration_s: Some(3.0),
            perception: rover_core::Perception::On,
            serial_detection,
            ..RunConfig::default()
        },
        &mut seen,
        true,
    )?;
    Ok(seen.seen)
}

#[test]
fn pipelined_detections_arrive_one_period_after_their_image_and_serial_ones_at_once() -> Result<()>
{
    let period_s = 1.0 / rover_core::DEFAULT_DETECT_HZ;
    // Control updates come every 10 ms: a delivery is seen within one of them.
    let control_s = 0.0101;
    let pipelined = deliveries(false)?;
    let serial = deliveries(true)?;
    assert_eq!(
        pipelined.len(),
        14,
        "images at 0.0..2.6 s delivered by 3 s: {pipelined:?}"
    );
    assert_eq!(serial.len(), 15, "images at 0.0..2.8 s: {serial:?}");
    for (i, (at, image)) in pipelined.iter().enumerate() {
        assert!(
            (image - i as f64 * period_s).abs() < 1e-6,
            "image {i} at {image} s"
        );
        let delay = at - image;
        assert!(
            delay > period_s - control_s && delay <= period_s + 1e-9,
            "pipelined image of {image} s delivered at {at} s"
        );
    }
    for (at, image) in &serial {
        assert!(
            at - image > -control_s && at - image <= 1e-9,
            "serial image of {image} s delivered at {at} s"
        );
    }
    // Nothing moves here (manual mode, no command): the same images give the same boxes.
    Ok(())
}
