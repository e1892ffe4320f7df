//! Golden traces: scripted headless runs whose traces must be reproduced byte for byte: same
//! physics, same script timing, same detector schedule, same follower. The manual-driving trace
//! was recorded before the loop moved into rover-core (app/src, commit bc11d80); the follow trace
//! when the follower gained its states, estimator and laser.
//!
//! The follow traces depend on the CPU (the detector's kernels) and the renderer: on the
//! machine they were recorded on (`tests/golden/follow.machine`) they are compared byte for
//! byte, elsewhere within stated tolerances (`rover_tests::golden`). `ROVER_GOLDEN_MACHINE=x`
//! pretends to be machine `x`, to run the tolerance comparison on the recording machine.
//!
//! Regenerate (only when a change is meant to alter behaviour, and say so in the commit):
//! `ROVER_BLESS=1 cargo test --workspace --test golden`.

use std::path::Path;

use anyhow::Result;
use rover_core::{RunConfig, run_headless};
use rover_sim::{
    physics::{SimOptions, Simulation},
    sensors::CameraSensor,
};
use rover_tests::golden::{self, Tolerance};
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
    let got = run_trace(world, robot, script, duration_s, serial_detection)?;
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
        let kept = keep(golden, &got);
        anyhow::bail!(
            "trace differs from {golden} at {line} ({} vs {} rows); this run's trace: {}",
            got.lines().count(),
            want.lines().count(),
            kept.display()
        );
    }
    Ok(())
}

/// Runs `world` (with `robot`, or the world's own) with `script` for `duration_s`: its trace.
fn run_trace(
    world: &str,
    robot: Option<&str>,
    script: &str,
    duration_s: f64,
    serial_detection: bool,
) -> Result<String> {
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
    Ok(std::fs::read_to_string(&trace)?)
}

