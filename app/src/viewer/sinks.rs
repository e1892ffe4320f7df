//! Where a recording goes: viewer modes (`--viewer`), `--record` files, the web viewer server,
//! and a watch that notices a viewer has gone away without slowing the loop.

use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{Context, Result};
use rerun::external::re_uri::ProxyUri;
use rerun::sink::{FileSink, GrpcSink, LogSink};

use super::images::ImageOptions;

/// The rerun SDK version rover is built with; a viewer must match it.
pub const RERUN_VERSION: &str = "0.36.3";

/// Where the recording goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Viewer {
    /// Start the native viewer (`rerun` on PATH) and stream to it.
    Spawn,
    /// Stream to a running viewer at this gRPC URL (`rerun+http://host:port/proxy`).
    Connect(String),
    /// Serve the web viewer from rover itself and print its URL.
    Web,
    /// Write an .rrd file only.
    Save(PathBuf),
    /// No viewer.
    None,
}

impl Viewer {
    /// Parses `--viewer MODE [ARG]`.
    pub fn parse(words: &[String]) -> Result<Self> {
        let arg = words.get(1).cloned();
        let mode = words.first().map(String::as_str).unwrap_or("none");
        Ok(match (mode, arg) {
            ("spawn", None) => Viewer::Spawn,
            ("web", None) => Viewer::Web,
            ("none", None) => Viewer::None,
            ("connect", url) => {
                Viewer::Connect(url.unwrap_or_else(|| rerun::DEFAULT_CONNECT_URL.to_owned()))
            }
            ("save", Some(path)) => Viewer::Save(PathBuf::from(path)),
            ("save", None) => anyhow::bail!("--viewer save needs a file: --viewer save run.rrd"),
            (m @ ("spawn" | "web" | "none"), Some(extra)) => {
                anyhow::bail!("--viewer {m} takes no argument, found '{extra}'")
            }
            (other, _) => anyhow::bail!(
                "--viewer '{other}' is unknown; expected spawn, connect [URL], web, save FILE.rrd or none"
            ),
        })
    }
}

/// Recorder settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RecorderOptions {
    /// Viewer mode.
    pub viewer: Viewer,
    /// Also record to this .rrd file.
    pub record: Option<PathBuf>,
    /// Write the .rrd footer (rerun keeps a per-chunk index in memory until the end for it).
    pub footer: bool,
    /// Image logging.
    pub images: ImageOptions,
    /// Web viewer (HTTP) port.
    pub web_port: u16,
    /// gRPC port of the web viewer's data server.
    pub grpc_port: u16,
}

impl Default for RecorderOptions {
    fn default() -> Self {
        Self {
            viewer: Viewer::None,
            record: None,
            footer: true,
            images: ImageOptions::default(),
            web_port: 9090,
            grpc_port: 9876,
        }
    }
}

/// What `rerun --version` on PATH says, if there is one.
pub fn viewer_on_path() -> Option<String> {
    let out = std::process::Command::new("rerun")
        .arg("--version")
        .stdin(std::process::Stdio::null())
        .output()
        .ok()?;
    out.status.success().then(|| {
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .nth(1)
            .unwrap_or("")
            .to_owned()
    })
}

/// The pip command that installs the matching viewer.
pub fn pip_command() -> String {
    format!("pip install rerun-sdk=={RERUN_VERSION}")
}

/// Picks the default viewer: the native one when a matching `rerun` is on PATH, else the web
/// viewer. Returns the choice and why.
pub fn default_viewer() -> (Viewer, String) {
    match viewer_on_path() {
        Some(v) if v == RERUN_VERSION => {
            (Viewer::Spawn, format!("found the Rerun viewer {v} on PATH"))
        }
        Some(v) => (
            Viewer::Web,
            format!(
                "the Rerun viewer on PATH is {v} but rover speaks {RERUN_VERSION}: `{}` to use the native viewer; serving the web viewer instead",
                pip_command()
            ),
        ),
        None => (
            Viewer::Web,
            format!(
                "no Rerun viewer on PATH (`{}` installs it); serving the web viewer instead",
                pip_command()
            ),
        ),
    }
}

