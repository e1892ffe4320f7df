//! The bumpers' readings: gazebo_msgs/ContactsState on each bumper's `bumperTopicName`, in its
//! `frameName`, at the contact sensor's rate: one ContactState per collision its link touches
//! (the link's collision first), with a wrench per contact point, nothing while it touches
//! nothing.

use rover_msgs::{ContactState, Vector3, Wrench};
use rover_sim::sensors::ContactsReading;

use super::events::TopicFamily;

/// The bumper topics on one transport, one per bumper in the plan's order.
pub(crate) trait BumperWire: Send {
    /// Publishes `reading` on its bumper's topic.
    fn contacts(&mut self, reading: &ContactsReading);
}

/// The bumper family.
pub(crate) struct Bumper {
    wire: Box<dyn BumperWire>,
}

impl Bumper {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn BumperWire>) -> Self {
        Self { wire }
    }
}

impl TopicFamily for Bumper {
    fn contacts(&mut self, reading: &ContactsReading) {
        self.wire.contacts(reading);
    }
}

/// `reading`'s contacts as the message's states, into `states` (its entries reused).
pub(crate) fn states(reading: &ContactsReading, states: &mut Vec<ContactState>) {
    states.truncate(reading.contacts.len());
    states.resize_with(reading.contacts.len(), ContactState::default);
    let v = |p: glam::Vec3| Vector3::from(p.as_dvec3().to_array());
    for (s, c) in states.iter_mut().zip(&reading.contacts) {
        s.collision1_name.clone_from(&reading.collision);
        s.collision2_name.clone_from(&c.other);
        let n = c.positions_m.len().max(1) as f32;
        let share = |total: glam::Vec3| v(total / n);
        s.wrenches.clear();
        s.wrenches.extend(c.positions_m.iter().map(|_| Wrench {
            force: share(c.force_n),
            torque: share(c.torque_nm),
        }));
        s.total_wrench = Wrench {
            force: v(c.force_n),
            torque: v(c.torque_nm),
        };
        s.contact_positions.clear();
        s.contact_positions
            .extend(c.positions_m.iter().map(|p| v(*p)));
        s.contact_normals.clear();
        s.contact_normals.extend(c.normals.iter().map(|p| v(*p)));
        s.depths.clear();
        s.depths.extend(c.depths_m.iter().map(|d| f64::from(*d)));
    }
}
