//! ROS 2 services over DDS. A service `/a/b` is a request topic `rq/a/bRequest` (type
//! `pkg::srv::dds_::Name_Request_`) and a reply topic `rr/a/bReply`
//! (`pkg::srv::dds_::Name_Response_`), reliable, volatile, keep last 10 (rmw's services QoS).
//! How a reply finds its request depends on the client's RMW, and rover reads each request the
//! way its client wrote it:
//!
//! - **rmw_fastrtps_cpp** (Fast DDS, ROS 2's default RMW): the payload is the request's fields
//!   alone; the request's id is its RTPS sample identity (the client's writer GUID and the
//!   sample's sequence number), and the client names its reply reader in the inline QoS
//!   `PID_RELATED_SAMPLE_IDENTITY`. The reply carries the request's sample identity back as its
//!   related sample identity, which is how the client matches it.
//! - **rmw_cyclonedds_cpp** (and plain Cyclone DDS peers): every request starts with a header,
//!   the client's id and the request's number (`uint64 guid; int64 seq`), and the reply carries
//!   the same header back in its payload.
//!
//! A request with a related sample identity is Fast DDS's; one without is Cyclone's. A request
//! that does not decode the way its mapping says is one warning per client (naming the mapping
//! and what was wrong) and no reply; the next request is read as usual.

use std::collections::HashSet;
use std::net::UdpSocket;
use std::time::SystemTime;

use crate::error::{Context, Result};
use rustdds::no_key::{DataReader, DataWriter, Decode, DefaultDecoder, DeserializerAdapter};
use rustdds::serialization::deserialize_from_cdr_with_rep_id;
use rustdds::{
    CDRSerializerAdapter, DomainParticipant, GUID, RTPSEntity, RepresentationIdentifier,
    SampleIdentity, TopicKind, WriteOptionsBuilder,
};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::bulk::{self, CDR_LE, Job, first_udp_v4, rtps_time};
use crate::dds::default_qos;

/// rmw_cyclonedds_cpp's request header: which client, which of its requests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RequestHeader {
    /// The client's id.
    pub guid: u64,
    /// The request's number.
    pub seq: i64,
}

/// A request or reply in Cyclone's mapping: the header, then the message's fields.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct WithHeader<T> {
    /// Which request.
    pub header: RequestHeader,
    /// The message.
    pub body: T,
}

/// Which request a reply answers, in the mapping its client used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RequestId {
    /// Cyclone's: the header from the request's payload, written back in the reply's.
    Cyclone(RequestHeader),
    /// Fast DDS's: the request's sample identity, written back as the reply's related one,
    /// and the client's reply reader (rmw_fastrtps_cpp names it in the request's related
    /// sample identity).
    FastDds {
        /// The request's sample identity.
        identity: SampleIdentity,
        /// The reader the reply is for.
        reply_reader: GUID,
    },
}

/// A service type: its request and response messages and their DDS type names.
pub trait ServiceType {
    /// The request's fields.
    type Request: DeserializeOwned + Send + 'static;
    /// The response's fields.
    type Response: Serialize + Clone + Send + 'static;
    /// `pkg::srv::dds_::Name_Request_`.
    const REQUEST_TYPE: &'static str;
    /// `pkg::srv::dds_::Name_Response_`.
    const RESPONSE_TYPE: &'static str;
}

/// A request as it came: its serialized payload and its encoding, decoded once its mapping is
/// known (the sample's inline QoS says which).
struct RawRequest {
    bytes: Vec<u8>,
    encoding: RepresentationIdentifier,
}

/// Keeps a request's bytes for [`Server::next_request`] to decode.
struct RawAdapter;

/// The encodings rover's CDR decoder reads (XCDR1, either byte order).
const RAW_ENCODINGS: [RepresentationIdentifier; 4] = [
    RepresentationIdentifier::CDR_LE,
    RepresentationIdentifier::CDR_BE,
    RepresentationIdentifier::PL_CDR_LE,
    RepresentationIdentifier::PL_CDR_BE,
];

impl DeserializerAdapter<RawRequest> for RawAdapter {
    type Error = std::convert::Infallible;
    type Decoded = RawRequest;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &RAW_ENCODINGS
    }

    fn transform_decoded(decoded: RawRequest) -> RawRequest {
        decoded
    }
}

