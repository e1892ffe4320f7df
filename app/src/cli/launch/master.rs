//! The ROS master a launch runs against: the one at `ROS_MASTER_URI` when it answers, else a
//! `rosmaster` rover starts on this machine (Debian's python3-rosmaster, found on PATH) and
//! stops when the launch ends. Parameters are set on it as roslaunch sets them.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use rover_core::{Launch, ParamValue};
use rover_ros1::{Value, ros_call};

/// How long a call to the master may take.
const CALL_TIMEOUT: Duration = Duration::from_secs(2);
/// How long a started rosmaster has to answer.
const START_TIMEOUT: Duration = Duration::from_secs(15);
/// The caller id rover uses towards the master, as roslaunch uses `/roslaunch`.
const CALLER: &str = "/roslaunch";

/// A ROS master, and the process when rover started it.
pub(crate) struct Master {
    /// Its URI (`http://host:port/`).
    pub(crate) uri: String,
    process: Option<Child>,
}

impl Master {
    /// The master at `ROS_MASTER_URI` (default `http://localhost:11311/`), started when none
    /// answers there.
    pub(crate) fn ensure() -> Result<Self> {
        let uri = master_uri();
        if answers(&uri) {
            tracing::info!("ROS master at {uri}");
            return Ok(Self { uri, process: None });
        }
        let (host, port) = host_port(&uri)?;
        if !is_local(&host) {
            bail!(
                "no ROS master answers at ROS_MASTER_URI={uri}, and {host} is not this machine, so rover cannot start one there"
            );
        }
        let ros_home = ros_home();
        let process = Command::new("rosmaster")
            .args(["--core", "-p", &port.to_string()])
            .env("ROS_HOME", &ros_home)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .with_context(|| {
                format!(
                    "no ROS master answers at {uri} and `rosmaster` could not be started (Debian: apt-get install python3-rosmaster; or start roscore yourself)"
                )
            })?;
        let mut master = Self {
            uri: uri.clone(),
            process: Some(process),
        };
        let start = Instant::now();
        while !answers(&uri) {
            if let Some(child) = master.process.as_mut()
                && let Ok(Some(status)) = child.try_wait()
            {
                let mut err = String::new();
                if let Some(mut pipe) = child.stderr.take() {
                    use std::io::Read as _;
                    let _ = pipe.read_to_string(&mut err);
                }
                master.process = None;
                bail!(
                    "rosmaster exited ({status}) before it answered at {uri}: {}",
                    err.trim()
                );
            }
            if start.elapsed() > START_TIMEOUT {
                master.stop();
                bail!("rosmaster did not answer at {uri} within {START_TIMEOUT:?}");
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        say!("started a ROS master at {uri} (rosmaster; it stops when rover does)");
        Ok(master)
    }

    /// Clears, deletes and sets the launch's parameters, as roslaunch does before starting
    /// nodes.
    pub(crate) fn set_params(&self, launch: &Launch) -> Result<()> {
        for ns in launch.clear_params.iter().chain(&launch.deletes) {
            let key = ns.trim_end_matches('/');
            if matches!(self.call("hasParam", key)?, Value::Bool(true)) {
                self.call_with("deleteParam", &[Value::from(key)])?;
            }
        }
        for (name, param) in &launch.params {
            let Some(value) = to_xmlrpc(&param.value) else {
                tracing::warn!(
                    "{}: parameter {name} is binary (binfile); rover does not set it",
                    param.at
                );
                continue;
            };
            self.call_with("setParam", &[Value::from(name.as_str()), value])
                .with_context(|| format!("setting parameter {name} ({})", param.at))?;
        }
        Ok(())
    }

    fn call(&self, method: &str, key: &str) -> Result<Value> {
        self.call_with(method, &[Value::from(key)])
    }

    fn call_with(&self, method: &str, args: &[Value]) -> Result<Value> {
        let mut all = vec![Value::from(CALLER)];
        all.extend_from_slice(args);
        ros_call(&self.uri, method, &all, CALL_TIMEOUT)
            .with_context(|| format!("{method} on the ROS master at {}", self.uri))
    }

    /// Stops the master when rover started it (SIGINT, then SIGKILL after 5 s).
    pub(crate) fn stop(&mut self) {
        if let Some(mut child) = self.process.take() {
            super::children::interrupt(&child);
            let start = Instant::now();
            while start.elapsed() < Duration::from_secs(5) {
                if let Ok(Some(_)) = child.try_wait() {
                    return;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

impl Drop for Master {
    fn drop(&mut self) {
        self.stop();
    }
}

/// `ROS_MASTER_URI`, else roslaunch's default `http://localhost:11311/`.
pub(super) fn master_uri() -> String {
    std::env::var("ROS_MASTER_URI")
        .ok()
        .filter(|u| !u.is_empty())
        .unwrap_or_else(|| "http://localhost:11311/".to_owned())
}

/// `ROS_HOME`, else `~/.ros` (created): where the master and the nodes run.
pub(super) fn ros_home() -> std::path::PathBuf {
    let home = std::env::var_os("ROS_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| std::path::Path::new(&h).join(".ros")))
        .unwrap_or_else(std::env::temp_dir);
    let _ = std::fs::create_dir_all(&home);
    home
}

fn answers(uri: &str) -> bool {
    ros_call(
        uri,
        "getPid",
        &[Value::from(CALLER)],
        Duration::from_millis(500),
    )
    .is_ok()
}

fn host_port(uri: &str) -> Result<(String, u16)> {
    let rest = uri
        .strip_prefix("http://")
        .with_context(|| format!("ROS_MASTER_URI={uri}: expected http://HOST:PORT/"))?;
    let authority = rest.split('/').next().unwrap_or(rest);
    let (host, port) = authority
        .rsplit_once(':')
        .with_context(|| format!("ROS_MASTER_URI={uri}: expected http://HOST:PORT/"))?;
    let port = port
        .parse()
        .with_context(|| format!("ROS_MASTER_URI={uri}: the port is not a number"))?;
    Ok((host.to_owned(), port))
}

fn is_local(host: &str) -> bool {
    if matches!(host, "localhost" | "127.0.0.1" | "::1" | "0.0.0.0") {
        return true;
    }
    let me = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
    host == me.trim() || std::env::var("ROS_IP").is_ok_and(|ip| ip == host)
}

/// A parameter as XML-RPC carries it (`None` for binary data, which rover's XML-RPC lacks).
fn to_xmlrpc(value: &ParamValue) -> Option<Value> {
    Some(match value {
        ParamValue::Bool(b) => Value::Bool(*b),
        // XML-RPC's ints are 32 bits; rospy sends larger ones as doubles too.
        ParamValue::Int(i) => match i32::try_from(*i) {
            Ok(v) => Value::Int(v),
            Err(_) => Value::Double(*i as f64),
        },
        ParamValue::Double(d) => Value::Double(*d),
        ParamValue::Str(s) => Value::Str(s.clone()),
        ParamValue::List(items) => {
            Value::Array(items.iter().map(to_xmlrpc).collect::<Option<_>>()?)
        }
        ParamValue::Map(entries) => Value::Struct(
            entries
                .iter()
                .map(|(k, v)| Some((k.clone(), to_xmlrpc(v)?)))
                .collect::<Option<_>>()?,
        ),
        ParamValue::Binary(_) => return None,
    })
}
