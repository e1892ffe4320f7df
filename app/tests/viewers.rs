//! Viewer modes with the real viewers: the web viewer rover serves renders in headless Chromium,
//! and a spawned native viewer killed mid-run does not stop the run.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::Result;
use rover_core::parse_trace;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A port nothing listens on now (the OS picks it), so parallel runs never collide.
fn free_port() -> Result<u16> {
    Ok(std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port())
}

/// Kills the child when dropped (a failing assertion must not leave a server running).
struct Reaper(std::process::Child);

impl Drop for Reaper {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn the_served_web_viewer_renders_the_run_in_chromium() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let (web_port, grpc_port) = (free_port()?, free_port()?);
    let mut child = Reaper(
        Command::new(env!("CARGO_BIN_EXE_rover"))
            .args(["--headless", "--duration", "3", "--viewer", "web"])
            .args(["--web-port", &web_port.to_string()])
            .args(["--grpc-port", &grpc_port.to_string()])
            .current_dir(repo())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()?,
    );
    let stdout = child
        .0
        .stdout
        .take()
        .ok_or_else(|| anyhow::anyhow!("no stdout"))?;
    // Wait for the run to finish; rover keeps serving and says where.
    let mut url = None;
    for line in BufReader::new(stdout).lines() {
        let line = line?;
        if let Some(rest) = line.strip_prefix("run finished; still serving the web viewer at ") {
            url = rest.split_whitespace().next().map(str::to_owned);
            break;
        }
    }
    let url = url.ok_or_else(|| anyhow::anyhow!("rover never said it was serving"))?;
    assert!(
        url.starts_with(&format!("http://127.0.0.1:{web_port}")),
        "{url}"
    );
    let shot = dir.path().join("web.png");
    let out = Command::new("node")
        .arg(repo().join("scripts/webview/screenshot.mjs"))
        .arg(&url)
        .arg(&shot)
        .args(["--wait-s", "150"])
        .output()
        .map_err(|e| anyhow::anyhow!("cannot run node ({e})"))?;
    let report = String::from_utf8_lossy(&out.stdout).to_string();
    println!("{report}");
    assert!(
        out.status.success(),
        "the web viewer did not render: {report}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_str(report.trim().lines().last().unwrap_or(""))?;
    assert_eq!(json["ok"], true);
    // The 3D view shows the scene: plenty of coloured (non-UI-grey) pixels.
    if let Ok(keep) = std::env::var("ROVER_KEEP_SCREENSHOT") {
        std::fs::copy(&shot, keep)?;
    }
    assert!(
        json["colourFrac"].as_f64().unwrap_or(0.0) > 0.01,
        "{report}"
    );
    Ok(())
}

#[test]
fn killing_the_spawned_viewer_mid_run_does_not_stop_the_run() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let rrd = dir.path().join("run.rrd");
    // The native viewer needs a display: a virtual one.
    let mut child = Reaper(
        Command::new("xvfb-run")
            .args(["-a", "-s", "-screen 0 1280x800x24"])
            .arg(env!("CARGO_BIN_EXE_rover"))
            // Paced to real time: the run lasts at least 12 s of wall time however fast this
            // machine is, so it is still running when the viewer is killed 4 s in.
            .args([
                "--headless",
                "--duration",
                "12",
                "--rtf",
                "1",
                "--viewer",
                "spawn",
            ])
            .arg("--trace")
            .arg(&trace)
            .arg("--record")
            .arg(&rrd)
            .current_dir(repo())
            .env("RUST_LOG", "info")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                anyhow::anyhow!("cannot run xvfb-run ({e}): apt-get install xvfb xauth")
            })?,
    );
    let stderr = child
        .0
        .stderr
        .take()
        .ok_or_else(|| anyhow::anyhow!("no stderr"))?;
    let lines = std::sync::Arc::new(std::sync::Mutex::new(Vec::<String>::new()));
    let sink = lines.clone();
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if let Ok(mut l) = sink.lock() {
                l.push(line);
            }
        }
    });
    // Find the viewer's pid, let it receive data for a moment, then kill it.
    let started = Instant::now();
    let pid = loop {
        let found = lines.lock().ok().and_then(|l| {
            l.iter().find_map(|line| {
                let rest = line.split("Rerun viewer started (pid ").nth(1)?;
                rest.split(',').next()?.parse::<u32>().ok()
            })
        });
        if let Some(pid) = found {
            break pid;
        }
        anyhow::ensure!(
            started.elapsed() < Duration::from_secs(120),
            "the viewer never started: {:?}",
            lines.lock().map(|l| l.clone()).unwrap_or_default()
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    std::thread::sleep(Duration::from_secs(4));
    // The pip `rerun` is a wrapper that runs the viewer as its child: kill both.
    let _ = Command::new("pkill")
        .args(["-KILL", "-P", &pid.to_string()])
        .status()?;
    let killed = Command::new("kill")
        .arg("-9")
        .arg(pid.to_string())
        .status()?;
    assert!(killed.success(), "could not kill the viewer (pid {pid})");
    let status = child.0.wait()?;
    let _ = reader.join();
    let log = lines.lock().map(|l| l.join("\n")).unwrap_or_default();
    assert!(
        status.success(),
        "rover failed after the viewer was killed:\n{log}"
    );
    assert!(log.contains("viewer has gone away"), "no warning:\n{log}");
    let rows = parse_trace(&std::fs::read_to_string(&trace)?)?;
    assert_eq!(rows.len(), 1200, "the trace is complete");
    assert!(
        std::fs::metadata(&rrd)?.len() > 100_000,
        "the recording went on"
    );
    Ok(())
}