/// The sinks of a recording, and what must live as long as it.
pub(super) struct Sinks {
    /// Viewer and file sinks.
    pub sinks: Vec<Box<dyn LogSink>>,
    /// Watches a streamed-to viewer.
    pub watch: Option<ViewerWatch>,
    /// Where the web viewer is, when serving it.
    pub web_url: Option<String>,
    /// The web viewer server (serves until dropped).
    pub web_server: Option<Box<dyn std::any::Any>>,
}

/// Opens what `options` asks for. `Ok(None)` when there is nothing to record to.
pub(super) fn open(options: &RecorderOptions) -> Result<Option<Sinks>> {
    if options.viewer == Viewer::None && options.record.is_none() {
        return Ok(None);
    }
    let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
    let mut files = Vec::new();
    if let Some(path) = &options.record {
        files.push(path.clone());
    }
    let mut watch = None;
    let mut web_url = None;
    let mut web_server: Option<Box<dyn std::any::Any>> = None;
    match &options.viewer {
        Viewer::None => {}
        Viewer::Save(path) => files.push(path.clone()),
        Viewer::Spawn => {
            if let Some(v) = viewer_on_path()
                && v != RERUN_VERSION
            {
                tracing::warn!(
                    "the Rerun viewer on PATH is {v}, rover streams {RERUN_VERSION}: run `{}`",
                    pip_command()
                );
            }
            let spawn = rerun::SpawnOptions {
                wait_for_bind: true,
                hide_welcome_screen: true,
                memory_limit: "50%".into(),
                ..rerun::SpawnOptions::default()
            };
            let info = rerun::spawn(&spawn).with_context(|| {
                format!(
                    "cannot start the Rerun viewer (`{}` installs it; or use --viewer web)",
                    pip_command()
                )
            })?;
            tracing::info!(
                "Rerun viewer started (pid {}, port {})",
                info.child_pid
                    .map_or_else(|| "?".to_owned(), |p| p.to_string()),
                info.port
            );
            let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
            sinks.push(Box::new(NonBlocking::new(GrpcSink::new(proxy_uri(&url)?))));
            watch = resolve("127.0.0.1", info.port).map(ViewerWatch::start);
        }
        Viewer::Connect(url) => {
            let uri = proxy_uri(url)?;
            let (host, port) =
                host_port(url).unwrap_or(("127.0.0.1".into(), rerun::DEFAULT_SERVER_PORT));
            // Resolved once, here, not on the loop thread: the watch then only dials an address.
            let addr = resolve(&host, port).filter(connects);
            let Some(addr) = addr else {
                anyhow::bail!(
                    "no Rerun viewer answers at {url}: start one with `rerun` (`{}`), or use --viewer web",
                    pip_command()
                );
            };
            sinks.push(Box::new(NonBlocking::new(GrpcSink::new(uri))));
            watch = Some(ViewerWatch::start(addr));
        }
        Viewer::Web => {
            let grpc = rerun::grpc_server::GrpcServerSink::new(
                "127.0.0.1",
                options.grpc_port,
                rerun::ServerOptions {
                    // The history kept for browsers that connect late. A fixed bound (not a
                    // share of RAM) keeps a long window session's memory flat: the window's
                    // stream (~3 MB/s) fills it in under a minute, after which the oldest data
                    // goes; a connected browser keeps its own copy.
                    memory_limit: rerun::MemoryLimit::from_bytes(WEB_HISTORY_BYTES),
                    ..rerun::ServerOptions::default()
                },
            )
            .context("cannot start the Rerun data server for the web viewer")?;
            sinks.push(Box::new(NonBlocking::new(grpc)));
            let connect = format!("rerun+http://127.0.0.1:{}/proxy", options.grpc_port);
            let server = rerun::serve_web_viewer(rerun::web_viewer::WebViewerConfig {
                bind_ip: "127.0.0.1".into(),
                web_port: options.web_port.into(),
                connect_to: vec![connect.clone()],
                open_browser: false,
                ..Default::default()
            })
            .with_context(|| format!("cannot serve the web viewer on port {}", options.web_port))?;
            web_url = Some(format!(
                "{}/?url={}",
                server.server_url(),
                connect.replace('+', "%2B")
            ));
            web_server = Some(Box::new(server));
        }
    }
    for path in &files {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
        }
        sinks.push(Box::new(
            FileSink::with_options(
                path,
                rerun::sink::FileSinkOptions {
                    write_footer: options.footer,
                },
            )
            .with_context(|| format!("cannot write {}", path.display()))?,
        ));
    }
    Ok(Some(Sinks {
        sinks,
        watch,
        web_url,
        web_server,
    }))
}

