//! The ROS 2 bridge (`rover --ros2`): the ROS 1 bridge's topics, names and frames
//! ([`RosPlan`]) spoken over DDS (RTPS) as ROS 2 nodes speak it, with RustDDS (pure Rust, no
//! ROS install): topic `/odom` is DDS topic `rt/odom`, type `nav_msgs/msg/Odometry` is
//! `nav_msgs::msg::dds_::Odometry_`, CDR little-endian, domain `ROS_DOMAIN_ID`.
//!
//! Like the ROS 1 bridge it is an adapter at the edge: an [`Observer`] that copies what the
//! session does into a channel for its publishing thread (never waiting: a full channel drops
//! the event and counts it), and an [`InputSource`] ([`Ros2Input`]) that turns `rt/cmd_vel`
//! into rover input like a key press. Stamps are sim time; `/clock` carries it.
//!
//! QoS as ROS 2 nodes expect: reliable, volatile, keep last 10 for `/odom`, `/tf`, `/clock` and
//! the command topic (rclcpp's default).
//!
//! This first step carries `/cmd_vel` in and `/clock`, `/odom` and `/tf` (odom -> base) out;
//! the other topics of the ROS 1 bridge follow (docs/ROS2.md says which).
//!
//! Why RustDDS and not ros2-client (the ROS 2 client library on top of it): the bridge needs
//! topics, writers and readers with chosen QoS — what RustDDS offers directly — and nothing of
//! ros2-client's node machinery (parameters, rosout, actions, async executors) yet; one crate
//! less to build (RustDDS's cold build: 2 min on 2 cores).

mod msgs;

use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

use anyhow::{Context, Result};
use rover_core::{Action, InputSource, LoopStats, Observer};
use rover_sim::{ControlSample, ODOM_POSE_COVARIANCE_DIAGONAL, RobotModel, Simulation, Twist};
use rustdds::no_key::{DataReader, DataWriter};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{
    CDRDeserializerAdapter, CDRSerializerAdapter, DomainParticipant, QosPolicies, QosPolicyBuilder,
    TopicKind,
};

use crate::ros::RosPlan;
use msgs::{Covariance, Header, RosMessage, Time};

/// `--ros2` settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ros2Options {
    /// The DDS domain (`ROS_DOMAIN_ID`, 0 by default).
    pub domain_id: u16,
}

impl Ros2Options {
    /// From the environment: `ROS_DOMAIN_ID` (0..=232, as ROS 2 allows; 0 when unset).
    pub fn from_env() -> Result<Self> {
        let domain_id = match std::env::var("ROS_DOMAIN_ID") {
            Ok(text) if !text.trim().is_empty() => {
                let id: u16 = text.trim().parse().with_context(|| {
                    format!("ROS_DOMAIN_ID must be a number 0..=232, found \"{text}\"")
                })?;
                anyhow::ensure!(id <= 232, "ROS_DOMAIN_ID must be 0..=232, found {id}");
                id
            }
            _ => 0,
        };
        Ok(Self { domain_id })
    }
}

/// A ROS name as its DDS topic: `/odom` -> `rt/odom`, `/a/b` -> `rt/a/b`.
pub fn dds_topic(ros_name: &str) -> String {
    format!("rt/{}", ros_name.trim_start_matches('/'))
}

/// rclcpp's default QoS: reliable, volatile, keep last 10.
fn default_qos() -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_millis(100),
        })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 })
        .build()
}

type Writer<M> = DataWriter<M, CDRSerializerAdapter<M>>;

/// A writer of `M` on the ROS topic `ros_name`.
fn writer<M: RosMessage>(
    participant: &DomainParticipant,
    publisher: &rustdds::Publisher,
    ros_name: &str,
    qos: &QosPolicies,
) -> Result<Writer<M>> {
    let topic = participant
        .create_topic(
            dds_topic(ros_name),
            M::DDS_TYPE.to_owned(),
            qos,
            TopicKind::NoKey,
        )
        .with_context(|| format!("creating the DDS topic for {ros_name}"))?;
    publisher
        .create_datawriter_no_key::<M, CDRSerializerAdapter<M>>(&topic, Some(qos.clone()))
        .with_context(|| format!("creating the writer for {ros_name}"))
}

