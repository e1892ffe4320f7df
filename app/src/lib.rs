//! rover, the application: headless runs, teleop, scripts and traces.
//!
//! The binary `rover` is a thin command line over this library, so tests drive exactly what
//! users run.

pub mod bench;
pub mod detect;
pub mod follower;
pub mod font;
pub mod gamepad;
pub mod headless;
pub mod paths;
pub mod pilot;
pub mod recorder;
pub mod reference;
pub mod script;
pub mod session;
pub mod teleop;
pub mod trace;
pub mod window;
