//! How ROS 2's tools find rover's node: `ros2 node list` and `ros2 node info` do not read DDS
//! discovery alone; every rmw publishes, per DDS participant, which nodes it holds and which
//! DDS readers and writers belong to each node, on the topic `ros_discovery_info` (no `rt/`
//! prefix), type `rmw_dds_common/msg/ParticipantEntitiesInfo`, reliable, transient local, keep
//! last 1 (a tool started later still gets it). rover's participant holds one node; its
//! entities are the bridge's readers and writers, the discovery writer itself excepted (as
//! rmw keeps it out of every node).
//!
//! An entity's ROS 2 id (`Gid`) is its DDS GUID (16 bytes), padded with zeros to the size the
//! distribution uses: 24 bytes up to Humble, 16 from Iron on. A peer of another size reads the
//! message wrongly, so the distribution is chosen (`--ros-distro`).

use crate::error::{Context, Result};
use rustdds::no_key::DataWriter;
use rustdds::{CDRSerializerAdapter, DomainParticipant, GUID, RTPSEntity, TopicKind};

use crate::dds::latched_qos;
use serde::ser::SerializeTuple;
use serde::{Serialize, Serializer};

/// The topic (a DDS name: ROS 2 does not prefix it).
pub const DISCOVERY_TOPIC: &str = "ros_discovery_info";
/// Its DDS type name.
const DISCOVERY_TYPE: &str = "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_";

/// A ROS 2 distribution, for what differs on the wire between them (the size of a `Gid`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum RosDistro {
    /// Humble Hawksbill (LTS, 2022): 24-byte Gids.
    Humble,
    /// Iron Irwini (2023): 16-byte Gids from here on.
    Iron,
    /// Jazzy Jalisco (LTS, 2024).
    Jazzy,
    /// Kilted Kaiju (2025).
    Kilted,
    /// Lyrical Luth (LTS, 2026): the newest LTS, the default.
    #[default]
    Lyrical,
}

impl RosDistro {
    /// Every distribution rover knows, oldest first.
    pub const ALL: [Self; 5] = [
        Self::Humble,
        Self::Iron,
        Self::Jazzy,
        Self::Kilted,
        Self::Lyrical,
    ];

    /// Bytes in a `rmw_dds_common/msg/Gid`.
    pub fn gid_len(self) -> usize {
        if self == Self::Humble { 24 } else { 16 }
    }

    /// The name `ROS_DISTRO` gives it.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Humble => "humble",
            Self::Iron => "iron",
            Self::Jazzy => "jazzy",
            Self::Kilted => "kilted",
            Self::Lyrical => "lyrical",
        }
    }

    /// The distribution a `ROS_DISTRO` value names; `None` for anything else (a ROS 1
    /// distribution such as `noetic`, or one rover does not know).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|d| d.as_str() == name.trim())
    }
}

/// `rmw_dds_common/msg/Gid`: `char[N] data`, a fixed array (no length on the wire).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Gid {
    bytes: [u8; 24],
    len: usize,
}

impl Gid {
    /// A DDS entity's id, in the size `distro` uses.
    pub fn new(guid: GUID, distro: RosDistro) -> Self {
        let mut bytes = [0; 24];
        bytes[..16].copy_from_slice(&guid.to_bytes());
        Self {
            bytes,
            len: distro.gid_len(),
        }
    }
}

impl Serialize for Gid {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut tuple = serializer.serialize_tuple(self.len)?;
        for b in &self.bytes[..self.len] {
            tuple.serialize_element(b)?;
        }
        tuple.end()
    }
}

/// `rmw_dds_common/msg/NodeEntitiesInfo`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NodeEntitiesInfo {
    /// The node's namespace (`/`).
    pub node_namespace: String,
    /// The node's name.
    pub node_name: String,
    /// Its DDS readers.
    pub reader_gid_seq: Vec<Gid>,
    /// Its DDS writers.
    pub writer_gid_seq: Vec<Gid>,
}

/// `rmw_dds_common/msg/ParticipantEntitiesInfo`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParticipantEntitiesInfo {
    /// The DDS participant.
    pub gid: Gid,
    /// The nodes it holds.
    pub node_entities_info_seq: Vec<NodeEntitiesInfo>,
}

/// A ROS 2 node name as namespace and base name: `rover` -> (`/`, `rover`), `/a/b/rover` ->
/// (`/a/b`, `rover`).
pub fn split_node_name(name: &str) -> (String, String) {
    let trimmed = name.trim_matches('/');
    match trimmed.rsplit_once('/') {
        Some((ns, base)) => (format!("/{ns}"), base.to_owned()),
        None => ("/".to_owned(), trimmed.to_owned()),
    }
}

