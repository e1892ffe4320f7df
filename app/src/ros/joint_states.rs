//! `/joint_states` (sensor_msgs/JointState) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use super::convert::{header, seq_of};
use crate::bridge::RosPlan;
use crate::bridge::joint_states::{JointArrays, JointStatesWire};

/// `/joint_states`' publisher.
pub(super) struct JointStates {
    publisher: Publisher<msgs::JointState>,
    msg: msgs::JointState,
}

impl JointStates {
    /// Advertises `/joint_states`, for the plan's joints.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise(&plan.joint_states_topic, 50, false)?,
            msg: msgs::JointState {
                header: header(""),
                name: plan.joints.iter().map(|j| j.name.clone()).collect(),
                ..msgs::JointState::default()
            },
        })
    }
}

impl JointStatesWire for JointStates {
    fn joint_states(&mut self, stamp_s: f64, joints: &JointArrays) {
        let msg = &mut self.msg;
        msg.position.clone_from(&joints.position);
        msg.velocity.clone_from(&joints.velocity);
        msg.effort.clone_from(&joints.effort);
        msg.header.seq = seq_of(&self.publisher);
        msg.header.stamp_s = stamp_s;
        self.publisher.publish(msg);
    }
}
