//! `/rosout` (rcl_interfaces/msg/Log), as every rclcpp and rclpy node has it: what rover logs
//! (the lines of rover's own crates it prints on stderr, as `RUST_LOG` filters them; not its
//! libraries', as a node's middleware logs stay out of `/rosout`) goes to ROS 2 as well, so
//! `ros2 topic echo /rosout` and rqt_console show rover's warnings beside the other nodes'.
//!
//! The tracing layer ([`layer`], installed with the log's formatter at start) copies each
//! event into a bounded channel while a `--ros2` bridge listens ([`Rosout::create`]
//! registers it); the bridge's publishing thread drains it at every control update and when it
//! ends, writing each line with rcl's `/rosout` QoS (reliable, transient local, keep last
//! 1000). A full channel drops lines rather than wait: logging never blocks the run.

use std::fmt::Write as _;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError};
use std::sync::{Mutex, PoisonError};
use std::time::{SystemTime, UNIX_EPOCH};

use anyhow::Result;
use rustdds::{DomainParticipant, GUID, RTPSEntity};
use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::layer::{Context, Layer};

use crate::bridge::events::{ControlUpdate, TopicFamily};
use rover_ros2::dds::{Writer, rosout_qos, writer};
use rover_ros2::msgs::{Log, Time};

/// The topic.
const ROSOUT_TOPIC: &str = "/rosout";

/// Lines waiting for the publishing thread, at most (more are dropped).
const WAITING_LINES: usize = 256;

/// Where the layer sends lines: the listening bridge's channel and its number, if one
/// listens (a bridge that ends takes its own channel away, not a newer bridge's).
static LISTENER: Mutex<Option<(u64, SyncSender<Log>)>> = Mutex::new(None);

/// The number the next listening bridge gets.
static NEXT_LISTENER: AtomicU64 = AtomicU64::new(0);

/// Stops listener `id`, unless another took its place.
fn stop_listening(id: u64) {
    let mut listener = LISTENER.lock().unwrap_or_else(PoisonError::into_inner);
    if listener.as_ref().is_some_and(|(current, _)| *current == id) {
        *listener = None;
    }
}

/// The tracing layer that copies rover's log lines to `/rosout` while a ROS 2 bridge listens.
pub struct RosoutLayer;

/// The layer to install beside the log's formatter (it does nothing until `--ros2` listens).
pub fn layer() -> RosoutLayer {
    RosoutLayer
}

impl<S: Subscriber> Layer<S> for RosoutLayer {
    fn on_event(&self, event: &Event<'_>, _ctx: Context<'_, S>) {
        // rover's own lines, as rcl sends a node's: not its libraries' (RustDDS's log stays
        // on stderr, as Fast DDS's does).
        if !event.metadata().target().starts_with("rover") {
            return;
        }
        let listener = LISTENER.lock().unwrap_or_else(PoisonError::into_inner);
        let Some((id, to)) = listener.as_ref() else {
            return;
        };
        let meta = event.metadata();
        let mut text = Text::default();
        event.record(&mut text);
        let since = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .unwrap_or_default();
        let line = Log {
            stamp: Time {
                sec: i32::try_from(since.as_secs()).unwrap_or(i32::MAX),
                nanosec: since.subsec_nanos(),
            },
            level: level_of(*meta.level()),
            name: String::new(),
            msg: text.0,
            file: meta.file().unwrap_or_default().to_owned(),
            function: meta.module_path().unwrap_or_default().to_owned(),
            line: meta.line().unwrap_or_default(),
        };
        // Full: the line is dropped; gone: the bridge ended (it unregisters as it goes).
        if let Err(TrySendError::Disconnected(_)) = to.try_send(line) {
            let id = *id;
            drop(listener);
            stop_listening(id);
        }
    }
}

/// rcl_interfaces/msg/Log's level for a tracing level (trace is debug).
fn level_of(level: Level) -> u8 {
    match level {
        Level::ERROR => Log::ERROR,
        Level::WARN => Log::WARN,
        Level::INFO => Log::INFO,
        Level::DEBUG | Level::TRACE => Log::DEBUG,
    }
}

/// An event's text: its message, then its other fields as `name=value`.
#[derive(Default)]
struct Text(String);

impl Visit for Text {
    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        if field.name() == "message" {
            let _ = write!(self.0, "{value:?}");
        } else {
            let sep = if self.0.is_empty() { "" } else { " " };
            let _ = write!(self.0, "{sep}{}={value:?}", field.name());
        }
    }

    fn record_str(&mut self, field: &Field, value: &str) {
        if field.name() == "message" {
            self.0.push_str(value);
        } else {
            self.record_debug(field, &value);
        }
    }
}

/// `/rosout`'s writer on the publishing thread, and the lines coming to it.
pub(super) struct Rosout {
    /// Its number as the listener.
    id: u64,
    writer: Writer<Log>,
    lines: Receiver<Log>,
    /// The logger's name: the node's (`rover`; `ns.rover` in a namespace, as rcl names it).
    name: String,
    /// A write failed (said once).
    warned: bool,
}

impl Rosout {
    /// Creates `/rosout`'s writer for the node `node_name` (`/ns/rover`) and starts listening
    /// to rover's log; the writer's GUID for `ros_discovery_info`.
    pub fn create(
        participant: &DomainParticipant,
        publisher: &rustdds::Publisher,
        node_name: &str,
    ) -> Result<(Self, GUID)> {
        let writer = writer::<Log>(participant, publisher, ROSOUT_TOPIC, &rosout_qos())?;
        let guid = writer.guid();
        let (to, lines) = std::sync::mpsc::sync_channel(WAITING_LINES);
        let id = NEXT_LISTENER.fetch_add(1, Ordering::Relaxed);
        *LISTENER.lock().unwrap_or_else(PoisonError::into_inner) = Some((id, to));
        let name = node_name.trim_start_matches('/').replace('/', ".");
        Ok((
            Self {
                id,
                writer,
                lines,
                name,
                warned: false,
            },
            guid,
        ))
    }

    /// Writes the lines that came. A write that fails (a reader that stopped acknowledging
    /// holds the writer's window full: rcl's QoS, keep last 1000, reliable) drops the lines
    /// waiting, at once: `/rosout` never holds the publishing thread up.
    fn drain(&mut self) {
        while let Ok(mut line) = self.lines.try_recv() {
            line.name.clone_from(&self.name);
            if let Err(e) = self.writer.write(line, None) {
                let dropped = self.lines.try_iter().count();
                if !std::mem::replace(&mut self.warned, true) {
                    tracing::warn!(
                        "ROS 2: {ROSOUT_TOPIC} could not be written ({e}); {dropped} lines \
                         dropped (said once)"
                    );
                }
                return;
            }
        }
    }
}

impl TopicFamily for Rosout {
    fn control(&mut self, _update: &ControlUpdate) {
        self.drain();
    }
}

impl Drop for Rosout {
    fn drop(&mut self) {
        stop_listening(self.id);
        self.drain();
    }
}
