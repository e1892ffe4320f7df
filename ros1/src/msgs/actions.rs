//! actionlib's messages (actionlib_msgs) and the two control_msgs actions MoveIt executes
//! through: FollowJointTrajectory and GripperCommand, as genaction writes their `Action*`
//! messages (`Header`, the goal's id or its status, then the goal, result or feedback).

use super::{Header, JointTrajectory, JointTrajectoryPoint};
use crate::error::Result;
use crate::msg::{Decode, Message, Reader, wire};

/// `actionlib_msgs/GoalID`: a goal's id and when it was sent; also what a `cancel` topic
/// carries (an empty id: every goal sent up to `stamp_s`, or every goal when that is 0 too).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GoalId {
    /// When the client sent it (s).
    pub stamp_s: f64,
    /// The client's id for it.
    pub id: String,
}

impl GoalId {
    fn write(&self, out: &mut Vec<u8>) {
        wire::time(out, self.stamp_s);
        wire::string(out, &self.id);
    }
    fn read(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            stamp_s: r.time_s(false)?,
            id: r.string()?,
        })
    }
}

impl Message for GoalId {
    const TYPE: &'static str = "actionlib_msgs/GoalID";
    fn encode(&self, out: &mut Vec<u8>) {
        self.write(out);
    }
}

impl Decode for GoalId {
    fn decode(bytes: &[u8]) -> Result<Self> {
        Self::read(&mut Reader::new(bytes))
    }
}

/// `actionlib_msgs/GoalStatus`: a goal and where it stands.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GoalStatus {
    /// The goal.
    pub goal_id: GoalId,
    /// One of the constants below.
    pub status: u8,
    /// Why, for people.
    pub text: String,
}

impl GoalStatus {
    /// Not yet processed by the server.
    pub const PENDING: u8 = 0;
    /// Being processed.
    pub const ACTIVE: u8 = 1;
    /// Cancelled after it started.
    pub const PREEMPTED: u8 = 2;
    /// Achieved.
    pub const SUCCEEDED: u8 = 3;
    /// Aborted by the server.
    pub const ABORTED: u8 = 4;
    /// Refused without being processed.
    pub const REJECTED: u8 = 5;
    /// Cancelled before it started.
    pub const RECALLED: u8 = 8;

    fn write(&self, out: &mut Vec<u8>) {
        self.goal_id.write(out);
        wire::u8(out, self.status);
        wire::string(out, &self.text);
    }
}

/// `actionlib_msgs/GoalStatusArray`: an action server's `status` topic.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GoalStatusArray {
    /// Stamp.
    pub header: Header,
    /// The goals the server tracks.
    pub status_list: Vec<GoalStatus>,
}

impl Message for GoalStatusArray {
    const TYPE: &'static str = "actionlib_msgs/GoalStatusArray";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        wire::len(out, self.status_list.len());
        for s in &self.status_list {
            s.write(out);
        }
    }
}

/// `control_msgs/JointTolerance`: a joint's allowed error (0: the controller's own; negative:
/// none).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointTolerance {
    /// The joint.
    pub name: String,
    /// Position (rad or m).
    pub position: f64,
    /// Velocity.
    pub velocity: f64,
    /// Acceleration.
    pub acceleration: f64,
}

impl JointTolerance {
    fn write(&self, out: &mut Vec<u8>) {
        wire::string(out, &self.name);
        wire::f64_fixed(out, &[self.position, self.velocity, self.acceleration]);
    }
    fn read(r: &mut Reader<'_>) -> Result<Self> {
        Ok(Self {
            name: r.string()?,
            position: r.f64()?,
            velocity: r.f64()?,
            acceleration: r.f64()?,
        })
    }
}

fn write_tolerances(out: &mut Vec<u8>, v: &[JointTolerance]) {
    wire::len(out, v.len());
    for t in v {
        t.write(out);
    }
}

fn read_tolerances(r: &mut Reader<'_>) -> Result<Vec<JointTolerance>> {
    // A name's length and three f64s at least.
    let n = r.len(28)?;
    (0..n).map(|_| JointTolerance::read(r)).collect()
}

/// `control_msgs/FollowJointTrajectoryGoal`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FollowJointTrajectoryGoal {
    /// The trajectory.
    pub trajectory: JointTrajectory,
    /// Allowed errors while it runs.
    pub path_tolerance: Vec<JointTolerance>,
    /// Allowed errors at its end.
    pub goal_tolerance: Vec<JointTolerance>,
    /// How late the end may be reached (s).
    pub goal_time_tolerance_s: f64,
}

/// `control_msgs/FollowJointTrajectoryActionGoal`: what `follow_joint_trajectory/goal` carries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FollowJointTrajectoryActionGoal {
    /// Stamp.
    pub header: Header,
    /// The goal's id.
    pub goal_id: GoalId,
    /// The goal.
    pub goal: FollowJointTrajectoryGoal,
}

