//! The node's servers: the accept loops (slave API and TCPROS) and the slave API's XML-RPC
//! methods (`getPid`, `publisherUpdate`, `requestTopic`, ...).

use std::io::BufReader;
use std::net::{TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::thread::JoinHandle;
use std::time::Duration;

use super::state::{Shared, lock};
use super::subscriber::connect_publishers;
use crate::error::{Error, Result};
use crate::xmlrpc::{self, Value};

/// Accept loops poll at this period (their sockets are non-blocking so they can stop).
const ACCEPT_POLL: Duration = Duration::from_millis(20);

pub(super) fn spawn(name: &str, f: impl FnOnce() + Send + 'static) -> Result<JoinHandle<()>> {
    Ok(std::thread::Builder::new().name(name.to_owned()).spawn(f)?)
}

pub(super) fn accept_loop(
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
pub(super) fn serve_slave(shared: Arc<Shared>, stream: TcpStream) -> Result<()> {
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
