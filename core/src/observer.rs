//! The one-way hook on a run: an [`Observer`] watches a [`Session`](crate::Session) (the trace
//! writer, the frame saver, the Rerun recorder, the window's HUD, the ROS bridge) and never
//! influences it. [`Fanout`] hands one session's events to several observers; [`LoopStats`] are
//! the loop figures they are shown.

use rover_perception::BoundingBoxes;
use rover_sim::{
    geometry::Pose,
    model::CameraInfo,
    physics::{ControlSample, Simulation},
    sensors::{
        CameraFrame, ContactsReading, FixReading, GroundTruthBox, ImuReading, LaserScan,
        PointCloud, PoseReading,
    },
};

use crate::arm::ArmStatus;
use crate::error::CoreError;
use crate::follower::FollowState;
use crate::pilot::Mode;

/// How bad an [`Observer::event`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventLevel {
    /// Information (mode changes).
    Info,
    /// Something the user should know (no detector, viewer gone).
    Warn,
}

/// Loop figures for HUDs and recorders.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LoopStats {
    /// Control mode.
    pub mode: Mode,
    /// What the follower is doing.
    pub follow_state: FollowState,
    /// Detector results per wall second (worker) or per sim second (lockstep).
    pub detector_hz: f64,
    /// Latency of the newest detection (ms, from frame submission to result).
    pub detector_latency_ms: f64,
    /// Frames the detector skipped because a newer one arrived.
    pub frames_dropped: u64,
    /// Camera frames rendered.
    pub frames: u64,
    /// Whether a detector is running.
    pub detector_ok: bool,
    /// Whether the detector failed during the run (an error or a panic in it); it stays off.
    pub detector_failed: bool,
    /// Whether the follower is steering around an obstacle (it has a laser and something is in
    /// the way of its own command).
    pub avoiding: bool,
    /// The follower's estimate of its target (odometry frame, m), while it has one.
    pub follow_target_m: Option<[f64; 2]>,
    /// The point the follower is driving to (odometry frame, m): the target while it is seen,
    /// where it was last going once it is lost (PURSUING).
    pub follow_goal_m: Option<[f64; 2]>,
    /// The arm's task (look, reach) and its points.
    pub arm: ArmStatus,
}

/// Watches a session without influencing it (the Rerun recorder, the window).
pub trait Observer {
    /// Once, when the session is set up: the scene, the camera's intrinsics and the detector's
    /// class names.
    fn start(&mut self, _sim: &Simulation, _camera: Option<&CameraInfo>, _labels: &[String]) {}
    /// After every control update (100 Hz for the tutorial car).
    fn control(&mut self, _sim: &Simulation, _sample: &ControlSample, _stats: &LoopStats) {}
    /// A camera image, taken at `frame.sim_time_s` from `world_from_camera` (the camera link).
    fn camera_frame(&mut self, _frame: &CameraFrame<'_>, _world_from_camera: Pose) {}
    /// Detections of an earlier camera image (see their `image_stamp`).
    fn detections(&mut self, _boxes: &BoundingBoxes, _labels: &[String]) {}
    /// With ground truth on ([`crate::SessionOptions::ground_truth`]): right after
    /// [`Observer::detections`], the ground truth of the image those detections came from.
    fn detections_truth(&mut self, _boxes: &BoundingBoxes, _truth: &[GroundTruthBox]) {}
    /// A laser scan, taken from `world_from_laser` (the sensor's frame) at `scan.stamp_s`.
    fn laser_scan(&mut self, _scan: &LaserScan, _world_from_laser: Pose) {}
    /// An IMU reading (of the robot's IMU `reading.sensor`), at `reading.stamp_s`.
    fn imu(&mut self, _reading: &ImuReading) {}
    /// A ground-truth pose reading (of the robot's p3d `reading.sensor`).
    fn p3d(&mut self, _reading: &PoseReading) {}
    /// A GPS fix (of the robot's GPS `fix.sensor`).
    fn gps(&mut self, _fix: &FixReading) {}
    /// A point cloud (a 3D lidar's, a depth camera's; `cloud.source` says which) in
    /// `cloud.frame_id`, that frame at `world_from_sensor` when it was taken.
    fn point_cloud(&mut self, _cloud: &PointCloud, _world_from_sensor: Pose) {}
    /// A bumper reading (of the robot's bumper `reading.sensor`): what its link touches now.
    fn contacts(&mut self, _reading: &ContactsReading) {}
    /// A mode change, a warning.
    fn event(&mut self, _sim_time_s: f64, _level: EventLevel, _text: &str) {}
    /// An observer that can no longer do its job (a trace or frame it cannot write) says so
    /// here, once; the runner decides whether the run stops.
    fn failure(&mut self) -> Option<CoreError> {
        None
    }
}

/// Two observers side by side, built on the stack where one is added for a moment (the
/// window's HUD beside the fan-out): no allocation.
impl<A: Observer + ?Sized, B: Observer + ?Sized> Observer for (&mut A, &mut B) {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        self.0.start(sim, camera, labels);
        self.1.start(sim, camera, labels);
    }
    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        self.0.control(sim, sample, stats);
        self.1.control(sim, sample, stats);
    }
    fn camera_frame(&mut self, frame: &CameraFrame<'_>, world_from_camera: Pose) {
        self.0.camera_frame(frame, world_from_camera);
        self.1.camera_frame(frame, world_from_camera);
    }
    fn detections(&mut self, boxes: &BoundingBoxes, labels: &[String]) {
        self.0.detections(boxes, labels);
        self.1.detections(boxes, labels);
    }
    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        self.0.detections_truth(boxes, truth);
        self.1.detections_truth(boxes, truth);
    }
    fn laser_scan(&mut self, scan: &LaserScan, world_from_laser: Pose) {
        self.0.laser_scan(scan, world_from_laser);
        self.1.laser_scan(scan, world_from_laser);
    }
    fn imu(&mut self, reading: &ImuReading) {
        self.0.imu(reading);
        self.1.imu(reading);
    }
    fn p3d(&mut self, reading: &PoseReading) {
        self.0.p3d(reading);
        self.1.p3d(reading);
    }
    fn gps(&mut self, fix: &FixReading) {
        self.0.gps(fix);
        self.1.gps(fix);
    }
    fn point_cloud(&mut self, cloud: &PointCloud, world_from_sensor: Pose) {
        self.0.point_cloud(cloud, world_from_sensor);
        self.1.point_cloud(cloud, world_from_sensor);
    }
    fn contacts(&mut self, reading: &ContactsReading) {
        self.0.contacts(reading);
        self.1.contacts(reading);
    }
    fn event(&mut self, sim_time_s: f64, level: EventLevel, text: &str) {
        self.0.event(sim_time_s, level, text);
        self.1.event(sim_time_s, level, text);
    }
    fn failure(&mut self) -> Option<CoreError> {
        self.0.failure().or_else(|| self.1.failure())
    }
}