impl Message for FollowJointTrajectoryActionGoal {
    const TYPE: &'static str = "control_msgs/FollowJointTrajectoryActionGoal";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.goal_id.write(out);
        self.goal.trajectory.encode(out);
        write_tolerances(out, &self.goal.path_tolerance);
        write_tolerances(out, &self.goal.goal_tolerance);
        wire::duration(out, self.goal.goal_time_tolerance_s);
    }
}

impl Decode for FollowJointTrajectoryActionGoal {
    fn decode(bytes: &[u8]) -> Result<Self> {
        let r = &mut Reader::new(bytes);
        Ok(Self {
            header: Header::decode(r)?,
            goal_id: GoalId::read(r)?,
            goal: FollowJointTrajectoryGoal {
                trajectory: JointTrajectory::read(r)?,
                path_tolerance: read_tolerances(r)?,
                goal_tolerance: read_tolerances(r)?,
                goal_time_tolerance_s: r.time_s(true)?,
            },
        })
    }
}

/// `control_msgs/FollowJointTrajectoryResult`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FollowJointTrajectoryResult {
    /// One of the constants below.
    pub error_code: i32,
    /// Why, for people.
    pub error_string: String,
}

impl FollowJointTrajectoryResult {
    /// The trajectory was followed.
    pub const SUCCESSFUL: i32 = 0;
    /// The goal is malformed.
    pub const INVALID_GOAL: i32 = -1;
    /// Its joints are not the controller's.
    pub const INVALID_JOINTS: i32 = -2;
    /// Its stamp is in the past.
    pub const OLD_HEADER_TIMESTAMP: i32 = -3;
    /// A path tolerance was exceeded.
    pub const PATH_TOLERANCE_VIOLATED: i32 = -4;
    /// The goal tolerance was not met in time.
    pub const GOAL_TOLERANCE_VIOLATED: i32 = -5;
}

/// `control_msgs/FollowJointTrajectoryActionResult`: what `follow_joint_trajectory/result`
/// carries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FollowJointTrajectoryActionResult {
    /// Stamp.
    pub header: Header,
    /// The goal and how it ended.
    pub status: GoalStatus,
    /// The result.
    pub result: FollowJointTrajectoryResult,
}

impl Message for FollowJointTrajectoryActionResult {
    const TYPE: &'static str = "control_msgs/FollowJointTrajectoryActionResult";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.status.write(out);
        wire::i32(out, self.result.error_code);
        wire::string(out, &self.result.error_string);
    }
}

/// `control_msgs/FollowJointTrajectoryFeedback`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FollowJointTrajectoryFeedback {
    /// Stamp.
    pub header: Header,
    /// The controller's joints.
    pub joint_names: Vec<String>,
    /// Where the trajectory wants them.
    pub desired: JointTrajectoryPoint,
    /// Where they are.
    pub actual: JointTrajectoryPoint,
    /// desired - actual.
    pub error: JointTrajectoryPoint,
}

/// `control_msgs/FollowJointTrajectoryActionFeedback`: what `follow_joint_trajectory/feedback`
/// carries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FollowJointTrajectoryActionFeedback {
    /// Stamp.
    pub header: Header,
    /// The goal it is about.
    pub status: GoalStatus,
    /// The feedback.
    pub feedback: FollowJointTrajectoryFeedback,
}

impl Message for FollowJointTrajectoryActionFeedback {
    const TYPE: &'static str = "control_msgs/FollowJointTrajectoryActionFeedback";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.status.write(out);
        let f = &self.feedback;
        f.header.encode(out);
        wire::len(out, f.joint_names.len());
        for n in &f.joint_names {
            wire::string(out, n);
        }
        f.desired.encode(out);
        f.actual.encode(out);
        f.error.encode(out);
    }
}

/// `control_msgs/GripperCommand`: where the fingers should go and how hard they may push.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GripperCommand {
    /// The gap, or the finger joint's position (m or rad).
    pub position: f64,
    /// The most force (N) or torque the fingers may use; 0 or less: no limit but the joints'.
    pub max_effort: f64,
}

/// `control_msgs/GripperCommandActionGoal`: what `gripper_cmd/goal` carries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GripperCommandActionGoal {
    /// Stamp.
    pub header: Header,
    /// The goal's id.
    pub goal_id: GoalId,
    /// The command.
    pub command: GripperCommand,
}

impl Message for GripperCommandActionGoal {
    const TYPE: &'static str = "control_msgs/GripperCommandActionGoal";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.goal_id.write(out);
        wire::f64_fixed(out, &[self.command.position, self.command.max_effort]);
    }
}

impl Decode for GripperCommandActionGoal {
    fn decode(bytes: &[u8]) -> Result<Self> {
        let r = &mut Reader::new(bytes);
        Ok(Self {
            header: Header::decode(r)?,
            goal_id: GoalId::read(r)?,
            command: GripperCommand {
                position: r.f64()?,
                max_effort: r.f64()?,
            },
        })
    }
}

