//! Message parts the ROS 1 encoders share.

use rover_ros1::msgs::{self, Header};
use rover_ros1::{Message, Publisher};
use rover_sim::physics::{JointTrajectory, TrajectoryPoint};

/// A header in `frame_id`, to be numbered and stamped when published.
pub(super) fn header(frame_id: &str) -> Header {
    Header {
        seq: 0,
        stamp_s: 0.0,
        frame_id: frame_id.to_owned(),
    }
}

/// A per-topic sequence number, as roscpp and rospy set `header.seq`: messages published so far.
pub(super) fn seq_of<T: Message>(p: &Publisher<T>) -> u32 {
    p.published() as u32
}

/// A trajectory_msgs/JointTrajectory as the simulation takes it (its stamp: when it starts, 0
/// for "now").
pub(super) fn sim_trajectory(msg: msgs::JointTrajectory) -> JointTrajectory {
    JointTrajectory {
        start_s: msg.header.stamp_s,
        joint_names: msg.joint_names,
        points: msg
            .points
            .into_iter()
            .map(|p| TrajectoryPoint {
                time_from_start_s: p.time_from_start_s,
                positions: p.positions,
                velocities: p.velocities,
                accelerations: p.accelerations,
            })
            .collect(),
    }
}
