//! `/joint_states` (sensor_msgs/msg/JointState) on ROS 2.

use anyhow::Result;

use super::sinks::{Out, Sinks};
use crate::bridge::RosPlan;
use crate::bridge::joint_states::{JointArrays, JointStatesWire};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Header, Time};

/// `/joint_states`.
pub(super) struct JointStates {
    out: Out<msgs::JointState>,
    msg: msgs::JointState,
}

impl JointStates {
    /// Creates `/joint_states` on `sinks`, for the plan's joints.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            out: sinks.out(&plan.joint_states_topic, &default_qos())?,
            msg: msgs::JointState {
                header: Header::default(),
                name: plan.joints.iter().map(|j| j.name.clone()).collect(),
                ..msgs::JointState::default()
            },
        })
    }
}

impl JointStatesWire for JointStates {
    fn joint_states(&mut self, stamp_s: f64, joints: &JointArrays) {
        let msg = &mut self.msg;
        msg.header.stamp = Time::from_secs(stamp_s);
        msg.position.clone_from(&joints.position);
        msg.velocity.clone_from(&joints.velocity);
        msg.effort.clone_from(&joints.effort);
        self.out.put(msg.header.stamp, msg);
    }
}
