//! What rover does itself in a launch: Gazebo (gazebo_ros' `empty_world.launch`, `gzserver`,
//! `gzclient`), `spawn_model`, `robot_state_publisher`, `joint_state_publisher`,
//! `controller_manager`'s spawner and darknet_ros. Everything else is a node rover starts.

use std::path::PathBuf;

use super::model::{Launch, LaunchError, LaunchNode, Location, ParamSource};
use super::value::{ParamValue, parse_bool, parse_yaml};

/// What a launch's `<node>` is to rover.
#[derive(Debug, Clone, PartialEq)]
pub enum NodeRole {
    /// gazebo_ros `spawn_model`: rover spawns the robot.
    Spawn,
    /// gazebo_ros `gzserver` / `gzclient`: rover's world and window.
    Gazebo,
    /// `robot_state_publisher`: rover publishes /tf itself.
    RobotStatePublisher,
    /// `joint_state_publisher` (or its GUI): rover publishes /joint_states itself.
    JointStatePublisher,
    /// `controller_manager spawner`: rover runs these controllers (from the loaded YAML).
    ControllerSpawner(Vec<String>),
    /// darknet_ros: rover's detector.
    Detector,
    /// Any other node: started as a process.
    Process,
}

impl NodeRole {
    /// What rover does in its place, in a few words (`None` for a started node).
    pub fn replaced_by(&self) -> Option<&'static str> {
        match self {
            Self::Spawn => Some("rover spawns the robot"),
            Self::Gazebo => Some("rover's world and window"),
            Self::RobotStatePublisher => Some("rover publishes /tf and /tf_static"),
            Self::JointStatePublisher => Some("rover publishes /joint_states"),
            Self::ControllerSpawner(_) => Some("rover runs the controllers"),
            Self::Detector => Some("rover's YOLO detector publishes /darknet_ros/*"),
            Self::Process => None,
        }
    }
}

/// gazebo_ros' world, from `empty_world.launch`'s args.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldRequest {
    /// `world_name` (a file, or one of Gazebo's own such as `worlds/empty.world`).
    pub world_name: Option<String>,
    /// `paused`.
    pub paused: bool,
    /// `gui` (and not `headless`).
    pub gui: bool,
    /// `use_sim_time`.
    pub use_sim_time: bool,
    /// Where it was asked for.
    pub at: Location,
}

/// `spawn_model`'s robot.
#[derive(Debug, Clone, PartialEq)]
pub struct SpawnRequest {
    /// `-model`.
    pub model: String,
    /// `-param`: the parameter holding the URDF.
    pub param: Option<String>,
    /// `-file`: a URDF/SDF file.
    pub file: Option<PathBuf>,
    /// `-x -y -z` (m).
    pub xyz_m: [f64; 3],
    /// `-Y` (rad).
    pub yaw_rad: f64,
    /// The node.
    pub at: Location,
}

/// darknet_ros' settings that matter to rover.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectorRequest {
    /// `yolo_model/threshold/value` from its network config, when that file could be read.
    pub threshold: Option<f32>,
    /// Where it was asked for.
    pub at: Location,
}

/// Everything rover does itself in a launch.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RoverPart {
    /// The world (gazebo_ros' `empty_world.launch` or a `gzserver` node).
    pub world: Option<WorldRequest>,
    /// The robot.
    pub spawn: Option<SpawnRequest>,
    /// The detector (darknet_ros).
    pub detector: Option<DetectorRequest>,
    /// Controllers the spawners name, with the YAML file they were loaded from.
    pub controllers: Vec<(String, Option<PathBuf>)>,
    /// Each node's role, in the order of [`Launch::nodes`].
    pub roles: Vec<NodeRole>,
}

impl RoverPart {
    /// What rover does with `launch` (read with [`super::LaunchOptions::rover`]).
    pub fn of(launch: &Launch) -> Result<Self, LaunchError> {
        let mut part = RoverPart::default();
        for include in &launch.provided {
            match include.package.as_str() {
                "gazebo_ros" => {
                    let flag = |name: &str, default: bool| {
                        include
                            .args
                            .get(name)
                            .and_then(|v| parse_bool(v))
                            .unwrap_or(default)
                    };
                    part.world = Some(WorldRequest {
                        world_name: include.args.get("world_name").cloned(),
                        paused: flag("paused", false),
                        gui: flag("gui", true) && !flag("headless", false),
                        use_sim_time: flag("use_sim_time", true),
                        at: include.at.clone(),
                    });
                }
                "darknet_ros" => {
                    let threshold = include
                        .args
                        .get("network_param_file")
                        .and_then(|f| std::fs::read_to_string(f).ok())
                        .and_then(|text| yolo_threshold(&text));
                    part.detector = Some(DetectorRequest {
                        threshold,
                        at: include.at.clone(),
                    });
                }
                _ => {}
            }
        }
        for node in &launch.nodes {
            let role = role_of(node);
            match &role {
                NodeRole::Spawn => {
                    if part.spawn.is_some() {
                        return Err(LaunchError::new(
                            &node.at.file,
                            node.at.line,
                            "a second spawn_model: rover simulates one robot",
                        ));
                    }
                    part.spawn = Some(spawn_request(node)?);
                }
                NodeRole::Gazebo if part.world.is_none() => {
                    part.world = Some(WorldRequest {
                        world_name: node
                            .args
                            .split_whitespace()
                            .find(|w| w.ends_with(".world") || w.ends_with(".sdf"))
                            .map(str::to_owned),
                        paused: node.args.split_whitespace().any(|w| w == "-u"),
                        gui: false,
                        use_sim_time: true,
                        at: node.at.clone(),
                    });
                }
                NodeRole::Detector if part.detector.is_none() => {
                    part.detector = Some(DetectorRequest {
                        threshold: None,
                        at: node.at.clone(),
                    });
                }
                NodeRole::ControllerSpawner(names) => {
                    for name in names {
                        let key = format!("{}{name}/type", node.namespace);
                        let file = launch.params.get(&key).and_then(|p| match &p.source {
                            ParamSource::Yaml(file) => file.clone(),
                            _ => None,
                        });
                        part.controllers.push((name.clone(), file));
                    }
                }
                _ => {}
            }
            part.roles.push(role);
        }
        Ok(part)
    }

