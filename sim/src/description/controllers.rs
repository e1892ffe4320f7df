//! Reads a ros_control controllers YAML (what `rosparam load` and `controller_spawner` take) into
//! a [`ControllerConfig`], checked against the robot: every joint it names must exist and be
//! actuated, every controller type must be one rover runs, gains must be there where the type
//! needs them. Errors name the file, the line and what was expected.
//!
//! ros2_control's files (controller_manager's format) are read too (`ros2_controllers.rs`).
//!
//! Controllers may sit at the top level or under one namespace (`arm: {my_controller: ...}`);
//! `gazebo_ros_control/pid_gains` and rover's `named_poses` may sit at either level too.

use std::path::Path;

use super::yaml::{self, Node, Value};

use crate::error::{Result, SimError};
use crate::model::actuation::Pid;
use crate::model::controllers::{
    CommandKind, ControllerConfig, ControllerKind, ControllerSpec, GripperSpec, NamedPose,
    TrajectoryConstraints, TrajectorySpec,
};
use crate::model::robot::RobotModel;

/// The controller types rover runs, for messages.
const SUPPORTED: &str = "joint_state_controller/JointStateController, \
effort_controllers/JointPositionController, position_controllers/JointPositionController, \
velocity_controllers/JointVelocityController, effort_controllers/JointVelocityController, \
effort_controllers/JointEffortController, position_controllers/JointTrajectoryController, \
effort_controllers/JointTrajectoryController, velocity_controllers/JointTrajectoryController, \
position_controllers/GripperActionController, effort_controllers/GripperActionController";

/// Whether `link` is `ancestor` or hangs from it.
fn carries(
    robot: &RobotModel,
    ancestor: crate::model::robot::LinkId,
    link: crate::model::robot::LinkId,
) -> bool {
    let mut at = link;
    for _ in 0..robot.link_ids().count() {
        if at == ancestor {
            return true;
        }
        match robot.joint_ids().find(|(_, j)| j.child == at) {
            Some((_, j)) => at = j.parent,
            None => return false,
        }
    }
    false
}

/// Reads and checks a controllers file for `robot`.
pub fn load_controllers(path: &Path, robot: &RobotModel) -> Result<ControllerConfig> {
    let text = crate::io::read_text(path)?;
    parse_controllers(&text, path, robot)
}

/// Parses and checks controllers YAML text; `path` is used in messages.
pub fn parse_controllers(text: &str, path: &Path, robot: &RobotModel) -> Result<ControllerConfig> {
    let first = yaml::load(text, path)?;
    let mut reader = Reader {
        path,
        robot,
        config: ControllerConfig {
            source: path.to_path_buf(),
            ..ControllerConfig::default()
        },
    };
    let Some(root) = first else {
        return Err(reader.error(1, "the file is empty; expected controllers, e.g.\n  arm_controller:\n    type: position_controllers/JointTrajectoryController\n    joints: [shoulder_joint, elbow_joint]"));
    };
    if !root.is_map() {
        return Err(reader.error(
            root.line,
            format!(
                "expected a mapping of controller names to settings, found {}",
                root.describe()
            ),
        ));
    }
    // ros2_control's format (controller_manager: ros__parameters:) as the ros_control file it
    // amounts to.
    let root = if super::ros2_controllers::is_ros2(&root) {
        super::ros2_controllers::to_ros1(&root, path)?
    } else {
        root
    };
    reader.level(&root, "", true)?;
    if reader.config.controllers.is_empty() {
        return Err(reader.error(
            root.line,
            "no controller found: expected entries with a `type` (such as position_controllers/JointTrajectoryController)",
        ));
    }
    Ok(reader.config)
}

struct Reader<'a> {
    path: &'a Path,
    robot: &'a RobotModel,
    config: ControllerConfig,
}

