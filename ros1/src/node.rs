//! A ROS 1 node: registers with the master, serves the slave API, accepts TCPROS subscribers
//! and connects to publishers. Everything runs on its own threads; publishing never blocks the
//! caller (each subscriber has a bounded queue, and a slow one loses messages, not the
//! publisher's time). When the master goes away the node says so once, keeps its peer
//! connections, and registers everything again when a master answers (also a new one: the
//! master's PID is watched).

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufReader, Write};
use std::marker::PhantomData;
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::error::{Error, Result};
use crate::msg::{Decode, Message, full_definition, md5sum};
use crate::tcpros::{read_frame, read_header, write_header};
use crate::xmlrpc::{self, Value};

/// How long master calls may take before the master counts as unreachable.
const MASTER_TIMEOUT: Duration = Duration::from_millis(1500);
/// How often the master is checked.
const WATCH_PERIOD: Duration = Duration::from_millis(500);
/// Accept loops poll at this period (their sockets are non-blocking so they can stop).
const ACCEPT_POLL: Duration = Duration::from_millis(20);

/// Where the node runs and how others reach it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeOptions {
    /// Global node name (`/rover`).
    pub name: String,
    /// `ROS_MASTER_URI`.
    pub master_uri: String,
    /// The host name or address peers use to reach this node (`ROS_IP`, `ROS_HOSTNAME`).
    pub host: String,
}

impl NodeOptions {
    /// Options from the environment, as rospy reads it: `ROS_MASTER_URI` (default
    /// `http://localhost:11311`), `ROS_IP`, else `ROS_HOSTNAME`, else the machine's host name.
    pub fn from_env(name: &str) -> Result<Self> {
        let var = |k: &str| std::env::var(k).ok().filter(|v| !v.trim().is_empty());
        let master_uri = var("ROS_MASTER_URI").unwrap_or_else(|| "http://localhost:11311".into());
        xmlrpc::host_port(&master_uri)
            .map_err(|e| Error::Config(format!("ROS_MASTER_URI={master_uri}: {e}")))?;
        let host = var("ROS_IP")
            .or_else(|| var("ROS_HOSTNAME"))
            .or_else(|| {
                std::fs::read_to_string("/proc/sys/kernel/hostname")
                    .ok()
                    .map(|h| h.trim().to_owned())
                    .filter(|h| !h.is_empty())
            })
            .unwrap_or_else(|| "localhost".into());
        Ok(Self {
            name: global_name(name)?,
            master_uri,
            host,
        })
    }
}

/// A name in the global namespace: `rover` -> `/rover`. Rejects names ROS would reject.
pub fn global_name(name: &str) -> Result<String> {
    let trimmed = name.trim_start_matches('/');
    let ok = !trimmed.is_empty()
        && trimmed.split('/').all(|part| {
            part.chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_' || c == '~')
                && part
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '~')
        });
    if ok {
        Ok(format!("/{trimmed}"))
    } else {
        Err(Error::Config(format!(
            "{name:?} is not a valid ROS name (letters, digits, '_' and '/', starting with a letter)"
        )))
    }
}

struct Publication {
    topic: String,
    type_name: &'static str,
    md5: String,
    definition: String,
    latched: bool,
    queue: usize,
    conns: Mutex<Vec<SyncSender<Arc<Vec<u8>>>>>,
    last: Mutex<Option<Arc<Vec<u8>>>>,
    published: AtomicU64,
    dropped: AtomicU64,
}

/// Decodes a message's bytes and queues it for the subscriber.
type Deliver = Box<dyn Fn(&[u8]) -> Result<()> + Send + Sync>;

struct Subscription {
    topic: String,
    type_name: &'static str,
    md5: String,
    definition: String,
    /// Publisher slave URIs with a live (or connecting) connection.
    connected: Mutex<BTreeSet<String>>,
    /// Sockets to those publishers (to shut them down with the node).
    streams: Mutex<Vec<TcpStream>>,
    deliver: Deliver,
}

#[derive(Default)]
struct MasterState {
    registered: bool,
    pid: Option<i32>,
    lost_reported: bool,
    ever_registered: bool,
}