/// [`RawAdapter`]'s decoder: a copy of the bytes.
#[derive(Clone, Copy)]
struct RawDecoder;

impl Decode<'_, RawRequest> for RawDecoder {
    type Error = std::convert::Infallible;

    fn decode_bytes(
        self,
        input_bytes: &[u8],
        encoding: RepresentationIdentifier,
    ) -> Result<RawRequest, Self::Error> {
        Ok(RawRequest {
            bytes: input_bytes.to_vec(),
            encoding,
        })
    }
}

impl DefaultDecoder<RawRequest> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}

/// A reply as its client's mapping writes it: with Cyclone's header, or the fields alone.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
enum Reply<T> {
    /// Cyclone's mapping.
    WithHeader(WithHeader<T>),
    /// Fast DDS's mapping (the id travels in the inline QoS).
    Bare(T),
    /// No fields: what RustDDS writes in place of a large reply rover sent itself.
    Placeholder,
}

/// One service's server: takes requests when polled, answers each at once or later.
pub struct Server<S: ServiceType> {
    name: String,
    requests: DataReader<RawRequest, RawAdapter>,
    replies: DataWriter<Reply<S::Response>, CDRSerializerAdapter<Reply<S::Response>>>,
    /// The sequence number of the reply writer's last sample (RustDDS numbers each admitted
    /// write, from 1).
    last_sequence: i64,
    /// Fast DDS replies too large for one RTPS DATA of RustDDS's.
    large: LargeReplies,
    /// The clients (request writers) already warned about.
    warned: HashSet<GUID>,
}

impl<S: ServiceType> Server<S> {
    /// Serves the service `ros_name` (`/rover/get_parameters`).
    pub fn new(
        participant: &DomainParticipant,
        subscriber: &rustdds::Subscriber,
        publisher: &rustdds::Publisher,
        ros_name: &str,
    ) -> Result<Self> {
        let name = ros_name.trim_start_matches('/');
        let qos = default_qos();
        let request_topic = participant
            .create_topic(
                format!("rq/{name}Request"),
                S::REQUEST_TYPE.to_owned(),
                &qos,
                TopicKind::NoKey,
            )
            .with_context(|| format!("creating the request topic of {ros_name}"))?;
        let reply_topic = participant
            .create_topic(
                format!("rr/{name}Reply"),
                S::RESPONSE_TYPE.to_owned(),
                &qos,
                TopicKind::NoKey,
            )
            .with_context(|| format!("creating the reply topic of {ros_name}"))?;
        Ok(Self {
            name: ros_name.to_owned(),
            requests: subscriber
                .create_datareader_no_key::<RawRequest, RawAdapter>(
                    &request_topic,
                    Some(qos.clone()),
                )
                .with_context(|| format!("creating the request reader of {ros_name}"))?,
            replies: publisher
                .create_datawriter_no_key(&reply_topic, Some(qos))
                .with_context(|| format!("creating the reply writer of {ros_name}"))?,
            last_sequence: 0,
            large: LargeReplies {
                participant: participant.clone(),
                socket: UdpSocket::bind(("0.0.0.0", 0)).context("opening a UDP socket")?,
                job: Job::default(),
                datagram: Vec::new(),
            },
            warned: HashSet::new(),
        })
    }

    /// The next request that came and decodes, if one did, with its id for the reply. A
    /// request that does not decode is one warning per client; the ones after it are read.
    pub fn next_request(&mut self) -> Option<(RequestId, S::Request)> {
        loop {
            let sample = match self.requests.take_next_sample() {
                Ok(Some(sample)) => sample,
                Ok(None) => return None,
                Err(e) => {
                    // Not tied to a client (the reader's own error): said once per service.
                    self.warn(
                        GUID::GUID_UNKNOWN,
                        &format!("a request could not be read ({e})"),
                    );
                    return None;
                }
            };
            let info = sample.sample_info();
            let client = info.writer_guid();
            let fast_dds = info
                .related_sample_identity()
                .map(|related| RequestId::FastDds {
                    identity: info.sample_identity(),
                    reply_reader: related.writer_guid,
                });
            let raw = sample.value();
            match decode_request::<S::Request>(raw, fast_dds) {
                Ok(request) => return Some(request),
                Err(what) => self.warn(client, &what),
            }
        }
    }

