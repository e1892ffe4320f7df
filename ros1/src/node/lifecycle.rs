//! [`Node`]'s methods: starting its threads, advertising, subscribing and setting parameters
//! (told to the master when registered), and unregistering and stopping when dropped.

use std::marker::PhantomData;
use std::net::TcpListener;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{TrySendError, sync_channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::master::{register_publication, register_subscription, watch_master};
use super::options::{NodeOptions, global_name};
use super::publisher::{Publisher, serve_subscriber};
use super::slave::{accept_loop, serve_slave, spawn};
use super::state::{MASTER_TIMEOUT, Node, Publication, Shared, Subscription, lock};
use super::subscriber::Subscriber;
use crate::error::{Error, Result};
use crate::msg::{Decode, Message, full_definition, md5sum};
use crate::xmlrpc::{self, Value};

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
