//! ros_gz_bridge's topic maps: the YAML file `parameter_bridge` takes as `config_file`, a list
//! of entries naming a gz topic, its ROS topic, both types and the direction. rover reads it to
//! give each gz-sim topic its ROS name and type (on ROS 2 and ROS 1 alike): TurtleBot3's Jazzy
//! file maps `cmd_vel` as geometry_msgs/msg/TwistStamped, for instance.
//!
//! ros_gz_bridge's rules: `topic_name` names both sides, else `ros_topic_name` and
//! `gz_topic_name` (one alone names both); both type names are required; `direction` is
//! `BIDIRECTIONAL` (the default), `GZ_TO_ROS` or `ROS_TO_GZ`. Where ros_gz_bridge warns and
//! skips an entry (an invalid direction, a type pair it has no bridge for), rover refuses the
//! file with the entry's line.

use std::path::{Path, PathBuf};

use super::yaml::{self, Node, Value};
use crate::error::{Result, SimError};

/// Which way a bridged topic flows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BridgeDirection {
    /// Both ways (`BIDIRECTIONAL`).
    Bidirectional,
    /// Simulation to ROS (`GZ_TO_ROS`): sensors, odometry, clock.
    GzToRos,
    /// ROS to simulation (`ROS_TO_GZ`): commands.
    RosToGz,
}

/// One entry of a topic map.
#[derive(Debug, Clone, PartialEq)]
pub struct TopicBridge {
    /// The ROS topic (as written: relative names are global on the bridge's node).
    pub ros_topic: String,
    /// The gz topic.
    pub gz_topic: String,
    /// The ROS type as written (`geometry_msgs/msg/TwistStamped`).
    pub ros_type: String,
    /// The gz type (`gz.msgs.Twist`).
    pub gz_type: String,
    /// Which way it flows.
    pub direction: BridgeDirection,
    /// `lazy`: the bridge subscribes only while someone listens (rover publishes regardless).
    pub lazy: bool,
    /// The entry's line.
    pub line: u32,
}

impl TopicBridge {
    /// The ROS type without the `/msg/` ROS 2 puts in it (`geometry_msgs/TwistStamped`).
    pub fn ros_type_short(&self) -> String {
        self.ros_type.replace("/msg/", "/")
    }
}

/// A ros_gz_bridge topic map.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TopicMap {
    /// The file it came from.
    pub source: PathBuf,
    /// Its entries, in file order.
    pub entries: Vec<TopicBridge>,
}

/// The ROS and gz message types ros_gz_bridge bridges that rover's topics use: each ROS type
/// with the gz types it pairs with.
const PAIRS: &[(&str, &[&str])] = &[
    ("rosgraph_msgs/Clock", &["gz.msgs.Clock"]),
    ("sensor_msgs/JointState", &["gz.msgs.Model"]),
    (
        "nav_msgs/Odometry",
        &["gz.msgs.Odometry", "gz.msgs.OdometryWithCovariance"],
    ),
    ("tf2_msgs/TFMessage", &["gz.msgs.Pose_V"]),
    ("geometry_msgs/Twist", &["gz.msgs.Twist"]),
    ("geometry_msgs/TwistStamped", &["gz.msgs.Twist"]),
    ("sensor_msgs/Imu", &["gz.msgs.IMU"]),
    ("sensor_msgs/LaserScan", &["gz.msgs.LaserScan"]),
    ("sensor_msgs/PointCloud2", &["gz.msgs.PointCloudPacked"]),
    ("sensor_msgs/Image", &["gz.msgs.Image"]),
    ("sensor_msgs/CameraInfo", &["gz.msgs.CameraInfo"]),
    ("sensor_msgs/NavSatFix", &["gz.msgs.NavSat"]),
    ("geometry_msgs/PoseArray", &["gz.msgs.Pose_V"]),
    ("geometry_msgs/PoseStamped", &["gz.msgs.Pose"]),
    ("std_msgs/Float64", &["gz.msgs.Double"]),
    (
        "trajectory_msgs/JointTrajectory",
        &["gz.msgs.JointTrajectory"],
    ),
    ("std_msgs/Bool", &["gz.msgs.Boolean"]),
    ("std_msgs/String", &["gz.msgs.StringMsg"]),
];

/// `/name` for a topic as the bridge's node resolves it (relative names are global there).
fn global(name: &str) -> String {
    format!("/{}", name.trim_start_matches('/'))
}

