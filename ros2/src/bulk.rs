//! Large best-effort samples (images, point clouds) sent in fragments of [`FRAGMENT_BYTES`],
//! paced, instead of RustDDS's.
//!
//! Why rover writes these datagrams itself: RustDDS 0.15.1 cuts every fragmented sample into
//! 256-byte fragments (a constant of the crate) packed into datagrams of the MTU of the
//! interface whose subnet holds the reader's address — 1,400 bytes here, though a reader on the
//! same machine is reached through the loopback device. A 640x480 rgb8 image is then ~700
//! datagrams and 3,600 fragments; a Fast DDS subscriber at the OS's default receive buffer
//! (208 KiB) lost three images in four of them (docs/ROS2.md, "Large samples"), where Fast
//! DDS's own writers send the same image in datagrams of up to 64 KB.
//!
//! RustDDS still owns the writer: it announces it (SEDP), matches readers by topic and QoS and
//! reports each match (a report lost to its status channel, which holds four, is made good
//! every second from discovery's readers of the topic). For each matched reader whose UDP
//! address discovery gives, this module
//! writes the RTPS message itself (header, INFO_DST, INFO_TS, then one DATA, or one DATA_FRAG
//! per datagram; RTPS 2.5 sections 8.3.7 and 9.4.5) from its own socket, with the writer's GUID
//! and its own sequence numbers; a reader with no UDP address (a shared-memory or multicast
//! only peer) gets the sample from RustDDS, to that reader alone.

use std::net::{SocketAddr, UdpSocket};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use byteorder::LittleEndian;
use rustdds::policy::{Durability, Reliability};
use rustdds::{
    DataWriterStatus, DomainParticipant, GUID, RTPSEntity, StatusEvented, TopicDescription,
    WriteOptionsBuilder,
};

use crate::dds::Writer;
use crate::error::{Context, Result};
use crate::msgs::RosMessage;

/// Serialized-payload bytes per fragment. A datagram of these (84 bytes of RTPS headers
/// added) fills a 16 KiB kernel buffer: the receiver's socket holds ~12 of them in the OS's
/// default 208 KiB, where 64 KB datagrams take 128 KiB each and only one or two fit.
pub const FRAGMENT_BYTES: usize = 15_900;

/// The slowest pace of a sample's datagrams, bytes per second: a 640x480 rgb8 image goes out
/// in ~31 ms, about the time between two images at 30 Hz. A writer whose samples come faster
/// than this carries them is paced faster ([`Pace`]).
///
/// Why no faster: the receiver's socket (208 KiB at the OS's default) must be drained while
/// the sample arrives, and on a busy machine its thread waits for a core. Measured with an
/// rclpy subscriber beside three busy loops on this 2-core machine (app/tests/rclpy.rs, the
/// side-by-side test): of 30 images a second, 17-29 % arrived at 60 MB/s, 63-75 % at 30 MB/s,
/// 53-68 % at 35 MB/s, 69-73 % at 25 MB/s (where a 30 Hz camera no longer fits).
pub const PACE_FLOOR_BYTES_PER_S: f64 = 30e6;

/// The share of the time between a writer's samples that one sample's datagrams are spread
/// over (the rest is slack for a late sending thread).
const PACE_SPREAD: f64 = 0.9;

/// How much of each new interval between samples enters the smoothed one (an exponential
/// moving average: a camera's jitter does not swing the pace).
const PACE_SMOOTHING: f64 = 0.2;

/// A writer's pace: each sample spread over [`PACE_SPREAD`] of the time between its samples
/// (smoothed), at no less than [`PACE_FLOOR_BYTES_PER_S`].
#[derive(Debug, Default)]
pub(crate) struct Pace {
    last: Option<Instant>,
    interval_s: Option<f64>,
}

