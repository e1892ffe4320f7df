//! rover-core: the loop of a rover run, free of windows, viewers and devices.
//!
//! Data flows one way: world + robot -> [`rover_sim`] -> camera -> [`rover_perception`] ->
//! [`Pilot`] (teleop | [`Follower`]) -> cmd_vel -> sim. A [`Session`] advances that loop one
//! physics step at a time; [`Observer`]s (trace writer, frame saver, and in the app the Rerun
//! recorder and the window's HUD) only watch it, composed by a [`Fanout`]. [`ScriptPlayer`]
//! feeds timed inputs to a session; [`headless::run`] paces it as fast as the CPU allows,
//! deterministically.
//!
//! Nothing here depends on winit, wgpu surfaces, rerun or gilrs: everything runs headless in
//! tests.

mod error;
pub mod follower;
pub mod headless;
mod observers;
pub mod paths;
mod pilot;
pub mod scenario;
pub mod script;
mod session;
pub mod teleop;
pub mod trace;

pub use error::{CoreError, Result};
pub use follower::{CameraGeometry, FollowState, Follower, FollowerConfig, LaserMount};
pub use headless::{DEFAULT_DETECT_HZ, Perception, RunConfig, RunSummary};
pub use observers::{Fanout, FrameSaver, RunFiles, RunFilesWritten, TraceObserver};
pub use pilot::{Mode, Pilot};
pub use scenario::{Scenario, ScenarioResult};
pub use script::{Action, Script, ScriptPlayer, Step};
pub use session::{
    DetectorMode, EventLevel, InputSource, LoopStats, NoInput, NoObserver, Observer, Session,
    SessionOptions,
};
pub use teleop::{KeyAction, Teleop, key_action};
pub use trace::{TRACE_HEADER, TraceRow, TraceWriter, parse_trace};