    /// Answers the request `id` names (now or later) with `body`, in its client's mapping.
    pub fn reply(&mut self, id: RequestId, body: S::Response) {
        let written = match id {
            RequestId::Cyclone(header) => self.replies.write_with_options(
                Reply::WithHeader(WithHeader { header, body }),
                WriteOptionsBuilder::new().build(),
            ),
            RequestId::FastDds {
                identity,
                reply_reader,
            } => {
                if self.large.serialize(&body) > MAX_FAST_DDS_REPLY_BYTES {
                    self.reply_large(identity, reply_reader);
                    return;
                }
                let options = WriteOptionsBuilder::new()
                    .related_sample_identity(identity)
                    .build();
                self.replies.write_with_options(Reply::Bare(body), options)
            }
        };
        match written {
            Ok(written) => self.last_sequence = i64::from(written.sequence_number),
            Err(e) => self.warn(
                GUID::GUID_UNKNOWN,
                &format!("a reply could not be sent ({e})"),
            ),
        }
    }

    /// A Fast DDS reply too large for one DATA (serialized in `self.large`): sent by rover as
    /// the reply writer's next sample to the client's reply reader ([`LargeReplies`]), then
    /// that sample number given to RustDDS with an empty placeholder for that reader alone,
    /// which it already holds and drops, so RustDDS's reliable bookkeeping and the reader's
    /// agree.
    fn reply_large(&mut self, identity: SampleIdentity, reader: GUID) {
        let sequence = self.last_sequence + 1;
        let sent = self
            .large
            .send(self.replies.guid(), sequence, identity, reader);
        if let Err(what) = sent {
            return self.warn(identity.writer_guid, &what);
        }
        let only_it = WriteOptionsBuilder::new().to_single_reader(reader).build();
        match self.replies.write_with_options(Reply::Placeholder, only_it) {
            Ok(written) => {
                self.last_sequence = i64::from(written.sequence_number);
                if self.last_sequence != sequence {
                    self.warn(
                        GUID::GUID_UNKNOWN,
                        &format!(
                            "a large reply went out as sample {sequence}, but RustDDS numbered \
                             it {}",
                            self.last_sequence
                        ),
                    );
                }
            }
            Err(e) => self.warn(
                GUID::GUID_UNKNOWN,
                &format!("a reply's placeholder could not be written ({e})"),
            ),
        }
    }

    /// Answers every request that came, with `answer`.
    pub fn serve(&mut self, mut answer: impl FnMut(S::Request) -> S::Response) {
        while let Some((id, request)) = self.next_request() {
            let body = answer(request);
            self.reply(id, body);
        }
    }

    fn warn(&mut self, client: GUID, what: &str) {
        if self.warned.insert(client) {
            if client == GUID::GUID_UNKNOWN {
                tracing::warn!("ROS 2 service {}: {what}; ignored", self.name);
            } else {
                tracing::warn!(
                    "ROS 2 service {}: {what} (client {:?}; said once per client); ignored",
                    self.name,
                    client.prefix
                );
            }
        }
    }

    /// The request reader's and reply writer's GUIDs, for `ros_discovery_info`.
    pub fn gids(&self) -> (GUID, GUID) {
        (self.requests.guid(), self.replies.guid())
    }
}

/// The largest reply RustDDS sends in Fast DDS's mapping: one that fits a single RTPS DATA
/// submessage on any IPv4 path (RustDDS packs up to the path's MTU, at least 1,280 bytes, less
/// headers and the inline QoS). A larger one would go out as DATA_FRAGs, which RustDDS 0.15.1
/// writes with a speedy `Option` tag byte before the inline QoS when a related sample identity
/// is set (`DataFrag::write_to`): Fast DDS cannot read them, and a debug build's assertion on
/// the submessage length stops the participant's event loop. Larger replies go through
/// [`LargeReplies`].
pub const MAX_FAST_DDS_REPLY_BYTES: usize = 1024;

/// RTPS parameter ids of a related sample identity: the standard one and Fast DDS's own (which
/// RustDDS also writes both of).
const PID_RELATED_SAMPLE_IDENTITY: [u16; 2] = [0x0083, 0x800f];
/// The parameter list's end.
const PID_SENTINEL: u16 = 0x0001;

