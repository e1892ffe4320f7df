//! Where the ROS 2 encoders put their messages: each topic's DDS writer (`--ros2`) and MCAP
//! channel (`--record-mcap`), either or both, with the QoS ROS 2 nodes expect.

use std::sync::{Arc, Mutex, PoisonError};

use anyhow::Result;
use rustdds::policy::Reliability;
use rustdds::{DomainParticipant, GUID, QosPolicies, RTPSEntity};

use super::mcap::McapRecorder;
use rover_ros2::acked::AckedWriter;
use rover_ros2::bulk::BulkWriter;
use rover_ros2::dds::{Writer, writer};
pub(super) use rover_ros2::dds::{latched_qos, sensor_qos};
use rover_ros2::msgs::{self, Header, Lent, RosMessage, Time};

/// The MCAP file, shared by every topic's channel on the publishing thread.
pub(super) type Recorder = Arc<Mutex<McapRecorder>>;

/// A header in `frame_id`, stamped when published.
pub(super) fn header(frame_id: &str) -> Header {
    Header {
        stamp: Time::default(),
        frame_id: frame_id.to_owned(),
    }
}

/// A topic's DDS writer: RustDDS's; for best-effort topics (whose samples may be large) the
/// one that sends paced 16 KB fragments (rover_ros2::bulk); for reliable topics of large
/// samples, the one that writes each after the last was acknowledged (rover_ros2::acked).
enum Dds<M: RosMessage> {
    Plain(Writer<M>),
    Bulk(BulkWriter<M>),
    Acked(AckedWriter<M>),
}

/// One topic: where its messages go.
pub(super) struct Out<M: RosMessage> {
    ros_name: String,
    dds: Option<Dds<M>>,
    mcap: Option<(Recorder, u16)>,
    /// A DDS write failed (said once).
    warned: bool,
}

impl<M: RosMessage + Clone> Out<M> {
    /// Puts `msg`, stamped `stamp`, on the topic: into the MCAP file, then to DDS (RustDDS
    /// takes what it writes, so DDS gets a copy). A failed DDS write is one warning per topic.
    pub fn put(&mut self, stamp: Time, msg: &M) {
        if let Some((file, channel)) = &self.mcap {
            file.lock()
                .unwrap_or_else(PoisonError::into_inner)
                .write(*channel, stamp, msg);
        }
        let written = match &mut self.dds {
            Some(Dds::Plain(w)) => w.write(msg.clone(), None).map_err(|e| e.to_string()),
            Some(Dds::Bulk(w)) => w.write(msg).map_err(|e| e.to_string()),
            Some(Dds::Acked(w)) => {
                // The writing thread holds the copy a while (an image's buffer then goes
                // to it, and the image pool makes a new one: one per detection image).
                w.write(msg.clone());
                Ok(())
            }
            None => Ok(()),
        };
        if let Err(e) = written
            && !std::mem::replace(&mut self.warned, true)
        {
            tracing::warn!(
                "ROS 2: writing {} failed ({e}); the run goes on",
                self.ros_name
            );
        }
    }
}

impl Out<msgs::Image> {
    /// Puts `data` (`encoding`, `(width, height)`) as an Image with `header`: lent to the
    /// message, back in `data` once it is written.
    pub fn put_image(
        &mut self,
        header: &Header,
        (width, height): (u32, u32),
        encoding: &str,
        data: &mut Vec<u8>,
    ) {
        let bytes_per_px = if encoding == "32FC1" { 4 } else { 3 };
        let lent = Lent::new(std::mem::take(data));
        let msg = msgs::Image {
            header: header.clone(),
            height,
            width,
            encoding: encoding.to_owned(),
            is_bigendian: 0,
            step: width * bytes_per_px,
            data: lent.clone(),
        };
        self.put(header.stamp, &msg);
        drop(msg);
        // A buffer still held elsewhere is let go; the pool makes a new one.
        *data = lent.take_back().unwrap_or_default();
    }
}

/// What the topics are created on.
pub(super) struct Sinks<'a> {
    /// The DDS participant and its publisher, with `--ros2`.
    pub dds: Option<(&'a DomainParticipant, &'a rustdds::Publisher)>,
    /// The MCAP file, with `--record-mcap`.
    pub mcap: Option<Recorder>,
    /// The DDS writers made so far (for `ros_discovery_info`).
    pub writers: Vec<GUID>,
}

impl Sinks<'_> {
    /// The topic `ros_name` of messages `M` on every sink, with `qos` on DDS.
    pub fn out<M: RosMessage + Send + 'static>(
        &mut self,
        ros_name: &str,
        qos: &QosPolicies,
    ) -> Result<Out<M>> {
        self.out_sized(ros_name, qos, false)
    }

    /// [`Self::out`] for a topic whose samples are large (images): a reliable one writes each
    /// sample once the last was acknowledged (rover_ros2::acked).
    pub fn out_large<M: RosMessage + Send + 'static>(
        &mut self,
        ros_name: &str,
        qos: &QosPolicies,
    ) -> Result<Out<M>> {
        self.out_sized(ros_name, qos, true)
    }

    fn out_sized<M: RosMessage + Send + 'static>(
        &mut self,
        ros_name: &str,
        qos: &QosPolicies,
        large: bool,
    ) -> Result<Out<M>> {
        let dds = match self.dds {
            Some((participant, publisher)) => {
                let w = writer(participant, publisher, ros_name, qos)?;
                self.writers.push(w.guid());
                Some(if qos.reliability() == Some(Reliability::BestEffort) {
                    Dds::Bulk(BulkWriter::new(participant, w, ros_name)?)
                } else if large {
                    Dds::Acked(AckedWriter::new(participant, w, ros_name)?)
                } else {
                    Dds::Plain(w)
                })
            }
            None => None,
        };
        let mcap = match &self.mcap {
            Some(file) => {
                let channel = file
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .channel::<M>(ros_name)?;
                Some((Arc::clone(file), channel))
            }
            None => None,
        };
        Ok(Out {
            ros_name: ros_name.to_owned(),
            dds,
            mcap,
            warned: false,
        })
    }

    /// The topic `ros_name`, or none (`None`).
    pub fn maybe<M: RosMessage + Send + 'static>(
        &mut self,
        ros_name: Option<&str>,
        qos: &QosPolicies,
    ) -> Result<Option<Out<M>>> {
        ros_name.map(|name| self.out(name, qos)).transpose()
    }
}
