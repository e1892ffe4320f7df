//! The bumpers' contacts (gazebo_msgs/ContactsState) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::sensors::ContactsReading;

use crate::bridge::RosPlan;
use crate::bridge::bumper::{BumperWire, states};

/// One publisher and message per bumper, in the plan's order.
pub(super) struct Bumper {
    topics: Vec<(Publisher<msgs::ContactsState>, msgs::ContactsState)>,
}

impl Bumper {
    /// Advertises each bumper's topic.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let topics = plan
            .bumpers
            .iter()
            .map(|topic| {
                Ok((
                    node.advertise(topic, 100, false)?,
                    msgs::ContactsState::default(),
                ))
            })
            .collect::<Result<_>>()?;
        Ok(Self { topics })
    }
}

impl BumperWire for Bumper {
    fn contacts(&mut self, r: &ContactsReading) {
        let Some((publisher, msg)) = self.topics.get_mut(r.sensor) else {
            return;
        };
        msg.header.seq = r.seq as u32;
        msg.header.stamp_s = r.stamp_s;
        if msg.header.frame_id != r.frame_id {
            msg.header.frame_id.clone_from(&r.frame_id);
        }
        states(r, &mut msg.states);
        publisher.publish(msg);
    }
}
