//! The arm's look and reach over ROS: `/rover/arm/task` in (std_msgs/String: `off`, `look`
//! or `reach`, as rover input), and out `/rover/arm/state` (std_msgs/String, latched, on every
//! change: `off`, `look`, or `reach <state>`), `/rover/arm/object` and `/rover/arm/goal`
//! (geometry_msgs/PointStamped in the robot's base frame, every control update while reach
//! has them: the object point it reaches for and the pre-grasp point the tool is sent to).

use anyhow::Result;
use rover_core::{Action, ArmMode, InputSource};
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher, Subscriber};

use super::convert::header;
use super::events::{ArmSample, ControlUpdate, TopicFamily};
use super::plan::RosPlan;

/// The task topic.
pub(super) const TASK_TOPIC: &str = "/rover/arm/task";

/// `/rover/arm/task` as rover input.
#[derive(Debug)]
pub(super) struct ArmTaskInput {
    sub: Subscriber<msgs::Text>,
}

impl ArmTaskInput {
    /// Subscribes to the task topic.
    pub fn subscribe(node: &Node) -> Result<Self> {
        Ok(Self {
            sub: node.subscribe(TASK_TOPIC, 10)?,
        })
    }
}

impl InputSource for ArmTaskInput {
    fn poll(&mut self) -> Option<Action> {
        while let Some(msg) = self.sub.try_recv() {
            match msg.data.trim() {
                "off" => return Some(Action::Arm(ArmMode::Off)),
                "look" => return Some(Action::Arm(ArmMode::Look)),
                "reach" => return Some(Action::Arm(ArmMode::Reach)),
                other => tracing::warn!(
                    "{TASK_TOPIC}: \"{other}\" is not a task; expected off, look or reach"
                ),
            }
        }
        None
    }
}

/// Publishes the arm's state and points.
pub(super) struct ArmTopics {
    state: Publisher<msgs::Text>,
    object: Publisher<msgs::PointStamped>,
    goal: Publisher<msgs::PointStamped>,
    text: msgs::Text,
    point: msgs::PointStamped,
    last: Option<(ArmMode, rover_core::ReachState)>,
}

impl ArmTopics {
    /// Advertises the topics.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            state: node.advertise("/rover/arm/state", 10, true)?,
            object: node.advertise("/rover/arm/object", 10, false)?,
            goal: node.advertise("/rover/arm/goal", 10, false)?,
            text: msgs::Text::default(),
            point: msgs::PointStamped {
                header: header(&plan.base_frame),
                ..msgs::PointStamped::default()
            },
            last: None,
        })
    }

    fn publish_point(&mut self, which: Which, p: Option<[f64; 3]>, stamp_s: f64) {
        let Some([x, y, z]) = p else {
            return;
        };
        self.point.header.stamp_s = stamp_s;
        self.point.point = msgs::Vector3 { x, y, z };
        let publisher = match which {
            Which::Object => &mut self.object,
            Which::Goal => &mut self.goal,
        };
        self.point.header.seq = super::convert::seq_of(publisher);
        publisher.publish(&self.point);
    }
}

enum Which {
    Object,
    Goal,
}

impl TopicFamily for ArmTopics {
    fn control(&mut self, update: &ControlUpdate) {
        let ArmSample {
            mode,
            reach,
            object_base_m,
            goal_base_m,
        } = update.arm;
        if self.last != Some((mode, reach)) {
            self.last = Some((mode, reach));
            self.text.data.clear();
            self.text.data.push_str(mode.as_str());
            if mode == ArmMode::Reach {
                self.text.data.push(' ');
                self.text.data.push_str(reach.as_str());
            }
            self.state.publish(&self.text);
        }
        if mode == ArmMode::Reach {
            let t = update.sample.sim_time_s;
            self.publish_point(Which::Object, object_base_m, t);
            self.publish_point(Which::Goal, goal_base_m, t);
        }
    }
}