/// Keeps a failing run's trace in the target folder for a look (best effort): its path.
fn keep(golden: &str, got: &str) -> std::path::PathBuf {
    let kept = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(Path::new(golden).file_name().unwrap_or_default());
    let _ = std::fs::write(&kept, got);
    kept
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
        rover_sim::model::World::load(&repo("worlds/walking.toml"))?,
        rover_sim::model::RobotModel::load(&repo("assets/robots/my_robot.urdf"))?,
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
// carries the laser car), when walking people got a gait (the same follow state on all 1,200
// rows, the path within 9.6 cm), and when the laser's person centre moved from 0.1 m to 3.5 cm
// beyond its returns (people's legs; the same follow state on all 1,200 rows of both traces,
// the paths within 9.7 and 8.7 cm).
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

/// The machine string the follow goldens are checked against: `ROVER_GOLDEN_MACHINE` when set
/// (to try the tolerance comparison on the recording machine), else this machine's.
fn this_machine() -> Result<String> {
    match std::env::var("ROVER_GOLDEN_MACHINE") {
        Ok(m) if !m.is_empty() => Ok(m),
        _ => machine(),
    }
}

/// The walking-person follow run against `golden`: byte for byte on the machine the follow
/// goldens were recorded on; elsewhere (detector and renderer floating point differ across
/// CPUs) within [`Tolerance::FOLLOW`]: the same follow state and mode on every row, the pose
/// within 5 cm, no row jumping away from its neighbours.
fn follow_golden(golden: &str, serial_detection: bool) -> Result<()> {
    let here = this_machine()?;
    let machine_file = repo("tests/golden/follow.machine");
    let bless = std::env::var_os("ROVER_BLESS").is_some();
    let recorded = if bless {
        std::fs::write(&machine_file, format!("{here}\n"))?;
        here.clone()
    } else {
        std::fs::read_to_string(&machine_file).map_err(|e| {
            anyhow::anyhow!("{}: {e}; this machine is `{here}`", machine_file.display())
        })?
    };
    if recorded.trim() == here {
        // Blessing, or the recording machine: byte for byte.
        return check(
            "worlds/walking.toml",
            None,
            "tests/golden/follow.toml",
            12.0,
            golden,
            serial_detection,
        );
    }
    println!(
        "the golden follow traces were recorded on `{}`, this machine is `{here}`: comparing \
         within tolerances {:?}",
        recorded.trim(),
        Tolerance::FOLLOW
    );
    let got = run_trace(
        "worlds/walking.toml",
        None,
        "tests/golden/follow.toml",
        12.0,
        serial_detection,
    )?;
    let want = std::fs::read_to_string(repo(golden))?;
    match golden::compare(&got, &want, &Tolerance::FOLLOW) {
        Ok(drift) => {
            println!("within tolerances of {golden}: {drift:?}");
            Ok(())
        }
        Err(problems) => {
            let kept = keep(golden, &got);
            anyhow::bail!(
                "trace differs from {golden} beyond the tolerances {:?}:\n{}\nthis run's trace: {}",
                Tolerance::FOLLOW,
                problems.join("\n"),
                kept.display()
            )
        }
    }
}

/// The tolerance comparison passes the recorded follow trace and fails it with one row's pose
/// moved by 1 cm (ground truth or odometry), a heading turned by 0.02 rad, one row's follow
/// state changed, or a row missing.
#[test]
fn the_golden_tolerance_catches_a_centimetre_on_one_row() -> Result<()> {
    let want = std::fs::read_to_string(repo("tests/golden/follow.csv"))?;
    let drift =
        golden::compare(&want, &want, &Tolerance::FOLLOW).map_err(|p| anyhow::anyhow!("{p:?}"))?;
    assert_eq!(drift.rows, 1200);
    assert_eq!(drift.position_m, 0.0);
    let lines: Vec<&str> = want.lines().collect();
    let changed = |row: usize, column: usize, f: &dyn Fn(&str) -> String| -> String {
        let mut out: Vec<String> = lines.iter().map(|l| (*l).to_owned()).collect();
        let mut cells: Vec<String> = out[row].split(',').map(str::to_owned).collect();
        cells[column] = f(&cells[column]);
        out[row] = cells.join(",");
        out.join("\n") + "\n"
    };
    let plus = |d: f64| move |v: &str| format!("{:.6}", v.parse::<f64>().unwrap_or(f64::NAN) + d);
    // Columns: sim_time_s,x_m,y_m,yaw_rad,odom_x_m,odom_y_m,odom_yaw_rad,...,follow_state.
    for (row, column, what) in [
        (600, 1, "x_m"),
        (601, 2, "y_m"),
        (900, 4, "odom_x_m"),
        (2, 5, "odom_y_m"),
    ] {
        let moved = changed(row, column, &plus(0.01));
        let result = golden::compare(&moved, &want, &Tolerance::FOLLOW);
        let problems = result.err().unwrap_or_default();
        assert!(
            problems
                .iter()
                .any(|p| p.starts_with(&format!("line {}:", row + 1)) && p.contains("jumped")),
            "{what} of line {} moved 1 cm passed: {problems:?}",
            row + 1
        );
    }
    let turned = changed(700, 3, &plus(0.02));
    assert!(
        golden::compare(&turned, &want, &Tolerance::FOLLOW).is_err(),
        "a heading turned 0.02 rad passed"
    );
    let state_column = lines[0]
        .split(',')
        .position(|c| c == "follow_state")
        .unwrap_or(usize::MAX);
    let state = changed(800, state_column, &|s: &str| {
        if s == "searching" {
            "tracking".into()
        } else {
            "searching".into()
        }
    });
    assert!(
        golden::compare(&state, &want, &Tolerance::FOLLOW).is_err(),
        "a changed follow state passed"
    );
    let short: String = lines[..1100].iter().map(|l| format!("{l}\n")).collect();
    assert!(
        golden::compare(&short, &want, &Tolerance::FOLLOW).is_err(),
        "a shorter trace passed"
    );
    Ok(())
}

/// The follow tolerances hold at their edges (`Tolerance::FOLLOW`: 5 cm, 0.05 rad): a smooth
/// drift growing to 4 cm in position, or to 0.04 rad in heading, over the whole run (ground
/// truth and odometry alike, each row a hair from the one before) passes; the same drift
/// grown to 6 cm or 0.06 rad fails, on the limit itself rather than on a jump between rows.
#[test]
fn the_golden_tolerance_holds_at_its_limits() -> Result<()> {
    let want = std::fs::read_to_string(repo("tests/golden/follow.csv"))?;
    let lines: Vec<&str> = want.lines().collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let column = |name: &str| header.iter().position(|c| *c == name);
    let rows = lines.len() - 1;
    // Adds `total * i / rows` to `columns` of row i: a drift that grows smoothly to `total`.
    let drifted = |columns: &[&str], total: f64| -> Result<String> {
        let indices: Vec<usize> = columns
            .iter()
            .map(|c| column(c).ok_or_else(|| anyhow::anyhow!("no column {c}")))
            .collect::<Result<_>>()?;
        let mut out = vec![lines[0].to_owned()];
        for (i, line) in lines[1..].iter().enumerate() {
            let mut cells: Vec<String> = line.split(',').map(str::to_owned).collect();
            for &k in &indices {
                let v: f64 = cells[k].parse()?;
                cells[k] = format!("{:.9}", v + total * (i + 1) as f64 / rows as f64);
            }
            out.push(cells.join(","));
        }
        Ok(out.join("\n") + "\n")
    };
    let position = ["x_m", "odom_x_m"];
    let heading = ["yaw_rad", "odom_yaw_rad"];
    for (columns, inside, outside, limit) in [
        (&position, 0.04, 0.06, "m from the golden one"),
        (&heading, 0.04, 0.06, "rad from the golden one"),
    ] {
        let drift = golden::compare(&drifted(columns, inside)?, &want, &Tolerance::FOLLOW)
            .map_err(|p| anyhow::anyhow!("{columns:?} drifting to {inside} failed: {p:?}"))?;
        println!("{columns:?} drifting to {inside}: {drift:?}");
        let problems = golden::compare(&drifted(columns, outside)?, &want, &Tolerance::FOLLOW)
            .err()
            .unwrap_or_default();
        assert!(
            problems.iter().any(|p| p.contains(limit))
                && !problems.iter().any(|p| p.contains("jumped")),
            "{columns:?} drifting to {outside} should fail on the limit alone: {problems:?}"
        );
    }
    Ok(())
}
