//! `/gazebo/model_states` (gazebo_msgs/ModelStates) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::ModelState;

use crate::bridge::model_states::{MODEL_STATES_TOPIC, ModelStatesWire};

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
    fn model_states(&mut self, _stamp_s: f64, names: &[String], states: &[ModelState]) {
        let m = &mut self.msg;
        if m.name.len() != names.len() {
            m.name = names.to_vec();
        }
        m.pose.clear();
        m.twist.clear();
        for s in states {
            let (t, r) = (s.pose.translation, s.pose.rotation);
            m.pose.push(msgs::Pose {
                position: vec3(t),
                orientation: msgs::Quaternion {
                    x: f64::from(r.x),
                    y: f64::from(r.y),
                    z: f64::from(r.z),
                    w: f64::from(r.w),
                },
            });
            m.twist.push(msgs::Twist {
                linear: vec3(s.linear_mps),
                angular: vec3(s.angular_radps),
            });
        }
        self.publisher.publish(m);
    }
}

fn vec3(v: glam::Vec3) -> msgs::Vector3 {
    msgs::Vector3 {
        x: f64::from(v.x),
        y: f64::from(v.y),
        z: f64::from(v.z),
    }
}
