//! The arm's state and points (std_msgs/msg/String, transient local; geometry_msgs/msg/
//! PointStamped) on ROS 2.

use anyhow::Result;

use super::sinks::{Out, Sinks, header, latched_qos};
use crate::bridge::RosPlan;
use crate::bridge::arm::{ArmPoint, ArmWire, GOAL_TOPIC, OBJECT_TOPIC, STATE_TOPIC};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// The arm's topics.
pub(super) struct Arm {
    state: Out<msgs::Text>,
    object: Out<msgs::PointStamped>,
    goal: Out<msgs::PointStamped>,
    text: msgs::Text,
    point: msgs::PointStamped,
}

impl Arm {
    /// Creates the arm's topics on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let state = sinks.out(STATE_TOPIC, &latched_qos())?;
        let [object, goal] = [OBJECT_TOPIC, GOAL_TOPIC].map(|t| sinks.out(t, &default_qos()));
        Ok(Self {
            state,
            object: object?,
            goal: goal?,
            text: msgs::Text::default(),
            point: msgs::PointStamped {
                header: header(&plan.base_frame),
                ..msgs::PointStamped::default()
            },
        })
    }
}

impl ArmWire for Arm {
    fn state(&mut self, stamp_s: f64, text: &str) {
        self.text.data.clear();
        self.text.data.push_str(text);
        self.state.put(Time::from_secs(stamp_s), &self.text);
    }

    fn point(&mut self, which: ArmPoint, stamp_s: f64, [x, y, z]: [f64; 3]) {
        let stamp = Time::from_secs(stamp_s);
        self.point.header.stamp = stamp;
        self.point.point = msgs::Vector3 { x, y, z };
        let out = match which {
            ArmPoint::Object => &mut self.object,
            ArmPoint::Goal => &mut self.goal,
        };
        out.put(stamp, &self.point);
    }
}