impl TopicMap {
    /// Reads a topic map file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::io::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses topic map text; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let err = |line: u32, m: String| SimError::invalid(path, Some(line), m);
        let Some(root) = yaml::load(text, path)? else {
            return Err(err(
                1,
                "the file is empty; expected a list of bridges (- ros_topic_name: ..., gz_topic_name: ..., ros_type_name: ..., gz_type_name: ..., direction: GZ_TO_ROS)".to_owned(),
            ));
        };
        let Value::List(items) = &root.value else {
            return Err(err(
                root.line,
                format!(
                    "expected a YAML list of bridges at the top level, found {}",
                    root.describe()
                ),
            ));
        };
        let mut entries = Vec::with_capacity(items.len());
        for item in items {
            entries.push(read_entry(item, path)?);
        }
        Ok(Self {
            source: path.to_path_buf(),
            entries,
        })
    }

    /// The entry bridging gz topic `gz_topic` (leading `/` or not), if any.
    pub fn for_gz_topic(&self, gz_topic: &str) -> Option<&TopicBridge> {
        let wanted = global(gz_topic);
        self.entries.iter().find(|e| global(&e.gz_topic) == wanted)
    }

    /// The ROS name (`/name`) of gz topic `gz_topic`, if the map bridges it.
    pub fn ros_name(&self, gz_topic: &str) -> Option<String> {
        self.for_gz_topic(gz_topic).map(|e| global(&e.ros_topic))
    }
}

fn read_entry(item: &Node, path: &Path) -> Result<TopicBridge> {
    let err = |line: u32, m: String| SimError::invalid(path, Some(line), m);
    if !item.is_map() {
        return Err(err(
            item.line,
            format!(
                "expected a bridge (a mapping of ros_topic_name, gz_topic_name, ros_type_name, gz_type_name, direction), found {}",
                item.describe()
            ),
        ));
    }
    let text = |key: &str| -> Result<Option<(String, u32)>> {
        match item.get(key) {
            None => Ok(None),
            Some(Node {
                value: Value::Text(t),
                line,
            }) => Ok(Some((t.trim().to_owned(), *line))),
            Some(other) => Err(err(
                other.line,
                format!("{key}: expected text, found {}", other.describe()),
            )),
        }
    };
    for (key, value) in item.entries() {
        if !matches!(
            key.as_str(),
            "topic_name"
                | "ros_topic_name"
                | "gz_topic_name"
                | "ros_type_name"
                | "gz_type_name"
                | "direction"
                | "lazy"
                | "publisher_queue"
                | "subscriber_queue"
        ) {
            tracing::warn!(
                "{}:{}: {key}: not a ros_gz_bridge key (QoS is set with qos_overrides parameters); ignored",
                path.display(),
                value.line
            );
        }
    }
    let (ros_topic, gz_topic) = topic_names(item, &text, path)?;
    let (ros_type, gz_norm) = type_names(item, &text, path)?;
    let direction = match text("direction")? {
        None => BridgeDirection::Bidirectional,
        Some((d, line)) => match d.as_str() {
            "BIDIRECTIONAL" => BridgeDirection::Bidirectional,
            "GZ_TO_ROS" => BridgeDirection::GzToRos,
            "ROS_TO_GZ" => BridgeDirection::RosToGz,
            other => {
                return Err(err(
                    line,
                    format!(
                        "direction: invalid direction '{other}'; expected BIDIRECTIONAL, GZ_TO_ROS or ROS_TO_GZ"
                    ),
                ));
            }
        },
    };
    let lazy = match item.get("lazy") {
        None => false,
        Some(Node {
            value: Value::Bool(b),
            ..
        }) => *b,
        Some(other) => {
            return Err(err(
                other.line,
                format!("lazy: expected true or false, found {}", other.describe()),
            ));
        }
    };
    Ok(TopicBridge {
        ros_topic,
        gz_topic,
        ros_type,
        gz_type: gz_norm,
        direction,
        lazy,
        line: item.line,
    })
}

/// The text of `key` in an entry, with its line.
type TextOf<'a> = dyn Fn(&str) -> Result<Option<(String, u32)>> + 'a;

/// An entry's ROS and gz topic names, by ros_gz_bridge's rules.
fn topic_names(item: &Node, text: &TextOf<'_>, path: &Path) -> Result<(String, String)> {
    let err = |line: u32, m: &str| SimError::invalid(path, Some(line), m);
    let (topic, ros, gz) = (
        text("topic_name")?,
        text("ros_topic_name")?,
        text("gz_topic_name")?,
    );
    Ok(match (topic, ros, gz) {
        (Some((_, line)), Some(_), _) | (Some((_, line)), _, Some(_)) => {
            return Err(err(
                line,
                "topic_name and ros_topic_name/gz_topic_name are mutually exclusive",
            ));
        }
        (Some((t, _)), None, None) => (t.clone(), t),
        (None, Some((r, _)), Some((g, _))) => (r, g),
        (None, Some((t, _)), None) | (None, None, Some((t, _))) => (t.clone(), t),
        (None, None, None) => {
            return Err(err(
                item.line,
                "expected topic_name, or ros_topic_name and gz_topic_name",
            ));
        }
    })
}

