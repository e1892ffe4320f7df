//! `/gazebo/model_states` (gazebo_msgs/msg/ModelStates) on ROS 2 and in `--record-mcap`.

use anyhow::Result;

use super::sinks::{Out, Sinks};
use crate::bridge::model_states::{
    MODEL_STATES_TOPIC, ModelPose, ModelStatesWire, fill_model_states,
};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// `/gazebo/model_states`, its message refilled in place.
pub(super) struct ModelStates {
    out: Out<msgs::ModelStates>,
    msg: msgs::ModelStates,
}

impl ModelStates {
    /// Creates `/gazebo/model_states` on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>) -> Result<Self> {
        Ok(Self {
            out: sinks.out(MODEL_STATES_TOPIC, &default_qos())?,
            msg: msgs::ModelStates::default(),
        })
    }
}

impl ModelStatesWire for ModelStates {
    fn model_states(&mut self, stamp_s: f64, names: &[String], models: &[ModelPose]) {
        use msgs::{Pose, Twist};
        fill_model_states!(self.msg, names, models, Pose, Twist);
        self.out.put(Time::from_secs(stamp_s), &self.msg);
    }
}
