//! Publishing: [`Publisher`] queues each message for every subscriber without waiting, and
//! one thread per subscriber does the TCPROS handshake and writes its queue to the socket.

use std::io::Write;
use std::marker::PhantomData;
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{TrySendError, sync_channel};
use std::time::Duration;

use super::state::{Publication, Shared, lock};
use crate::error::{Error, Result};
use crate::msg::Message;
use crate::tcpros::{read_header, write_header};

/// Publishes one topic. Serializes into a small pool of reusable buffers, so steady publishing
/// allocates nothing once every buffer has grown to the message size.
pub struct Publisher<T> {
    pub(super) publication: Arc<Publication>,
    pub(super) pool: Vec<Arc<Vec<u8>>>,
    pub(super) _type: PhantomData<fn(&T)>,
}

impl<T> std::fmt::Debug for Publisher<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Publisher")
            .field("topic", &self.publication.topic)
            .finish_non_exhaustive()
    }
}

impl<T: Message> Publisher<T> {
    /// The topic's global name.
    pub fn topic(&self) -> &str {
        &self.publication.topic
    }

    /// Subscribers connected now.
    pub fn subscribers(&self) -> usize {
        lock(&self.publication.conns).len()
    }

    /// Messages published so far.
    pub fn published(&self) -> u64 {
        self.publication.published.load(Ordering::Relaxed)
    }

    /// Messages a slow subscriber did not get (summed over subscribers).
    pub fn dropped(&self) -> u64 {
        self.publication.dropped.load(Ordering::Relaxed)
    }

    /// Sends `msg` to every subscriber without waiting for any of them.
    pub fn publish(&mut self, msg: &T) {
        let p = &self.publication;
        if !p.latched && lock(&p.conns).is_empty() {
            p.published.fetch_add(1, Ordering::Relaxed);
            return;
        }
        let mut frame = match self.pool.iter().position(|b| Arc::strong_count(b) == 1) {
            Some(i) => self.pool.swap_remove(i),
            None => Arc::new(Vec::new()),
        };
        let Some(buf) = Arc::get_mut(&mut frame) else {
            return;
        };
        buf.clear();
        buf.extend_from_slice(&[0; 4]);
        msg.encode(buf);
        let len = u32::try_from(buf.len() - 4).unwrap_or(u32::MAX);
        buf[..4].copy_from_slice(&len.to_le_bytes());
        // The last message is set under the subscribers' lock, which a new subscriber holds
        // while it takes the last message and joins: it gets each message once, this one
        // either as the latched one or from the queue.
        let mut conns = lock(&p.conns);
        if p.latched {
            *lock(&p.last) = Some(frame.clone());
        }
        conns.retain(|tx| match tx.try_send(frame.clone()) {
            Ok(()) => true,
            Err(TrySendError::Full(_)) => {
                p.dropped.fetch_add(1, Ordering::Relaxed);
                true
            }
            Err(TrySendError::Disconnected(_)) => false,
        });
        drop(conns);
        p.published.fetch_add(1, Ordering::Relaxed);
        if self.pool.len() < 4 {
            self.pool.push(frame);
        }
    }
}

/// One subscriber connecting to a topic this node publishes: the handshake, then this thread
/// writes the subscriber's queue to its socket until either side goes.
pub(super) fn serve_subscriber(shared: Arc<Shared>, stream: TcpStream) -> Result<()> {
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut stream = stream;
    let header = read_header(&mut stream)?;
    let topic = header.get("topic").cloned().unwrap_or_default();
    let me = shared.options.name.clone();
    let Some(p) = lock(&shared.publications).get(&topic).cloned() else {
        let text = format!("{me} does not publish {topic}");
        write_header(&mut stream, &[("error", &text)])?;
        return Err(Error::protocol(text));
    };
    let wanted = header.get("md5sum").map(String::as_str).unwrap_or("*");
    if wanted != "*" && wanted != p.md5 {
        let text = format!(
            "{topic} is {} ({}), the subscriber expects md5 {wanted}",
            p.type_name, p.md5
        );
        write_header(&mut stream, &[("error", &text)])?;
        return Err(Error::protocol(text));
    }
    write_header(
        &mut stream,
        &[
            ("callerid", &me),
            ("topic", &p.topic),
            ("type", p.type_name),
            ("md5sum", &p.md5),
            ("message_definition", &p.definition),
            ("latching", if p.latched { "1" } else { "0" }),
        ],
    )?;
    if header.get("tcp_nodelay").map(String::as_str) == Some("1") {
        stream.set_nodelay(true)?;
    }
    stream.set_write_timeout(Some(Duration::from_secs(5)))?;
    let (tx, rx) = sync_channel::<Arc<Vec<u8>>>(p.queue);
    {
        // Under the lock `publish` sets the last message in: no message falls between the
        // latched one and the queue.
        let mut conns = lock(&p.conns);
        if p.latched
            && let Some(last) = lock(&p.last).clone()
        {
            let _ = tx.try_send(last);
        }
        conns.push(tx);
    }
    drop(p);
    for frame in rx {
        stream.write_all(&frame)?;
    }
    Ok(())
}