struct Shared {
    options: NodeOptions,
    slave_uri: String,
    tcpros_port: u16,
    publications: Mutex<BTreeMap<String, Arc<Publication>>>,
    subscriptions: Mutex<BTreeMap<String, Arc<Subscription>>>,
    params: Mutex<Vec<(String, Value)>>,
    master: Mutex<MasterState>,
    /// Held while a topic, subscription or parameter is added and (when registered) told to
    /// the master, and while the master watch registers everything: a topic added during a
    /// registration is either in its snapshot or registered by `advertise` itself once the
    /// watch has set `registered` (without it, one added between the snapshot and `registered
    /// = true` was never told to the master: `rostopic echo` waited for it for ever). Taken
    /// before any other lock of this struct.
    registration: Mutex<()>,
    shutdown: AtomicBool,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panicking peer thread must not take the node down with it.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// A running node. Dropping it unregisters (briefly waiting for the master) and stops its
/// threads.
pub struct Node {
    shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
}

impl std::fmt::Debug for Node {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Node")
            .field("name", &self.shared.options.name)
            .field("slave_uri", &self.shared.slave_uri)
            .finish_non_exhaustive()
    }
}

impl Node {
    /// Starts the node's servers and its master watch. Does not wait for a master: when none
    /// answers, the node says so once and registers when one does.
    pub fn start(options: NodeOptions) -> Result<Self> {
        let slave = TcpListener::bind(("0.0.0.0", 0))?;
        let tcpros = TcpListener::bind(("0.0.0.0", 0))?;
        slave.set_nonblocking(true)?;
        tcpros.set_nonblocking(true)?;
        let slave_uri = format!("http://{}:{}/", options.host, slave.local_addr()?.port());
        let shared = Arc::new(Shared {
            tcpros_port: tcpros.local_addr()?.port(),
            slave_uri,
            options,
            publications: Mutex::default(),
            subscriptions: Mutex::default(),
            params: Mutex::default(),
            master: Mutex::default(),
            registration: Mutex::default(),
            shutdown: AtomicBool::new(false),
        });
        let mut threads = Vec::new();
        let s = shared.clone();
        threads.push(spawn("ros-slave-api", move || {
            accept_loop(&s, &slave, serve_slave)
        })?);
        let s = shared.clone();
        threads.push(spawn("ros-tcpros", move || {
            accept_loop(&s, &tcpros, serve_subscriber)
        })?);
        let s = shared.clone();
        threads.push(spawn("ros-master-watch", move || watch_master(&s))?);
        Ok(Self { shared, threads })
    }

    /// The node's global name.
    pub fn name(&self) -> &str {
        &self.shared.options.name
    }

    /// The master this node talks to.
    pub fn master_uri(&self) -> &str {
        &self.shared.options.master_uri
    }

    /// The node's slave API URI.
    pub fn uri(&self) -> &str {
        &self.shared.slave_uri
    }

    /// Whether the node is registered with a live master right now.
    pub fn is_registered(&self) -> bool {
        lock(&self.shared.master).registered
    }

    /// Advertises a topic. `queue` is each subscriber's queue length (messages beyond it are
    /// dropped for that subscriber); a latched topic hands its last message to new subscribers.
    pub fn advertise<T: Message>(
        &self,
        topic: &str,
        queue: usize,
        latched: bool,
    ) -> Result<Publisher<T>> {
        let topic = global_name(topic)?;
        let publication = Arc::new(Publication {
            md5: md5sum(T::TYPE)?,
            definition: full_definition(T::TYPE)?,
            type_name: T::TYPE,
            topic: topic.clone(),
            latched,
            queue: queue.max(1),
            conns: Mutex::default(),
            last: Mutex::default(),
            published: AtomicU64::new(0),
            dropped: AtomicU64::new(0),
        });
        let _registering = lock(&self.shared.registration);
        lock(&self.shared.publications).insert(topic, publication.clone());
        if lock(&self.shared.master).registered
            && let Err(e) = register_publication(&self.shared, &publication)
        {
            tracing::debug!("registering {}: {e}", publication.topic);
            lock(&self.shared.master).registered = false;
        }
        Ok(Publisher {
            publication,
            pool: Vec::new(),
            _type: PhantomData,
        })
    }

