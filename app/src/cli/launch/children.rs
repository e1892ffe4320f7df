//! The nodes of a launch that rover does not stand in for, as child processes: their output
//! prefixed with the node's name (`output="screen"`; `log` goes to a file), a node that dies
//! reported (and started again with `respawn="true"`; `required="true"` stops the launch), and
//! all of them stopped as roslaunch stops them: SIGINT, then SIGTERM after 15 s, then SIGKILL.

use std::io::{BufRead as _, BufReader, Read, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rover_core::{LaunchNode, NodeOutput as Output};

/// roslaunch's wait after SIGINT before SIGTERM.
const SIGINT_WAIT: Duration = Duration::from_secs(15);
/// ... and after SIGTERM before SIGKILL.
const SIGTERM_WAIT: Duration = Duration::from_secs(2);
/// How often the supervisor looks at its processes.
const POLL: Duration = Duration::from_millis(50);

/// One node to start: its name, command line and environment.
pub(crate) struct NodeProcess {
    /// The node (name, output, respawn, required).
    pub(crate) node: LaunchNode,
    /// Its command line.
    pub(crate) command: Vec<String>,
    /// Environment added to rover's.
    pub(crate) env: Vec<(String, String)>,
    /// Its working folder.
    pub(crate) cwd: PathBuf,
}

struct Running {
    spec: NodeProcess,
    child: Option<Child>,
    pipes: Vec<JoinHandle<()>>,
    /// When to start it again (respawn).
    restart_at: Option<Instant>,
    starts: u32,
}

/// The started nodes and the thread watching them.
pub(crate) struct Children {
    procs: Arc<Mutex<Vec<Running>>>,
    stopping: Arc<AtomicBool>,
    supervisor: Option<JoinHandle<()>>,
    /// Why the launch was stopped by a `required="true"` node, when it was.
    required_exit: Arc<Mutex<Option<String>>>,
}

/// Sends SIGINT to a child (as Ctrl-C would).
pub(crate) fn interrupt(child: &Child) {
    send(child, nix::sys::signal::Signal::SIGINT);
}

fn send(child: &Child, signal: nix::sys::signal::Signal) {
    if let Ok(pid) = i32::try_from(child.id()) {
        let _ = nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), signal);
    }
}

impl Children {
    /// Starts every node; `stop` is set when a required node dies. `log_dir` takes the stdout
    /// of `output="log"` nodes.
    pub(crate) fn start(nodes: Vec<NodeProcess>, stop: Arc<AtomicBool>, log_dir: &Path) -> Self {
        let mut procs = Vec::with_capacity(nodes.len());
        for spec in nodes {
            let mut running = Running {
                spec,
                child: None,
                pipes: Vec::new(),
                restart_at: None,
                starts: 0,
            };
            running.spawn(log_dir);
            procs.push(running);
        }
        let procs = Arc::new(Mutex::new(procs));
        let stopping = Arc::new(AtomicBool::new(false));
        let required_exit = Arc::new(Mutex::new(None));
        let supervisor = {
            let watch = Watch {
                stop,
                required_exit: Arc::clone(&required_exit),
                log_dir: log_dir.to_path_buf(),
            };
            let (procs, stopping) = (Arc::clone(&procs), Arc::clone(&stopping));
            std::thread::Builder::new()
                .name("launch-supervisor".into())
                .spawn(move || supervise(&procs, &stopping, &watch))
                .ok()
        };
        Self {
            procs,
            stopping,
            supervisor,
            required_exit,
        }
    }

    /// Why a `required="true"` node stopped the launch, when one did.
    pub(crate) fn required_exit(&self) -> Option<String> {
        self.required_exit.lock().ok().and_then(|r| r.clone())
    }

    /// Stops every node (SIGINT, SIGTERM after 15 s, SIGKILL after 2 s more), in reverse
    /// order of start, and waits for their output to be printed.
    pub(crate) fn stop(&mut self) {
        self.stopping.store(true, Ordering::SeqCst);
        if let Some(h) = self.supervisor.take() {
            let _ = h.join();
        }
        let mut procs = match self.procs.lock() {
            Ok(p) => p,
            Err(poisoned) => poisoned.into_inner(),
        };
        let alive = |procs: &mut Vec<Running>| {
            procs
                .iter_mut()
                .filter_map(|p| p.child.as_mut())
                .any(|c| matches!(c.try_wait(), Ok(None)))
        };
        for (signal, wait) in [
            (nix::sys::signal::Signal::SIGINT, SIGINT_WAIT),
            (nix::sys::signal::Signal::SIGTERM, SIGTERM_WAIT),
            (nix::sys::signal::Signal::SIGKILL, SIGTERM_WAIT),
        ] {
            if !alive(&mut procs) {
                break;
            }
            for p in procs.iter_mut().rev() {
                if let Some(child) = p.child.as_mut()
                    && matches!(child.try_wait(), Ok(None))
                {
                    if signal != nix::sys::signal::Signal::SIGINT {
                        tracing::warn!("[{}] still running; sending {signal}", p.spec.node.name);
                    }
                    send(child, signal);
                }
            }
            let start = Instant::now();
            while alive(&mut procs) && start.elapsed() < wait {
                std::thread::sleep(POLL);
            }
        }
        for p in procs.iter_mut() {
            if let Some(mut child) = p.child.take() {
                let _ = child.wait();
            }
            for h in p.pipes.drain(..) {
                let _ = h.join();
            }
        }
    }
}

