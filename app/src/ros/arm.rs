//! The arm's look and reach on ROS 1: `/rover/arm/task` in, its state and points out.

use anyhow::Result;
use rover_core::{Action, InputSource};
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher, Subscriber};

use super::convert::{header, seq_of};
use crate::bridge::RosPlan;
use crate::bridge::arm::{ArmPoint, ArmWire, GOAL_TOPIC, OBJECT_TOPIC, STATE_TOPIC};
use crate::bridge::input::{TASK_TOPIC, arm_task};

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
            if let Some(action) = arm_task(&msg.data) {
                return Some(action);
            }
        }
        None
    }
}

/// The arm's publishers.
pub(super) struct Arm {
    state: Publisher<msgs::Text>,
    object: Publisher<msgs::PointStamped>,
    goal: Publisher<msgs::PointStamped>,
    text: msgs::Text,
    point: msgs::PointStamped,
}

impl Arm {
    /// Advertises the topics (the state latched).
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            state: node.advertise(STATE_TOPIC, 10, true)?,
            object: node.advertise(OBJECT_TOPIC, 10, false)?,
            goal: node.advertise(GOAL_TOPIC, 10, false)?,
            text: msgs::Text::default(),
            point: msgs::PointStamped {
                header: header(&plan.base_frame),
                ..msgs::PointStamped::default()
            },
        })
    }
}

impl ArmWire for Arm {
    fn state(&mut self, _stamp_s: f64, text: &str) {
        self.text.data.clear();
        self.text.data.push_str(text);
        self.state.publish(&self.text);
    }

    fn point(&mut self, which: ArmPoint, stamp_s: f64, [x, y, z]: [f64; 3]) {
        let publisher = match which {
            ArmPoint::Object => &mut self.object,
            ArmPoint::Goal => &mut self.goal,
        };
        self.point.header.stamp_s = stamp_s;
        self.point.header.seq = seq_of(publisher);
        self.point.point = msgs::Vector3 { x, y, z };
        publisher.publish(&self.point);
    }
}