/// What the loop thread hands the publishing thread.
enum Event {
    /// A control update: its sample.
    Control(ControlSample),
}

/// The observer half of the bridge.
pub struct Ros2Bridge {
    tx: Option<SyncSender<Event>>,
    thread: Option<JoinHandle<()>>,
    dropped: u64,
}

impl std::fmt::Debug for Ros2Bridge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Bridge")
            .field("dropped", &self.dropped)
            .finish_non_exhaustive()
    }
}

/// The input half: `rt/cmd_vel` (geometry_msgs/msg/Twist) as manual input.
pub struct Ros2Input {
    cmd_vel: DataReader<msgs::Twist, CDRDeserializerAdapter<msgs::Twist>>,
    warned: bool,
}

impl std::fmt::Debug for Ros2Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Input").finish_non_exhaustive()
    }
}

impl InputSource for Ros2Input {
    fn poll(&mut self) -> Option<Action> {
        let mut newest = None;
        loop {
            match self.cmd_vel.take_next_sample() {
                Ok(Some(sample)) => {
                    let t = sample.value();
                    newest = Some(Action::CmdVel(Twist::new(t.linear.x, t.angular.z)));
                }
                Ok(None) => return newest,
                Err(e) => {
                    // A peer's garbage or a wrong type: said once, the run goes on.
                    if !std::mem::replace(&mut self.warned, true) {
                        tracing::warn!("ROS 2: a cmd_vel sample could not be read ({e}); ignored");
                    }
                    return newest;
                }
            }
        }
    }
}

impl Ros2Bridge {
    /// Joins DDS domain `options.domain_id`, creates the robot's topics and starts the
    /// publishing thread.
    pub fn start(options: &Ros2Options, robot: &RobotModel) -> Result<(Self, Ros2Input)> {
        let plan = RosPlan::for_robot(robot);
        let participant = DomainParticipant::new(options.domain_id)
            .with_context(|| format!("joining DDS domain {}", options.domain_id))?;
        let qos = default_qos();
        let subscriber = participant
            .create_subscriber(&qos)
            .context("creating the DDS subscriber")?;
        let cmd_topic = participant
            .create_topic(
                dds_topic(&plan.cmd_topic),
                msgs::Twist::DDS_TYPE.to_owned(),
                &qos,
                TopicKind::NoKey,
            )
            .context("creating the cmd_vel topic")?;
        let cmd_vel = subscriber
            .create_datareader_no_key::<msgs::Twist, CDRDeserializerAdapter<msgs::Twist>>(
                &cmd_topic, None,
            )
            .context("creating the cmd_vel reader")?;
        let topics = Topics::create(&participant, &plan)?;
        let (tx, rx) = sync_channel::<Event>(64);
        let thread = std::thread::Builder::new()
            .name("ros2-bridge".into())
            .spawn(move || run(participant, topics, &rx))
            .context("starting the ROS 2 bridge thread")?;
        tracing::info!(
            "ROS 2: DDS domain {}; cmd_vel on {}, odometry on {}",
            options.domain_id,
            dds_topic(&plan.cmd_topic),
            dds_topic(&plan.odom_topic)
        );
        Ok((
            Self {
                tx: Some(tx),
                thread: Some(thread),
                dropped: 0,
            },
            Ros2Input {
                cmd_vel,
                warned: false,
            },
        ))
    }

    /// Events dropped because the publishing thread was behind.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Sends what is queued and stops the thread.
    pub fn finish(&mut self) {
        self.tx = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }

