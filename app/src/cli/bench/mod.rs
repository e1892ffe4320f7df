//! `rover bench`: physics-only real-time factor on a world (single-threaded), camera frame
//! time, recording overhead and detector stages (beside onnxruntime).
//!
//! One file per group of benchmarks: `physics` (the figure of eight), `detector` (stages,
//! onnxruntime, `--profile`), `sensors` (camera, laser, IMU and p3d), `overhead` (recording, the ROS
//! bridge), `people` (the people sweep) and `stats` (the median they share). This file only
//! re-exports them.

mod detector;
mod overhead;
mod people;
mod physics;
mod sensors;
mod stats;

pub use detector::{DetectorBench, detector};
pub use overhead::{RecordBench, RosBench, record, ros};
pub use physics::{PhysicsBench, physics};
pub use sensors::{CameraBench, LaserBench, SensorsBench, camera, laser, sensors};

pub(crate) use detector::bench_detect;
pub(crate) use overhead::{bench_record, bench_ros};
pub(crate) use people::bench_people;
pub(crate) use physics::bench_cmd;
pub(crate) use sensors::{bench_camera, bench_laser, bench_sensors};
pub(crate) use stats::median;
