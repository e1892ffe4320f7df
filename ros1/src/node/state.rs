//! The node's shared state: the [`Node`] handle, what its threads share (publications,
//! subscriptions, parameters, the master's state) and the lock helper they all use.

use std::collections::{BTreeMap, BTreeSet};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, AtomicU64};
use std::sync::mpsc::SyncSender;
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::Duration;

use super::options::NodeOptions;
use crate::error::Result;
use crate::xmlrpc::Value;

/// How long master calls may take before the master counts as unreachable.
pub(super) const MASTER_TIMEOUT: Duration = Duration::from_millis(1500);

pub(super) struct Publication {
    pub(super) topic: String,
    pub(super) type_name: &'static str,
    pub(super) md5: String,
    pub(super) definition: String,
    pub(super) latched: bool,
    pub(super) queue: usize,
    pub(super) conns: Mutex<Vec<SyncSender<Arc<Vec<u8>>>>>,
    pub(super) last: Mutex<Option<Arc<Vec<u8>>>>,
    pub(super) published: AtomicU64,
    pub(super) dropped: AtomicU64,
}

/// Decodes a message's bytes and queues it for the subscriber.
pub(super) type Deliver = Box<dyn Fn(&[u8]) -> Result<()> + Send + Sync>;

pub(super) struct Subscription {
    pub(super) topic: String,
    pub(super) type_name: &'static str,
    pub(super) md5: String,
    pub(super) definition: String,
    /// Publisher slave URIs with a live (or connecting) connection.
    pub(super) connected: Mutex<BTreeSet<String>>,
    /// Sockets to those publishers (to shut them down with the node).
    pub(super) streams: Mutex<Vec<TcpStream>>,
    pub(super) deliver: Deliver,
}

#[derive(Default)]
pub(super) struct MasterState {
    pub(super) registered: bool,
    pub(super) pid: Option<i32>,
    pub(super) lost_reported: bool,
    pub(super) ever_registered: bool,
}

pub(super) struct Shared {
    pub(super) options: NodeOptions,
    pub(super) slave_uri: String,
    pub(super) tcpros_port: u16,
    pub(super) publications: Mutex<BTreeMap<String, Arc<Publication>>>,
    pub(super) subscriptions: Mutex<BTreeMap<String, Arc<Subscription>>>,
    pub(super) params: Mutex<Vec<(String, Value)>>,
    pub(super) master: Mutex<MasterState>,
    /// Held while a topic, subscription or parameter is added and (when registered) told to
    /// the master, and while the master watch registers everything: a topic added during a
    /// registration is either in its snapshot or registered by `advertise` itself once the
    /// watch has set `registered` (without it, one added between the snapshot and `registered
    /// = true` was never told to the master: `rostopic echo` waited for it for ever). Taken
    /// before any other lock of this struct.
    pub(super) registration: Mutex<()>,
    pub(super) shutdown: AtomicBool,
}

pub(super) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panicking peer thread must not take the node down with it.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// A running node. Dropping it unregisters (briefly waiting for the master) and stops its
/// threads.
pub struct Node {
    pub(super) shared: Arc<Shared>,
    pub(super) threads: Vec<JoinHandle<()>>,
}

impl std::fmt::Debug for Node {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Node")
            .field("name", &self.shared.options.name)
            .field("slave_uri", &self.shared.slave_uri)
            .finish_non_exhaustive()
    }
}