impl Reader<'_> {
    fn error(&self, line: u32, message: impl Into<String>) -> SimError {
        SimError::invalid(self.path, Some(line), message)
    }

    /// One mapping level: controllers, `gazebo_ros_control`, `named_poses`, and (at the top
    /// only) namespaces holding those.
    fn level(&mut self, map: &Node, namespace: &str, top: bool) -> Result<()> {
        for (key, node) in map.entries() {
            if key == "gazebo_ros_control" {
                if let Some(gains) = node.get("pid_gains") {
                    for (joint, g) in gains.entries() {
                        self.check_joint(joint, g.line)?;
                        let pid = self.pid(g, &format!("pid_gains/{joint}"))?;
                        self.config.pid_gains.push((joint.clone(), pid));
                    }
                }
            } else if key == "named_poses" {
                self.named_poses(node)?;
            } else if node.get("type").is_some() {
                let spec = self.controller(key, namespace, node)?;
                self.config.controllers.push(spec);
            } else if node.get("joint").is_some() || node.get("joints").is_some() {
                return Err(self.error(
                    node.line,
                    format!("controller `{key}` has no `type`; expected one of: {SUPPORTED}"),
                ));
            } else if top && node.is_map() {
                self.level(node, key, false)?;
            } else {
                tracing::debug!(
                    "{}:{}: `{key}` is not a controller; ignored",
                    self.path.display(),
                    node.line
                );
            }
        }
        Ok(())
    }

    fn check_joint(&self, joint: &str, line: u32) -> Result<()> {
        let Some(id) = self.robot.joint_id(joint) else {
            let moving: Vec<&str> = self
                .robot
                .actuated_joints()
                .into_iter()
                .map(|id| self.robot.joint(id).name.as_str())
                .collect();
            return Err(self.error(
                line,
                format!(
                    "robot \"{}\" has no joint \"{joint}\"; its actuated joints: {}",
                    self.robot.name,
                    moving.join(", ")
                ),
            ));
        };
        if !self.robot.actuated_joints().contains(&id) {
            return Err(self.error(
                line,
                format!(
                    "joint \"{joint}\" cannot be commanded: it is fixed, passive, a drive wheel or mimics another joint"
                ),
            ));
        }
        Ok(())
    }

    fn number(&self, node: &Node, what: &str) -> Result<f64> {
        match node.value {
            Value::Number(x) if x.is_finite() => Ok(x),
            _ => Err(self.error(
                node.line,
                format!(
                    "`{what}` must be a finite number, found {}",
                    node.describe()
                ),
            )),
        }
    }

    fn optional_number(&self, map: &Node, key: &str, default: f64) -> Result<f64> {
        map.get(key).map_or(Ok(default), |n| self.number(n, key))
    }

    fn text<'n>(&self, node: &'n Node, what: &str) -> Result<&'n str> {
        match &node.value {
            Value::Text(s) => Ok(s),
            _ => Err(self.error(
                node.line,
                format!("`{what}` must be a name, found {}", node.describe()),
            )),
        }
    }

    /// `{p, i, d, i_clamp}` (control_toolbox's names; `i_clamp_max` is taken for `i_clamp`).
    /// `gains/<joint>`: the entry of a `gains` map for `joint`, which must be there.
    fn joint_gains(&self, gains: &Node, joint: &str) -> Result<Pid> {
        let Some(pid) = gains.get(joint) else {
            return Err(self.error(
                gains.line,
                format!("`gains` has no entry for joint \"{joint}\""),
            ));
        };
        self.pid(pid, &format!("gains/{joint}"))
    }

    fn pid(&self, node: &Node, what: &str) -> Result<Pid> {
        if !node.is_map() {
            return Err(self.error(
                node.line,
                format!(
                    "`{what}` must be gains {{p: ..., i: ..., d: ..., i_clamp: ...}}, found {}",
                    node.describe()
                ),
            ));
        }
        let Some(p) = node.get("p") else {
            return Err(self.error(
                node.line,
                format!(
                    "`{what}` has no `p` gain; expected {{p: ..., i: ..., d: ..., i_clamp: ...}}"
                ),
            ));
        };
        let pid = Pid {
            p: self.number(p, "p")?,
            i: self.optional_number(node, "i", 0.0)?,
            d: self.optional_number(node, "d", 0.0)?,
            i_clamp: match node.get("i_clamp") {
                Some(n) => self.number(n, "i_clamp")?,
                None => self.optional_number(node, "i_clamp_max", 0.0)?,
            },
        };
        if pid.p < 0.0 || pid.i < 0.0 || pid.d < 0.0 || pid.i_clamp < 0.0 {
            return Err(self.error(node.line, format!("`{what}`: gains must not be negative")));
        }
        Ok(pid)
    }

    fn joint_of(&self, node: &Node, name: &str) -> Result<String> {
        let Some(j) = node.get("joint") else {
            return Err(self.error(
                node.line,
                format!("controller `{name}` needs `joint: <joint name>`"),
            ));
        };
        let joint = self.text(j, "joint")?.to_owned();
        self.check_joint(&joint, j.line)?;
        Ok(joint)
    }

    fn controller(&self, name: &str, namespace: &str, node: &Node) -> Result<ControllerSpec> {
        let type_node = node.get("type").unwrap_or(node);
        let type_name = self.text(type_node, "type")?.trim().to_owned();
        let needs_pid = |me: &Self| -> Result<Pid> {
            match node.get("pid") {
                Some(p) => me.pid(p, &format!("{name}/pid")),
                None => Err(me.error(
                    node.line,
                    format!("controller `{name}` ({type_name}) needs `pid: {{p: ..., i: ..., d: ..., i_clamp: ...}}`"),
                )),
            }
        };
        let kind = match type_name.as_str() {
            "joint_state_controller/JointStateController" => {
                let rate = self.optional_number(node, "publish_rate", 50.0)?;
                if rate <= 0.0 {
                    return Err(self.error(node.line, "`publish_rate` must be above 0 Hz"));
                }
                ControllerKind::JointState {
                    publish_rate_hz: rate,
                }
            }
            "effort_controllers/JointPositionController" => ControllerKind::Joint {
                joint: self.joint_of(node, name)?,
                command: CommandKind::PositionPid(needs_pid(self)?),
            },
            "position_controllers/JointPositionController" => ControllerKind::Joint {
                joint: self.joint_of(node, name)?,
                command: CommandKind::Position,
            },
            "velocity_controllers/JointVelocityController"
            | "effort_controllers/JointVelocityController" => ControllerKind::Joint {
                joint: self.joint_of(node, name)?,
                command: CommandKind::Velocity,
            },
            "effort_controllers/JointEffortController" => ControllerKind::Joint {
                joint: self.joint_of(node, name)?,
                command: CommandKind::Effort,
            },
            "position_controllers/JointTrajectoryController"
            | "effort_controllers/JointTrajectoryController"
            | "velocity_controllers/JointTrajectoryController" => {
                ControllerKind::Trajectory(self.trajectory(name, &type_name, node)?)
            }
            "position_controllers/GripperActionController"
            | "effort_controllers/GripperActionController" => {
                ControllerKind::Gripper(self.gripper(name, node)?)
            }
            other => {
                return Err(self.error(
                    type_node.line,
                    format!(
                        "controller `{name}`: type \"{other}\" is not one rover runs; expected one of: {SUPPORTED}"
                    ),
                ));
            }
        };
        let line = node.line;
        for other in &self.config.controllers {
            let shared = other.joints().iter().find(|j| kind.joints().contains(j));
            if let Some(joint) = shared {
                return Err(self.error(
                    line,
                    format!(
                        "controller `{name}` drives joint \"{joint}\", which controller `{}` (line {}) already drives; a joint takes one controller",
                        other.name, other.line
                    ),
                ));
            }
        }
        Ok(ControllerSpec {
            name: name.to_owned(),
            namespace: namespace.to_owned(),
            type_name,
            kind,
            line,
            topic: None,
        })
    }
}

