//! Pick and place: the arm grasps the object of a class the detector sees and puts it on (or
//! in) a place, as a MoveIt pick-and-place node does it with a planning scene.
//!
//! 1. **See.** Each detector message's most confident box of the class becomes the object's
//!    centre and radius in the arm's base frame, from the depth image (as reach estimates it,
//!    [`crate::object_estimate`]). [`PickConfig::sightings`] sightings in a row that agree
//!    within [`PickConfig::agree_m`] are averaged: the object.
//! 2. **Plan** (all of it at once, from the arm's pose now, in the world's planning scene,
//!    [`rover_sim::planning::PlanningScene`]):
//!    - the grasp: the tool at the object's centre, coming in along a direction tilted
//!      [`PickConfig::approach_pitches_deg`] below horizontal (straight down first), the first
//!      that IK reaches and where nothing but the object is within the margin with the fingers
//!      open; the pre-grasp [`PickConfig::approach_m`] back along it;
//!    - the place: the tool over the place's top, the object's bottom
//!      [`PickConfig::drop_height_m`] above it, the object carried in the hand (a sphere on
//!      the tool);
//!    - joint-space paths (RRT-Connect, [`rover_sim::planning::plan_path`]) to the pre-grasp, from the
//!      lift to the place, and home; straight lines by IK for the approach, the lift and the
//!      retreat. A grasp or place no direction reaches, or one that collides, is refused with
//!      the reason.
//! 3. **Run.** The gripper opens, the arm follows the timed paths (each joint at most
//!    [`PickConfig::speed_scale`] of its velocity limit) as a trajectory controller's moving
//!    setpoints, the gripper closes with [`PickConfig::squeeze_n`] until it stalls on the object
//!    (closing all the way means it missed), the arm lifts, carries, the gripper opens over the
//!    place, and the arm retreats and goes back to where it started.

mod config;
mod deliver;
mod fetch;
mod ground;
mod plan;
mod reachability;
mod route;
mod run;
mod see;
mod setup;
mod stance;
mod state;
mod ways;
mod world;

pub use config::PickConfig;
pub use state::{Pick, PickState};
