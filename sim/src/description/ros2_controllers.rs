//! ros2_control's controllers files (controller_manager's format, what gz_ros2_control's
//! `<parameters>` and `ros2 control load_controller` read), read as the ros_control file they
//! amount to, so that one reader checks both:
//!
//! ```yaml
//! controller_manager:
//!   ros__parameters:
//!     update_rate: 100
//!     joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
//!     arm_controller: {type: joint_trajectory_controller/JointTrajectoryController}
//! arm_controller:
//!   ros__parameters:
//!     joints: [shoulder_joint, elbow_joint]
//!     command_interfaces: [position]
//! ```
//!
//! | ros2_control type | rover runs it as |
//! |---|---|
//! | joint_state_broadcaster/JointStateBroadcaster | joint_state_controller at `update_rate` |
//! | joint_trajectory_controller/JointTrajectoryController | `<interface>_controllers/JointTrajectoryController`, the first of `command_interfaces` (position by default), with its `constraints` and `gains` |
//! | position_controllers/JointGroupPositionController, velocity_.../JointGroupVelocityController, effort_.../JointGroupEffortController, forward_command_controller/ForwardCommandController (`interface_name`) | the one-joint controller of that interface (one joint each) |
//! | position_controllers/GripperActionController, parallel_gripper_action_controller/GripperActionController | position_controllers/GripperActionController |

use std::path::Path;

use super::yaml::{Node, Value};
use crate::error::{Result, SimError};

/// The controller types read, for messages.
const SUPPORTED: &str = "joint_state_broadcaster/JointStateBroadcaster, \
joint_trajectory_controller/JointTrajectoryController, \
position_controllers/JointGroupPositionController, velocity_controllers/JointGroupVelocityController, \
effort_controllers/JointGroupEffortController, forward_command_controller/ForwardCommandController, \
position_controllers/GripperActionController, parallel_gripper_action_controller/GripperActionController";

/// Whether a controllers file is ros2_control's (`controller_manager: ros__parameters:`).
pub(crate) fn is_ros2(root: &Node) -> bool {
    root.get("controller_manager")
        .and_then(|c| c.get("ros__parameters"))
        .is_some()
}

fn text(line: u32, s: &str) -> Node {
    Node {
        line,
        value: Value::Text(s.to_owned()),
    }
}

/// The ros_control file a ros2_control file amounts to; every value keeps its line.
pub(crate) fn to_ros1(root: &Node, path: &Path) -> Result<Node> {
    let err = |line: u32, m: String| SimError::invalid(path, Some(line), m);
    let Some(manager) = root
        .get("controller_manager")
        .and_then(|c| c.get("ros__parameters"))
    else {
        return Err(err(
            root.line,
            "expected controller_manager: ros__parameters:".to_owned(),
        ));
    };
    let update_rate = match manager.get("update_rate") {
        None => 100.0,
        Some(Node {
            value: Value::Number(hz),
            ..
        }) if *hz > 0.0 => *hz,
        Some(n) => {
            return Err(err(
                n.line,
                format!("update_rate: expected Hz above 0, found {}", n.describe()),
            ));
        }
    };
    // rover's own named poses ride along as they are.
    let mut out: Vec<(String, Node)> = root
        .entries()
        .iter()
        .filter(|(k, _)| k == "named_poses")
        .cloned()
        .collect();
    for (name, entry) in manager.entries() {
        if let Some(controller) = controller(root, name, entry, update_rate, path)? {
            out.push((name.clone(), controller));
        }
    }
    Ok(Node {
        line: root.line,
        value: Value::Map(out),
    })
}

