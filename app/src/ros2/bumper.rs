//! The bumpers' contacts (gazebo_msgs/msg/ContactsState) on ROS 2, reliable as gazebo_ros's
//! bumper publishes them.

use anyhow::Result;
use rover_sim::sensors::ContactsReading;

use super::sinks::{Out, Sinks};
use crate::bridge::RosPlan;
use crate::bridge::bumper::{BumperWire, states};
use rover_ros2::dds::default_qos;
use rover_ros2::msgs::{self, Time};

/// One topic and message per bumper, in the plan's order.
pub(super) struct Bumper {
    topics: Vec<(Out<msgs::ContactsState>, msgs::ContactsState)>,
}

impl Bumper {
    /// Creates each bumper's topic on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        let topics = plan
            .bumpers
            .iter()
            .map(|topic| {
                Ok((
                    sinks.out(topic, &default_qos())?,
                    msgs::ContactsState::default(),
                ))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl BumperWire for Bumper {
    fn contacts(&mut self, r: &ContactsReading) {
        let Some((out, msg)) = self.topics.get_mut(r.sensor) else {
            return;
        };
        msg.header.stamp = Time::from_secs(r.stamp_s);
        if msg.header.frame_id != r.frame_id {
            msg.header.frame_id.clone_from(&r.frame_id);
        }
        states(r, &mut msg.states);
        out.put(msg.header.stamp, msg);
    }
}
