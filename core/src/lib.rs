//! rover-core: the loop of a rover run, free of windows, viewers and devices.
//!
//! Data flows one way: world + robot -> [`rover_sim`] -> camera -> [`rover_perception`] ->
//! [`Pilot`] (teleop | [`Follower`]) -> cmd_vel -> sim. A [`Session`] advances that loop one
//! physics step at a time, driven by [`Action`]s (keys, scripted steps, an [`InputSource`]);
//! [`Observer`]s (trace writer, frame saver, and in the app the Rerun recorder and the window's
//! HUD) only watch it, composed by a [`Fanout`]. [`ScriptPlayer`] feeds timed inputs to a
//! session; [`run_headless`] paces it as fast as the CPU allows, deterministically, and
//! [`run_scenario`] judges the follower on a scenario file.
//!
//! Nothing here depends on winit, wgpu surfaces, rerun or gilrs: everything runs headless in
//! tests. The modules are private; this page lists the API.

mod arm;
mod dataset;
mod detection;
mod error;
mod follower;
mod headless;
mod input;
mod judge;
mod launch;
mod observer;
mod paths;
mod people_sweep;
mod pilot;
mod run_files;
mod scenario;
mod script;
mod sensors;
mod session;
mod shard;
mod teleop;
mod trace;

pub use arm::{
    ArmConfig, ArmMode, ArmStatus, DepthView, Look, LookConfig, Pick, PickConfig, PickState, Reach,
    ReachConfig, ReachState, ReachStep, Upright, hidden_by_robot, object_estimate, object_point,
    pregrasp, robot_share, upright_extent,
};
pub use dataset::{
    COCO_CATEGORY_IDS, DatasetFormat, DatasetProgress, DatasetSpec, DatasetSummary, DetectedBox,
    ImageFormat, ImageRecord, LabelledBox, MANIFEST, MANIFEST_FORMAT, Manifest, PersonShot,
    Randomization, SHARD_MANIFEST, Shot, Split, coco_category, coco_json, coco_results, data_yaml,
    merge_dataset, write_dataset, write_whole, yolo_class,
};
pub use error::{CoreError, Result};
pub use follower::{
    AvoidConfig, Avoided, CameraGeometry, FollowState, FollowTarget, Follower, FollowerConfig,
    LaserMount, TargetFilter, range_bearing_from,
};
pub use headless::{
    DEFAULT_DETECT_HZ, Perception, RunConfig, RunSummary, UNTIL_STOPPED_S, run_headless,
    run_headless_driven, run_headless_observed,
};
pub use input::{Action, InputSource, JointAction, NoInput};
pub use judge::{ClassTally, LiveJudge, MATCH_IOU, eval_objects};
pub use launch::{
    DetectorRequest, Launch, LaunchError, LaunchNode, LaunchOptions, Location as LaunchLocation,
    NodeRole, Output as NodeOutput, PROVIDED_PACKAGES, Param as LaunchParam, ParamSource,
    ParamValue, ProvidedInclude, RoverPart, SpawnRequest, WorldRequest, canonical_name,
    find_launch_file, find_node_executable, load as load_launch, ns_join, provided_placeholder,
    role_of, shell_split,
};
pub use observer::{EventLevel, Fanout, LoopStats, NoObserver, Observer};
pub use paths::{bundled_path, default_robot_path};
pub use people_sweep::{
    SWEEP_DISTANCES_M, SWEEP_HEADINGS_DEG, SWEEP_POSTURES, SweepPosture, SweepView, sweep,
};
pub use pilot::{Mode, Pilot};
pub use run_files::{FrameSaver, RunFiles, RunFilesWritten, TraceObserver};
pub use scenario::{
    Scenario, ScenarioCheck, ScenarioCriteria, ScenarioMetrics, ScenarioOptions, ScenarioResult,
    Sensor, collect_scenario_files, judge_scenario, robot_name, run_scenario,
};
pub use script::{Script, ScriptPlayer, Step};
pub use session::{DetectorMode, Session, SessionOptions};
pub use shard::{
    SHARD_FORMAT, ShardIndex, ShardManifest, check_shard_set, sha256_of as file_sha256,
};
pub use teleop::{KeyAction, TELEOP_KEYS, Teleop, key_action};
pub use trace::{
    TRACE_HEADER, TRACE_TRUTH_COLUMNS, TraceParseError, TraceRow, TraceWriter, TruthColumns,
    parse_trace, trace_joints,
};