    /// Subscribes to a topic; messages arrive in the returned [`Subscriber`] (at most `queue`
    /// waiting; newer ones are dropped while it is full).
    pub fn subscribe<T: Decode + Send + 'static>(
        &self,
        topic: &str,
        queue: usize,
    ) -> Result<Subscriber<T>> {
        self.subscribe_with(topic, T::TYPE, queue, T::decode)
    }

    /// Subscribes to a topic of a known type without decoding it: each message arrives as its
    /// serialized bytes (rospy's `AnyMsg`, for tools and benchmarks).
    pub fn subscribe_raw(
        &self,
        topic: &str,
        type_name: &str,
        queue: usize,
    ) -> Result<Subscriber<Vec<u8>>> {
        let type_name = crate::msg::known_types()
            .find(|t| *t == type_name)
            .ok_or_else(|| Error::UnknownType(type_name.to_owned()))?;
        self.subscribe_with(topic, type_name, queue, |b| Ok(b.to_vec()))
    }

    fn subscribe_with<T: Send + 'static>(
        &self,
        topic: &str,
        type_name: &'static str,
        queue: usize,
        decode: fn(&[u8]) -> Result<T>,
    ) -> Result<Subscriber<T>> {
        let topic = global_name(topic)?;
        let (tx, rx) = sync_channel::<T>(queue.max(1));
        let dropped = Arc::new(AtomicU64::new(0));
        let counter = dropped.clone();
        let subscription = Arc::new(Subscription {
            md5: md5sum(type_name)?,
            definition: full_definition(type_name)?,
            type_name,
            topic: topic.clone(),
            connected: Mutex::default(),
            streams: Mutex::default(),
            deliver: Box::new(move |bytes| {
                let msg = decode(bytes)?;
                if let Err(TrySendError::Full(_)) = tx.try_send(msg) {
                    counter.fetch_add(1, Ordering::Relaxed);
                }
                Ok(())
            }),
        });
        let _registering = lock(&self.shared.registration);
        lock(&self.shared.subscriptions).insert(topic, subscription.clone());
        if lock(&self.shared.master).registered
            && let Err(e) = register_subscription(&self.shared, &subscription)
        {
            tracing::debug!("subscribing {}: {e}", subscription.topic);
            lock(&self.shared.master).registered = false;
        }
        Ok(Subscriber { rx, dropped })
    }

    /// Sets a parameter on the master, now when it is reachable and again whenever the node
    /// registers (a restarted master has lost it).
    pub fn set_param(&self, key: &str, value: Value) -> Result<()> {
        let key = global_name(key)?;
        let _registering = lock(&self.shared.registration);
        {
            let mut params = lock(&self.shared.params);
            params.retain(|(k, _)| *k != key);
            params.push((key.clone(), value.clone()));
        }
        if lock(&self.shared.master).registered {
            xmlrpc::ros_call(
                &self.shared.options.master_uri,
                "setParam",
                &[Value::from(self.name()), Value::from(key), value],
                MASTER_TIMEOUT,
            )?;
        }
        Ok(())
    }

    /// Waits up to `timeout` for the node to be registered with a master.
    pub fn wait_registered(&self, timeout: Duration) -> bool {
        let start = Instant::now();
        while start.elapsed() < timeout {
            if self.is_registered() {
                return true;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        self.is_registered()
    }
}

impl Drop for Node {
    fn drop(&mut self) {
        let shared = &self.shared;
        if lock(&shared.master).registered {
            let master = &shared.options.master_uri;
            let quick = Duration::from_millis(300);
            let me = Value::from(shared.options.name.as_str());
            let api = Value::from(shared.slave_uri.as_str());
            let pubs: Vec<String> = lock(&shared.publications).keys().cloned().collect();
            for topic in pubs {
                let _ = xmlrpc::call(
                    master,
                    "unregisterPublisher",
                    &[me.clone(), Value::from(topic), api.clone()],
                    quick,
                );
            }
            let subs: Vec<String> = lock(&shared.subscriptions).keys().cloned().collect();
            for topic in subs {
                let _ = xmlrpc::call(
                    master,
                    "unregisterSubscriber",
                    &[me.clone(), Value::from(topic), api.clone()],
                    quick,
                );
            }
        }
        shared.shutdown.store(true, Ordering::SeqCst);
        // Subscriber writers end when their senders go.
        for p in lock(&shared.publications).values() {
            lock(&p.conns).clear();
        }
        for s in lock(&shared.subscriptions).values() {
            for stream in lock(&s.streams).drain(..) {
                let _ = stream.shutdown(std::net::Shutdown::Both);
            }
        }
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// Publishes one topic. Serializes into a small pool of reusable buffers, so steady publishing
/// allocates nothing once every buffer has grown to the message size.
pub struct Publisher<T> {
    publication: Arc<Publication>,
    pool: Vec<Arc<Vec<u8>>>,
    _type: PhantomData<fn(&T)>,
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

/// Messages of a subscribed topic.
#[derive(Debug)]
pub struct Subscriber<T> {
    rx: Receiver<T>,
    dropped: Arc<AtomicU64>,
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

fn spawn(name: &str, f: impl FnOnce() + Send + 'static) -> Result<JoinHandle<()>> {
    Ok(std::thread::Builder::new().name(name.to_owned()).spawn(f)?)
}

fn accept_loop(
    shared: &Arc<Shared>,
    listener: &TcpListener,
    serve: fn(Arc<Shared>, TcpStream) -> Result<()>,
) {
    while !shared.shutdown.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, peer)) => {
                let s = shared.clone();
                let spawned =
                    std::thread::Builder::new()
                        .name("ros-peer".into())
                        .spawn(move || {
                            if let Err(e) = stream
                                .set_nonblocking(false)
                                .map_err(Error::from)
                                .and_then(|()| serve(s, stream))
                            {
                                tracing::debug!("ROS peer {peer}: {e}");
                            }
                        });
                if let Err(e) = spawned {
                    tracing::warn!("ROS: cannot start a thread for {peer}: {e}");
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(ACCEPT_POLL);
            }
            Err(e) => {
                tracing::debug!("ROS accept: {e}");
                std::thread::sleep(ACCEPT_POLL);
            }
        }
    }
}

fn ok(value: Value) -> Value {
    Value::Array(vec![Value::Int(1), Value::from(""), value])
}

fn fail(text: &str) -> Value {
    Value::Array(vec![Value::Int(-1), Value::from(text), Value::Int(0)])
}

/// One slave API request.
fn serve_slave(shared: Arc<Shared>, stream: TcpStream) -> Result<()> {
    stream.set_read_timeout(Some(Duration::from_secs(5)))?;
    let mut reader = BufReader::new(stream.try_clone()?);
    let (_, body) = xmlrpc::read_http(&mut reader)?;
    let reply = match xmlrpc::parse_call(&body) {
        Ok((method, params)) => xmlrpc::response_body(&slave_api(&shared, &method, &params)),
        Err(e) => xmlrpc::fault_body(1, &e.to_string()),
    };
    let mut out = stream;
    xmlrpc::write_response(&mut out, &reply)?;
    Ok(())
}

fn slave_api(shared: &Arc<Shared>, method: &str, params: &[Value]) -> Value {
    let topic_list = |names: Vec<(String, &'static str)>| {
        Value::Array(
            names
                .into_iter()
                .map(|(t, ty)| Value::Array(vec![Value::from(t), Value::from(ty)]))
                .collect(),
        )
    };
    match method {
        "getPid" => ok(Value::Int(i32::try_from(std::process::id()).unwrap_or(0))),
        "getMasterUri" => ok(Value::from(shared.options.master_uri.as_str())),
        "getBusStats" => ok(Value::Array(vec![
            Value::Array(vec![]),
            Value::Array(vec![]),
            Value::Array(vec![]),
        ])),
        "getBusInfo" => ok(Value::Array(vec![])),
        "getPublications" => topic_list(
            lock(&shared.publications)
                .values()
                .map(|p| (p.topic.clone(), p.type_name))
                .collect(),
        ),
        "getSubscriptions" => topic_list(
            lock(&shared.subscriptions)
                .values()
                .map(|s| (s.topic.clone(), s.type_name))
                .collect(),
        ),
        "paramUpdate" => ok(Value::Int(0)),
        "shutdown" => {
            let why = params.get(1).and_then(Value::as_str).unwrap_or("");
            tracing::warn!(
                "ROS: asked to shut down ({why}); rover keeps running (stop it from its window or with Ctrl-C)"
            );
            ok(Value::Int(0))
        }
        "publisherUpdate" => {
            let topic = params.get(1).and_then(Value::as_str).unwrap_or("");
            let uris: Vec<String> = params
                .get(2)
                .and_then(Value::as_array)
                .unwrap_or(&[])
                .iter()
                .filter_map(|v| v.as_str().map(str::to_owned))
                .collect();
            let sub = lock(&shared.subscriptions).get(topic).cloned();
            if let Some(sub) = sub {
                connect_publishers(shared, &sub, &uris);
            }
            ok(Value::Int(0))
        }
        "requestTopic" => {
            let topic = params.get(1).and_then(Value::as_str).unwrap_or("");
            let tcpros = params
                .get(2)
                .and_then(Value::as_array)
                .unwrap_or(&[])
                .iter()
                .any(|p| {
                    p.as_array().and_then(|a| a.first()).and_then(Value::as_str) == Some("TCPROS")
                });
            if !lock(&shared.publications).contains_key(topic) {
                fail(&format!("{} does not publish {topic}", shared.options.name))
            } else if !tcpros {
                fail("only TCPROS is supported")
            } else {
                ok(Value::Array(vec![
                    Value::from("TCPROS"),
                    Value::from(shared.options.host.as_str()),
                    Value::Int(i32::from(shared.tcpros_port)),
                ]))
            }
        }
        other => fail(&format!("unknown method {other}")),
    }
}

/// One subscriber connecting to a topic this node publishes: the handshake, then this thread
/// writes the subscriber's queue to its socket until either side goes.
fn serve_subscriber(shared: Arc<Shared>, stream: TcpStream) -> Result<()> {
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

fn connect_publishers(shared: &Arc<Shared>, sub: &Arc<Subscription>, uris: &[String]) {
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

fn register_publication(shared: &Shared, p: &Publication) -> Result<()> {
    xmlrpc::ros_call(
        &shared.options.master_uri,
        "registerPublisher",
        &[
            Value::from(shared.options.name.as_str()),
            Value::from(p.topic.as_str()),
            Value::from(p.type_name),
            Value::from(shared.slave_uri.as_str()),
        ],
        MASTER_TIMEOUT,
    )?;
    Ok(())
}

fn register_subscription(shared: &Arc<Shared>, sub: &Arc<Subscription>) -> Result<()> {
    let publishers = xmlrpc::ros_call(
        &shared.options.master_uri,
        "registerSubscriber",
        &[
            Value::from(shared.options.name.as_str()),
            Value::from(sub.topic.as_str()),
            Value::from(sub.type_name),
            Value::from(shared.slave_uri.as_str()),
        ],
        MASTER_TIMEOUT,
    )?;
    let uris: Vec<String> = publishers
        .as_array()
        .unwrap_or(&[])
        .iter()
        .filter_map(|v| v.as_str().map(str::to_owned))
        .collect();
    connect_publishers(shared, sub, &uris);
    Ok(())
}

fn register_all(shared: &Arc<Shared>) -> Result<()> {
    let pubs: Vec<Arc<Publication>> = lock(&shared.publications).values().cloned().collect();
    for p in pubs {
        register_publication(shared, &p)?;
    }
    let subs: Vec<Arc<Subscription>> = lock(&shared.subscriptions).values().cloned().collect();
    for s in subs {
        register_subscription(shared, &s)?;
    }
    let params = lock(&shared.params).clone();
    for (key, value) in params {
        xmlrpc::ros_call(
            &shared.options.master_uri,
            "setParam",
            &[
                Value::from(shared.options.name.as_str()),
                Value::from(key),
                value,
            ],
            MASTER_TIMEOUT,
        )?;
    }
    Ok(())
}

/// Registers when a master answers, and again when it comes back or is replaced.
fn watch_master(shared: &Arc<Shared>) {
    let master = shared.options.master_uri.clone();
    let me = Value::from(shared.options.name.as_str());
    while !shared.shutdown.load(Ordering::SeqCst) {
        let pid = xmlrpc::ros_call(&master, "getPid", std::slice::from_ref(&me), MASTER_TIMEOUT)
            .and_then(|v| {
                v.as_int()
                    .ok_or_else(|| Error::protocol(format!("getPid answered {v:?}")))
            });
        match pid {
            Ok(pid) => {
                let (needed, returning) = {
                    let m = lock(&shared.master);
                    (!m.registered || m.pid != Some(pid), m.ever_registered)
                };
                if needed {
                    // Everything added from here on waits until `registered` says so.
                    let _registering = lock(&shared.registration);
                    match register_all(shared) {
                        Ok(()) => {
                            let mut m = lock(&shared.master);
                            m.registered = true;
                            m.pid = Some(pid);
                            m.lost_reported = false;
                            m.ever_registered = true;
                            if returning {
                                tracing::warn!(
                                    "ROS master {master} is back: {} registered again",
                                    shared.options.name
                                );
                            } else {
                                tracing::info!(
                                    "ROS: {} registered with {master}",
                                    shared.options.name
                                );
                            }
                        }
                        Err(e) => {
                            lock(&shared.master).registered = false;
                            tracing::debug!("ROS registration with {master}: {e}");
                        }
                    }
                }
            }
            Err(e) => {
                let mut m = lock(&shared.master);
                m.registered = false;
                if !m.lost_reported {
                    m.lost_reported = true;
                    if m.ever_registered {
                        tracing::warn!(
                            "ROS master {master} went away ({e}); rover keeps running and registers again when it returns"
                        );
                    } else {
                        tracing::warn!(
                            "no ROS master at {master} ({e}); is roscore running? rover runs on and registers when one answers"
                        );
                    }
                }
            }
        }
        let start = Instant::now();
        while start.elapsed() < WATCH_PERIOD && !shared.shutdown.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(25));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{Twist, Vector3};

    #[test]
    fn names_resolve_to_the_global_namespace() -> Result<()> {
        assert_eq!(global_name("rover")?, "/rover");
        assert_eq!(global_name("/camera/image_raw")?, "/camera/image_raw");
        assert!(global_name("").is_err());
        assert!(global_name("1abc").is_err());
        assert!(global_name("a b").is_err());
        Ok(())
    }

    /// A master on a free port that takes `delay` over each registration and remembers the
    /// topics registered with it (XML-RPC over real sockets; its threads end with the test
    /// process).
    fn slow_master(delay: Duration) -> Result<(String, Arc<Mutex<Vec<String>>>)> {
        let listener = TcpListener::bind(("127.0.0.1", 0))?;
        let uri = format!("http://127.0.0.1:{}/", listener.local_addr()?.port());
        let seen = Arc::new(Mutex::new(Vec::new()));
        let topics = seen.clone();
        std::thread::spawn(move || {
            for stream in listener.incoming() {
                let Ok(stream) = stream else { break };
                let topics = topics.clone();
                std::thread::spawn(move || -> Result<()> {
                    let mut reader = BufReader::new(stream.try_clone()?);
                    let (_, body) = xmlrpc::read_http(&mut reader)?;
                    let (method, params) = xmlrpc::parse_call(&body)?;
                    let value = match method.as_str() {
                        "getPid" => Value::Int(42),
                        "registerPublisher" | "registerSubscriber" => {
                            std::thread::sleep(delay);
                            if let Some(topic) = params.get(1).and_then(Value::as_str) {
                                lock(&topics).push(topic.to_owned());
                            }
                            Value::Array(vec![])
                        }
                        _ => Value::Int(0),
                    };
                    let reply = Value::Array(vec![Value::Int(1), Value::from(""), value]);
                    let mut out = stream;
                    xmlrpc::write_response(&mut out, &xmlrpc::response_body(&reply))?;
                    Ok(())
                });
            }
        });
        Ok((uri, seen))
    }

    /// Topics advertised while the node is registering with a slow master all reach it. Before
    /// the registration lock, one advertised between the watch's snapshot and `registered =
    /// true` was never registered, and `rostopic echo` waited for it until killed (the ROS 1
    /// tests' intermittent failure, a different topic each time).
    #[test]
    fn topics_advertised_during_registration_all_reach_the_master() -> Result<()> {
        let (master_uri, seen) = slow_master(Duration::from_millis(15))?;
        let node = Node::start(NodeOptions {
            name: "/racer".into(),
            master_uri,
            host: "127.0.0.1".into(),
        })?;
        let mut publishers = Vec::new();
        let topics: Vec<String> = (0..40).map(|i| format!("/topic_{i}")).collect();
        for topic in &topics {
            publishers.push(node.advertise::<Twist>(topic, 1, false)?);
            std::thread::sleep(Duration::from_millis(5));
        }
        assert!(node.wait_registered(Duration::from_secs(20)));
        let start = Instant::now();
        let missing = loop {
            let got = lock(&seen).clone();
            let missing: Vec<&String> = topics.iter().filter(|t| !got.contains(t)).collect();
            if missing.is_empty() || start.elapsed() > Duration::from_secs(5) {
                break missing.into_iter().cloned().collect::<Vec<_>>();
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        assert!(missing.is_empty(), "never registered: {missing:?}");
        Ok(())
    }

    /// Two nodes of this crate without a master: the subscriber is pointed at the publisher
    /// by hand (what `publisherUpdate` does), over real sockets.
    #[test]
    fn a_publisher_and_a_subscriber_talk_over_tcpros() -> Result<()> {
        let options = |name: &str| NodeOptions {
            name: global_name(name).unwrap_or_default(),
            master_uri: "http://127.0.0.1:9/".into(),
            host: "127.0.0.1".into(),
        };
        let a = Node::start(options("a"))?;
        let b = Node::start(options("b"))?;
        let mut publisher = a.advertise::<Twist>("cmd_vel", 10, false)?;
        let subscriber = b.subscribe::<Twist>("/cmd_vel", 10)?;
        let sub = lock(&b.shared.subscriptions).get("/cmd_vel").cloned();
        let Some(sub) = sub else {
            panic!("subscription missing");
        };
        connect_publishers(&b.shared, &sub, &[a.uri().to_owned()]);
        let start = Instant::now();
        while publisher.subscribers() == 0 && start.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(10));
        }
        assert_eq!(publisher.subscribers(), 1);
        let msg = Twist {
            linear: Vector3 {
                x: 0.1,
                ..Vector3::default()
            },
            angular: Vector3::default(),
        };
        publisher.publish(&msg);
        assert_eq!(subscriber.recv_timeout(Duration::from_secs(10)), Some(msg));
        Ok(())
    }

    /// A subscriber that connects and then never reads must not slow the publisher: its queue
    /// fills and further messages are dropped for it.
    #[test]
    fn a_subscriber_that_never_reads_loses_messages_and_blocks_nothing() -> Result<()> {
        use crate::msgs::Image;
        let node = Node::start(NodeOptions {
            name: "/pub".into(),
            master_uri: "http://127.0.0.1:9/".into(),
            host: "127.0.0.1".into(),
        })?;
        let mut publisher = node.advertise::<Image>("/camera/image_raw", 2, false)?;
        // The slave API tells where to connect, as it tells rospy.
        let reply = xmlrpc::ros_call(
            node.uri(),
            "requestTopic",
            &[
                Value::from("/slow"),
                Value::from("/camera/image_raw"),
                Value::Array(vec![Value::Array(vec![Value::from("TCPROS")])]),
            ],
            Duration::from_secs(10),
        )?;
        let port = reply
            .as_array()
            .and_then(|a| a.get(2))
            .and_then(Value::as_int)
            .ok_or_else(|| Error::protocol(format!("requestTopic: {reply:?}")))?;
        let mut stream = TcpStream::connect(("127.0.0.1", u16::try_from(port).unwrap_or(0)))?;
        write_header(
            &mut stream,
            &[
                ("callerid", "/slow"),
                ("topic", "/camera/image_raw"),
                ("md5sum", "*"),
                ("type", "sensor_msgs/Image"),
            ],
        )?;
        let header = read_header(&mut stream)?;
        assert_eq!(
            header.get("md5sum").map(String::as_str),
            Some("060021388200f6f0f447d0fcd9c64743")
        );
        assert!(header.contains_key("message_definition"));
        let start = Instant::now();
        while publisher.subscribers() == 0 && start.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(10));
        }
        assert_eq!(publisher.subscribers(), 1);
        let (done_tx, done_rx) = std::sync::mpsc::channel();
        let worker = std::thread::spawn(move || {
            let image = Image {
                width: 640,
                height: 480,
                step: 1920,
                encoding: "rgb8".into(),
                data: vec![7; 640 * 480 * 3],
                ..Image::default()
            };
            for _ in 0..100 {
                publisher.publish(&image);
            }
            let _ = done_tx.send(publisher.dropped());
        });
        // 100 images are 92 MB: far more than the socket buffers and the queue of 2 hold.
        let dropped = done_rx.recv_timeout(Duration::from_secs(120));
        assert!(
            matches!(dropped, Ok(d) if d > 50),
            "publishing to a stuck subscriber: {dropped:?} dropped"
        );
        let _ = worker.join();
        drop(stream);
        Ok(())
    }
}
