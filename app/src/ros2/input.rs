//! The bridge's input half: what ROS 2 peers send rover, as rover input — `rt/cmd_vel`
//! (geometry_msgs/msg/Twist, like a key press; TwistStamped where a ros_gz_bridge map says so), `rt/rover/arm/task` (std_msgs/msg/String:
//! `off`, `look`, `reach`) and each controller's command topic as ros2_control names it:
//! `/<controller>/joint_trajectory` (trajectory_msgs/msg/JointTrajectory) for a joint
//! trajectory controller, `/<controller>/commands` (std_msgs/msg/Float64MultiArray, its joint's
//! value) for a single-joint controller, as forward_command_controller takes it. A sample that
//! does not decode (a peer's garbage, a wrong type) is one warning per topic; the run goes on.

use anyhow::{Context, Result};
use rover_core::{Action, InputSource, JointAction};
use rover_sim::physics::Twist;
use rustdds::no_key::DataReader;
use rustdds::{CDRDeserializerAdapter, DomainParticipant, GUID, RTPSEntity, TopicKind};
use serde::de::DeserializeOwned;

use super::convert::sim_trajectory;
use crate::bridge::RosPlan;
use crate::bridge::action_intake::GoalCommands;
use crate::bridge::input::{TASK_TOPIC, arm_task, poll_in_turn};
use rover_ros2::dds::{dds_topic, default_qos};
use rover_ros2::msgs::{self, RosMessage};
use rover_ros2::parameters::Parameters;

/// A reader of `M` on one topic that warns once about samples it cannot read.
struct Reader<M: RosMessage + DeserializeOwned> {
    reader: DataReader<M, CDRDeserializerAdapter<M>>,
    ros_name: String,
    warned: bool,
}

impl<M: RosMessage + DeserializeOwned> Reader<M> {
    fn new(
        participant: &DomainParticipant,
        subscriber: &rustdds::Subscriber,
        ros_name: &str,
    ) -> Result<Self> {
        let topic = participant
            .create_topic(
                dds_topic(ros_name),
                M::DDS_TYPE.to_owned(),
                &default_qos(),
                TopicKind::NoKey,
            )
            .with_context(|| format!("creating the DDS topic for {ros_name}"))?;
        let reader = subscriber
            .create_datareader_no_key::<M, CDRDeserializerAdapter<M>>(&topic, None)
            .with_context(|| format!("creating the reader of {ros_name}"))?;
        Ok(Self {
            reader,
            ros_name: ros_name.to_owned(),
            warned: false,
        })
    }

    /// The next sample, if one came.
    fn next(&mut self) -> Option<M> {
        match self.reader.take_next_sample() {
            Ok(Some(sample)) => Some(sample.into_value()),
            Ok(None) => None,
            Err(e) => {
                // A peer's garbage or a wrong type: said once, the run goes on.
                if !std::mem::replace(&mut self.warned, true) {
                    tracing::warn!(
                        "ROS 2: a {} sample could not be read ({e}); ignored",
                        self.ros_name
                    );
                }
                None
            }
        }
    }
}

/// A controller's command topic.
enum Command {
    /// A joint trajectory controller's `~/joint_trajectory`.
    Trajectory(Reader<msgs::JointTrajectory>),
    /// A single-joint controller's `~/commands`.
    Value(Reader<msgs::Float64MultiArray>),
    /// A gz-sim joint controller system's `<topic>` (std_msgs/msg/Float64 through ros_gz_bridge).
    Single(Reader<msgs::Float64>),
}

/// The drive's command topic, of the plan's type.
enum CmdVel {
    /// geometry_msgs/msg/Twist.
    Twist(Reader<msgs::Twist>),
    /// geometry_msgs/msg/TwistStamped (a ros_gz_bridge map says so).
    Stamped(Reader<msgs::TwistStamped>),
}

impl CmdVel {
    fn next(&mut self) -> Option<msgs::Twist> {
        match self {
            Self::Twist(r) => r.next(),
            Self::Stamped(r) => r.next().map(|m| m.twist),
        }
    }

    fn guid(&self) -> GUID {
        match self {
            Self::Twist(r) => r.reader.guid(),
            Self::Stamped(r) => r.reader.guid(),
        }
    }
}

/// The input half of the bridge.
pub struct Ros2Input {
    cmd_vel: CmdVel,
    task: Reader<msgs::Text>,
    /// Each controller's name and command topic.
    controllers: Vec<(String, Command)>,
    /// Where the next poll of the controllers starts, so that every topic gets its turn.
    next: usize,
    /// The node's parameter services, answered when polled.
    parameters: Parameters,
    /// Trajectories of the goals the action servers accepted (and stops for cancelled ones).
    actions: GoalCommands,
    /// The participant, kept until the readers are gone (the bridge thread may stop first;
    /// a reader outliving its participant cannot say goodbye to it).
    _participant: DomainParticipant,
}

