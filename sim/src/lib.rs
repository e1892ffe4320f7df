//! rover-sim: the simulation core of rover.
//!
//! Loads a robot from URDF or xacro ([`model::RobotModel`], honouring the `<gazebo>`
//! diff_drive, camera and laser extensions) and a world from TOML or Gazebo SDF
//! ([`model::World`]), steps rapier3d physics at a fixed rate and drives the wheels like
//! gazebo_ros_diff_drive ([`physics::Simulation`]), renders the robot's camera offscreen with
//! wgpu ([`sensors::CameraSensor`], [`render::CameraRenderer`]) and casts its laser's rays
//! ([`sensors::LaserSensor`]). Free of UI and viewer code, so it runs headless in tests.
//!
//! Frames follow REP-103: x forward, y left, z up; camera images are in the optical frame
//! (z forward, x right, y down).
//!
//! The API is grouped by module, as rapier groups its own (`dynamics`, `geometry`,
//! `pipeline`), one module a layer, each importing only the ones before it:
//! [`geometry`] (poses, shapes, colours) -> [`model`] (plain data: robots, worlds, people,
//! drives, sensors, meshes; `model::human` and `model::actor` for skinned people) ->
//! [`description`] (file formats -> model) -> [`physics`] (the simulation) -> [`planning`]
//! (the arm's planner and its planning scene) -> [`render`] -> [`sensors`]. Errors
//! ([`SimError`], [`Result`], [`Location`]) and the seeded random numbers ([`SplitMix64`]) that
//! every layer uses sit at the root. Each item has one path. Viewers that draw the scene use
//! the same triangles the camera renders: [`render::shape_mesh`], [`render::object_mesh`] and
//! [`render::person_parts`] give [`model::MeshData`] in each thing's own frame.

pub mod description;
mod error;
pub mod geometry;
mod io;
pub mod model;
mod noise;
pub mod physics;
pub mod planning;
pub mod render;
pub mod sensors;

pub use error::{Location, Result, SimError};
pub use noise::SplitMix64;
