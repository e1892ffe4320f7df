//! DDS helpers shared by the bridge's halves: ROS names as DDS topics, rclcpp's default QoS,
//! and typed writers.

use crate::error::{Context, Result};
use rustdds::no_key::DataWriter;
use rustdds::policy::{Durability, History, Lifespan, Reliability};
use rustdds::{CDRSerializerAdapter, DomainParticipant, QosPolicies, QosPolicyBuilder, TopicKind};

use crate::msgs::RosMessage;

/// A ROS name as its DDS topic: `/odom` -> `rt/odom`, `/a/b` -> `rt/a/b`.
pub fn dds_topic(ros_name: &str) -> String {
    format!("rt/{}", ros_name.trim_start_matches('/'))
}

/// Reliable (`true`) or best effort, `durability`, keep last `depth`.
fn qos(reliable: bool, durability: Durability, depth: i32) -> QosPolicies {
    let reliability = if reliable {
        Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_millis(100),
        }
    } else {
        Reliability::BestEffort
    };
    QosPolicyBuilder::new()
        .reliability(reliability)
        .durability(durability)
        .history(History::KeepLast { depth })
        .build()
}

/// rclcpp's default QoS: reliable, volatile, keep last 10.
pub fn default_qos() -> QosPolicies {
    qos(true, Durability::Volatile, 10)
}

/// What a late joiner must still get: reliable, transient local, keep last 1 (tf2's static
/// broadcaster, robot_state_publisher's description, rmw's `ros_discovery_info`).
pub fn latched_qos() -> QosPolicies {
    qos(true, Durability::TransientLocal, 1)
}

/// rclcpp's ParameterEventsQoS: reliable, volatile, keep last 1000.
pub fn parameter_events_qos() -> QosPolicies {
    qos(true, Durability::Volatile, 1000)
}

/// rcl's `/rosout` QoS: reliable, transient local, keep last 1000, each line kept 10 s (a
/// late rqt_console gets the recent lines); a write never waits for a full window (a line is
/// dropped instead).
pub fn rosout_qos() -> QosPolicies {
    QosPolicyBuilder::new()
        .reliability(Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_millis(0),
        })
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1000 })
        .lifespan(Lifespan {
            duration: rustdds::Duration::from_secs(10),
        })
        .build()
}

/// rclcpp's SensorDataQoS: best effort, volatile, keep last 5 (images, scans).
pub fn sensor_qos() -> QosPolicies {
    qos(false, Durability::Volatile, 5)
}

/// A DDS writer of the message `M`, CDR little-endian.
pub type Writer<M> = DataWriter<M, CDRSerializerAdapter<M>>;

/// A writer of `M` on the ROS topic `ros_name`.
pub fn writer<M: RosMessage>(
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