impl Pace {
    /// The pace, bytes per second, of a sample of `bytes` written at `now`.
    pub(crate) fn next(&mut self, bytes: usize, now: Instant) -> f64 {
        if let Some(last) = self.last.replace(now) {
            let dt_s = now.saturating_duration_since(last).as_secs_f64();
            self.interval_s = Some(match self.interval_s {
                Some(interval_s) => interval_s + PACE_SMOOTHING * (dt_s - interval_s),
                None => dt_s,
            });
        }
        match self.interval_s {
            Some(interval_s) if interval_s > 0.0 => {
                (bytes as f64 / (PACE_SPREAD * interval_s)).max(PACE_FLOOR_BYTES_PER_S)
            }
            _ => PACE_FLOOR_BYTES_PER_S,
        }
    }
}

/// How often a matched reader whose address is not yet known is looked up again.
const LOOKUP_EVERY: Duration = Duration::from_secs(1);

/// RTPS submessage ids (RTPS 2.5, 9.4.5.1.1).
const INFO_TS: u8 = 0x09;
const INFO_DST: u8 = 0x0e;
const DATA: u8 = 0x15;
const DATA_FRAG: u8 = 0x16;
/// Submessage flags: E (little-endian), Q (inline QoS follows), and DATA's D (data present).
const FLAG_LITTLE_ENDIAN: u8 = 0x01;
const FLAG_INLINE_QOS: u8 = 0x02;
const FLAG_DATA: u8 = 0x04;
/// The CDR little-endian encapsulation (RTPS 2.5, 10.2) that starts each serialized payload.
pub(crate) const CDR_LE: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// One matched reader: where its datagrams go (`None`: not known yet).
#[derive(Debug)]
pub(crate) struct Reader {
    pub guid: GUID,
    pub to: Option<SocketAddr>,
}

/// The readers RustDDS matched to a writer of `topic` (best effort and volatile, or reliable
/// and transient local), with their UDP addresses as discovery gives them.
#[derive(Debug)]
pub(crate) struct Matched {
    pub readers: Vec<Reader>,
    /// The writer's DDS topic.
    topic: String,
    /// The writer is reliable and transient local (it matches any reader of the topic), not
    /// best effort and volatile.
    reliable_writer: bool,
    last_lookup: Option<Instant>,
}

impl Matched {
    /// None yet, for a best-effort, volatile writer of `topic` (`reliable_writer`: a
    /// reliable, transient-local one).
    pub fn new(topic: &str, reliable_writer: bool) -> Self {
        Self {
            readers: Vec::new(),
            topic: topic.to_owned(),
            reliable_writer,
            last_lookup: None,
        }
    }

    /// Takes the writer's match and unmatch statuses.
    pub fn follow(&mut self, statuses: impl Iterator<Item = DataWriterStatus>) {
        for status in statuses {
            if let DataWriterStatus::PublicationMatched {
                current, reader, ..
            } = status
            {
                self.readers.retain(|r| r.guid != reader);
                if current.count_change() > 0 {
                    self.readers.push(Reader {
                        guid: reader,
                        to: None,
                    });
                    self.last_lookup = None;
                }
            }
        }
    }

