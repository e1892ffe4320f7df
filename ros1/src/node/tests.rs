//! The node's unit tests: names, registration with a slow master, and two nodes talking over
//! real sockets.

use std::io::BufReader;
use std::net::{TcpListener, TcpStream};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::state::lock;
use super::subscriber::connect_publishers;
use super::{Node, NodeOptions, global_name};
use crate::error::{Error, Result};
use crate::msgs::{Twist, Vector3};
use crate::tcpros::{read_header, write_header};
use crate::xmlrpc::{self, Value};

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