/// A viewer sink that never blocks the recording stream, and so never the loop: rerun applies
/// back-pressure from a slow viewer (a browser on a busy CPU) all the way back to the logging
/// call, which stalled the window's simulation for seconds in soak runs. Messages go through a
/// bounded queue to a thread that feeds the real sink (which may block there); when the queue
/// is full the new message is dropped for that viewer and counted, with one warning. `.rrd`
/// files are not wrapped: a recording stays complete.
pub struct NonBlocking {
    /// `None` only while dropping (to end the feeder thread before joining it).
    tx: Option<mpsc::SyncSender<SinkCommand>>,
    dropped: std::sync::atomic::AtomicU64,
    thread: Option<JoinHandle<()>>,
}

enum SinkCommand {
    Msg(Box<rerun::log::LogMsg>),
    Flush(
        Duration,
        mpsc::SyncSender<std::result::Result<(), rerun::sink::SinkFlushError>>,
    ),
}

impl NonBlocking {
    /// Messages (chunks, ~1 MB at most for a raw camera image) waiting for a slow viewer.
    const QUEUE: usize = 64;

    /// Feeds `inner` from its own thread.
    pub fn new(inner: impl LogSink + 'static) -> Self {
        let (tx, rx) = mpsc::sync_channel::<SinkCommand>(Self::QUEUE);
        let thread = std::thread::Builder::new()
            .name("rerun-viewer-feed".into())
            .spawn(move || {
                for command in rx {
                    match command {
                        SinkCommand::Msg(msg) => inner.send(*msg),
                        SinkCommand::Flush(timeout, reply) => {
                            let _ = reply.send(inner.flush_blocking(timeout));
                        }
                    }
                }
                // The inner sink (and a web viewer's data server) lives until the recording
                // stream is dropped.
            })
            .ok();
        Self {
            tx: Some(tx),
            dropped: Default::default(),
            thread,
        }
    }
}

impl LogSink for NonBlocking {
    fn send(&self, msg: rerun::log::LogMsg) {
        let Some(tx) = &self.tx else {
            return;
        };
        if let Err(mpsc::TrySendError::Full(_)) = tx.try_send(SinkCommand::Msg(Box::new(msg))) {
            let before = self.dropped.fetch_add(1, Ordering::Relaxed);
            if before == 0 {
                tracing::warn!(
                    "the Rerun viewer is not keeping up: dropping data for it rather than slowing the run (a --record file still gets everything)"
                );
            }
        }
    }

    fn flush_blocking(
        &self,
        timeout: Duration,
    ) -> std::result::Result<(), rerun::sink::SinkFlushError> {
        let Some(tx) = &self.tx else {
            return Ok(());
        };
        let (reply_tx, reply_rx) = mpsc::sync_channel(1);
        // Waiting here is fine: flushes happen at the end of a run, not in the loop.
        if tx.send(SinkCommand::Flush(timeout, reply_tx)).is_err() {
            return Ok(());
        }
        reply_rx
            // rerun flushes with `Duration::MAX` when finalizing: saturate, never overflow.
            .recv_timeout(timeout.saturating_add(Duration::from_secs(1)))
            .unwrap_or(Err(rerun::sink::SinkFlushError::Timeout))
    }
}

impl Drop for NonBlocking {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
        let dropped = self.dropped.load(Ordering::Relaxed);
        if dropped > 0 {
            tracing::info!("Rerun viewer: {dropped} messages dropped while it was behind");
        }
    }
}

/// History the web viewer's data server keeps (see above).
const WEB_HISTORY_BYTES: u64 = 64 << 20;

fn proxy_uri(url: &str) -> Result<ProxyUri> {
    url.parse::<ProxyUri>().map_err(|e| {
        anyhow::anyhow!(
            "'{url}' is not a Rerun gRPC URL ({e}); expected e.g. {}",
            rerun::DEFAULT_CONNECT_URL
        )
    })
}

