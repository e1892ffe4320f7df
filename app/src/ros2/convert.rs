//! ROS 2's messages as the simulation takes them: one decoder each, shared by the topics and
//! the actions that carry them (as `app/src/ros/convert.rs` is ROS 1's).

use rover_ros2::msgs::{self, Duration, Time};
use rover_sim::physics::{JointTrajectory, TrajectoryPoint};

/// A trajectory_msgs/msg/JointTrajectory as the simulation takes it (its stamp: when it
/// starts, 0 for "now"), from a controller's `~/joint_trajectory` or a FollowJointTrajectory
/// goal.
pub(super) fn sim_trajectory(msg: msgs::JointTrajectory) -> JointTrajectory {
    let seconds = |Duration { sec, nanosec }| f64::from(sec) + f64::from(nanosec) * 1e-9;
    let Time { sec, nanosec } = msg.header.stamp;
    JointTrajectory {
        start_s: seconds(Duration { sec, nanosec }),
        joint_names: msg.joint_names,
        points: msg
            .points
            .into_iter()
            .map(|p| TrajectoryPoint {
                time_from_start_s: seconds(p.time_from_start),
                positions: p.positions,
                velocities: p.velocities,
                accelerations: p.accelerations,
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_and_durations_become_seconds() {
        let msg = msgs::JointTrajectory {
            header: msgs::Header {
                stamp: Time {
                    sec: 3,
                    nanosec: 500_000_000,
                },
                frame_id: String::new(),
            },
            joint_names: vec!["a".into()],
            points: vec![msgs::JointTrajectoryPoint {
                positions: vec![0.25],
                time_from_start: Duration {
                    sec: 1,
                    nanosec: 250_000_000,
                },
                ..msgs::JointTrajectoryPoint::default()
            }],
        };
        let t = sim_trajectory(msg);
        assert_eq!(t.start_s, 3.5);
        assert_eq!(t.joint_names, ["a"]);
        assert_eq!(t.points[0].time_from_start_s, 1.25);
        assert_eq!(t.points[0].positions, [0.25]);
    }
}
