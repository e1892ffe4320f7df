//! Faults during a run, with the real binary: a detector that panics or errors mid-run, the
//! model file corrupted mid-run, SIGINT/SIGTERM during a headless recording and in the window,
//! and a full disk under the trace and the .rrd. Recordings are checked with Rerun's own
//! `rerun rrd verify` (PyPI rerun-sdk 0.36.3, which scripts/setup.sh puts on PATH).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use anyhow::Result;
use rover_core::{TraceRow, parse_trace};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn rover() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rover"));
    c.env("RUST_LOG", "info");
    c
}

/// `rerun rrd verify [--check-footers false] FILE`; `None` (with the reason printed) when the
/// rerun CLI is not installed.
fn rrd_verify(path: &Path, footers: bool) -> Result<Option<Output>> {
    let mut c = Command::new("rerun");
    c.args(["rrd", "verify"]);
    if !footers {
        c.args(["--check-footers", "false"]);
    }
    match c.arg(path).output() {
        Ok(out) => Ok(Some(out)),
        Err(e) => {
            rover_tests::skip(format!(
                "rrd verify: no `rerun` CLI on PATH ({e}); ./test installs rerun-sdk 0.36.3"
            ))?;
            Ok(None)
        }
    }
}

fn assert_verified(path: &Path, footers: bool) -> Result<()> {
    if let Some(out) = rrd_verify(path, footers)? {
        let all = format!("{}{}", text(&out.stdout), text(&out.stderr));
        assert!(
            out.status.success() && all.contains("verified without error"),
            "rerun rrd verify {} (footers {footers}): {all}",
            path.display()
        );
    }
    Ok(())
}

fn wait_for(
    child: &mut Child,
    what: &str,
    limit: Duration,
    ready: impl Fn() -> bool,
) -> Result<()> {
    let t0 = Instant::now();
    while !ready() {
        if let Some(status) = child.try_wait()? {
            anyhow::bail!("rover exited ({status}) before {what}");
        }
        anyhow::ensure!(t0.elapsed() < limit, "no {what} within {limit:?}");
        std::thread::sleep(Duration::from_millis(100));
    }
    Ok(())
}

fn signal(pid: u32, name: &str) -> Result<()> {
    let status = Command::new("kill")
        .arg(format!("-{name}"))
        .arg(pid.to_string())
        .status()?;
    anyhow::ensure!(status.success(), "kill -{name} {pid} failed");
    Ok(())
}

/// The text of every `TextLog` in the recording's `/log`, read back with Rerun's decoder.
fn text_logs(path: &Path) -> Result<Vec<String>> {
    use rerun::external::re_log_encoding::DecoderApp;
    use rerun::log::{Chunk, LogMsg};
    let reader = std::io::BufReader::new(std::fs::File::open(path)?);
    let mut out = Vec::new();
    for msg in DecoderApp::decode_eager(reader)? {
        if let LogMsg::ArrowMsg(store, arrow) = msg?
            && store.is_recording()
        {
            let chunk = Chunk::from_arrow_msg(&arrow)?;
            if chunk.entity_path().to_string() != "/log" {
                continue;
            }
            let texts: Vec<_> = chunk
                .component_descriptors()
                .filter(|d| d.component.as_str() == "TextLog:text")
                .map(|d| d.component)
                .collect();
            for component in texts {
                for batch in chunk.iter_slices::<String>(component) {
                    out.extend(batch.iter().map(|s| s.as_str().to_owned()));
                }
            }
        }
    }
    Ok(out)
}

fn rows_of(path: &Path) -> Result<Vec<TraceRow>> {
    Ok(parse_trace(&std::fs::read_to_string(path)?)?)
}

