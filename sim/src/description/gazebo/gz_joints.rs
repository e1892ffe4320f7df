//! gz-sim's joint controller systems, read as rover's controllers (the ones a ros_control
//! controllers file gives), each on its own gz `<topic>`:
//!
//! | system | rover's controller | command (ROS type through ros_gz_bridge) | default topic |
//! |---|---|---|---|
//! | JointPositionController | a position with `<p_gain>`, `<i_gain>`, `<d_gain>` (gz-sim's 1, 0.1, 0.01) | std_msgs/Float64 | `/model/<model>/joint/<joint>/<joint_index>/cmd_pos` |
//! | JointController | a velocity | std_msgs/Float64 | `/model/<model>/joint/<joint>/cmd_vel` |
//! | JointTrajectoryController | a trajectory over its `<joint_name>`s, with `<position_p_gain>` ... per joint | trajectory_msgs/JointTrajectory | `/model/<model>/joint_trajectory` |
//!
//! A system without a `<joint_name>` is an error at its line; one naming a joint the robot
//! does not have (or cannot drive) is one at its line too, once the joints are known.

use std::path::Path;

use super::values::{Ctx, Node, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::{Result, SimError, quoted_list};
use crate::model::actuation::Pid;
use crate::model::controllers::{
    CommandKind, ControllerConfig, ControllerKind, ControllerSpec, TrajectoryConstraints,
    TrajectorySpec,
};
use crate::model::robot::RobotModel;

/// The joint controller systems.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum JointSystem {
    /// `gz-sim-joint-position-controller-system`.
    Position,
    /// `gz-sim-joint-controller-system`.
    Velocity,
    /// `gz-sim-joint-trajectory-controller-system`.
    Trajectory,
}

impl JointSystem {
    /// Which joint system a plugin is, by its file's short name or its class.
    pub(super) fn of(stem: &str, class: &str) -> Option<Self> {
        match (stem, class) {
            ("joint-position-controller", _) | (_, "JointPositionController") => {
                Some(Self::Position)
            }
            ("joint-controller", _) | (_, "JointController") => Some(Self::Velocity),
            ("joint-trajectory-controller", _) | (_, "JointTrajectoryController") => {
                Some(Self::Trajectory)
            }
            _ => None,
        }
    }

    fn file(self) -> &'static str {
        match self {
            Self::Position => "gz-sim-joint-position-controller-system",
            Self::Velocity => "gz-sim-joint-controller-system",
            Self::Trajectory => "gz-sim-joint-trajectory-controller-system",
        }
    }
}

/// The controller a joint system on model `model` is.
pub(super) fn parse(
    ctx: &Ctx<'_, '_>,
    plugin: Node<'_, '_>,
    system: JointSystem,
) -> Result<ControllerSpec> {
    let what = format!("the {} plugin", system.file());
    let line = line_of(ctx.doc, plugin);
    let joints: Vec<String> = elements(plugin)
        .filter(|p| p.has_tag_name("joint_name"))
        .map(|p| text_of(p).to_owned())
        .filter(|j| !j.is_empty())
        .collect();
    let Some(first) = joints.first().cloned() else {
        return Err(ctx.err(plugin, format!("{what}: expected a <joint_name>")));
    };
    if joints.len() > 1 && system != JointSystem::Trajectory {
        return Err(ctx.err(
            plugin,
            format!(
                "{what}: {} <joint_name>s; rover drives one joint per joint controller system: give each joint its own",
                joints.len()
            ),
        ));
    }
    let topic_of = |default: String| {
        elements(plugin)
            .find(|p| p.has_tag_name("topic"))
            .map(|p| text_of(p).to_owned())
            .filter(|t| !t.is_empty())
            .unwrap_or(default)
    };
    let model = ctx.model;
    let (name, topic, kind) = match system {
        JointSystem::Position => {
            let mut pid = Pid {
                p: 1.0,
                i: 0.1,
                d: 0.01,
                i_clamp: 1.0,
            };
            let mut index = 0u32;
            for p in elements(plugin) {
                match p.tag_name().name() {
                    "p_gain" => pid.p = ctx.non_negative(p, &what, "gain")?,
                    "i_gain" => pid.i = ctx.non_negative(p, &what, "gain")?,
                    "d_gain" => pid.d = ctx.non_negative(p, &what, "gain")?,
                    "i_max" => pid.i_clamp = ctx.non_negative(p, &what, "N m")?,
                    "joint_index" => {
                        index = text_of(p).parse().map_err(|_| {
                            ctx.err(
                                p,
                                format!(
                                    "<joint_index> in {what}: expected 0 or a positive whole number, found '{}'",
                                    text_of(p)
                                ),
                            )
                        })?
                    }
                    _ => {}
                }
            }
            (
                format!("{first}_position_controller"),
                topic_of(format!("/model/{model}/joint/{first}/{index}/cmd_pos")),
                ControllerKind::Joint {
                    joint: first,
                    command: CommandKind::PositionPid(pid),
                },
            )
        }
        JointSystem::Velocity => (
            format!("{first}_velocity_controller"),
            topic_of(format!("/model/{model}/joint/{first}/cmd_vel")),
            ControllerKind::Joint {
                joint: first,
                command: CommandKind::Velocity,
            },
        ),
        JointSystem::Trajectory => {
            let gains = trajectory_gains(ctx, plugin, &what, joints.len())?;
            let n = joints.len();
            (
                "joint_trajectory_controller".to_owned(),
                topic_of(format!("/model/{model}/joint_trajectory")),
                ControllerKind::Trajectory(TrajectorySpec {
                    joints,
                    gains,
                    constraints: TrajectoryConstraints {
                        goal_time_s: 0.0,
                        stopped_velocity_tolerance: 0.01,
                        trajectory: vec![0.0; n],
                        goal: vec![0.0; n],
                    },
                    state_publish_rate_hz: 50.0,
                }),
            )
        }
    };
    Ok(ControllerSpec {
        name,
        namespace: String::new(),
        type_name: plugin.attribute("name").unwrap_or(system.file()).to_owned(),
        kind,
        line,
        topic: Some(topic),
    })
}

