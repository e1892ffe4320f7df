//! Sensors on sim time: the camera (`camera.rs`, rendering through `render`) and the 2D laser
//! (`laser.rs`, ray casts against the physics scene), both with seeded noise.

pub(crate) mod camera;
pub(crate) mod laser;

pub use camera::{CameraFrame, CameraSensor};
pub use laser::{LaserScan, LaserSensor};