    /// At most every [`LOOKUP_EVERY`] (at once after a new match): the readers discovery has
    /// of the topic that the writer matches (what a lost match report left out comes in; one
    /// gone from discovery goes), and each one's address.
    pub fn look_up(&mut self, participant: &DomainParticipant) {
        if self.last_lookup.is_some_and(|t| t.elapsed() < LOOKUP_EVERY) {
            return;
        }
        self.last_lookup = Some(Instant::now());
        let discovered = participant.discovered_readers();
        self.readers.retain(|r| {
            discovered
                .iter()
                .any(|d| d.reader_proxy.remote_reader_guid == r.guid)
        });
        for d in &discovered {
            let qos = d.subscription_topic_data.qos();
            let durability_fits = if self.reliable_writer {
                matches!(
                    qos.durability(),
                    None | Some(Durability::Volatile | Durability::TransientLocal)
                )
            } else {
                matches!(qos.durability(), None | Some(Durability::Volatile))
                    && !matches!(qos.reliability(), Some(Reliability::Reliable { .. }))
            };
            let matches = d.subscription_topic_data.topic_name() == &self.topic && durability_fits;
            let guid = d.reader_proxy.remote_reader_guid;
            if matches && !self.readers.iter().any(|r| r.guid == guid) {
                self.readers.push(Reader { guid, to: None });
            }
        }
        for reader in self.readers.iter_mut().filter(|r| r.to.is_none()) {
            reader.to = discovered
                .iter()
                .find(|d| d.reader_proxy.remote_reader_guid == reader.guid)
                .and_then(|d| first_udp_v4(&d.reader_proxy.unicast_locator_list));
            if let Some(to) = reader.to {
                tracing::debug!("ROS 2: reader {:?} at {to}", reader.guid);
            }
        }
    }
}

/// The first IPv4 UDP address among discovery's `locators` (RustDDS's locators turn into
/// socket addresses; the other kinds become IPv6's unspecified address).
pub(crate) fn first_udp_v4<L: Copy + Into<SocketAddr>>(locators: &[L]) -> Option<SocketAddr> {
    locators
        .iter()
        .map(|l| (*l).into())
        .find(|a: &SocketAddr| a.is_ipv4() && a.port() != 0)
}

/// One sample to send: its writer's GUID, serialized payload (CDR encapsulation first),
/// sequence number, source time, inline QoS (a serialized parameter list with its sentinel;
/// empty: none) and readers (GUID, address).
#[derive(Default)]
pub(crate) struct Job {
    pub writer: [u8; 16],
    pub payload: Vec<u8>,
    pub sequence: i64,
    pub stamp: (u32, u32),
    pub inline_qos: Vec<u8>,
    pub readers: Vec<([u8; 16], SocketAddr)>,
    /// How fast its datagrams go out, bytes per second to each reader.
    pub pace_bytes_per_s: f64,
}

/// What the publishing side hands the sending thread: the newest job (an older one not yet
/// started is dropped, as best effort allows), spare jobs to reuse, and whether to stop.
#[derive(Default)]
struct Handoff {
    next: Option<Job>,
    spare: Vec<Job>,
    stop: bool,
}