/// A trajectory controller's `<position_p_gain>`, `<position_i_gain>`, `<position_d_gain>`
/// (one per joint, in order; gz-sim's defaults 0 where they stop): `None` when none is given,
/// so that rover's hold drives the joints.
fn trajectory_gains(
    ctx: &Ctx<'_, '_>,
    plugin: Node<'_, '_>,
    what: &str,
    joints: usize,
) -> Result<Option<Vec<Pid>>> {
    let mut gains = vec![
        Pid {
            p: 0.0,
            i: 0.0,
            d: 0.0,
            i_clamp: 0.0,
        };
        joints
    ];
    let mut counts = [0usize; 3];
    for p in elements(plugin) {
        let slot = match p.tag_name().name() {
            "position_p_gain" => 0,
            "position_i_gain" => 1,
            "position_d_gain" => 2,
            _ => continue,
        };
        let k = counts[slot];
        counts[slot] += 1;
        let Some(pid) = gains.get_mut(k) else {
            return Err(ctx.err(
                p,
                format!(
                    "<{}> in {what}: more gains than <joint_name>s ({joints})",
                    p.tag_name().name()
                ),
            ));
        };
        let v = ctx.non_negative(p, what, "gain")?;
        match slot {
            0 => pid.p = v,
            1 => pid.i = v,
            _ => pid.d = v,
        }
    }
    Ok((counts[0] > 0).then_some(gains))
}

/// The robot's controllers from its joint systems: every joint they name must be one the
/// robot can drive, and no joint may take two (an error at the system's line).
pub(crate) fn config(
    robot: &RobotModel,
    specs: Vec<ControllerSpec>,
    path: &Path,
) -> Result<ControllerConfig> {
    let actuated = robot.actuated_joints();
    let mut taken: Vec<(&str, u32)> = Vec::new();
    for spec in &specs {
        for joint in spec.joints() {
            let drivable = robot
                .joint_id(joint)
                .is_some_and(|id| actuated.contains(&id));
            if !drivable {
                return Err(SimError::invalid(
                    path,
                    Some(spec.line),
                    format!(
                        "<joint_name>{joint}</joint_name> in the {} plugin: the robot has no joint of that name it can drive; its actuated joints: {}",
                        spec.type_name,
                        quoted_list(actuated.iter().map(|&id| &robot.joint(id).name))
                    ),
                ));
            }
            if let Some((_, line)) = taken.iter().find(|(j, _)| j == joint) {
                return Err(SimError::invalid(
                    path,
                    Some(spec.line),
                    format!(
                        "joint \"{joint}\" is driven by the system at line {line} already; a joint takes one controller"
                    ),
                ));
            }
            taken.push((joint, spec.line));
        }
    }
    Ok(ControllerConfig {
        source: path.to_path_buf(),
        controllers: specs,
        pid_gains: Vec::new(),
        named_poses: Vec::new(),
    })
}
