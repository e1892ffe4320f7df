//! Golden traces: scripted headless runs whose traces must be reproduced byte for byte: same
//! physics, same script timing, same detector schedule, same follower. The manual-driving trace
//! was recorded before the loop moved into rover-core (app/src, commit bc11d80); the follow trace
//! when the follower gained its states, estimator and laser.
//!
//! Regenerate (only when a change is meant to alter behaviour, and say so in the commit):
//! `ROVER_BLESS=1 cargo test --workspace --test golden`.

use std::path::Path;

use anyhow::Result;
use rover_core::{RunConfig, run_headless};
use rover_sim::{CameraSensor, SimOptions, Simulation};
use rover_tests::repo;

/// Runs `world` (with `robot`, or the world's own) with `script` for `duration_s` and compares
/// the trace with `golden`.
fn check(
    world: &str,
    robot: Option<&str>,
    script: &str,
    duration_s: f64,
    golden: &str,
    serial_detection: bool,
) -> Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    run_headless(&RunConfig {
        world: Some(repo(world)),
        robot: robot.map(repo),
        script: Some(repo(script)),
        duration_s: Some(duration_s),
        trace: Some(trace.clone()),
        serial_detection,
        ..RunConfig::default()
    })?;
    let got = std::fs::read_to_string(&trace)?;
    let golden_path = repo(golden);
    if std::env::var_os("ROVER_BLESS").is_some() {
        std::fs::write(&golden_path, &got)?;
        return Ok(());
    }
    let want = std::fs::read_to_string(&golden_path)?;
    if got != want {
        let line = got
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .map_or_else(|| "length".to_owned(), |i| format!("line {}", i + 1));
        let kept = Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(Path::new(golden).file_name().unwrap_or_default());
        let _ = std::fs::write(&kept, &got);
        anyhow::bail!(
            "trace differs from {golden} at {line} ({} vs {} rows); this run's trace: {}",
            got.lines().count(),
            want.lines().count(),
            kept.display()
        );
    }
    Ok(())
}

#[test]
fn manual_driving_reproduces_the_golden_trace() -> Result<()> {
    // The tutorial car as recorded at bc11d80 (the default world now carries the laser car):
    // columns 1-10 are those of the original recording; `follow_state` was added after.
    check(
        "worlds/playground.toml",
        Some("assets/robots/my_robot.urdf"),
        "tests/golden/drive.toml",
        9.0,
        "tests/golden/drive.csv",
        false,
    )
}

/// What the follow trace depends on beyond rover: the CPU features tract's kernels pick and
/// the renderer (llvmpipe's JIT). The golden trace was recorded on `follow.machine`.
fn machine() -> Result<String> {
    let sim = Simulation::new(
        rover_sim::World::load(&repo("worlds/walking.toml"))?,
        rover_sim::RobotModel::load(&repo("assets/robots/my_robot.urdf"))?,
        &SimOptions::default(),
    )?;
    let adapter = CameraSensor::new(&sim)?.renderer().adapter().to_owned();
    #[cfg(target_arch = "x86_64")]
    let features = ["avx512f", "avx512vnni", "avx2", "fma"]
        .into_iter()
        .filter(|f| match *f {
            "avx512f" => std::arch::is_x86_feature_detected!("avx512f"),
            "avx512vnni" => std::arch::is_x86_feature_detected!("avx512vnni"),
            "avx2" => std::arch::is_x86_feature_detected!("avx2"),
            _ => std::arch::is_x86_feature_detected!("fma"),
        })
        .collect::<Vec<_>>()
        .join(",");
    #[cfg(not(target_arch = "x86_64"))]
    let features = String::new();
    Ok(format!("{} [{features}] {adapter}", std::env::consts::ARCH))
}

// Re-recorded when the follower gained its states, estimator and laser (the walking world now
// carries the laser car), and when walking people got a gait (the same follow state on all
// 1,200 rows, the path within 9.6 cm).
#[test]
fn following_a_walking_person_reproduces_the_golden_trace() -> Result<()> {
    // Detection on the loop's thread (--serial-detect): unchanged by pipelined detection.
    follow_golden("tests/golden/follow.csv", true)
}

#[test]
fn following_with_pipelined_detection_reproduces_its_golden_trace() -> Result<()> {
    // The default: detection on a second thread, results one period (0.2 s) after their image.
    follow_golden("tests/golden/follow_pipelined.csv", false)
}

/// Determinism under load: the pipelined run (detector on its own thread, results at a fixed
/// sim-time delay) gives the same bytes while two busy threads load both cores, so the
/// detector thread is late on the wall clock and the loop has to wait for it.
#[test]
fn the_pipelined_golden_trace_holds_while_both_cores_are_busy() -> Result<()> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let load: Vec<_> = (0..2)
        .map(|_| {
            let stop = std::sync::Arc::clone(&stop);
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                    x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
                }
                x
            })
        })
        .collect();
    let result = follow_golden("tests/golden/follow_pipelined.csv", false);
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    for t in load {
        let _ = t.join();
    }
    result
}

/// The walking-person follow run against `golden`, on the machine the follow goldens were
/// recorded on (detector and renderer floating point differ across CPUs); elsewhere a note.
fn follow_golden(golden: &str, serial_detection: bool) -> Result<()> {
    let here = machine()?;
    let machine_file = repo("tests/golden/follow.machine");
    if std::env::var_os("ROVER_BLESS").is_some() {
        std::fs::write(&machine_file, format!("{here}\n"))?;
    } else {
        let recorded = std::fs::read_to_string(&machine_file).map_err(|e| {
            anyhow::anyhow!("{}: {e}; this machine is `{here}`", machine_file.display())
        })?;
        if recorded.trim() != here {
            eprintln!(
                "skipped: the golden follow traces were recorded on `{}`, this machine is \
                 `{here}` (detector and renderer floating point differ across CPUs); the manual \
                 golden trace and the determinism tests still run",
                recorded.trim()
            );
            return Ok(());
        }
    }
    check(
        "worlds/walking.toml",
        None,
        "tests/golden/follow.toml",
        12.0,
        golden,
        serial_detection,
    )
}
