//! The arm's room: what the arm does with what the camera sees — look (turn a camera's chain
//! onto a detection), reach (the tool to a pre-grasp point), pick (grasp and place, the base
//! driving with `fetch`) — and the session's arm task that runs them.

mod arm_task;
mod depth;
mod look;
mod pick;
mod reach;
mod shape;

pub(crate) use arm_task::ArmTask;
pub use arm_task::{ArmConfig, ArmMode, ArmStatus};
pub use depth::{DepthView, hidden_by_robot, object_estimate, object_point, robot_share};
pub use look::{Look, LookConfig};
pub use pick::{Pick, PickConfig, PickState};
pub use reach::{Reach, ReachConfig, ReachState, ReachStep, pregrasp};
pub use shape::{Upright, upright_extent};
