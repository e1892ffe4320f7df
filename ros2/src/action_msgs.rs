//! The messages of the ROS 2 actions rover serves, `control_msgs/action/FollowJointTrajectory`
//! (Humble's and Jazzy's layout; from Lyrical on the feedback carries two more fields,
//! `index` and `multi_dof_index`, control_msgs 6) and `control_msgs/action/GripperCommand`,
//! and action_msgs' goal bookkeeping: serde structs in CDR layout, as `msgs.rs`.

use serde::ser::SerializeStruct;
use serde::{Deserialize, Serialize, Serializer};

use crate::msgs::{
    Duration, Header, JointTrajectory, JointTrajectoryPoint, Time, Transform, Twist,
};
use crate::services::ServiceType;

/// `unique_identifier_msgs/msg/UUID`: a goal's id.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Uuid {
    /// Its 16 bytes.
    pub uuid: [u8; 16],
}

/// `action_msgs/msg/GoalInfo`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GoalInfo {
    /// Which goal.
    pub goal_id: Uuid,
    /// When it was accepted.
    pub stamp: Time,
}

/// `action_msgs/msg/GoalStatus`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GoalStatus {
    /// Which goal, accepted when.
    pub goal_info: GoalInfo,
    /// [`STATUS_EXECUTING`], ...
    pub status: i8,
}

/// The goal is being executed.
pub const STATUS_EXECUTING: i8 = 2;
/// The goal reached its end.
pub const STATUS_SUCCEEDED: i8 = 4;
/// The goal was cancelled (or preempted by a new one).
pub const STATUS_CANCELED: i8 = 5;
/// The goal ended without reaching its end.
pub const STATUS_ABORTED: i8 = 6;

/// `action_msgs/msg/GoalStatusArray`, on `.../_action/status`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct GoalStatusArray {
    /// Every goal the server remembers.
    pub status_list: Vec<GoalStatus>,
}

/// `action_msgs/srv/CancelGoal`: a goal (a zero id: every goal accepted up to the stamp) in;
/// a return code and the goals now cancelling out.
pub struct CancelGoal;
impl ServiceType for CancelGoal {
    type Request = GoalInfo;
    type Response = (i8, Vec<GoalInfo>);
    const REQUEST_TYPE: &'static str = "action_msgs::srv::dds_::CancelGoal_Request_";
    const RESPONSE_TYPE: &'static str = "action_msgs::srv::dds_::CancelGoal_Response_";
}

/// CancelGoal: cancelling.
pub const CANCEL_ERROR_NONE: i8 = 0;
/// CancelGoal: no such goal.
pub const CANCEL_ERROR_UNKNOWN_GOAL_ID: i8 = 2;
/// CancelGoal: the goal already ended.
pub const CANCEL_ERROR_GOAL_TERMINATED: i8 = 3;

/// `control_msgs/msg/JointTolerance`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
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

/// `control_msgs/msg/JointComponentTolerance`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointComponentTolerance {
    /// The joint.
    pub joint_name: String,
    /// Which component (1-5: x, y, z axis, translation, rotation).
    pub component: u16,
    /// Position.
    pub position: f64,
    /// Velocity.
    pub velocity: f64,
    /// Acceleration.
    pub acceleration: f64,
}

/// `trajectory_msgs/msg/MultiDOFJointTrajectoryPoint`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiDofPoint {
    /// Transforms.
    pub transforms: Vec<Transform>,
    /// Velocities.
    pub velocities: Vec<Twist>,
    /// Accelerations.
    pub accelerations: Vec<Twist>,
    /// When, after the start.
    pub time_from_start: Duration,
}

/// `trajectory_msgs/msg/MultiDOFJointTrajectory`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiDofTrajectory {
    /// Stamp and frame.
    pub header: Header,
    /// Joints.
    pub joint_names: Vec<String>,
    /// Points.
    pub points: Vec<MultiDofPoint>,
}