/// SIGINT and SIGTERM in the middle of a headless `--record --trace` run: exit code 130, the
/// trace parses in full and ends where the run did, and the .rrd passes `rerun rrd verify`
/// with its footer.
#[test]
fn a_signal_ends_a_headless_recording_with_complete_files() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let script = repo().join("examples/scripts/follow.toml");
    for sig in ["INT", "TERM"] {
        let rrd = dir.path().join(format!("{sig}.rrd"));
        let trace = dir.path().join(format!("{sig}.csv"));
        let mut child = rover()
            .args(["--headless", "--duration", "600", "--script"])
            .arg(&script)
            .arg("--record")
            .arg(&rrd)
            .arg("--trace")
            .arg(&trace)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()?;
        // The recording has started (the file sink has written) and the run is under way.
        wait_for(&mut child, "a recording", Duration::from_secs(300), || {
            std::fs::metadata(&rrd).is_ok_and(|m| m.len() > 200_000)
        })?;
        signal(child.id(), sig)?;
        let out = child.wait_with_output()?;
        let stdout = text(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(130),
            "SIG{sig}: {stdout}\n{}",
            text(&out.stderr)
        );
        assert!(stdout.contains("interrupted by a signal"), "{stdout}");
        let rows = rows_of(&trace)?;
        assert!(
            !rows.is_empty() && stdout.contains(&format!("({} rows)", rows.len())),
            "{stdout}"
        );
        let last = rows.last().map_or(0.0, |r| r.sim_time_s);
        assert!(last < 599.0, "the run was cut short, at {last} s");
        assert_verified(&rrd, true)?;
    }
    Ok(())
}

/// Closing the window with SIGTERM (as a desktop session's logout does) finishes the trace
/// and the recording as the close button does.
#[test]
fn a_signal_closes_the_window_with_complete_files() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let rrd = dir.path().join("window.rrd");
    let trace = dir.path().join("window.csv");
    let script = dir.path().join("run.sh");
    std::fs::write(
        &script,
        r#"set -u
"$ROVER" --viewer none --no-detector --record "$RRD" --trace "$TRACE" > "$LOG" 2>&1 &
pid=$!
for _ in $(seq 600); do
  [ -s "$RRD" ] && [ "$(stat -c %s "$RRD")" -gt 100000 ] && break
  sleep 0.2
done
sleep 1
kill -TERM "$pid"
wait "$pid"
echo "rover exit $?" >> "$LOG"
"#,
    )?;
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24", "bash"])
        .arg(&script)
        .env("ROVER", env!("CARGO_BIN_EXE_rover"))
        .env("RRD", &rrd)
        .env("TRACE", &trace)
        .env("LOG", dir.path().join("rover.log"))
        .output()
        .map_err(|e| anyhow::anyhow!("cannot run xvfb-run ({e}): apt-get install xvfb xauth"))?;
    let log = std::fs::read_to_string(dir.path().join("rover.log")).unwrap_or_default();
    assert!(
        log.contains("rover exit 130") && log.contains("interrupted by a signal"),
        "{log}\n{}",
        text(&out.stderr)
    );
    let rows = rows_of(&trace)?;
    assert!(!rows.is_empty(), "{log}");
    assert!(log.contains(&format!("({} rows)", rows.len())), "{log}");
    assert_verified(&rrd, true)?;
    Ok(())
}

/// A detector that panics (or errors) mid-run: the run goes on, the log and the recording say
/// so, the follower holds still, and manual commands still drive the car.
#[test]
fn a_failing_detector_stops_the_follower_and_manual_driving_goes_on() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let script = dir.path().join("script.toml");
    std::fs::write(
        &script,
        "steps = [ { at = 0.0, toggle = \"follow\" }, { at = 4.0, toggle = \"follow\" }, \
         { at = 4.5, cmd_vel = [-0.3, 0.0] } ]\n",
    )?;
    for kind in ["panic", "error"] {
        let trace = dir.path().join(format!("{kind}.csv"));
        let rrd = dir.path().join(format!("{kind}.rrd"));
        let out = rover()
            .args(["--headless", "--duration", "7", "--script"])
            .arg(&script)
            .arg("--trace")
            .arg(&trace)
            .arg("--record")
            .arg(&rrd)
            .arg(format!("--inject-fault={kind}@3"))
            .output()?;
        let stderr = text(&out.stderr);
        assert!(
            out.status.success(),
            "{kind}: {}\n{stderr}",
            text(&out.stdout)
        );
        let expected = if kind == "panic" {
            "detector failed: the detector crashed: injected fault after 3 detections"
        } else {
            "detector failed"
        };
        assert!(
            stderr.contains(expected) && stderr.contains("manual driving works"),
            "{kind}: {stderr}"
        );
        assert_eq!(stderr.matches("detector failed").count(), 1, "{stderr}");
        let rows = rows_of(&trace)?;
        // Three detections (0.0, 0.2, 0.4 s), the fourth fails; from 1 s on in follow mode
        // the follower holds still.
        let following: Vec<&TraceRow> = rows
            .iter()
            .filter(|r| r.sim_time_s >= 1.0 && r.sim_time_s < 4.0)
            .collect();
        assert!(!following.is_empty());
        for r in &following {
            assert_eq!(r.mode, "follow", "{r:?}");
            assert_eq!((r.cmd_linear_mps, r.cmd_angular_radps), (0.0, 0.0), "{r:?}");
        }
        // Manual driving: backwards at 0.3 m/s from 4.5 s.
        let at = |t: f64| rows.iter().find(|r| r.sim_time_s >= t).map(|r| r.x_m);
        let (Some(x5), Some(x7)) = (at(5.0), at(6.9)) else {
            anyhow::bail!("trace too short: {} rows", rows.len());
        };
        assert!(x5 - x7 > 0.4, "{kind}: reversed {:.3} m", x5 - x7);
        // The recording carries the warning (Rerun's text log) and stays valid.
        assert_verified(&rrd, true)?;
        let logs = text_logs(&rrd)?;
        assert!(
            logs.iter().any(|l| l.starts_with("detector failed")),
            "the .rrd's text log: {logs:?}"
        );
    }
    Ok(())
}