/// An observer that ignores everything.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoObserver;

impl Observer for NoObserver {}

/// Hands every event to each of its observers, in the order they were added.
#[derive(Default)]
pub struct Fanout<'a> {
    observers: Vec<&'a mut dyn Observer>,
}

impl std::fmt::Debug for Fanout<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fanout")
            .field("observers", &self.observers.len())
            .finish()
    }
}

impl<'a> Fanout<'a> {
    /// Adds an observer.
    pub fn push(&mut self, observer: &'a mut dyn Observer) {
        self.observers.push(observer);
    }

    /// Adds an observer if there is one.
    pub fn push_some<O: Observer>(&mut self, observer: Option<&'a mut O>) {
        if let Some(o) = observer {
            self.observers.push(o);
        }
    }
}

impl Observer for Fanout<'_> {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        for o in &mut self.observers {
            o.start(sim, camera, labels);
        }
    }
    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        for o in &mut self.observers {
            o.control(sim, sample, stats);
        }
    }
    fn camera_frame(&mut self, frame: &CameraFrame<'_>, world_from_camera: Pose) {
        for o in &mut self.observers {
            o.camera_frame(frame, world_from_camera);
        }
    }
    fn detections(&mut self, boxes: &BoundingBoxes, labels: &[String]) {
        for o in &mut self.observers {
            o.detections(boxes, labels);
        }
    }
    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        for o in &mut self.observers {
            o.detections_truth(boxes, truth);
        }
    }
    fn laser_scan(&mut self, scan: &LaserScan, world_from_laser: Pose) {
        for o in &mut self.observers {
            o.laser_scan(scan, world_from_laser);
        }
    }
    fn imu(&mut self, reading: &ImuReading) {
        for o in &mut self.observers {
            o.imu(reading);
        }
    }
    fn p3d(&mut self, reading: &PoseReading) {
        for o in &mut self.observers {
            o.p3d(reading);
        }
    }
    fn gps(&mut self, fix: &FixReading) {
        for o in &mut self.observers {
            o.gps(fix);
        }
    }
    fn point_cloud(&mut self, cloud: &PointCloud, world_from_sensor: Pose) {
        for o in &mut self.observers {
            o.point_cloud(cloud, world_from_sensor);
        }
    }
    fn contacts(&mut self, reading: &ContactsReading) {
        for o in &mut self.observers {
            o.contacts(reading);
        }
    }
    fn event(&mut self, sim_time_s: f64, level: EventLevel, text: &str) {
        for o in &mut self.observers {
            o.event(sim_time_s, level, text);
        }
    }
    fn failure(&mut self) -> Option<CoreError> {
        self.observers.iter_mut().find_map(|o| o.failure())
    }
}