/// `control_msgs/GripperCommandResult` (and `GripperCommandFeedback`, the same fields).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GripperCommandResult {
    /// Where the fingers are (m or rad).
    pub position: f64,
    /// The effort they exert (N or N m).
    pub effort: f64,
    /// They push with the most effort allowed and do not move.
    pub stalled: bool,
    /// They reached the commanded position.
    pub reached_goal: bool,
}

impl GripperCommandResult {
    fn write(&self, out: &mut Vec<u8>) {
        wire::f64_fixed(out, &[self.position, self.effort]);
        wire::u8(out, u8::from(self.stalled));
        wire::u8(out, u8::from(self.reached_goal));
    }
}

/// `control_msgs/GripperCommandActionResult`: what `gripper_cmd/result` carries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GripperCommandActionResult {
    /// Stamp.
    pub header: Header,
    /// The goal and how it ended.
    pub status: GoalStatus,
    /// The result.
    pub result: GripperCommandResult,
}

impl Message for GripperCommandActionResult {
    const TYPE: &'static str = "control_msgs/GripperCommandActionResult";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.status.write(out);
        self.result.write(out);
    }
}

/// `control_msgs/GripperCommandActionFeedback`: what `gripper_cmd/feedback` carries.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GripperCommandActionFeedback {
    /// Stamp.
    pub header: Header,
    /// The goal it is about.
    pub status: GoalStatus,
    /// The feedback (GripperCommandFeedback: the result's fields).
    pub feedback: GripperCommandResult,
}

impl Message for GripperCommandActionFeedback {
    const TYPE: &'static str = "control_msgs/GripperCommandActionFeedback";
    fn encode(&self, out: &mut Vec<u8>) {
        self.header.encode(out);
        self.status.write(out);
        self.feedback.write(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msg::md5sum;

    /// genpy's sums for the `.msg` files in tests/ros_msgs (the FollowJointTrajectory ones are
    /// also in ../shared/ros/README.md).
    #[test]
    fn md5_sums_match_genpy() -> Result<()> {
        for (t, sum) in [
            ("actionlib_msgs/GoalID", "302881f31927c1df708a2dbab0e80ee8"),
            (
                "actionlib_msgs/GoalStatus",
                "d388f9b87b3c471f784434d671988d4a",
            ),
            (
                "actionlib_msgs/GoalStatusArray",
                "8b2b82f13216d0a8ea88bd3af735e619",
            ),
            (
                "control_msgs/FollowJointTrajectoryActionGoal",
                "cff5c1d533bf2f82dd0138d57f4304bb",
            ),
            (
                "control_msgs/FollowJointTrajectoryActionFeedback",
                "d8920dc4eae9fc107e00999cce4be641",
            ),
            (
                "control_msgs/FollowJointTrajectoryActionResult",
                "c4fb3b000dc9da4fd99699380efcc5d9",
            ),
            (
                "control_msgs/GripperCommandActionGoal",
                "aa581f648a35ed681db2ec0bf7a82bea",
            ),
            (
                "control_msgs/GripperCommandActionFeedback",
                "653dff30c045f5e6ff3feb3409f4558d",
            ),
            (
                "control_msgs/GripperCommandActionResult",
                "143702cb2df0f163c5283cedc5efc6b6",
            ),
        ] {
            assert_eq!(md5sum(t)?, sum, "{t}");
        }
        Ok(())
    }

    #[test]
    fn goals_read_back_what_was_written() -> Result<()> {
        let goal = FollowJointTrajectoryActionGoal {
            goal_id: GoalId {
                stamp_s: 12.5,
                id: "/client-1-12.5".into(),
            },
            goal: FollowJointTrajectoryGoal {
                trajectory: JointTrajectory {
                    joint_names: vec!["a".into(), "b".into()],
                    points: vec![JointTrajectoryPoint {
                        positions: vec![0.1, -0.2],
                        time_from_start_s: 1.5,
                        ..JointTrajectoryPoint::default()
                    }],
                    ..JointTrajectory::default()
                },
                path_tolerance: vec![JointTolerance {
                    name: "a".into(),
                    position: 0.1,
                    ..JointTolerance::default()
                }],
                goal_tolerance: Vec::new(),
                goal_time_tolerance_s: 0.5,
            },
            ..FollowJointTrajectoryActionGoal::default()
        };
        let mut bytes = Vec::new();
        goal.encode(&mut bytes);
        assert_eq!(FollowJointTrajectoryActionGoal::decode(&bytes)?, goal);
        let gripper = GripperCommandActionGoal {
            command: GripperCommand {
                position: 0.01,
                max_effort: 20.0,
            },
            ..GripperCommandActionGoal::default()
        };
        bytes.clear();
        gripper.encode(&mut bytes);
        assert_eq!(GripperCommandActionGoal::decode(&bytes)?, gripper);
        // A truncated goal is an error, not a panic.
        assert!(GripperCommandActionGoal::decode(&bytes[..bytes.len() - 3]).is_err());
        Ok(())
    }
}
