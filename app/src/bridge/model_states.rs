//! `/gazebo/model_states` (gazebo_msgs/ModelStates): every model's name, world pose and world
//! twist, as gazebo_ros publishes them for Gazebo's models. rover's models are the robot, the
//! world's objects, its SDF models and its people ([`rover_sim::Simulation::model_states_into`]).
//! Published each control update (Gazebo publishes each physics step; users judge a grasp or
//! a place from it, and a control update is rover's unit of change for them).

use rover_sim::ModelState;

use super::events::{ControlUpdate, Start, TopicFamily};

/// The topic, as gazebo_ros names it on ROS 1 and ROS 2 (gazebo_ros_pkgs' ROS 2
/// `gazebo_ros_state` publishes `/model_states` only when asked; rover keeps one name).
pub(crate) const MODEL_STATES_TOPIC: &str = "/gazebo/model_states";

/// `/gazebo/model_states` on one transport.
pub(crate) trait ModelStatesWire: Send {
    /// Publishes the models' states; `names[i]` is the name of `states[i]`.
    fn model_states(&mut self, stamp_s: f64, names: &[String], states: &[ModelState]);
}

/// The model states family.
pub(crate) struct ModelStates {
    wire: Box<dyn ModelStatesWire>,
    names: Vec<String>,
}

impl ModelStates {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn ModelStatesWire>) -> Self {
        Self {
            wire,
            names: Vec::new(),
        }
    }
}

impl TopicFamily for ModelStates {
    fn start(&mut self, start: &Start) {
        self.names.clone_from(&start.model_names);
    }

    fn control(&mut self, update: &ControlUpdate) {
        if self.names.len() == update.models.len() {
            self.wire
                .model_states(update.sample.sim_time_s, &self.names, &update.models);
        }
    }
}
