//! `/gazebo/model_states` (gazebo_msgs/msg/ModelStates) on ROS 2 and in `--record-mcap`.

use anyhow::Result;
use rover_sim::ModelState;

use super::dds::default_qos;
use super::msgs::{self, Time};
use super::sinks::{Out, Sinks};
use crate::bridge::model_states::{MODEL_STATES_TOPIC, ModelStatesWire};

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
    fn model_states(&mut self, stamp_s: f64, names: &[String], states: &[ModelState]) {
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
        self.out.put(Time::from_secs(stamp_s), m);
    }
}

fn vec3(v: glam::Vec3) -> msgs::Vector3 {
    msgs::Vector3 {
        x: f64::from(v.x),
        y: f64::from(v.y),
        z: f64::from(v.z),
    }
}