/// The hand-off and its signal.
#[derive(Default)]
struct Shared {
    handoff: Mutex<Handoff>,
    ready: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Handoff> {
        self.handoff.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// A best-effort writer of `M` whose samples travel in [`FRAGMENT_BYTES`] fragments, paced
/// ([`Pace`]) by a thread of their own (the newest sample wins).
pub struct BulkWriter<M: RosMessage> {
    writer: Writer<M>,
    participant: DomainParticipant,
    matched: Matched,
    /// The last sequence number used, on either path (so a reader moved from RustDDS's path to
    /// this one never sees a number go back).
    sequence: i64,
    pace: Pace,
    shared: Arc<Shared>,
    sender: Option<JoinHandle<()>>,
    /// A send or write failed (said once).
    warned: bool,
}

impl<M: RosMessage> BulkWriter<M> {
    /// Wraps RustDDS's `writer` (best effort, created on `participant`); `name` names the
    /// sending thread.
    pub fn new(participant: &DomainParticipant, writer: Writer<M>, name: &str) -> Result<Self> {
        let socket = UdpSocket::bind(("0.0.0.0", 0)).context("opening a UDP socket")?;
        let shared = Arc::new(Shared::default());
        let sender = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name(format!("dds {name}"))
                .spawn(move || send_jobs(&shared, &socket))
                .context("starting a sending thread")?
        };
        let matched = Matched::new(&writer.topic().name(), false);
        Ok(Self {
            writer,
            participant: participant.clone(),
            matched,
            sequence: 0,
            pace: Pace::default(),
            shared,
            sender: Some(sender),
            warned: false,
        })
    }

    /// The writer's GUID (what discovery announces).
    pub fn guid(&self) -> GUID {
        self.writer.guid()
    }

    /// The readers matched now, and how many of them this writer sends to itself (the others,
    /// whose UDP address is not known, get RustDDS's datagrams).
    pub fn matched(&mut self) -> (usize, usize) {
        self.follow_matches();
        let readers = &self.matched.readers;
        let direct = readers.iter().filter(|r| r.to.is_some()).count();
        (readers.len(), direct)
    }

    /// Takes RustDDS's matches and unmatches.
    fn follow_matches(&mut self) {
        let writer = &self.writer;
        self.matched
            .follow(std::iter::from_fn(|| writer.try_recv_status()));
    }
}

impl<M: RosMessage + Clone> BulkWriter<M> {
    /// Writes `msg` to every matched reader: an error if it cannot be serialized; a failed
    /// write is one warning per writer.
    pub fn write(&mut self, msg: &M) -> Result<()> {
        self.follow_matches();
        self.matched.look_up(&self.participant);
        self.sequence += 1;
        let readers = &self.matched.readers;
        if readers.iter().any(|r| r.to.is_some()) {
            let mut job = self.shared.lock().spare.pop().unwrap_or_default();
            job.payload.clear();
            job.payload.extend_from_slice(&CDR_LE);
            rustdds::cdr_encoding::to_writer::<M, LittleEndian, _>(&mut job.payload, msg)
                .context("serializing a sample")?;
            job.writer = self.writer.guid().to_bytes();
            job.sequence = self.sequence;
            job.stamp = rtps_time(SystemTime::now());
            job.pace_bytes_per_s = self.pace.next(job.payload.len(), Instant::now());
            job.inline_qos.clear();
            job.readers.clear();
            job.readers.extend(
                readers
                    .iter()
                    .filter_map(|r| Some((r.guid.to_bytes(), r.to?))),
            );
            let mut handoff = self.shared.lock();
            if let Some(old) = handoff.next.replace(job) {
                handoff.spare.push(old);
            }
            drop(handoff);
            self.shared.ready.notify_one();
        }
        for reader in readers.iter().filter(|r| r.to.is_none()) {
            let only_it = WriteOptionsBuilder::new()
                .to_single_reader(reader.guid)
                .build();
            match self.writer.write_with_options(msg.clone(), only_it) {
                // RustDDS numbers each write: ours never fall behind its.
                Ok(written) => {
                    self.sequence = self.sequence.max(i64::from(written.sequence_number));
                }
                Err(e) => {
                    if !std::mem::replace(&mut self.warned, true) {
                        tracing::warn!("ROS 2: a sample could not be written ({e})");
                    }
                }
            }
        }
        Ok(())
    }
}

impl<M: RosMessage> Drop for BulkWriter<M> {
    fn drop(&mut self) {
        self.shared.lock().stop = true;
        self.shared.ready.notify_one();
        if let Some(sender) = self.sender.take() {
            let _ = sender.join();
        }
    }
}

/// The sending thread: each newest job, paced, until told to stop (what is queued is sent).
fn send_jobs(shared: &Shared, socket: &UdpSocket) {
    let mut datagram = Vec::with_capacity(FRAGMENT_BYTES + 128);
    let mut warned = false;
    loop {
        let job = {
            let mut handoff = shared.lock();
            loop {
                if let Some(job) = handoff.next.take() {
                    break job;
                }
                if handoff.stop {
                    return;
                }
                handoff = shared
                    .ready
                    .wait(handoff)
                    .unwrap_or_else(PoisonError::into_inner);
            }
        };
        if let Err(e) = send(
            &job,
            socket,
            &mut datagram,
            BULK_CUT,
            Some(job.pace_bytes_per_s),
        ) && !std::mem::replace(&mut warned, true)
        {
            tracing::warn!("ROS 2: a sample could not be sent ({e}); the run goes on");
        }
        shared.lock().spare.push(job);
    }
}
/// How a sample is cut for the wire: the fragment size its DATA_FRAGs announce, and how many
/// fragments go in one datagram (one DATA_FRAG submessage).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cut {
    pub fragment_bytes: usize,
    pub per_datagram: usize,
}