/// `control_msgs/action/FollowJointTrajectory`'s goal.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FollowJointTrajectoryGoal {
    /// The trajectory.
    pub trajectory: JointTrajectory,
    /// Multi-DOF joints' trajectory (rover's controllers have none: must be empty).
    pub multi_dof_trajectory: MultiDofTrajectory,
    /// Path tolerances (rover applies the controller's own, from its controllers file).
    pub path_tolerance: Vec<JointTolerance>,
    /// Multi-DOF path tolerances.
    pub component_path_tolerance: Vec<JointComponentTolerance>,
    /// Goal tolerances (the controller's own apply).
    pub goal_tolerance: Vec<JointTolerance>,
    /// Multi-DOF goal tolerances.
    pub component_goal_tolerance: Vec<JointComponentTolerance>,
    /// How late the goal may be reached (the controller's `goal_time` applies).
    pub goal_time_tolerance: Duration,
}

/// `control_msgs/action/FollowJointTrajectory`'s result.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FollowJointTrajectoryResult {
    /// 0 SUCCESSFUL, -1 INVALID_GOAL, -2 INVALID_JOINTS, -4 PATH_TOLERANCE_VIOLATED,
    /// -5 GOAL_TOLERANCE_VIOLATED.
    pub error_code: i32,
    /// Why, in words.
    pub error_string: String,
}

/// SendGoal: the goal's id and the goal in; accepted and when out.
pub struct SendGoal;
impl ServiceType for SendGoal {
    type Request = (Uuid, FollowJointTrajectoryGoal);
    type Response = (bool, Time);
    const REQUEST_TYPE: &'static str =
        "control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Request_";
    const RESPONSE_TYPE: &'static str =
        "control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Response_";
}

/// GetResult: a goal's id in; its final status and result out, once it ended.
pub struct GetResult;
impl ServiceType for GetResult {
    type Request = Uuid;
    type Response = (i8, FollowJointTrajectoryResult);
    const REQUEST_TYPE: &'static str =
        "control_msgs::action::dds_::FollowJointTrajectory_GetResult_Request_";
    const RESPONSE_TYPE: &'static str =
        "control_msgs::action::dds_::FollowJointTrajectory_GetResult_Response_";
}

/// The feedback topic's type name.
pub const FEEDBACK_TYPE: &str =
    "control_msgs::action::dds_::FollowJointTrajectory_FeedbackMessage_";
/// The status topic's type name.
pub const STATUS_TYPE: &str = "action_msgs::msg::dds_::GoalStatusArray_";

/// `FollowJointTrajectory_FeedbackMessage`: the goal's id and the feedback, its layout that of
/// the distribution the peers run (`with_index`: Lyrical's).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FeedbackMessage {
    /// Which goal.
    pub goal_id: Uuid,
    /// Stamped with sim time.
    pub header: Header,
    /// The controller's joints.
    pub joint_names: Vec<String>,
    /// Where the trajectory wants them now.
    pub desired: JointTrajectoryPoint,
    /// Where they are.
    pub actual: JointTrajectoryPoint,
    /// `desired - actual`.
    pub error: JointTrajectoryPoint,
    /// The trajectory point being executed (the first not yet due).
    pub index: i32,
    /// Whether the message has `index` and `multi_dof_index` (control_msgs 6, Lyrical on).
    pub with_index: bool,
}

impl Serialize for FeedbackMessage {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        /// The feedback part, as the action's `Feedback` struct.
        struct Feedback<'a>(&'a FeedbackMessage);
        impl Serialize for Feedback<'_> {
            fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                let m = self.0;
                let empty_point = MultiDofPoint::default();
                let mut s = serializer.serialize_struct("Feedback", 13)?;
                s.serialize_field("header", &m.header)?;
                s.serialize_field("joint_names", &m.joint_names)?;
                s.serialize_field("desired", &m.desired)?;
                s.serialize_field("actual", &m.actual)?;
                s.serialize_field("error", &m.error)?;
                if m.with_index {
                    s.serialize_field("index", &m.index)?;
                }
                s.serialize_field("multi_dof_joint_names", &Vec::<String>::new())?;
                s.serialize_field("multi_dof_desired", &empty_point)?;
                s.serialize_field("multi_dof_actual", &empty_point)?;
                s.serialize_field("multi_dof_error", &empty_point)?;
                if m.with_index {
                    s.serialize_field("multi_dof_index", &0i32)?;
                }
                s.end()
            }
        }
        let mut s = serializer.serialize_struct("FeedbackMessage", 2)?;
        s.serialize_field("goal_id", &self.goal_id)?;
        s.serialize_field("feedback", &Feedback(self))?;
        s.end()
    }
}

