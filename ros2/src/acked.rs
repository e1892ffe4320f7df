//! Large reliable samples (the detection image): paced, and one at a time.
//!
//! Why: RustDDS 0.15.1 sends a fragmented sample as 256-byte fragments, back to back (see
//! [`crate::bulk`]). A 640x480 image is ~3,600 of them in ~700 datagrams; a Fast DDS
//! subscriber's socket at the OS's default receive buffer loses most of a burst it does not
//! drain at once, and asks for the fragments again (NACK_FRAG). RustDDS repairs eight fragments
//! a round, every 10 ms, so an image takes seconds to repair, and the next image's burst is
//! lost the same way: measured, a default rclpy subscriber got no detection image in 20 s.
//!
//! So, sample by sample, on a thread of its own:
//! - the sample goes first to each matched reader whose UDP address discovery gives, from this
//!   module's socket, in datagrams of 62 of RustDDS's 256-byte fragments (the same fragment
//!   size and numbering, so RustDDS's repairs fit what the reader holds), paced at
//!   [`PACE_FLOOR_BYTES_PER_S`], with the sequence number RustDDS gives it next;
//! - then RustDDS writes it: it numbers it, keeps it, sends its own copy (a reader that has
//!   the sample already drops it), announces it with heartbeats and repairs what a reader
//!   still lacks; a reader with no UDP address gets RustDDS's copy alone;
//! - the next sample is written once every matched reader has acknowledged this one (or after
//!   [`ACK_WAIT`]); newer samples replace the one waiting (keep last 1, as the topic's history
//!   says).

use std::net::UdpSocket;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use byteorder::LittleEndian;
use rustdds::{
    DomainParticipant, GUID, RTPSEntity, StatusEvented, TopicDescription, WriteOptionsBuilder,
};

use crate::bulk::{self, CDR_LE, Cut, Job, Matched, PACE_FLOOR_BYTES_PER_S, rtps_time};
use crate::dds::Writer;
use crate::error::{Context, Result};
use crate::msgs::RosMessage;

/// RustDDS's fragment size (its constant `FRAGMENT_SIZE`), 62 to a datagram: 15,872 bytes,
/// a datagram that fills a 16 KiB kernel buffer, as [`crate::bulk`]'s do.
const CUT: Cut = Cut {
    fragment_bytes: 256,
    per_datagram: 62,
};

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

/// A reliable writer of `M` whose thread sends each sample paced, then writes it through
/// RustDDS and waits for its acknowledgement (at most [`ACK_WAIT`]).
pub struct AckedWriter<M: RosMessage> {
    guid: GUID,
    shared: Arc<Shared<M>>,
    thread: Option<JoinHandle<()>>,
}

impl<M: RosMessage + Send + 'static> AckedWriter<M> {
    /// Wraps RustDDS's reliable, transient-local `writer`, created on `participant`; `name`
    /// names the writing thread.
    pub fn new(participant: &DomainParticipant, writer: Writer<M>, name: &str) -> Result<Self> {
        let guid = writer.guid();
        let socket = UdpSocket::bind(("0.0.0.0", 0)).context("opening a UDP socket")?;
        let shared = Arc::new(Shared {
            slot: Mutex::new(Slot {
                next: None,
                stop: false,
            }),
            ready: Condvar::new(),
        });
        let mut sender = Sender {
            matched: Matched::new(&writer.topic().name(), true),
            participant: participant.clone(),
            writer,
            socket,
            job: Job::default(),
            datagram: Vec::with_capacity(CUT.fragment_bytes * CUT.per_datagram + 128),
            sequence: 0,
            warned: false,
        };
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name(format!("dds {name}"))
                .spawn(move || sender.run(&shared))
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

/// What the writing thread owns.
struct Sender<M: RosMessage> {
    matched: Matched,
    participant: DomainParticipant,
    writer: Writer<M>,
    socket: UdpSocket,
    /// The sample being sent (its buffers reused).
    job: Job,
    datagram: Vec<u8>,
    /// The sequence number RustDDS gave the last sample.
    sequence: i64,
    /// A write or send failed (said once).
    warned: bool,
}

impl<M: RosMessage> Sender<M> {
    /// The newest sample, sent and written, then a wait for its acknowledgement, until told
    /// to stop.
    fn run(&mut self, shared: &Shared<M>) {
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
            if let Err(e) = self.send_paced(&msg) {
                self.warn(&format!("a sample could not be sent ({e})"));
            }
            match self
                .writer
                .write_with_options(msg, WriteOptionsBuilder::new().build())
            {
                Ok(written) => {
                    let sequence = i64::from(written.sequence_number);
                    if sequence != self.sequence + 1 {
                        self.warn(&format!(
                            "RustDDS numbered a sample {sequence}, not {} as sent",
                            self.sequence + 1
                        ));
                    }
                    self.sequence = sequence;
                }
                Err(e) => {
                    self.warn(&format!("a sample could not be written ({e})"));
                    continue;
                }
            }
            // Not acknowledged in time: the next sample goes anyway (RustDDS keeps
            // repairing). The wait is in steps, so a stop is not held up by it.
            let started = Instant::now();
            while started.elapsed() < ACK_WAIT && !shared.lock().stop {
                if matches!(self.writer.wait_for_acknowledgments(ACK_STEP), Ok(true)) {
                    break;
                }
            }
        }
    }

    /// Sends `msg`, numbered as RustDDS numbers it next, to each matched reader with a UDP
    /// address, paced.
    fn send_paced(&mut self, msg: &M) -> Result<()> {
        let writer = &self.writer;
        self.matched
            .follow(std::iter::from_fn(|| writer.try_recv_status()));
        self.matched.look_up(&self.participant);
        let job = &mut self.job;
        job.readers.clear();
        job.readers.extend(
            self.matched
                .readers
                .iter()
                .filter_map(|r| Some((r.guid.to_bytes(), r.to?))),
        );
        if job.readers.is_empty() {
            return Ok(());
        }
        job.payload.clear();
        job.payload.extend_from_slice(&CDR_LE);
        rustdds::cdr_encoding::to_writer::<M, LittleEndian, _>(&mut job.payload, msg)
            .context("serializing a sample")?;
        job.writer = writer.guid().to_bytes();
        // RustDDS numbers a writer's samples 1, 2, ...: this writer writes them all.
        job.sequence = self.sequence + 1;
        job.stamp = rtps_time(SystemTime::now());
        job.inline_qos.clear();
        bulk::send(
            job,
            &self.socket,
            &mut self.datagram,
            CUT,
            Some(PACE_FLOOR_BYTES_PER_S),
        )
        .context("sending a sample")
    }

    fn warn(&mut self, what: &str) {
        if !std::mem::replace(&mut self.warned, true) {
            tracing::warn!("ROS 2: {what}; the run goes on");
        }
    }
}