/// Host and port of a `rerun+http://host:port/...` URL.
fn host_port(url: &str) -> Option<(String, u16)> {
    let rest = url.split("://").nth(1)?;
    let authority = rest.split('/').next()?;
    let (host, port) = authority.rsplit_once(':')?;
    let host = host.trim_start_matches('[').trim_end_matches(']');
    Some((host.to_owned(), port.parse().ok()?))
}

fn resolve(host: &str, port: u16) -> Option<SocketAddr> {
    (host, port).to_socket_addrs().ok()?.next()
}

fn connects(addr: &SocketAddr) -> bool {
    TcpStream::connect_timeout(addr, Duration::from_millis(500)).is_ok()
}

/// Probes a viewer's address every 2 s on its own thread; the loop only reads a flag.
pub(super) struct ViewerWatch {
    gone: Arc<AtomicBool>,
    stop: Option<Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl ViewerWatch {
    fn start(addr: SocketAddr) -> Self {
        let gone = Arc::new(AtomicBool::new(false));
        let (stop, stopped) = mpsc::channel::<()>();
        let flag = Arc::clone(&gone);
        let thread = std::thread::Builder::new()
            .name("rover-viewer-watch".into())
            .spawn(move || {
                loop {
                    match stopped.recv_timeout(Duration::from_secs(2)) {
                        Err(RecvTimeoutError::Timeout) => {}
                        Ok(()) | Err(RecvTimeoutError::Disconnected) => return,
                    }
                    if !connects(&addr) {
                        flag.store(true, Ordering::Relaxed);
                        return;
                    }
                }
            })
            .ok();
        Self {
            gone,
            stop: Some(stop),
            thread,
        }
    }

    /// True once the viewer stopped answering.
    pub fn gone(&self) -> bool {
        self.gone.load(Ordering::Relaxed)
    }
}

impl Drop for ViewerWatch {
    fn drop(&mut self) {
        drop(self.stop.take());
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The recording's path and size, for the summary `rover` prints after a run.
pub fn describe_file(path: &Path) -> String {
    match std::fs::metadata(path) {
        Ok(m) => format!("{} ({:.1} MB)", path.display(), m.len() as f64 / 1e6),
        Err(_) => path.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viewer_modes_parse_with_their_arguments() -> Result<()> {
        let p = |w: &[&str]| Viewer::parse(&w.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(p(&["spawn"])?, Viewer::Spawn);
        assert_eq!(p(&["web"])?, Viewer::Web);
        assert_eq!(
            p(&["connect"])?,
            Viewer::Connect(rerun::DEFAULT_CONNECT_URL.to_owned())
        );
        assert_eq!(p(&["save", "a.rrd"])?, Viewer::Save(PathBuf::from("a.rrd")));
        assert!(p(&["save"]).is_err());
        assert!(p(&["spawn", "x"]).is_err());
        let e = p(&["native"])
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("spawn, connect [URL], web, save FILE.rrd or none"),
            "{e}"
        );
        Ok(())
    }

    #[test]
    fn grpc_urls_give_host_and_port() {
        assert_eq!(
            host_port("rerun+http://127.0.0.1:9876/proxy"),
            Some(("127.0.0.1".to_owned(), 9876))
        );
        assert_eq!(
            host_port("rerun+http://viewer.lan:1234/proxy"),
            Some(("viewer.lan".to_owned(), 1234))
        );
        assert_eq!(
            host_port("rerun+http://[::1]:9876/proxy"),
            Some(("::1".to_owned(), 9876))
        );
        assert!(proxy_uri("http://localhost:9876").is_err());
    }

    #[test]
    fn the_watch_notices_a_listener_closing_and_dials_its_host() -> Result<()> {
        let listener = std::net::TcpListener::bind("127.0.0.1:0")?;
        let addr = listener.local_addr()?;
        let watch = ViewerWatch::start(addr);
        assert!(!watch.gone());
        drop(listener);
        // The thread probes every 2 s; wait for it without assuming how fast this machine is.
        let deadline = std::time::Instant::now() + Duration::from_secs(60);
        while !watch.gone() && std::time::Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(50));
        }
        assert!(watch.gone(), "the watch never noticed the viewer leaving");
        Ok(())
    }
}
