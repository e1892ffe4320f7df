//! `/gazebo/model_states` (gazebo_msgs/ModelStates) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};

use crate::bridge::model_states::{
    MODEL_STATES_TOPIC, ModelPose, ModelStatesWire, fill_model_states,
};

/// `/gazebo/model_states`'s publisher and its message, refilled in place.
pub(super) struct ModelStates {
    publisher: Publisher<msgs::ModelStates>,
    msg: msgs::ModelStates,
}

impl ModelStates {
    /// Advertises `/gazebo/model_states`.
    pub fn advertise(node: &Node) -> Result<Self> {
        Ok(Self {
            publisher: node.advertise(MODEL_STATES_TOPIC, 10, false)?,
            msg: msgs::ModelStates::default(),
        })
    }
}

impl ModelStatesWire for ModelStates {
    fn model_states(&mut self, _stamp_s: f64, names: &[String], models: &[ModelPose]) {
        use msgs::{Pose, Twist};
        fill_model_states!(self.msg, names, models, Pose, Twist);
        self.publisher.publish(&self.msg);
    }
}
