//! A trajectory for a joint trajectory controller (trajectory_msgs/JointTrajectory, as the
//! controller's `command` topic and FollowJointTrajectory's goal carry it), and the one check
//! of it: what joint_trajectory_controller refuses, as a typed error ([`TrajectoryError`])
//! that the ROS bridges map to control_msgs' error codes and the simulation reports.

/// A trajectory for a joint trajectory controller (trajectory_msgs/JointTrajectory).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointTrajectory {
    /// When it starts (sim time, s); 0: on arrival (`header.stamp` zero, as rostopic sends).
    pub start_s: f64,
    /// The joints each point lists, in the points' order.
    pub joint_names: Vec<String>,
    /// The points, in time order.
    pub points: Vec<TrajectoryPoint>,
}

/// One point of a [`JointTrajectory`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrajectoryPoint {
    /// Positions (rad or m), one per joint.
    pub positions: Vec<f64>,
    /// Velocities, one per joint, or empty.
    pub velocities: Vec<f64>,
    /// Accelerations, one per joint, or empty.
    pub accelerations: Vec<f64>,
    /// When the point is due after the trajectory's start (s).
    pub time_from_start_s: f64,
}

/// Why a controller refuses a trajectory. The first two are about its joints (control_msgs'
/// INVALID_JOINTS), the others about its points (INVALID_GOAL).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrajectoryError {
    /// It names a joint the controller does not drive.
    #[error("joint \"{joint}\" is not one of its joints ({})", known.join(", "))]
    UnknownJoint {
        /// The joint named.
        joint: String,
        /// The controller's joints.
        known: Vec<String>,
    },
    /// It leaves out one of the controller's joints (joint_trajectory_controller's
    /// `allow_partial_joints_goal` is false by default).
    #[error("the trajectory does not list joint \"{joint}\"")]
    MissingJoint {
        /// The joint left out.
        joint: String,
    },
    /// A point's arrays do not give one value per joint.
    #[error(
        "point {index} must give {joints} positions (and 0 or {joints} velocities and \
         accelerations), found {positions}, {velocities}, {accelerations}"
    )]
    PointSize {
        /// The point.
        index: usize,
        /// The trajectory's joints.
        joints: usize,
        /// Its positions.
        positions: usize,
        /// Its velocities.
        velocities: usize,
        /// Its accelerations.
        accelerations: usize,
    },
    /// A point holds a NaN or an infinity.
    #[error("point {index} has a value that is not a finite number")]
    NotFinite {
        /// The point.
        index: usize,
    },
    /// A point is not due later than the one before.
    #[error("point {index}: time_from_start {time_s:.3} s must be later than the point before")]
    NotIncreasing {
        /// The point.
        index: usize,
        /// Its time from the start (s).
        time_s: f64,
    },
}

impl TrajectoryError {
    /// Whether it is about the trajectory's joints (INVALID_JOINTS) rather than its points.
    pub fn is_about_joints(&self) -> bool {
        matches!(self, Self::UnknownJoint { .. } | Self::MissingJoint { .. })
    }
}

impl JointTrajectory {
    /// Checks it against a controller's `joints` (in the controller's order), as
    /// joint_trajectory_controller does; for each of those joints, its index in
    /// `joint_names`. A trajectory without points passes (on the `command` topic it stops the
    /// controller where the joints are).
    pub fn check(&self, joints: &[&str]) -> Result<Vec<usize>, TrajectoryError> {
        if let Some(extra) = self
            .joint_names
            .iter()
            .find(|n| !joints.contains(&n.as_str()))
        {
            return Err(TrajectoryError::UnknownJoint {
                joint: extra.clone(),
                known: joints.iter().map(|j| (*j).to_owned()).collect(),
            });
        }
        let order = joints
            .iter()
            .map(|joint| {
                self.joint_names
                    .iter()
                    .position(|n| n == joint)
                    .ok_or_else(|| TrajectoryError::MissingJoint {
                        joint: (*joint).to_owned(),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let n = self.joint_names.len();
        let mut last_s = f64::NEG_INFINITY;
        for (index, p) in self.points.iter().enumerate() {
            let optional = |a: &[f64]| a.is_empty() || a.len() == n;
            if p.positions.len() != n || !optional(&p.velocities) || !optional(&p.accelerations) {
                return Err(TrajectoryError::PointSize {
                    index,
                    joints: n,
                    positions: p.positions.len(),
                    velocities: p.velocities.len(),
                    accelerations: p.accelerations.len(),
                });
            }
            let values = p
                .positions
                .iter()
                .chain(&p.velocities)
                .chain(&p.accelerations);
            if !values.clone().all(|x| x.is_finite()) || !p.time_from_start_s.is_finite() {
                return Err(TrajectoryError::NotFinite { index });
            }
            if p.time_from_start_s <= last_s {
                return Err(TrajectoryError::NotIncreasing {
                    index,
                    time_s: p.time_from_start_s,
                });
            }
            last_s = p.time_from_start_s;
        }
        Ok(order)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trajectory(names: &[&str], points: &[(&[f64], f64)]) -> JointTrajectory {
        JointTrajectory {
            start_s: 0.0,
            joint_names: names.iter().map(|n| (*n).to_owned()).collect(),
            points: points
                .iter()
                .map(|(q, t)| TrajectoryPoint {
                    positions: q.to_vec(),
                    time_from_start_s: *t,
                    ..TrajectoryPoint::default()
                })
                .collect(),
        }
    }

    #[test]
    fn a_good_trajectory_gives_each_joint_its_column() {
        let t = trajectory(&["b", "a"], &[(&[0.1, 0.2], 1.0), (&[0.3, 0.4], 2.0)]);
        assert_eq!(t.check(&["a", "b"]), Ok(vec![1, 0]));
        assert_eq!(
            trajectory(&["a", "b"], &[]).check(&["a", "b"]),
            Ok(vec![0, 1])
        );
    }

    #[test]
    fn each_refusal_names_what_was_wrong() {
        let joints = ["a", "b"];
        let err = |t: JointTrajectory| t.check(&joints).err();
        let unknown = err(trajectory(&["a", "x"], &[(&[0.1, 0.2], 1.0)]));
        assert_eq!(
            unknown.as_ref().map(ToString::to_string).as_deref(),
            Some("joint \"x\" is not one of its joints (a, b)")
        );
        assert!(unknown.is_some_and(|e| e.is_about_joints()));
        assert_eq!(
            err(trajectory(&["a"], &[(&[0.1], 1.0)])),
            Some(TrajectoryError::MissingJoint { joint: "b".into() })
        );
        let short = err(trajectory(&["a", "b"], &[(&[0.1], 1.0)]));
        assert!(matches!(
            short,
            Some(TrajectoryError::PointSize {
                index: 0,
                positions: 1,
                ..
            })
        ));
        assert!(!short.is_some_and(|e| e.is_about_joints()));
        assert_eq!(
            err(trajectory(&["a", "b"], &[(&[f64::NAN, 0.2], 1.0)])),
            Some(TrajectoryError::NotFinite { index: 0 })
        );
        assert_eq!(
            err(trajectory(
                &["a", "b"],
                &[(&[0.1, 0.2], 1.0), (&[0.1, 0.2], 1.0)]
            )),
            Some(TrajectoryError::NotIncreasing {
                index: 1,
                time_s: 1.0
            })
        );
    }
}