// The controllers that take more than one joint: grippers, trajectories, named poses.
impl Reader<'_> {
    /// A gripper action controller: its finger joint must close between limits (prismatic or
    /// revolute) and move a link nothing else moving hangs from (a finger, not an arm joint).
    fn gripper(&self, name: &str, node: &Node) -> Result<GripperSpec> {
        let joint = self.joint_of(node, name)?;
        let line = node.get("joint").map_or(node.line, |j| j.line);
        let robot = self.robot;
        if let Some(id) = robot.joint_id(&joint) {
            let j = robot.joint(id);
            if j.position_limits().is_none() {
                return Err(self.error(
                    line,
                    format!(
                        "controller `{name}`: joint \"{joint}\" has no position limits; a gripper's finger joint is prismatic or revolute with <limit lower upper>"
                    ),
                ));
            }
            let beyond = robot.joint_ids().find(|(_, other)| {
                other.is_moving() && other.mimic.is_none() && carries(robot, j.child, other.parent)
            });
            if let Some((_, other)) = beyond {
                return Err(self.error(
                    line,
                    format!(
                        "controller `{name}`: joint \"{joint}\" is not a finger joint: joint \"{}\" moves beyond it; name the joint that moves a finger",
                        other.name
                    ),
                ));
            }
        }
        let number = |key: &str, default: f64| -> Result<f64> {
            let v = self.optional_number(node, key, default)?;
            if v < 0.0 {
                return Err(self.error(node.line, format!("`{key}` must not be negative")));
            }
            Ok(v)
        };
        let allow_stalling = match node.get("allow_stalling") {
            None => false,
            Some(n) => match n.value {
                Value::Bool(b) => b,
                _ => {
                    return Err(self.error(
                        n.line,
                        format!(
                            "`allow_stalling` must be true or false, found {}",
                            n.describe()
                        ),
                    ));
                }
            },
        };
        let gains = match node.get("gains") {
            None => None,
            Some(g) => Some(self.joint_gains(g, &joint)?),
        };
        Ok(GripperSpec {
            joint,
            goal_tolerance: number("goal_tolerance", 0.01)?,
            stalled_velocity_threshold: number("stalled_velocity_threshold", 0.001)?,
            stall_timeout_s: number("stall_timeout", 1.0)?,
            allow_stalling,
            gains,
        })
    }

    fn trajectory(&self, name: &str, type_name: &str, node: &Node) -> Result<TrajectorySpec> {
        let Some(list) = node.get("joints") else {
            return Err(self.error(
                node.line,
                format!("controller `{name}` needs `joints: [<joint>, ...]`"),
            ));
        };
        let Value::List(items) = &list.value else {
            return Err(self.error(
                list.line,
                format!(
                    "`joints` must be a list of joint names, found {}",
                    list.describe()
                ),
            ));
        };
        if items.is_empty() {
            return Err(self.error(list.line, "`joints` is empty"));
        }
        let mut joints: Vec<String> = Vec::with_capacity(items.len());
        for item in items {
            let joint = self.text(item, "joints")?.to_owned();
            self.check_joint(&joint, item.line)?;
            if joints.contains(&joint) {
                return Err(self.error(item.line, format!("joint \"{joint}\" is listed twice")));
            }
            joints.push(joint);
        }
        let gains = if type_name.starts_with("position_controllers/") {
            None
        } else {
            let Some(g) = node.get("gains") else {
                return Err(self.error(
                    node.line,
                    format!("controller `{name}` ({type_name}) needs `gains: {{<joint>: {{p: ..., i: ..., d: ...}}}}` for each joint"),
                ));
            };
            let mut out = Vec::with_capacity(joints.len());
            for joint in &joints {
                out.push(self.joint_gains(g, joint)?);
            }
            Some(out)
        };
        let empty = Node {
            line: node.line,
            value: Value::Map(Vec::new()),
        };
        let c = node.get("constraints").unwrap_or(&empty);
        let mut constraints = TrajectoryConstraints {
            goal_time_s: self.optional_number(c, "goal_time", 0.0)?,
            stopped_velocity_tolerance: self.optional_number(
                c,
                "stopped_velocity_tolerance",
                0.01,
            )?,
            trajectory: Vec::with_capacity(joints.len()),
            goal: Vec::with_capacity(joints.len()),
        };
        for (key, value) in c.entries() {
            if !matches!(key.as_str(), "goal_time" | "stopped_velocity_tolerance")
                && !joints.contains(key)
            {
                return Err(self.error(
                    value.line,
                    format!(
                        "`constraints/{key}`: \"{key}\" is not one of this controller's joints ({})",
                        joints.join(", ")
                    ),
                ));
            }
        }
        for joint in &joints {
            let j = c.get(joint).unwrap_or(&empty);
            constraints
                .trajectory
                .push(self.optional_number(j, "trajectory", 0.0)?.abs());
            constraints
                .goal
                .push(self.optional_number(j, "goal", 0.0)?.abs());
        }
        let state_publish_rate_hz = self.optional_number(node, "state_publish_rate", 50.0)?;
        Ok(TrajectorySpec {
            joints,
            gains,
            constraints,
            state_publish_rate_hz,
        })
    }

    fn named_poses(&mut self, node: &Node) -> Result<()> {
        for (name, pose) in node.entries() {
            if !pose.is_map() || pose.entries().is_empty() {
                return Err(self.error(
                    pose.line,
                    format!("named pose `{name}` must map joint names to positions, e.g. {{arm_1_joint: 0.2}}"),
                ));
            }
            let mut joints = Vec::with_capacity(pose.entries().len());
            for (joint, value) in pose.entries() {
                self.check_joint(joint, value.line)?;
                joints.push((joint.clone(), self.number(value, joint)?));
            }
            self.config.named_poses.push(NamedPose {
                name: name.clone(),
                joints,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::controllers::CommandKind;

    const ARM: &str = r#"<robot name="arm">
      <link name="base"/><link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <link name="l2"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
      <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
    </robot>"#;

    fn robot() -> RobotModel {
        match RobotModel::from_str(ARM, Path::new("arm.urdf")) {
            Ok(r) => r,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn reads_namespaced_controllers_gains_constraints_and_poses() -> Result<()> {
        let yaml = "arm:\n  joint_state_controller:\n    type: joint_state_controller/JointStateController\n    publish_rate: 100\n  j1_position_controller:\n    type: effort_controllers/JointPositionController\n    joint: j1\n    pid: {p: 100.0, i: 0.01, d: 10.0}\n  traj:\n    type: position_controllers/JointTrajectoryController\n    joints: [j2]\n    constraints:\n      goal_time: 0.5\n      j2: {trajectory: 0.2, goal: 0.05}\nnamed_poses:\n  home: {j1: 0.1, j2: -0.3}\n";
        let c = parse_controllers(yaml, Path::new("c.yaml"), &robot())?;
        assert_eq!(c.controllers.len(), 3);
        assert_eq!(c.controllers[1].namespace, "arm");
        assert_eq!(c.controllers[1].line, 5);
        assert!(matches!(
            c.controllers[1].kind,
            ControllerKind::Joint { command: CommandKind::PositionPid(Pid { p, .. }), .. } if p == 100.0
        ));
        let ControllerKind::Trajectory(t) = &c.controllers[2].kind else {
            panic!("not a trajectory controller: {:?}", c.controllers[2]);
        };
        assert_eq!(t.constraints.goal, [0.05]);
        assert_eq!(t.constraints.goal_time_s, 0.5);
        assert_eq!(c.named_pose("home").map(|p| p.joints.len()), Some(2));
        Ok(())
    }

    fn error_of(yaml: &str) -> String {
        match parse_controllers(yaml, Path::new("c.yaml"), &robot()) {
            Ok(c) => panic!("accepted: {c:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bad_files_get_located_errors() {
        let unknown_joint =
            error_of("c:\n  type: position_controllers/JointPositionController\n  joint: elbow\n");
        assert!(
            unknown_joint.contains("c.yaml:3")
                && unknown_joint.contains("no joint \"elbow\"")
                && unknown_joint.contains("j1, j2"),
            "{unknown_joint}"
        );
        let unknown_type =
            error_of("c:\n  type: effort_controllers/JointGroupPositionController\n  joint: j1\n");
        assert!(
            unknown_type.contains("c.yaml:2") && unknown_type.contains("not one rover runs"),
            "{unknown_type}"
        );
        let no_gains =
            error_of("c:\n  type: effort_controllers/JointPositionController\n  joint: j1\n");
        assert!(no_gains.contains("needs `pid"), "{no_gains}");
        let no_p = error_of(
            "c:\n  type: effort_controllers/JointPositionController\n  joint: j1\n  pid: {d: 1}\n",
        );
        assert!(no_p.contains("no `p` gain"), "{no_p}");
        let twice = error_of(
            "a:\n  type: position_controllers/JointPositionController\n  joint: j1\nb:\n  type: velocity_controllers/JointVelocityController\n  joint: j1\n",
        );
        assert!(
            twice.contains("c.yaml:4") && twice.contains("already drives"),
            "{twice}"
        );
        let not_yaml = error_of("c: [unclosed\n");
        assert!(not_yaml.contains("not valid YAML"), "{not_yaml}");
        let no_type = error_of("c:\n  joint: j1\n");
        assert!(no_type.contains("has no `type`"), "{no_type}");
    }
}