impl std::fmt::Debug for Ros2Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Input")
            .field("controllers", &self.controllers.len())
            .finish_non_exhaustive()
    }
}

/// A controller's ROS 2 command topic from its ROS 1 one (`/<ns>/<name>/command`).
fn ros2_command_topic(ros1_topic: &str, trajectory: bool) -> String {
    let base = ros1_topic.strip_suffix("/command").unwrap_or(ros1_topic);
    if trajectory {
        format!("{base}/joint_trajectory")
    } else {
        format!("{base}/commands")
    }
}

impl Ros2Input {
    /// Subscribes to the robot's input topics and serves node `node`'s parameters
    /// (`description`: the URDF); replies go out through `publisher`.
    pub(super) fn subscribe(
        participant: &DomainParticipant,
        publisher: &rustdds::Publisher,
        plan: &RosPlan,
        node: &str,
        description: &str,
        actions: GoalCommands,
    ) -> Result<Self> {
        let subscriber = participant
            .create_subscriber(&default_qos())
            .context("creating the DDS subscriber")?;
        let parameters = Parameters::serve(participant, &subscriber, publisher, node, description)?;
        let mut controllers = Vec::with_capacity(plan.controllers.len());
        for c in &plan.controllers {
            let topic = if c.explicit {
                c.command_topic.clone()
            } else {
                ros2_command_topic(&c.command_topic, c.trajectory)
            };
            let command = match (c.trajectory, c.explicit) {
                (true, _) => Command::Trajectory(Reader::new(participant, &subscriber, &topic)?),
                (false, false) => Command::Value(Reader::new(participant, &subscriber, &topic)?),
                (false, true) => Command::Single(Reader::new(participant, &subscriber, &topic)?),
            };
            controllers.push((c.name.clone(), command));
        }
        Ok(Self {
            cmd_vel: if plan.cmd_stamped {
                CmdVel::Stamped(Reader::new(participant, &subscriber, &plan.cmd_topic)?)
            } else {
                CmdVel::Twist(Reader::new(participant, &subscriber, &plan.cmd_topic)?)
            },
            task: Reader::new(participant, &subscriber, TASK_TOPIC)?,
            controllers,
            next: 0,
            parameters,
            actions,
            _participant: participant.clone(),
        })
    }

    /// The readers' and writers' GUIDs (topics and services), for `ros_discovery_info`.
    pub(super) fn gids(&self) -> (Vec<GUID>, Vec<GUID>) {
        let mut readers = vec![self.cmd_vel.guid(), self.task.reader.guid()];
        readers.extend(self.controllers.iter().map(|(_, c)| match c {
            Command::Trajectory(r) => r.reader.guid(),
            Command::Value(r) => r.reader.guid(),
            Command::Single(r) => r.reader.guid(),
        }));
        let (requests, replies) = self.parameters.gids();
        readers.extend(requests);
        (readers, replies)
    }

    /// The next controller command, every topic in turn.
    fn controller(&mut self) -> Option<Action> {
        poll_in_turn(
            &mut self.controllers,
            &mut self.next,
            |(name, command)| match command {
                Command::Trajectory(reader) => reader.next().map(|m| JointAction::Trajectory {
                    controller: name.to_owned(),
                    trajectory: Box::new(sim_trajectory(m)),
                }),
                Command::Value(reader) => reader.next().and_then(|m| {
                    m.data.first().map(|&value| JointAction::Controller {
                        name: name.clone(),
                        value,
                    })
                }),
                Command::Single(reader) => reader.next().map(|m| JointAction::Controller {
                    name: name.clone(),
                    value: m.data,
                }),
            },
        )
    }
}

impl InputSource for Ros2Input {
    fn poll(&mut self) -> Option<Action> {
        self.parameters.poll();
        if let Some(action) = self.actions.poll() {
            return Some(action);
        }
        let mut newest = None;
        while let Some(t) = self.cmd_vel.next() {
            newest = Some(Action::CmdVel(Twist::new(t.linear.x, t.angular.z)));
        }
        if newest.is_some() {
            return newest;
        }
        while let Some(task) = self.task.next() {
            if let Some(action) = arm_task(&task.data) {
                return Some(action);
            }
        }
        self.controller()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controller_topics_take_ros2_control_names() {
        assert_eq!(
            ros2_command_topic("/arm_controller/command", true),
            "/arm_controller/joint_trajectory"
        );
        assert_eq!(
            ros2_command_topic("/my_robot/joint1_position_controller/command", false),
            "/my_robot/joint1_position_controller/commands"
        );
    }
}
