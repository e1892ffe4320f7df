//! Large reliable samples (the detection image) written one at a time: the next is written
//! once every matched reader has acknowledged the last, and the newest sample waiting wins.
//!
//! Why: RustDDS 0.15.1 sends a fragmented sample as 256-byte fragments, back to back (see
//! [`crate::bulk`]). A 640x480 image is ~3,600 of them; a Fast DDS subscriber's socket at the
//! OS's default receive buffer loses most of a burst it does not drain at once, and asks for
//! them again (NACK_FRAG). RustDDS repairs eight fragments a round, every 10 ms: an image takes
//! seconds to repair. When the publisher writes the next image before that, its burst is lost
//! as well and the repairs of both compete: measured, a default rclpy subscriber got no
//! detection image in 20 s. Writing the next image only once the last is acknowledged (or
//! [`ACK_WAIT`] has passed) lets the repair finish; a subscriber then gets an image every few
//! seconds at worst, and each one it gets is whole and in order, as reliability promises.
//! Between acknowledgements, newer samples replace the one waiting (keep last 1, as the
//! topic's history says).

use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rustdds::{GUID, RTPSEntity};

use crate::dds::Writer;
use crate::error::{Context, Result};
use crate::msgs::RosMessage;

/// The longest a written sample holds back the next one (a reader that stopped acknowledging
/// is not waited for longer).
pub const ACK_WAIT: Duration = Duration::from_secs(5);

/// How long one wait for the acknowledgement lasts before a stop is looked for.
const ACK_STEP: Duration = Duration::from_millis(100);

/// The sample waiting, and whether to stop.
struct Slot<M> {
    next: Option<M>,
    stop: bool,
}

/// The slot and its signal.
struct Shared<M> {
    slot: Mutex<Slot<M>>,
    ready: Condvar,
}

impl<M> Shared<M> {
    fn lock(&self) -> MutexGuard<'_, Slot<M>> {
        self.slot.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// A reliable writer of `M` whose thread writes one sample at a time, each after the last was
/// acknowledged (or after [`ACK_WAIT`]).
pub struct AckedWriter<M: RosMessage> {
    guid: GUID,
    shared: Arc<Shared<M>>,
    thread: Option<JoinHandle<()>>,
}

impl<M: RosMessage + Send + 'static> AckedWriter<M> {
    /// Wraps RustDDS's reliable `writer`; `name` names the writing thread.
    pub fn new(writer: Writer<M>, name: &str) -> Result<Self> {
        let guid = writer.guid();
        let shared = Arc::new(Shared {
            slot: Mutex::new(Slot {
                next: None,
                stop: false,
            }),
            ready: Condvar::new(),
        });
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name(format!("dds {name}"))
                .spawn(move || write_samples(&shared, &writer))
                .context("starting a writing thread")?
        };
        Ok(Self {
            guid,
            shared,
            thread: Some(thread),
        })
    }

    /// The writer's GUID (what discovery announces).
    pub fn guid(&self) -> GUID {
        self.guid
    }

    /// Hands `msg` to the writing thread: it replaces a sample still waiting there.
    pub fn write(&self, msg: M) {
        self.shared.lock().next = Some(msg);
        self.shared.ready.notify_one();
    }
}

impl<M: RosMessage> Drop for AckedWriter<M> {
    fn drop(&mut self) {
        self.shared.lock().stop = true;
        self.shared.ready.notify_one();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The writing thread: the newest sample, then a wait for its acknowledgement, until told to
/// stop.
fn write_samples<M: RosMessage>(shared: &Shared<M>, writer: &Writer<M>) {
    let mut warned = false;
    loop {
        let msg = {
            let mut slot = shared.lock();
            loop {
                if slot.stop {
                    return;
                }
                if let Some(msg) = slot.next.take() {
                    break msg;
                }
                slot = shared
                    .ready
                    .wait(slot)
                    .unwrap_or_else(PoisonError::into_inner);
            }
        };
        if let Err(e) = writer.write(msg, None) {
            if !std::mem::replace(&mut warned, true) {
                tracing::warn!("ROS 2: a sample could not be written ({e}); the run goes on");
            }
            continue;
        }
        // Not acknowledged in time: the next sample goes anyway (RustDDS keeps repairing).
        // The wait is in steps, so a stop is not held up by it.
        let started = Instant::now();
        while started.elapsed() < ACK_WAIT && !shared.lock().stop {
            if matches!(writer.wait_for_acknowledgments(ACK_STEP), Ok(true)) {
                break;
            }
        }
    }
}
