//! Motion planning for an arm: the planner (RRT-Connect in joint space, shortcutting, the
//! time parameterisation: `planner`) and the planning scene it checks configurations against
//! (the arm's links against the world, the robot's other links and themselves: `scene`), as
//! MoveIt pairs OMPL with its planning scene. Above `physics` (the scene reads the simulation's
//! colliders), beside `render` and `sensors`.

mod planner;
mod scene;

pub use planner::{PlanError, PlannerOptions, TimedPath, plan_path};
pub use scene::{PlanningScene, SceneContact};
