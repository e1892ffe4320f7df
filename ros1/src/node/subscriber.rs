//! Subscribing: [`Subscriber`] hands out the messages, and one thread per publisher asks it
//! for the topic over its slave API, connects over TCPROS and delivers what arrives.

use std::io::BufReader;
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::Receiver;
use std::time::Duration;

use super::state::{Shared, Subscription, lock};
use crate::error::{Error, Result};
use crate::tcpros::{read_frame, read_header, write_header};
use crate::xmlrpc::{self, Value};

/// Messages of a subscribed topic.
#[derive(Debug)]
pub struct Subscriber<T> {
    pub(super) rx: Receiver<T>,
    pub(super) dropped: Arc<AtomicU64>,
}

impl<T> Subscriber<T> {
    /// The next waiting message, if any.
    pub fn try_recv(&self) -> Option<T> {
        self.rx.try_recv().ok()
    }

    /// The newest waiting message, discarding older ones.
    pub fn latest(&self) -> Option<T> {
        let mut last = None;
        while let Some(m) = self.try_recv() {
            last = Some(m);
        }
        last
    }

    /// Waits up to `timeout` for a message.
    pub fn recv_timeout(&self, timeout: Duration) -> Option<T> {
        self.rx.recv_timeout(timeout).ok()
    }

    /// Messages dropped because the queue was full.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }
}

pub(super) fn connect_publishers(shared: &Arc<Shared>, sub: &Arc<Subscription>, uris: &[String]) {
    for uri in uris {
        if uri == &shared.slave_uri || !lock(&sub.connected).insert(uri.clone()) {
            continue;
        }
        let (s, sub2, uri2) = (shared.clone(), sub.clone(), uri.clone());
        let spawned = std::thread::Builder::new()
            .name("ros-subscription".into())
            .spawn(move || {
                if let Err(e) = read_publisher(&s, &sub2, &uri2) {
                    tracing::debug!("{} from {uri2}: {e}", sub2.topic);
                }
                lock(&sub2.connected).remove(&uri2);
            });
        if let Err(e) = spawned {
            tracing::warn!("ROS: cannot start a thread for {uri}: {e}");
            lock(&sub.connected).remove(uri);
        }
    }
}

fn read_publisher(shared: &Shared, sub: &Subscription, uri: &str) -> Result<()> {
    let me = shared.options.name.as_str();
    let reply = xmlrpc::ros_call(
        uri,
        "requestTopic",
        &[
            Value::from(me),
            Value::from(sub.topic.as_str()),
            Value::Array(vec![Value::Array(vec![Value::from("TCPROS")])]),
        ],
        Duration::from_secs(3),
    )?;
    let (host, port) = match reply.as_array() {
        Some([proto, host, port]) if proto.as_str() == Some("TCPROS") => (
            host.as_str().unwrap_or("").to_owned(),
            port.as_int().unwrap_or(0),
        ),
        _ => return Err(Error::protocol(format!("requestTopic answered {reply:?}"))),
    };
    let port = u16::try_from(port).map_err(|_| Error::protocol(format!("bad port {port}")))?;
    let mut stream = TcpStream::connect((host.as_str(), port))?;
    stream.set_nodelay(true)?;
    write_header(
        &mut stream,
        &[
            ("callerid", me),
            ("topic", &sub.topic),
            ("type", sub.type_name),
            ("md5sum", &sub.md5),
            ("message_definition", &sub.definition),
            ("tcp_nodelay", "1"),
        ],
    )?;
    let header = read_header(&mut stream)?;
    if let Some(e) = header.get("error") {
        return Err(Error::protocol(format!("publisher refused: {e}")));
    }
    // Reads block; dropping the node shuts the socket down, which ends them.
    lock(&sub.streams).push(stream.try_clone()?);
    let mut buf = Vec::new();
    let mut reader = BufReader::new(stream);
    while !shared.shutdown.load(Ordering::SeqCst) {
        read_frame(&mut reader, &mut buf)?;
        if let Err(e) = (sub.deliver)(&buf) {
            tracing::warn!("{}: dropping a message: {e}", sub.topic);
        }
    }
    Ok(())
}
