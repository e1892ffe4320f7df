//! The shared harness of the ROS 1 tests (`ros.rs`, `gz_ros.rs`): a master on a free port,
//! rover and ROS tools started against it, their logs.

#![allow(
    dead_code,
    unused_imports,
    reason = "each test file uses part of the harness"
)]

use std::ffi::{OsStr, OsString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail, ensure};
use rover_core::{TraceRow, parse_trace};
use rover_ros1::Value;
use rover_ros1::ros_call;

pub(crate) static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

pub(crate) const PYTHON: &str = "/usr/bin/python3";

pub(crate) fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub(crate) fn shared_ros() -> PathBuf {
    repo().join("../shared/ros")
}

/// Why these tests cannot run here, if they cannot.
pub(crate) fn missing_ros() -> Option<String> {
    for tool in ["/usr/bin/rosmaster", "/usr/bin/rostopic", "/usr/bin/rosbag"] {
        if !Path::new(tool).exists() {
            return Some(format!(
                "{tool} not found (apt-get install python3-rosmaster python3-rostopic python3-rosbag ros-core; ./test does)"
            ));
        }
    }
    let ok = Command::new(PYTHON)
        .args(["-c", "import rospy, geometry_msgs.msg, nav_msgs.msg"])
        .status()
        .is_ok_and(|s| s.success());
    (!ok).then(|| format!("{PYTHON} cannot import rospy/geometry_msgs/nav_msgs"))
}

/// This test cannot run here: a failure in strict mode (CI), else a counted skip.
pub(crate) fn skip(reason: &str) -> Result<()> {
    rover_tests::skip(reason)
}

/// A master on a free port, its environment, and the processes started against it (killed
/// when dropped).
pub(crate) struct RosGraph {
    pub(crate) dir: tempfile::TempDir,
    pub(crate) master_uri: String,
    pub(crate) port: u16,
    pub(crate) master: Option<Child>,
    pub(crate) children: Vec<Child>,
    /// Index of rover in `children`.
    pub(crate) rover: Option<usize>,
}

impl RosGraph {
    pub(crate) fn start() -> Result<Self> {
        let dir = tempfile::tempdir()?;
        let port = std::net::TcpListener::bind("127.0.0.1:0")?
            .local_addr()?
            .port();
        let mut graph = Self {
            master_uri: format!("http://127.0.0.1:{port}/"),
            port,
            dir,
            master: None,
            children: Vec::new(),
            rover: None,
        };
        graph.start_master()?;
        Ok(graph)
    }

    pub(crate) fn start_master(&mut self) -> Result<()> {
        let log = std::fs::File::create(self.dir.path().join("master.log"))?;
        let child = self
            .command("/usr/bin/rosmaster")
            .args(["--core", "-p", &self.port.to_string()])
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()
            .context("starting rosmaster")?;
        self.master = Some(child);
        self.wait_for(Duration::from_secs(30), "the master to answer", |g| {
            ros_call(
                &g.master_uri,
                "getPid",
                &[Value::from("/test")],
                Duration::from_secs(1),
            )
            .is_ok()
        })
    }

    pub(crate) fn kill_master(&mut self) {
        if let Some(mut m) = self.master.take() {
            let _ = m.kill();
            let _ = m.wait();
        }
    }

