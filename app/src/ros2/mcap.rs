//! `--record-mcap FILE`: what the ROS 2 bridge publishes, written as ROS 2 writes a bag — an
//! MCAP file (the `mcap` crate, Foxglove's own) with one channel per topic, CDR messages
//! (`cdr`, little-endian with its 4-byte encapsulation header, as on the wire) and `ros2msg`
//! schemas carrying each type's definition ([`rover_ros2::definitions`]). Log and publish times are
//! the messages' sim-time stamps in nanoseconds. Chunks are LZ4-compressed: cheap on the CPU
//! the loop needs, and read by every MCAP reader.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use byteorder::LittleEndian;
use mcap::records::MessageHeader;

use rover_ros2::definitions::ros_type_name;
use rover_ros2::msgs::{RosMessage, Time};

/// CDR little-endian's encapsulation header (representation id 0x0001, options 0).
const CDR_LE_HEADER: [u8; 4] = [0, 1, 0, 0];

/// An MCAP file being written.
pub(super) struct McapRecorder {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    /// The serialized message, reused.
    buffer: Vec<u8>,
    sequence: u32,
    /// A write failed (said once); nothing more is written.
    failed: bool,
}

/// What a finished recording holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct McapSummary {
    /// Messages written.
    pub messages: u64,
    /// Channels (topics).
    pub channels: u32,
}

impl McapRecorder {
    /// Creates `path` (replacing a file there).
    pub(super) fn create(path: &Path) -> Result<Self> {
        let file = File::create(path)
            .with_context(|| format!("cannot create the MCAP file {}", path.display()))?;
        let writer = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Lz4))
            .profile("ros2")
            .library(concat!("rover ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .with_context(|| format!("cannot start the MCAP file {}", path.display()))?;
        Ok(Self {
            writer,
            path: path.to_owned(),
            buffer: Vec::new(),
            sequence: 0,
            failed: false,
        })
    }

    /// A channel for messages `M` on the ROS topic `ros_name`, with `M`'s schema.
    pub(super) fn channel<M: RosMessage>(&mut self, ros_name: &str) -> Result<u16> {
        let schema = self
            .writer
            .add_schema(
                &ros_type_name(M::DDS_TYPE),
                "ros2msg",
                M::DEFINITION.as_bytes(),
            )
            .with_context(|| format!("MCAP: adding the schema of {ros_name}"))?;
        self.writer
            .add_channel(schema, ros_name, "cdr", &BTreeMap::new())
            .with_context(|| format!("MCAP: adding the channel {ros_name}"))
    }

    /// Writes `msg` on `channel`, stamped `stamp`. A failure (disk full) is said once and ends
    /// the recording; the run goes on.
    pub(super) fn write<M: RosMessage>(&mut self, channel: u16, stamp: Time, msg: &M) {
        if self.failed {
            return;
        }
        self.buffer.clear();
        self.buffer.extend_from_slice(&CDR_LE_HEADER);
        let result = rustdds::cdr_encoding::to_writer::<M, LittleEndian, _>(&mut self.buffer, msg)
            .map_err(anyhow::Error::from)
            .and_then(|()| {
                let time_ns = u64::try_from(stamp.sec).unwrap_or(0) * 1_000_000_000
                    + u64::from(stamp.nanosec);
                let header = MessageHeader {
                    channel_id: channel,
                    sequence: self.sequence,
                    log_time: time_ns,
                    publish_time: time_ns,
                };
                self.sequence = self.sequence.wrapping_add(1);
                Ok(self.writer.write_to_known_channel(&header, &self.buffer)?)
            });
        if let Err(e) = result {
            self.failed = true;
            tracing::error!(
                "MCAP: writing {} failed ({e:#}); the recording stops here",
                self.path.display()
            );
        }
    }

    /// Writes the summary and closes the file.
    pub(super) fn finish(mut self) -> Result<McapSummary> {
        let summary = self
            .writer
            .finish()
            .with_context(|| format!("MCAP: finishing {}", self.path.display()))?;
        anyhow::ensure!(
            !self.failed,
            "MCAP: {} was not written in full (see the error above)",
            self.path.display()
        );
        let stats = summary.stats.unwrap_or_default();
        Ok(McapSummary {
            messages: stats.message_count,
            channels: stats.channel_count,
        })
    }
}
