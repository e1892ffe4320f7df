//! ROS 2 services over DDS, as rmw_cyclonedds_cpp carries them: a service `/a/b` is a request
//! topic `rq/a/bRequest` (type `pkg::srv::dds_::Name_Request_`) and a reply topic
//! `rr/a/bReply` (`pkg::srv::dds_::Name_Response_`), reliable, volatile, keep last 10 (rmw's
//! services QoS). Every request starts with a header, the client's id and the request's
//! number (`uint64 guid; int64 seq`); the reply carries the same header back, which is how
//! the client matches it.
//!
//! rmw_fastrtps_cpp (Fast DDS) carries the request's id in the RTPS sample identity instead
//! of the payload; rover answers rmw_cyclonedds_cpp's clients (and plain Cyclone DDS peers) only.

use anyhow::{Context, Result};
use rustdds::no_key::{DataReader, DataWriter};
use rustdds::{
    CDRDeserializerAdapter, CDRSerializerAdapter, DomainParticipant, GUID, RTPSEntity, TopicKind,
};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use super::dds::default_qos;

/// rmw_cyclonedds_cpp's request header: which client, which of its requests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RequestHeader {
    /// The client's id.
    pub guid: u64,
    /// The request's number.
    pub seq: i64,
}

/// A request or reply: the header, then the message's fields.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct WithHeader<T> {
    /// Which request.
    pub header: RequestHeader,
    /// The message.
    pub body: T,
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

type Request<S> = WithHeader<<S as ServiceType>::Request>;
type Reply<S> = WithHeader<<S as ServiceType>::Response>;

/// One service's server: takes requests when polled, answers each at once.
pub struct Server<S: ServiceType> {
    name: String,
    requests: DataReader<Request<S>, CDRDeserializerAdapter<Request<S>>>,
    replies: DataWriter<Reply<S>, CDRSerializerAdapter<Reply<S>>>,
    warned: bool,
}

impl<S: ServiceType> Server<S>
where
    Request<S>: DeserializeOwned,
    Reply<S>: Serialize,
{
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
                .create_datareader_no_key(&request_topic, Some(qos.clone()))
                .with_context(|| format!("creating the request reader of {ros_name}"))?,
            replies: publisher
                .create_datawriter_no_key(&reply_topic, Some(qos))
                .with_context(|| format!("creating the reply writer of {ros_name}"))?,
            warned: false,
        })
    }

    /// The next request that came, if one did (with its header, for the reply). A request
    /// that does not decode is one warning per service.
    pub fn next_request(&mut self) -> Option<(RequestHeader, S::Request)> {
        match self.requests.take_next_sample() {
            Ok(Some(sample)) => {
                let request = sample.into_value();
                Some((request.header, request.body))
            }
            Ok(None) => None,
            Err(e) => {
                // A peer's garbage or a wrong type: said once; the next poll goes on.
                self.warn(&format!("a request could not be read ({e})"));
                None
            }
        }
    }

    /// Answers the request `header` names (now or later) with `body`.
    pub fn reply(&mut self, header: RequestHeader, body: S::Response) {
        if let Err(e) = self.replies.write(WithHeader { header, body }, None) {
            self.warn(&format!("a reply could not be sent ({e})"));
        }
    }

    /// Answers every request that came, with `answer`.
    pub fn serve(&mut self, mut answer: impl FnMut(S::Request) -> S::Response) {
        while let Some((header, request)) = self.next_request() {
            let body = answer(request);
            self.reply(header, body);
        }
    }

    fn warn(&mut self, what: &str) {
        if !std::mem::replace(&mut self.warned, true) {
            tracing::warn!("ROS 2 service {}: {what}; ignored", self.name);
        }
    }

    /// The request reader's and reply writer's GUIDs, for `ros_discovery_info`.
    pub fn gids(&self) -> (GUID, GUID) {
        (self.requests.guid(), self.replies.guid())
    }
}