/// An entry's ROS type (as written) and gz type (`ignition.msgs.` read as `gz.msgs.`), a pair
/// ros_gz_bridge bridges.
fn type_names(item: &Node, text: &TextOf<'_>, path: &Path) -> Result<(String, String)> {
    let err = |line: u32, m: String| SimError::invalid(path, Some(line), m);
    let (Some((ros_type, ros_line)), Some((gz_type, gz_line))) =
        (text("ros_type_name")?, text("gz_type_name")?)
    else {
        return Err(err(
            item.line,
            "both ros_type_name and gz_type_name must be set".to_owned(),
        ));
    };
    let short = ros_type.replace("/msg/", "/");
    let Some((_, gz_types)) = PAIRS.iter().find(|(r, _)| *r == short) else {
        return Err(err(
            ros_line,
            format!(
                "ros_type_name: unknown type '{ros_type}'; expected one of {}",
                PAIRS
                    .iter()
                    .map(|(r, _)| r.replacen('/', "/msg/", 1))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    };
    let gz_norm = gz_type.replace("ignition.msgs.", "gz.msgs.");
    if !gz_types.contains(&gz_norm.as_str()) {
        return Err(err(
            gz_line,
            format!(
                "gz_type_name: no bridge between {ros_type} and '{gz_type}'; expected {}",
                gz_types.join(" or ")
            ),
        ));
    }
    Ok((ros_type, gz_norm))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_read_with_ros_gz_bridges_rules() -> Result<()> {
        let text = "\
- ros_topic_name: \"cmd_vel\"
  gz_topic_name: \"/model/tb3/cmd_vel\"
  ros_type_name: \"geometry_msgs/msg/TwistStamped\"
  gz_type_name: \"gz.msgs.Twist\"
  direction: ROS_TO_GZ
- topic_name: clock
  ros_type_name: rosgraph_msgs/msg/Clock
  gz_type_name: gz.msgs.Clock
  lazy: true
";
        let map = TopicMap::parse(text, Path::new("b.yaml"))?;
        assert_eq!(map.entries.len(), 2);
        let cmd = map
            .for_gz_topic("model/tb3/cmd_vel")
            .ok_or_else(|| SimError::invalid(Path::new("x"), None, "missing"))?;
        assert_eq!(cmd.direction, BridgeDirection::RosToGz);
        assert_eq!(cmd.ros_type_short(), "geometry_msgs/TwistStamped");
        assert_eq!(
            map.ros_name("/model/tb3/cmd_vel").as_deref(),
            Some("/cmd_vel")
        );
        assert_eq!(map.ros_name("clock").as_deref(), Some("/clock"));
        assert_eq!(map.entries[1].direction, BridgeDirection::Bidirectional);
        assert!(map.entries[1].lazy);
        Ok(())
    }

    #[test]
    fn bad_entries_are_located_errors() {
        let cases = [
            ("", "the file is empty", 1),
            ("a: 1\n", "expected a YAML list", 1),
            (
                "- topic_name: x\n  ros_type_name: sensor_msgs/msg/Imu\n  gz_type_name: gz.msgs.IMU\n  direction: BOTH\n",
                "invalid direction 'BOTH'",
                4,
            ),
            (
                "- topic_name: x\n  ros_type_name: sensor_msgs/msg/Nope\n  gz_type_name: gz.msgs.IMU\n",
                "unknown type 'sensor_msgs/msg/Nope'",
                2,
            ),
            (
                "- topic_name: x\n  ros_type_name: sensor_msgs/msg/Imu\n  gz_type_name: gz.msgs.LaserScan\n",
                "no bridge between sensor_msgs/msg/Imu and 'gz.msgs.LaserScan'",
                3,
            ),
            (
                "- topic_name: x\n  ros_type_name: sensor_msgs/msg/Imu\n",
                "both ros_type_name and gz_type_name",
                1,
            ),
            (
                "- topic_name: x\n  ros_topic_name: y\n  ros_type_name: sensor_msgs/msg/Imu\n  gz_type_name: gz.msgs.IMU\n",
                "mutually exclusive",
                1,
            ),
        ];
        for (text, expected, line) in cases {
            let err = match TopicMap::parse(text, Path::new("bridge.yaml")) {
                Ok(m) => panic!("{text:?} parsed: {m:?}"),
                Err(e) => e.to_string(),
            };
            assert!(err.contains(expected), "{err}");
            assert!(err.contains(&format!("bridge.yaml:{line}")), "{err}");
        }
    }
}
