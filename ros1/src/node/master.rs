//! Registration with the master: publications, subscriptions and parameters, and the watch
//! that registers everything again when the master comes back or is replaced.

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use super::state::{MASTER_TIMEOUT, Publication, Shared, Subscription, lock};
use super::subscriber::connect_publishers;
use crate::error::{Error, Result};
use crate::xmlrpc::{self, Value};

/// How often the master is checked.
const WATCH_PERIOD: Duration = Duration::from_millis(500);

pub(super) fn register_publication(shared: &Shared, p: &Publication) -> Result<()> {
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

pub(super) fn register_subscription(shared: &Arc<Shared>, sub: &Arc<Subscription>) -> Result<()> {
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
pub(super) fn watch_master(shared: &Arc<Shared>) {
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