/// `control_msgs/msg/GripperCommand`: where the fingers should go, and the most effort.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GripperCommand {
    /// The finger joint's position (m or rad).
    pub position: f64,
    /// The most effort (N or N m); 0 or less: the joint's limit.
    pub max_effort: f64,
}

/// `control_msgs/action/GripperCommand`'s goal.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GripperCommandGoal {
    /// The command.
    pub command: GripperCommand,
}

/// `control_msgs/action/GripperCommand`'s result (and its feedback: the same fields).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GripperCommandResult {
    /// Where the finger is.
    pub position: f64,
    /// The effort it exerts.
    pub effort: f64,
    /// It pushes without moving, short of the goal.
    pub stalled: bool,
    /// It reached the goal.
    pub reached_goal: bool,
}

/// GripperCommand's SendGoal.
pub struct GripperSendGoal;
impl ServiceType for GripperSendGoal {
    type Request = (Uuid, GripperCommandGoal);
    type Response = (bool, Time);
    const REQUEST_TYPE: &'static str =
        "control_msgs::action::dds_::GripperCommand_SendGoal_Request_";
    const RESPONSE_TYPE: &'static str =
        "control_msgs::action::dds_::GripperCommand_SendGoal_Response_";
}

/// GripperCommand's GetResult.
pub struct GripperGetResult;
impl ServiceType for GripperGetResult {
    type Request = Uuid;
    type Response = (i8, GripperCommandResult);
    const REQUEST_TYPE: &'static str =
        "control_msgs::action::dds_::GripperCommand_GetResult_Request_";
    const RESPONSE_TYPE: &'static str =
        "control_msgs::action::dds_::GripperCommand_GetResult_Response_";
}

/// GripperCommand's feedback topic type name.
pub const GRIPPER_FEEDBACK_TYPE: &str =
    "control_msgs::action::dds_::GripperCommand_FeedbackMessage_";

/// `GripperCommand_FeedbackMessage`: the goal's id and the feedback.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GripperFeedbackMessage {
    /// Which goal.
    pub goal_id: Uuid,
    /// The finger now.
    pub feedback: GripperCommandResult,
}

#[cfg(test)]
mod tests {
    use super::*;
    use byteorder::LittleEndian;

    /// Lyrical's feedback (control_msgs 6) has `index` after `error` and `multi_dof_index` at
    /// the end: 8 bytes more, the index where it belongs; the older layout reads as before.
    #[test]
    fn lyricals_feedback_carries_the_point_index() {
        let mut m = FeedbackMessage {
            goal_id: Uuid { uuid: [3; 16] },
            joint_names: vec!["a".into()],
            index: 7,
            ..FeedbackMessage::default()
        };
        let bytes = |m: &FeedbackMessage| {
            rustdds::serialization::to_vec::<_, LittleEndian>(m).unwrap_or_default()
        };
        let old = bytes(&m);
        m.with_index = true;
        let new = bytes(&m);
        assert_eq!(new.len(), old.len() + 8);
        assert_eq!(&old[..16], &[3; 16]);
        // After the error point come the multi-DOF names (an empty sequence: 4 bytes) and
        // three empty multi-DOF points (3 empty sequences and a Duration: 20 bytes each); the
        // index goes before them.
        let index_at = old.len() - 4 - 3 * 20;
        assert_eq!(new[index_at..index_at + 4], 7i32.to_le_bytes());
        assert_eq!(new[index_at + 4..new.len() - 4], old[index_at..]);
        assert_eq!(new[new.len() - 4..], 0i32.to_le_bytes());
    }
}
