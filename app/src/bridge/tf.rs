//! `/tf` (odom -> base with `publishOdomTF`, the moving joints' links, every control update)
//! and `/tf_static` (fixed joints, the camera's optical frame, laser frames), kept for late
//! joiners, as tf2_msgs/TFMessage.

use rover_sim::geometry::Pose;
use rover_sim::sensors::Schedule;

use super::events::{ControlUpdate, Start, TopicFamily, Transform};
use super::odom::odom_pose;
use super::plan::{JointSource, RosPlan};

/// `/tf` and `/tf_static` on one transport.
pub(crate) trait TfWire: Send {
    /// Publishes the transforms that never change (once, kept for late joiners).
    fn tf_static(&mut self, transforms: &[Transform]);
    /// Publishes the moving transforms at sim time `stamp_s`.
    fn tf(&mut self, stamp_s: f64, transforms: &[Transform]);
}

/// The tf family.
pub(crate) struct Tf {
    wire: Box<dyn TfWire>,
    /// Whether the first transform is odom -> base.
    odom_tf: bool,
    /// Indices (in the plan's joints) of the joints whose links go on `/tf`, in `transforms`
    /// order after odom -> base.
    joints_on_tf: Vec<usize>,
    transforms: Vec<Transform>,
    /// The odometry's rate (gz-sim's DiffDrive publishes its transform with its odometry).
    rate: Schedule,
}

impl Tf {
    /// The family on `wire`, for the plan's frames.
    pub fn new(wire: Box<dyn TfWire>, plan: &RosPlan) -> Self {
        let mut transforms = Vec::new();
        if plan.odom_tf {
            transforms.push(Transform::new(
                &plan.odom_frame,
                &plan.base_frame,
                Pose::IDENTITY,
            ));
        }
        let joints_on_tf = joints_on_tf(plan);
        transforms.extend(joints_on_tf.iter().map(|&i| {
            let j = &plan.joints[i];
            Transform::new(&j.parent_link, &j.child_link, j.parent_from_child_at_rest)
        }));
        Self {
            wire,
            odom_tf: plan.odom_tf,
            joints_on_tf,
            transforms,
            rate: Schedule::new(plan.odom_rate_hz),
        }
    }
}

impl TopicFamily for Tf {
    fn start(&mut self, start: &Start) {
        self.wire.tf_static(&start.static_tf);
    }

    fn control(&mut self, update: &ControlUpdate) {
        if !self.rate.take(update.sample.sim_time_s) {
            return;
        }
        let mut next = self.transforms.iter_mut();
        if self.odom_tf
            && let Some(t) = next.next()
        {
            (t.translation, t.rotation) = odom_pose(&update.sample);
        }
        for (&i, t) in self.joints_on_tf.iter().zip(next) {
            if let Some(s) = update.joints.get(i) {
                t.set_pose(s.parent_from_child);
            }
        }
        if !self.transforms.is_empty() {
            self.wire.tf(update.sample.sim_time_s, &self.transforms);
        }
    }
}

/// Indices (in the plan's joints) of the joints whose links go on `/tf`: wheels as
/// `publishWheelTF` says; every other moving joint's link always, as robot_state_publisher
/// would from `/joint_states`.
fn joints_on_tf(plan: &RosPlan) -> Vec<usize> {
    plan.joints
        .iter()
        .enumerate()
        .filter(|(_, j)| plan.wheel_tf || !matches!(j.source, JointSource::Wheel { .. }))
        .map(|(i, _)| i)
        .collect()
}