/// The participant's announcement of its node, kept for late joiners.
pub struct Discovery {
    writer: DataWriter<ParticipantEntitiesInfo, CDRSerializerAdapter<ParticipantEntitiesInfo>>,
    info: ParticipantEntitiesInfo,
    distro: RosDistro,
}

impl Discovery {
    /// Creates the `ros_discovery_info` writer of `participant` for node `name` (a ROS 2
    /// node name, possibly with a namespace).
    pub fn new(
        participant: &DomainParticipant,
        publisher: &rustdds::Publisher,
        name: &str,
        distro: RosDistro,
    ) -> Result<Self> {
        let qos = latched_qos();
        let topic = participant
            .create_topic(
                DISCOVERY_TOPIC.to_owned(),
                DISCOVERY_TYPE.to_owned(),
                &qos,
                TopicKind::NoKey,
            )
            .context("creating the DDS topic ros_discovery_info")?;
        let writer = publisher
            .create_datawriter_no_key(&topic, Some(qos))
            .context("creating the ros_discovery_info writer")?;
        let (node_namespace, node_name) = split_node_name(name);
        Ok(Self {
            writer,
            info: ParticipantEntitiesInfo {
                gid: Gid::new(participant.guid(), distro),
                node_entities_info_seq: vec![NodeEntitiesInfo {
                    node_namespace,
                    node_name,
                    reader_gid_seq: Vec::new(),
                    writer_gid_seq: Vec::new(),
                }],
            },
            distro,
        })
    }

    /// Adds the node's readers and writers (their DDS GUIDs) and publishes the whole message
    /// again, as rmw does on every change.
    pub fn add(&mut self, readers: &[GUID], writers: &[GUID]) -> Result<()> {
        let distro = self.distro;
        if let Some(node) = self.info.node_entities_info_seq.first_mut() {
            node.reader_gid_seq
                .extend(readers.iter().map(|&g| Gid::new(g, distro)));
            node.writer_gid_seq
                .extend(writers.iter().map(|&g| Gid::new(g, distro)));
        }
        self.writer
            .write(self.info.clone(), None)
            .context("publishing ros_discovery_info")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cdr(info: &ParticipantEntitiesInfo) -> Vec<u8> {
        rustdds::serialization::to_vec::<_, byteorder::LittleEndian>(info).unwrap_or_default()
    }

    #[test]
    fn a_gid_is_the_guid_padded_to_the_distros_size_without_a_length() {
        let guid = GUID::from_bytes([7; 16]);
        let one_node = |distro| ParticipantEntitiesInfo {
            gid: Gid::new(guid, distro),
            node_entities_info_seq: vec![NodeEntitiesInfo {
                node_namespace: "/".into(),
                node_name: "rover".into(),
                reader_gid_seq: vec![Gid::new(guid, distro)],
                writer_gid_seq: Vec::new(),
            }],
        };
        for (distro, n) in [(RosDistro::Humble, 24), (RosDistro::Jazzy, 16)] {
            let bytes = cdr(&one_node(distro));
            // gid, then the sequence's length (1), its node: namespace "/\0" (len 2), name
            // "rover\0" (len 6), pad to 4, readers (1 + one gid), writers (0).
            assert_eq!(&bytes[..16], &[7; 16]);
            assert!(bytes[16..n].iter().all(|&b| b == 0));
            assert_eq!(bytes[n..n + 4], 1u32.to_le_bytes());
            let name_at = n + 4 + 4 + 2 + 2;
            assert_eq!(bytes[name_at..name_at + 4], 6u32.to_le_bytes());
            assert_eq!(&bytes[name_at + 4..name_at + 9], b"rover");
            let readers_at = name_at + 4 + 6 + 2;
            assert_eq!(bytes[readers_at..readers_at + 4], 1u32.to_le_bytes());
            assert_eq!(bytes.len(), readers_at + 4 + n + 4);
        }
    }

    #[test]
    fn node_names_split_into_namespace_and_name() {
        assert_eq!(split_node_name("rover"), ("/".into(), "rover".into()));
        assert_eq!(split_node_name("/rover"), ("/".into(), "rover".into()));
        assert_eq!(
            split_node_name("/a/b/rover"),
            ("/a/b".into(), "rover".into())
        );
    }

    #[test]
    fn ros_distro_names_what_ros_distro_says_and_nothing_else() {
        assert_eq!(RosDistro::from_name("humble"), Some(RosDistro::Humble));
        assert_eq!(RosDistro::from_name("jazzy\n"), Some(RosDistro::Jazzy));
        assert_eq!(RosDistro::from_name("noetic"), None);
        assert_eq!(RosDistro::default().gid_len(), 16);
    }
}