    fn send(&mut self, event: Event) {
        if let Some(tx) = &self.tx {
            match tx.try_send(event) {
                Ok(()) => {}
                Err(TrySendError::Full(_)) => self.dropped += 1,
                Err(TrySendError::Disconnected(_)) => self.tx = None,
            }
        }
    }
}

impl Drop for Ros2Bridge {
    fn drop(&mut self) {
        self.finish();
    }
}

impl Observer for Ros2Bridge {
    fn control(&mut self, _sim: &Simulation, sample: &ControlSample, _stats: &LoopStats) {
        self.send(Event::Control(*sample));
    }
}

/// The writers and the messages they reuse.
struct Topics {
    clock: Writer<msgs::Clock>,
    odom: Writer<msgs::Odometry>,
    tf: Writer<msgs::TfMessage>,
    odom_msg: msgs::Odometry,
    tf_msg: Option<msgs::TfMessage>,
}

/// A 6x6 covariance with `diagonal` on its diagonal.
fn covariance(diagonal: [f64; 6]) -> Covariance {
    let mut c = [0.0; 36];
    for (i, d) in diagonal.iter().enumerate() {
        c[i * 7] = *d;
    }
    Covariance(c)
}

impl Topics {
    fn create(participant: &DomainParticipant, plan: &RosPlan) -> Result<Self> {
        let qos = default_qos();
        let publisher = participant
            .create_publisher(&qos)
            .context("creating the DDS publisher")?;
        let cov = covariance(ODOM_POSE_COVARIANCE_DIAGONAL);
        let mut odom_msg = msgs::Odometry {
            header: Header {
                stamp: Time::default(),
                frame_id: plan.odom_frame.clone(),
            },
            child_frame_id: plan.base_frame.clone(),
            ..msgs::Odometry::default()
        };
        odom_msg.pose.covariance = cov;
        odom_msg.twist.covariance = cov;
        let tf_msg = plan.odom_tf.then(|| msgs::TfMessage {
            transforms: vec![msgs::TransformStamped {
                header: Header {
                    stamp: Time::default(),
                    frame_id: plan.odom_frame.clone(),
                },
                child_frame_id: plan.base_frame.clone(),
                transform: msgs::Transform::default(),
            }],
        });
        Ok(Self {
            clock: writer(participant, &publisher, "/clock", &qos)?,
            odom: writer(participant, &publisher, &plan.odom_topic, &qos)?,
            tf: writer(participant, &publisher, "/tf", &qos)?,
            odom_msg,
            tf_msg,
        })
    }

    fn control(&mut self, sample: &ControlSample) {
        let stamp = Time::from_secs(sample.sim_time_s);
        let o = sample.odometry;
        let _ = self.clock.write(msgs::Clock { clock: stamp }, None);
        let msg = &mut self.odom_msg;
        msg.header.stamp = stamp;
        msg.pose.pose.position = msgs::Vector3 {
            x: o.x_m,
            y: o.y_m,
            z: 0.0,
        };
        msg.pose.pose.orientation = msgs::Quaternion::from_yaw(o.yaw_rad);
        msg.twist.twist.linear.x = o.linear_mps;
        msg.twist.twist.angular.z = o.angular_radps;
        let _ = self.odom.write(msg.clone(), None);
        if let Some(tf) = &mut self.tf_msg {
            if let Some(t) = tf.transforms.first_mut() {
                t.header.stamp = stamp;
                t.transform.translation = msg.pose.pose.position;
                t.transform.rotation = msg.pose.pose.orientation;
            }
            let _ = self.tf.write(tf.clone(), None);
        }
    }
}

/// The publishing thread: every event to the topics, until the bridge hangs up.
fn run(participant: DomainParticipant, mut topics: Topics, events: &Receiver<Event>) {
    for event in events {
        match event {
            Event::Control(sample) => topics.control(&sample),
        }
    }
    drop(topics);
    drop(participant);
}