    /// A command with this graph's ROS environment.
    pub(crate) fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("ROS_MASTER_URI", &self.master_uri)
            .env("ROS_IP", "127.0.0.1")
            .env("ROS_HOME", self.dir.path())
            .env("ROS_LOG_DIR", self.dir.path().join("log"))
            .env("PYTHONUNBUFFERED", "1")
            // A DDS domain of the graph's own, for rover's --ros2 and its peers.
            .env("ROS_DOMAIN_ID", self.dds_domain().to_string())
            .stdin(Stdio::null());
        c
    }

    /// The graph's DDS domain (ROS 2 allows 0..=232), from its master's port.
    pub(crate) fn dds_domain(&self) -> u16 {
        120 + self.port % 100
    }

    /// Starts a process whose output goes to `<dir>/<name>.log`.
    pub(crate) fn spawn(&mut self, name: &str, mut command: Command) -> Result<()> {
        let log = std::fs::File::create(self.log_path(name))?;
        let child = command
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()
            .with_context(|| format!("starting {name}"))?;
        self.children.push(child);
        Ok(())
    }

    pub(crate) fn log_path(&self, name: &str) -> PathBuf {
        self.dir.path().join(format!("{name}.log"))
    }

    pub(crate) fn log(&self, name: &str) -> String {
        std::fs::read_to_string(self.log_path(name)).unwrap_or_default()
    }

    /// `rover --headless --ros` for `duration_s` of sim time, tracing to `<dir>/trace.csv`.
    pub(crate) fn spawn_rover(&mut self, duration_s: f64, extra: &[&str]) -> Result<()> {
        let mut c = self.command(env!("CARGO_BIN_EXE_rover"));
        c.args(["--headless", "--ros", "--rtf", "1", "--duration"])
            .arg(duration_s.to_string())
            .arg("--trace")
            .arg(self.trace_path())
            .args(extra)
            .env("RUST_LOG", "info");
        self.rover = Some(self.children.len());
        self.spawn("rover", c)?;
        self.wait_for(
            Duration::from_secs(120),
            "rover to register",
            Self::rover_registered,
        )
    }

    /// Whether the master knows the node /rover.
    pub(crate) fn rover_registered(&self) -> bool {
        ros_call(
            &self.master_uri,
            "lookupNode",
            &[Value::from("/test"), Value::from("/rover")],
            Duration::from_secs(1),
        )
        .is_ok()
    }

    pub(crate) fn trace_path(&self) -> PathBuf {
        self.dir.path().join("trace.csv")
    }

    /// Runs a subscriber like [`Self::run`]; also says how long it ran and whether rover was
    /// still running after it, for a failure's message (one that heard nothing may have come
    /// after rover finished).
    pub(crate) fn run_subscriber(
        &mut self,
        command: Command,
        timeout: Duration,
    ) -> Result<(String, String)> {
        let start = Instant::now();
        let out = self.run(command, timeout)?;
        let rover = match self.rover.and_then(|i| self.children.get_mut(i)) {
            None => "not started".to_owned(),
            Some(rover) => match rover.try_wait() {
                Ok(None) => "still running".to_owned(),
                Ok(Some(status)) => format!("already exited ({status})"),
                Err(e) => format!("unknown ({e})"),
            },
        };
        let note = format!(
            "it ran {:.1} s; rover then {rover}",
            start.elapsed().as_secs_f64()
        );
        Ok((out, note))
    }

    /// Waits for rover (the first child named rover) to exit; returns its trace.
    pub(crate) fn wait_rover(&mut self, timeout: Duration) -> Result<Vec<TraceRow>> {
        let start = Instant::now();
        let rover = self
            .rover
            .and_then(|i| self.children.get_mut(i))
            .context("no rover process")?;
        loop {
            if let Some(status) = rover.try_wait()? {
                ensure!(status.success(), "rover failed: {}", self.log("rover"));
                break;
            }
            if start.elapsed() > timeout {
                bail!("rover did not finish in {timeout:?}: {}", self.log("rover"));
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(parse_trace(&std::fs::read_to_string(self.trace_path())?)?)
    }

    pub(crate) fn wait_for(
        &self,
        timeout: Duration,
        what: &str,
        mut ready: impl FnMut(&Self) -> bool,
    ) -> Result<()> {
        let start = Instant::now();
        while !ready(self) {
            if start.elapsed() > timeout {
                bail!(
                    "timed out waiting for {what}; rover log:\n{}",
                    self.log("rover")
                );
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    }

    /// Writes `script` to `<dir>/<name>` and runs it with the graph's python, as [`Self::run`].
    pub(crate) fn run_python(&self, name: &str, script: &str, timeout: Duration) -> Result<String> {
        self.run_python_with(name, script, None, timeout)
    }

    /// As [`Self::run_python`], with `python_path` (generated messages) on its PYTHONPATH.
    pub(crate) fn run_python_with(
        &self,
        name: &str,
        script: &str,
        python_path: Option<&Path>,
        timeout: Duration,
    ) -> Result<String> {
        let path = self.dir.path().join(name);
        std::fs::write(&path, script)?;
        let mut c = self.command(PYTHON);
        c.arg(&path);
        if let Some(py) = python_path {
            c.env("PYTHONPATH", py);
        }
        self.run(c, timeout)
    }

    /// The words after `key ` on the first line of `out` that starts with it; an error with
    /// the output and rover's log when none does.
    pub(crate) fn keyed_line(&self, out: &str, key: &str) -> Result<Vec<String>> {
        let found = out
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key} ")))
            .with_context(|| format!("no {key}:\n{out}\nrover:\n{}", self.log("rover")))?;
        Ok(found.split(' ').map(str::to_owned).collect())
    }

    /// Starts the Python `script` as the child `ros2_peer` (its output in that log), with
    /// `python_path` (see [`both_transports`]).
    pub(crate) fn spawn_ros2_peer(&mut self, python_path: &OsStr, script: &str) -> Result<()> {
        let path = self.dir.path().join("ros2_peer.py");
        std::fs::write(&path, script)?;
        let mut peer = self.command("python3");
        peer.arg(&path).env("PYTHONPATH", python_path);
        self.spawn("ros2_peer", peer)
    }

    /// Starts rover with TIAGo (`urdf`), its wheels driven, and `extra` arguments.
    pub(crate) fn spawn_tiago(
        &mut self,
        duration_s: f64,
        urdf: &Path,
        extra: &[&str],
    ) -> Result<()> {
        let urdf = urdf.to_string_lossy();
        let mut args = vec![
            "--robot",
            urdf.as_ref(),
            "--drive",
            "wheel_left_joint,wheel_right_joint",
        ];
        args.extend_from_slice(extra);
        self.spawn_rover(duration_s, &args)
    }

    /// Runs a ROS tool to completion (killed after `timeout`); returns its stdout + stderr.
    pub(crate) fn run(&self, mut command: Command, timeout: Duration) -> Result<String> {
        let mut child = command
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()?;
        rover_tests::wait_or_kill(&mut child, timeout)?;
        let mut out = String::new();
        if let Some(mut o) = child.stdout.take() {
            o.read_to_string(&mut out)?;
        }
        if let Some(mut e) = child.stderr.take() {
            e.read_to_string(&mut out)?;
        }
        Ok(out)
    }

    /// rospy can import darknet_ros_msgs: generated from ../shared/ros with genpy.
    pub(crate) fn darknet_msgs(&self) -> Result<PathBuf> {
        rover_tests::ros::darknet_msgs(&shared_ros(), &self.dir.path().join("py"))
    }
}

impl Drop for RosGraph {
    fn drop(&mut self) {
        for c in &mut self.children {
            let _ = c.kill();
            let _ = c.wait();
        }
        self.kill_master();
    }
}

pub(crate) fn lock() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner())
}
