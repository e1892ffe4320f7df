//! `/gazebo/model_states` (gazebo_msgs/ModelStates): every model's name, world pose and world
//! twist, as gazebo_ros publishes them for Gazebo's models. rover's models are the robot, the
//! world's objects, its SDF models and its people ([`rover_sim::physics::Simulation::model_states_into`]).
//! Published each control update (Gazebo publishes each physics step; users judge a grasp or
//! a place from it, and a control update is rover's unit of change for them).

use rover_sim::physics::ModelState;

use super::events::{ControlUpdate, Start, TopicFamily};

/// The topic, as gazebo_ros names it on ROS 1 and ROS 2 (gazebo_ros_pkgs' ROS 2
/// `gazebo_ros_state` publishes `/model_states` only when asked; rover keeps one name).
pub(crate) const MODEL_STATES_TOPIC: &str = "/gazebo/model_states";

/// One model's state as the messages carry it (world frame).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ModelPose {
    /// Position (m).
    pub position: [f64; 3],
    /// Orientation, x y z w.
    pub orientation: [f64; 4],
    /// Linear velocity (m/s).
    pub linear: [f64; 3],
    /// Angular velocity (rad/s).
    pub angular: [f64; 3],
}

impl From<&ModelState> for ModelPose {
    fn from(s: &ModelState) -> Self {
        let (t, r) = (s.pose.translation, s.pose.rotation);
        let v = |v: glam::Vec3| [f64::from(v.x), f64::from(v.y), f64::from(v.z)];
        Self {
            position: v(t),
            orientation: [r.x, r.y, r.z, r.w].map(f64::from),
            linear: v(s.linear_mps),
            angular: v(s.angular_radps),
        }
    }
}

/// Fills a transport's ModelStates message `$msg` (fields `name`, `pose`, `twist`, of that
/// transport's `$pose` and `$twist` types) from the family's names and models, reusing its
/// buffers: the one body both encoders share.
macro_rules! fill_model_states {
    ($msg:expr, $names:expr, $models:expr, $pose:ident, $twist:ident) => {{
        let (m, names, models) = (&mut $msg, $names, $models);
        if m.name.len() != names.len() {
            m.name = names.to_vec();
        }
        m.pose.clear();
        m.pose.extend(models.iter().map(|p| $pose {
            position: p.position.into(),
            orientation: p.orientation.into(),
        }));
        m.twist.clear();
        m.twist.extend(models.iter().map(|p| $twist {
            linear: p.linear.into(),
            angular: p.angular.into(),
        }));
    }};
}
pub(crate) use fill_model_states;

/// `/gazebo/model_states` on one transport.
pub(crate) trait ModelStatesWire: Send {
    /// Publishes the models' states; `names[i]` is the name of `models[i]`.
    fn model_states(&mut self, stamp_s: f64, names: &[String], models: &[ModelPose]);
}

/// The model states family.
pub(crate) struct ModelStates {
    wire: Box<dyn ModelStatesWire>,
    names: Vec<String>,
    /// The states as the messages carry them, reused.
    models: Vec<ModelPose>,
}

impl ModelStates {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn ModelStatesWire>) -> Self {
        Self {
            wire,
            names: Vec::new(),
            models: Vec::new(),
        }
    }
}

impl TopicFamily for ModelStates {
    fn start(&mut self, start: &Start) {
        self.names.clone_from(&start.model_names);
    }

    fn control(&mut self, update: &ControlUpdate) {
        if self.names.len() == update.models.len() {
            self.models.clear();
            self.models
                .extend(update.models.iter().map(ModelPose::from));
            self.wire
                .model_states(update.sample.sim_time_s, &self.names, &self.models);
        }
    }
}