/// The model file is read once, at start: overwriting it mid-run changes nothing (the follower
/// keeps tracking, no detector error); a corrupt file at start is a clear error naming it.
#[test]
fn a_model_file_corrupted_mid_run_does_not_touch_the_run() -> Result<()> {
    let model = rover_perception::ensure_default_model()?;
    let dir = tempfile::tempdir()?;
    let copy = dir.path().join("model.onnx");
    std::fs::copy(&model, &copy)?;
    let trace = dir.path().join("trace.csv");
    let mut child = rover()
        .args(["--headless", "--duration", "6", "--script"])
        .arg(repo().join("examples/scripts/follow.toml"))
        .arg("--model")
        .arg(&copy)
        .arg("--trace")
        .arg(&trace)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    // Wait until the detector has loaded: the follower's first state change is logged after
    // the session (and its detector) started.
    let stderr_pipe = child
        .stderr
        .take()
        .ok_or_else(|| anyhow::anyhow!("no stderr"))?;
    let (line_tx, line_rx) = std::sync::mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr_pipe)
            .lines()
            .map_while(|l| l.ok())
        {
            let _ = line_tx.send(line);
        }
    });
    let mut stderr = String::new();
    let t0 = Instant::now();
    loop {
        let line = line_rx.recv_timeout(Duration::from_secs(300))?;
        stderr.push_str(&line);
        stderr.push('\n');
        if line.contains("follower: ") {
            break;
        }
        anyhow::ensure!(
            t0.elapsed() < Duration::from_secs(300),
            "no follower state: {stderr}"
        );
    }
    std::fs::write(&copy, b"this is no longer an ONNX model")?;
    let status = child.wait()?;
    let _ = reader.join();
    stderr.extend(line_rx.try_iter().map(|l| l + "\n"));
    assert!(status.success(), "{stderr}");
    assert!(
        stderr.contains("follower: waiting -> searching"),
        "{stderr}"
    );
    assert!(!stderr.contains("detector failed"), "{stderr}");
    let rows = rows_of(&trace)?;
    let tracking = rows
        .iter()
        .filter(|r| r.sim_time_s > 4.0 && r.follow_state == "tracking")
        .count();
    assert!(
        tracking > 100,
        "the follower kept tracking: {tracking} rows\n{stderr}"
    );

    // Started with the corrupt file: a clear error naming it, manual driving still works.
    let out = rover()
        .args(["--headless", "--duration", "1", "--script"])
        .arg(repo().join("examples/scripts/follow.toml"))
        .arg("--model")
        .arg(&copy)
        .output()?;
    let all = format!("{}{}", text(&out.stdout), text(&out.stderr));
    assert!(all.contains(&copy.display().to_string()), "{all}");
    Ok(())
}

/// A tmpfs of `bytes` mounted at a new folder, unmounted on drop; `None` (reason printed)
/// where mounting is not allowed (not root, no CAP_SYS_ADMIN).
struct SmallDisk {
    dir: tempfile::TempDir,
}