/// Controller `name` of the controller manager (its `entry` there, its parameters under
/// `root`), as ros_control would have it; `None` for a manager entry that is no controller.
fn controller(
    root: &Node,
    name: &str,
    entry: &Node,
    update_rate: f64,
    path: &Path,
) -> Result<Option<Node>> {
    let err = |line: u32, m: String| SimError::invalid(path, Some(line), m);
    let Some(type_node) = entry.get("type") else {
        return Ok(None);
    };
    let Value::Text(kind) = &type_node.value else {
        return Err(err(
            type_node.line,
            format!(
                "{name}: type must be a name, found {}",
                type_node.describe()
            ),
        ));
    };
    let params = root.get(name).and_then(|n| n.get("ros__parameters"));
    let mut fields: Vec<(String, Node)> = params.map_or(Vec::new(), |p| {
        p.entries()
            .iter()
            .filter(|(k, _)| {
                !matches!(
                    k.as_str(),
                    "command_interfaces"
                        | "state_interfaces"
                        | "interface_name"
                        | "joints"
                        | "type"
                )
            })
            .cloned()
            .collect()
    });
    let joints = params.and_then(|p| p.get("joints"));
    let ros1 = match kind.as_str() {
        "joint_state_broadcaster/JointStateBroadcaster" => {
            fields.push((
                "publish_rate".into(),
                Node {
                    line: entry.line,
                    value: Value::Number(update_rate),
                },
            ));
            "joint_state_controller/JointStateController".to_owned()
        }
        "joint_trajectory_controller/JointTrajectoryController" => {
            if let Some(j) = joints {
                fields.push(("joints".into(), j.clone()));
            }
            let interface =
                first_text(params.and_then(|p| p.get("command_interfaces"))).unwrap_or("position");
            format!("{interface}_controllers/JointTrajectoryController")
        }
        "position_controllers/JointGroupPositionController"
        | "velocity_controllers/JointGroupVelocityController"
        | "effort_controllers/JointGroupEffortController"
        | "forward_command_controller/ForwardCommandController" => {
            let interface = match kind.split('_').next() {
                Some(i @ ("position" | "velocity" | "effort")) => i,
                _ => first_text(params.and_then(|p| p.get("interface_name"))).unwrap_or("position"),
            };
            fields.push(("joint".into(), one_joint(joints, name, entry.line, path)?));
            match interface {
                "velocity" => "velocity_controllers/JointVelocityController".to_owned(),
                "effort" => "effort_controllers/JointEffortController".to_owned(),
                _ => "position_controllers/JointPositionController".to_owned(),
            }
        }
        "position_controllers/GripperActionController"
        | "parallel_gripper_action_controller/GripperActionController"
        | "gripper_controllers/GripperActionController" => {
            "position_controllers/GripperActionController".to_owned()
        }
        other => {
            return Err(err(
                type_node.line,
                format!(
                    "{name}: controller type '{other}' is not one rover runs; expected one of: {SUPPORTED}"
                ),
            ));
        }
    };
    fields.push(("type".into(), text(type_node.line, &ros1)));
    Ok(Some(Node {
        line: entry.line,
        value: Value::Map(fields),
    }))
}

/// The first name of a list (`command_interfaces: [position]`) or a name.
fn first_text(node: Option<&Node>) -> Option<&str> {
    match &node?.value {
        Value::Text(s) => Some(s),
        Value::List(items) => match &items.first()?.value {
            Value::Text(s) => Some(s),
            _ => None,
        },
        _ => None,
    }
}

/// The one joint of a group controller, which rover runs one joint at a time.
fn one_joint(joints: Option<&Node>, name: &str, line: u32, path: &Path) -> Result<Node> {
    match joints.map(|j| &j.value) {
        Some(Value::List(items)) if items.len() == 1 => Ok(items[0].clone()),
        Some(Value::List(items)) => Err(SimError::invalid(
            path,
            joints.map(|j| j.line),
            format!(
                "{name}: {} joints; rover runs a group controller for one joint: give each joint its own",
                items.len()
            ),
        )),
        _ => Err(SimError::invalid(
            path,
            Some(line),
            format!("{name}: expected `joints: [JOINT]` under {name}: ros__parameters:"),
        )),
    }
}