/// Fast DDS replies larger than [`MAX_FAST_DDS_REPLY_BYTES`] (`robot_description` through
/// `get_parameters`), sent by rover itself as `rover_ros2::bulk` sends images: the reply
/// writer's next sample, from rover's own socket, to the client's reply reader (named in the
/// request; its address from discovery), with the related sample identity in each
/// submessage's inline QoS. Over one machine's loopback the few datagrams of a reply arrive;
/// one lost on a network is not repaired (RustDDS holds only the placeholder) and the client's
/// call times out.
struct LargeReplies {
    participant: DomainParticipant,
    socket: UdpSocket,
    /// The reply being answered: its payload, serialized by [`Self::serialize`], then the
    /// rest of its message.
    job: Job,
    datagram: Vec<u8>,
}

impl LargeReplies {
    /// Serializes `body` as a reply's payload (CDR, little endian, after its encapsulation);
    /// its size in bytes (`usize::MAX` when it does not serialize).
    fn serialize<R: Serialize>(&mut self, body: &R) -> usize {
        let payload = &mut self.job.payload;
        payload.clear();
        payload.extend_from_slice(&CDR_LE);
        match rustdds::cdr_encoding::to_writer::<R, byteorder::LittleEndian, _>(&mut *payload, body)
        {
            Ok(()) => payload.len(),
            Err(_) => usize::MAX,
        }
    }

    /// Sends the serialized reply as sample `sequence` of the writer `writer`, the reply to
    /// the request `identity` names, to `reader`; what went wrong, in words.
    fn send(
        &mut self,
        writer: GUID,
        sequence: i64,
        identity: SampleIdentity,
        reader: GUID,
    ) -> Result<(), String> {
        let to = self
            .participant
            .discovered_readers()
            .iter()
            .find(|d| d.reader_proxy.remote_reader_guid == reader)
            .and_then(|d| first_udp_v4(&d.reader_proxy.unicast_locator_list));
        let Some(to) = to else {
            return Err(format!(
                "a large reply to a Fast DDS client is not sent: its reply reader {reader:?} is \
                 not discovered, or has no UDP address"
            ));
        };
        let job = &mut self.job;
        job.readers.clear();
        job.readers.push((reader.to_bytes(), to));
        job.writer = writer.to_bytes();
        job.sequence = sequence;
        job.stamp = rtps_time(SystemTime::now());
        job.inline_qos.clear();
        let request = i64::from(identity.sequence_number);
        for pid in PID_RELATED_SAMPLE_IDENTITY {
            job.inline_qos.extend_from_slice(&pid.to_le_bytes());
            job.inline_qos.extend_from_slice(&24u16.to_le_bytes());
            job.inline_qos
                .extend_from_slice(&identity.writer_guid.to_bytes());
            job.inline_qos
                .extend_from_slice(&((request >> 32) as i32).to_le_bytes());
            job.inline_qos
                .extend_from_slice(&(request as u32).to_le_bytes());
        }
        job.inline_qos
            .extend_from_slice(&PID_SENTINEL.to_le_bytes());
        job.inline_qos.extend_from_slice(&0u16.to_le_bytes());
        bulk::send(job, &self.socket, &mut self.datagram, bulk::BULK_CUT, None)
            .map_err(|e| format!("a large reply could not be sent ({e})"))
    }
}

/// A request's fields and id, read the way its mapping says (`fast_dds`: the sample carried a
/// related sample identity, and this is its id); what was wrong, in words, when it does not
/// decode.
fn decode_request<T: DeserializeOwned>(
    raw: &RawRequest,
    fast_dds: Option<RequestId>,
) -> Result<(RequestId, T), String> {
    if let Some(id) = fast_dds {
        let (body, _) =
            deserialize_from_cdr_with_rep_id::<T>(&raw.bytes, raw.encoding).map_err(|e| {
                format!(
                    "a request in Fast DDS's mapping (the id in the sample identity) did not \
                     decode: {e} ({} bytes)",
                    raw.bytes.len()
                )
            })?;
        Ok((id, body))
    } else {
        let (request, _) =
            deserialize_from_cdr_with_rep_id::<WithHeader<T>>(&raw.bytes, raw.encoding).map_err(
                |e| {
                    format!(
                        "a request in Cyclone DDS's mapping (a 16-byte header, no related sample \
                         identity) did not decode: {e} ({} bytes)",
                        raw.bytes.len()
                    )
                },
            )?;
        Ok((RequestId::Cyclone(request.header), request.body))
    }
}