impl Drop for Children {
    fn drop(&mut self) {
        self.stop();
    }
}

impl Running {
    fn spawn(&mut self, log_dir: &Path) {
        let spec = &self.spec;
        let name = spec.node.name.clone();
        let Some((program, args)) = spec.command.split_first() else {
            return;
        };
        let mut cmd = Command::new(program);
        cmd.args(args)
            .envs(spec.env.iter().map(|(k, v)| (k, v)))
            // Python buffers stdout into a pipe; roslaunch's nodes write to a terminal.
            .env("PYTHONUNBUFFERED", "1")
            .current_dir(&spec.cwd)
            .stdin(Stdio::inherit())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        match cmd.spawn() {
            Ok(mut child) => {
                self.starts += 1;
                let to_log = (spec.node.output == Output::Log).then(|| {
                    log_dir.join(format!("{}-{}-stdout.log", sanitize(&name), self.starts))
                });
                if let Some(out) = child.stdout.take() {
                    self.pipes
                        .push(pipe(name.clone(), out, Sink::stdout(to_log)));
                }
                if let Some(err) = child.stderr.take() {
                    self.pipes.push(pipe(name.clone(), err, Sink::Stderr));
                }
                tracing::debug!("[{name}] started: {}", spec.command.join(" "));
                self.child = Some(child);
            }
            Err(e) => {
                tracing::warn!("[{name}] cannot start {}: {e}", spec.command.join(" "));
                self.child = None;
            }
        }
    }
}

fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '-'
            }
        })
        .collect()
}

/// What the supervisor needs besides the processes.
struct Watch {
    /// The run's stop flag (set when a required node exits).
    stop: Arc<AtomicBool>,
    required_exit: Arc<Mutex<Option<String>>>,
    log_dir: PathBuf,
}

fn supervise(procs: &Mutex<Vec<Running>>, stopping: &AtomicBool, w: &Watch) {
    while !stopping.load(Ordering::SeqCst) {
        if let Ok(mut procs) = procs.lock() {
            for p in procs.iter_mut() {
                watch(p, w);
            }
        }
        std::thread::sleep(POLL);
    }
}

/// Reports a node that exited, and starts it again when it should.
fn watch(p: &mut Running, w: &Watch) {
    let stop = &w.stop;
    if let Some(at) = p.restart_at
        && Instant::now() >= at
        && !stop.load(Ordering::SeqCst)
    {
        p.restart_at = None;
        say!("[{}] respawning", p.spec.node.name);
        p.spawn(&w.log_dir);
        return;
    }
    let Some(child) = p.child.as_mut() else {
        return;
    };
    let Ok(Some(status)) = child.try_wait() else {
        return;
    };
    let pid = child.id();
    p.child = None;
    let node = &p.spec.node;
    if status.success() {
        say!("[{}] process has finished cleanly (pid {pid})", node.name);
    } else {
        tracing::warn!(
            "[{}] process has died [pid {pid}, {status}, cmd {}] ({})",
            node.name,
            p.spec.command.join(" "),
            node.at
        );
    }
    if node.required {
        let why = format!(
            "required node {} exited ({status}; {}): the launch stopped",
            node.full_name(),
            node.at
        );
        tracing::warn!("{why}");
        if let Ok(mut r) = w.required_exit.lock() {
            r.get_or_insert(why);
        }
        stop.store(true, Ordering::SeqCst);
    } else if node.respawn && !stop.load(Ordering::SeqCst) {
        p.restart_at = Some(Instant::now() + Duration::from_secs_f64(node.respawn_delay_s));
    }
}

enum Sink {
    Stdout,
    Stderr,
    File(std::fs::File, PathBuf),
}

impl Sink {
    fn stdout(log: Option<PathBuf>) -> Self {
        let Some(path) = log else {
            return Self::Stdout;
        };
        match std::fs::File::create(&path) {
            Ok(f) => Self::File(f, path),
            Err(e) => {
                tracing::warn!("cannot write {}: {e}; printing it instead", path.display());
                Self::Stdout
            }
        }
    }
}

/// A thread copying a child's output, line by line, prefixed with `[name]`.
fn pipe(name: String, stream: impl Read + Send + 'static, mut sink: Sink) -> JoinHandle<()> {
    std::thread::spawn(move || {
        let mut reader = BufReader::new(stream);
        let mut line = Vec::new();
        loop {
            line.clear();
            match reader.read_until(b'\n', &mut line) {
                Ok(0) | Err(_) => break,
                Ok(_) => {}
            }
            let text = String::from_utf8_lossy(&line);
            let text = text.trim_end_matches(['\n', '\r']);
            let failed = match &mut sink {
                Sink::Stdout => {
                    let _ = writeln!(std::io::stdout().lock(), "[{name}] {text}");
                    None
                }
                Sink::Stderr => {
                    let _ = writeln!(std::io::stderr().lock(), "[{name}] {text}");
                    None
                }
                Sink::File(f, path) => writeln!(f, "{text}")
                    .err()
                    .map(|e| format!("cannot write {}: {e}; printing it instead", path.display())),
            };
            if let Some(why) = failed {
                tracing::warn!("{why}");
                sink = Sink::Stdout;
            }
        }
    })
}