/// This module's cut: one [`FRAGMENT_BYTES`] fragment a datagram.
pub(crate) const BULK_CUT: Cut = Cut {
    fragment_bytes: FRAGMENT_BYTES,
    per_datagram: 1,
};

/// Sends `job`'s sample to each of its readers: one DATA when it fits a datagram, else one
/// DATA_FRAG per datagram of `cut`, datagram by datagram to every reader, paced at
/// `pace_bytes_per_s` to each (`None`: at once).
pub(crate) fn send(
    job: &Job,
    socket: &UdpSocket,
    d: &mut Vec<u8>,
    cut: Cut,
    pace_bytes_per_s: Option<f64>,
) -> std::io::Result<()> {
    let sample_bytes = job.payload.len();
    let datagram_bytes = cut.fragment_bytes * cut.per_datagram;
    let fragments = sample_bytes.div_ceil(cut.fragment_bytes).max(1);
    let datagrams = sample_bytes.div_ceil(datagram_bytes).max(1);
    let started = Instant::now();
    let mut sent_bytes = 0usize;
    for datagram in 0..datagrams {
        let first = datagram * cut.per_datagram;
        let start = first * cut.fragment_bytes;
        let end = (start + datagram_bytes).min(sample_bytes);
        let frags = Frags {
            first,
            count: (end - start).div_ceil(cut.fragment_bytes).max(1),
            total: fragments,
            size: cut.fragment_bytes,
        };
        for (reader, to) in &job.readers {
            message(d, job, *reader, frags, (start, end));
            socket.send_to(d, to)?;
        }
        // Each reader's socket drains on its own: the pace is per reader.
        sent_bytes += d.len();
        // Ahead of the pace: wait until the bytes sent so far are due.
        if let Some(pace) = pace_bytes_per_s
            && datagram + 1 < datagrams
            && let Some(ahead) =
                Duration::from_secs_f64(sent_bytes as f64 / pace).checked_sub(started.elapsed())
        {
            std::thread::sleep(ahead);
        }
    }
    Ok(())
}

/// The fragments one datagram carries: from `first` (0-based), `count` of them, of `total`
/// fragments of `size` bytes.
#[derive(Clone, Copy)]
struct Frags {
    first: usize,
    count: usize,
    total: usize,
    size: usize,
}