impl SmallDisk {
    fn mount(bytes: u64) -> Result<Option<Self>> {
        let dir = tempfile::tempdir()?;
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={bytes}"), "tmpfs"])
            .arg(dir.path())
            .output();
        match out {
            Ok(o) if o.status.success() => Ok(Some(Self { dir })),
            Ok(o) => {
                rover_tests::skip(format!(
                    "disk-full test: cannot mount a small tmpfs ({}); run as root",
                    text(&o.stderr).trim()
                ))?;
                Ok(None)
            }
            Err(e) => {
                rover_tests::skip(format!("disk-full test: no mount command ({e})"))?;
                Ok(None)
            }
        }
    }
    fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.dir.path()).status();
    }
}

/// A disk that fills up under the trace: the run stops with an error that says how many rows
/// the file keeps, and the file parses with exactly those rows (no half row at the end). Under
/// the .rrd: the run finishes (trace complete), exits with an error saying the recording is
/// not complete, and what was written reads back (`rerun rrd verify --check-footers false`).
#[test]
fn a_full_disk_keeps_what_was_written_readable() -> Result<()> {
    let Some(disk) = SmallDisk::mount(64 << 10)? else {
        return Ok(());
    };
    let trace = disk.path().join("trace.csv");
    let out = rover()
        .args(["--headless", "--duration", "20", "--trace"])
        .arg(&trace)
        .output()?;
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("No space left on device"), "{stderr}");
    let rows = rows_of(&trace)?;
    assert!(
        stderr.contains(&format!(
            "keeps its first {} rows, each complete",
            rows.len()
        )),
        "{} rows\n{stderr}",
        rows.len()
    );
    assert!(rows.len() > 100, "{}", rows.len());
    drop(disk);

    let Some(disk) = SmallDisk::mount(300 << 10)? else {
        return Ok(());
    };
    let other = tempfile::tempdir()?;
    let trace = other.path().join("trace.csv");
    let rrd = disk.path().join("run.rrd");
    let out = rover()
        .args(["--headless", "--duration", "4", "--script"])
        .arg(repo().join("examples/scripts/follow.toml"))
        .arg("--record")
        .arg(&rrd)
        .arg("--trace")
        .arg(&trace)
        .output()?;
    let stderr = text(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("was not written in full"), "{stderr}");
    assert_eq!(
        rows_of(&trace)?.len(),
        400,
        "the run itself went on to its end"
    );
    assert!(std::fs::metadata(&rrd)?.len() > 100_000);
    assert_verified(&rrd, false)?;
    Ok(())
}

/// In the window a failing detector shows on the HUD ("detector FAILED" and the warning, in
/// the warning colour) and in the log, and the window keeps running to its duration.
#[test]
fn a_failing_detector_shows_on_the_window_hud() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let shot = dir.path().join("hud.png");
    let log = dir.path().join("rover.log");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(env!("CARGO_BIN_EXE_rover"))
        .args([
            "--viewer",
            "none",
            "--duration",
            "6",
            "--inject-fault=panic@2",
        ])
        .arg("--screenshot")
        .arg(&shot)
        .stderr(std::fs::File::create(&log)?)
        .output()
        .map_err(|e| anyhow::anyhow!("cannot run xvfb-run ({e}): apt-get install xvfb xauth"))?;
    let log = std::fs::read_to_string(&log)?;
    assert!(out.status.success(), "{}\n{log}", text(&out.stdout));
    assert!(
        log.contains("detector failed: the detector crashed"),
        "{log}"
    );
    // The HUD's warning colour (255, 120, 90) is only used for a failure or a warning.
    let img = image::open(&shot)?.into_rgb8();
    let warm = img.pixels().filter(|p| p.0 == [255, 120, 90]).count();
    assert!(warm > 200, "{warm} pixels in the HUD's warning colour");
    Ok(())
}

/// `--record-no-footer` (long recordings with flat memory): the file reads back without the
/// footer; with it (the default) the footer is there.
#[test]
fn a_recording_without_its_footer_is_still_valid() -> Result<()> {
    let dir = tempfile::tempdir()?;
    for footer in [false, true] {
        let rrd = dir.path().join(format!("footer-{footer}.rrd"));
        let mut c = rover();
        c.args(["--headless", "--duration", "1", "--record"])
            .arg(&rrd);
        if !footer {
            c.arg("--record-no-footer");
        }
        let out = c.output()?;
        assert!(out.status.success(), "{}", text(&out.stderr));
        assert_verified(&rrd, footer)?;
        if !footer && let Some(out) = rrd_verify(&rrd, true)? {
            assert!(
                !out.status.success(),
                "a footer check passed on a file without one"
            );
        }
    }
    Ok(())
}