    /// The controllers file the spawners' controllers were loaded from (the first one).
    pub fn controllers_file(&self) -> Option<&PathBuf> {
        self.controllers.iter().find_map(|(_, f)| f.as_ref())
    }
}

/// What `node` is to rover.
pub fn role_of(node: &LaunchNode) -> NodeRole {
    let words = || {
        node.args
            .split_whitespace()
            .filter(|w| !w.starts_with('-') && !w.contains(":="))
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    match (node.pkg.as_str(), node.node_type.as_str()) {
        ("gazebo_ros", "spawn_model") => NodeRole::Spawn,
        ("gazebo_ros", "gzserver" | "gzclient" | "gazebo" | "debug") => NodeRole::Gazebo,
        ("robot_state_publisher", _) => NodeRole::RobotStatePublisher,
        ("joint_state_publisher" | "joint_state_publisher_gui", _) => NodeRole::JointStatePublisher,
        ("controller_manager", "spawner") => NodeRole::ControllerSpawner(words()),
        ("controller_manager", "controller_manager") => {
            let w = words();
            match w.split_first() {
                Some((first, rest)) if first == "spawn" || first == "load" => {
                    NodeRole::ControllerSpawner(rest.to_vec())
                }
                _ => NodeRole::Process,
            }
        }
        ("darknet_ros", "darknet_ros") => NodeRole::Detector,
        _ => NodeRole::Process,
    }
}

fn spawn_request(node: &LaunchNode) -> Result<SpawnRequest, LaunchError> {
    let err = |m: String| LaunchError::new(&node.at.file, node.at.line, m);
    let words: Vec<&str> = node.args.split_whitespace().collect();
    let mut req = SpawnRequest {
        model: String::new(),
        param: None,
        file: None,
        xyz_m: [0.0; 3],
        yaw_rad: 0.0,
        at: node.at.clone(),
    };
    let mut i = 0;
    while i < words.len() {
        let flag = words[i];
        let takes_value = matches!(
            flag,
            "-param"
                | "-file"
                | "-model"
                | "-x"
                | "-y"
                | "-z"
                | "-R"
                | "-P"
                | "-Y"
                | "-database"
                | "-reference_frame"
                | "-gazebo_namespace"
                | "-robot_namespace"
                | "-package_to_model"
        );
        let value = if takes_value {
            i += 1;
            Some(
                *words
                    .get(i)
                    .ok_or_else(|| err(format!("spawn_model: {flag} needs a value")))?,
            )
        } else {
            None
        };
        let number = |v: Option<&str>| -> Result<f64, LaunchError> {
            v.and_then(|v| v.parse::<f64>().ok())
                .filter(|f| f.is_finite())
                .ok_or_else(|| err(format!("spawn_model: {flag} needs a number")))
        };
        match flag {
            "-param" => req.param = value.map(str::to_owned),
            "-file" => req.file = value.map(PathBuf::from),
            "-model" => req.model = value.unwrap_or_default().to_owned(),
            "-x" => req.xyz_m[0] = number(value)?,
            "-y" => req.xyz_m[1] = number(value)?,
            "-z" => req.xyz_m[2] = number(value)?,
            "-Y" => req.yaw_rad = number(value)?,
            "-database" => {
                return Err(err(
                    "spawn_model -database: rover has no Gazebo model database; spawn from -param or -file".to_owned(),
                ));
            }
            _ => {}
        }
        i += 1;
    }
    if req.param.is_none() && req.file.is_none() {
        return Err(err(
            "spawn_model: expected -param NAME or -file FILE for the robot's description"
                .to_owned(),
        ));
    }
    Ok(req)
}

/// darknet_ros' `yolo_model: threshold: value:` from a network config YAML.
fn yolo_threshold(text: &str) -> Option<f32> {
    let value = parse_yaml(text).ok()?;
    let get = |v: &ParamValue, key: &str| -> Option<ParamValue> {
        match v {
            ParamValue::Map(entries) => entries
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v.clone()),
            _ => None,
        }
    };
    let t = get(&get(&get(&value, "yolo_model")?, "threshold")?, "value")?;
    match t {
        ParamValue::Double(d) => Some(d as f32),
        ParamValue::Int(i) => Some(i as f32),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn darknet_threshold_is_read_from_its_config() {
        let yaml = "yolo_model:\n  config_file:\n    name: yolov2-tiny.cfg\n  threshold:\n    value: 0.4\n";
        assert_eq!(yolo_threshold(yaml), Some(0.4));
        assert_eq!(yolo_threshold("a: 1"), None);
    }
}