/// Writes into `d` the RTPS message that carries bytes `start..end` of `job`'s payload,
/// the fragments `frags` (a whole sample, one DATA, when `frags.total` is 1), to `reader`.
fn message(
    d: &mut Vec<u8>,
    job: &Job,
    reader: [u8; 16],
    frags: Frags,
    (start, end): (usize, usize),
) {
    let writer = &job.writer;
    d.clear();
    // Header: protocol, version 2.4, vendor (RustDDS's), the writer's GUID prefix.
    d.extend_from_slice(b"RTPS");
    d.extend_from_slice(&[2, 4, 0x01, 0x12]);
    d.extend_from_slice(&writer[..12]);
    submessage_header(d, INFO_DST, FLAG_LITTLE_ENDIAN, 12);
    d.extend_from_slice(&reader[..12]);
    submessage_header(d, INFO_TS, FLAG_LITTLE_ENDIAN, 8);
    d.extend_from_slice(&job.stamp.0.to_le_bytes());
    d.extend_from_slice(&job.stamp.1.to_le_bytes());
    let qos = &job.inline_qos;
    let q = if qos.is_empty() { 0 } else { FLAG_INLINE_QOS };
    if frags.total == 1 {
        let length = 20 + qos.len() + (end - start);
        submessage_header(d, DATA, FLAG_LITTLE_ENDIAN | FLAG_DATA | q, length);
        d.extend_from_slice(&0u16.to_le_bytes()); // extra flags
        d.extend_from_slice(&16u16.to_le_bytes()); // octets from here to the inline QoS
    } else {
        let length = 32 + qos.len() + (end - start);
        submessage_header(d, DATA_FRAG, FLAG_LITTLE_ENDIAN | q, length);
        d.extend_from_slice(&0u16.to_le_bytes());
        d.extend_from_slice(&28u16.to_le_bytes());
    }
    d.extend_from_slice(&reader[12..]);
    d.extend_from_slice(&writer[12..]);
    d.extend_from_slice(&((job.sequence >> 32) as i32).to_le_bytes());
    d.extend_from_slice(&(job.sequence as u32).to_le_bytes());
    if frags.total > 1 {
        d.extend_from_slice(&(frags.first as u32 + 1).to_le_bytes()); // 1-based
        d.extend_from_slice(&(frags.count as u16).to_le_bytes()); // fragments in this submessage
        d.extend_from_slice(&(frags.size as u16).to_le_bytes());
        d.extend_from_slice(&(job.payload.len() as u32).to_le_bytes());
    }
    d.extend_from_slice(qos);
    d.extend_from_slice(&job.payload[start..end]);
}

/// Appends a submessage header: `id`, `flags`, and the length of what follows it.
fn submessage_header(d: &mut Vec<u8>, id: u8, flags: u8, length: usize) {
    d.push(id);
    d.push(flags);
    d.extend_from_slice(&(length as u16).to_le_bytes());
}

/// `t` as RTPS's Time_t: seconds since the Unix epoch and fractions of 2^-32 s.
pub(crate) fn rtps_time(t: SystemTime) -> (u32, u32) {
    let since = t.duration_since(UNIX_EPOCH).unwrap_or_default();
    let fraction = (u64::from(since.subsec_nanos()) << 32) / 1_000_000_000;
    (since.as_secs() as u32, fraction as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pace of `bytes`-byte samples written every `interval`, after `n` of them.
    fn pace_after(bytes: usize, interval: Duration, n: u32) -> f64 {
        let mut pace = Pace::default();
        let start = Instant::now();
        (0..n).fold(0.0, |_, k| pace.next(bytes, start + interval * k))
    }

    #[test]
    fn a_sample_is_spread_over_most_of_the_time_to_the_next_at_no_less_than_the_floor() {
        let image_rgb8 = 640 * 480 * 3;
        let image_32fc1 = 640 * 480 * 4;
        let at_30_hz = Duration::from_secs_f64(1.0 / 30.0);
        // The first sample knows no interval: the floor.
        assert_eq!(pace_after(image_rgb8, at_30_hz, 1), PACE_FLOOR_BYTES_PER_S);
        // 30 rgb8 images a second: 0.9 of 33 ms each.
        let rgb8 = pace_after(image_rgb8, at_30_hz, 30);
        assert!(
            (rgb8 - 30.0 * image_rgb8 as f64 / 0.9).abs() < 1e3,
            "{rgb8}"
        );
        let sending_s = image_rgb8 as f64 / rgb8;
        assert!(sending_s < at_30_hz.as_secs_f64(), "{sending_s}");
        // A depth image, a third larger, faster.
        assert!(pace_after(image_32fc1, at_30_hz, 30) > 1.3 * rgb8);
        // One image a second: the floor, not 0.9 s an image.
        let slow = pace_after(image_rgb8, Duration::from_secs(1), 10);
        assert_eq!(slow, PACE_FLOOR_BYTES_PER_S);
        // Samples in one instant (no interval) take the floor.
        assert_eq!(
            pace_after(image_rgb8, Duration::ZERO, 5),
            PACE_FLOOR_BYTES_PER_S
        );
    }
}
