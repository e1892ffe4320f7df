//! What the loop thread hands the publishing thread, the interface every topic family
//! implements there, and the buffers that travel back for reuse. Nothing here knows a
//! transport.
//!
//! One [`Event`] per observer callback carries everything any family needs from it. The
//! publishing thread shows each event to every family in turn ([`TopicFamily`]); the buffers
//! it still holds afterwards go back to the loop thread ([`BufferReturn`]), so steady running
//! allocates nothing.

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

use rover_perception::BoundingBox;
use rover_sim::{
    geometry::Pose,
    model::CameraInfo,
    physics::ControlSample,
    sensors::{ContactsReading, FixReading, ImuReading, LaserScan, PointCloud, PoseReading},
};

/// One frame's pose in another, as tf carries it.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Transform {
    /// The parent frame.
    pub parent: String,
    /// The child frame.
    pub child: String,
    /// The child's origin in the parent frame (m).
    pub translation: [f64; 3],
    /// The child's orientation in the parent frame (unit quaternion x, y, z, w).
    pub rotation: [f64; 4],
}

impl Transform {
    /// `parent_from_child` as the transform from `parent` to `child`.
    pub fn new(parent: &str, child: &str, parent_from_child: Pose) -> Self {
        let mut t = Self {
            parent: parent.to_owned(),
            child: child.to_owned(),
            ..Self::default()
        };
        t.set_pose(parent_from_child);
        t
    }

    /// Sets the pose, frames unchanged.
    pub fn set_pose(&mut self, parent_from_child: Pose) {
        let (v, q) = (parent_from_child.translation, parent_from_child.rotation);
        self.translation = [v.x, v.y, v.z].map(f64::from);
        self.rotation = [q.x, q.y, q.z, q.w].map(f64::from);
    }
}

/// The run starts.
pub(crate) struct Start {
    /// Transforms that never change (`/tf_static`).
    pub static_tf: Vec<Transform>,
    /// The camera's calibration, when the robot has a camera.
    pub camera: Option<CameraInfo>,
    /// The models' names (`/gazebo/model_states`), in the order of
    /// [`ControlUpdate::models`].
    pub model_names: Vec<String>,
}

/// A control update.
pub(crate) struct ControlUpdate {
    /// What the simulation reported.
    pub sample: ControlSample,
    /// One per joint of the plan's `joints`, in that order.
    pub joints: Vec<JointSample>,
    /// The arm's task.
    pub arm: ArmSample,
    /// One per controller of the plan's `controllers`, in that order: what its trajectory
    /// does (default for controllers that take no trajectory); then one per gripper of the
    /// plan's `grippers`.
    pub runs: Vec<RunSample>,
    /// Every model's world pose and twist (a recycled buffer).
    pub models: Vec<rover_sim::physics::ModelState>,
}

/// A trajectory controller's run at a control update.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct RunSample {
    /// Whether a trajectory runs.
    pub active: bool,
    /// Trajectories started so far.
    pub runs: u64,
    /// How the last one ended (`None` while it runs).
    pub outcome: Option<rover_sim::physics::TrajectoryOutcome>,
    /// A gripper's finger and how its last command ended (zeros for other controllers).
    pub gripper: GripperSample,
}

/// A gripper controller's finger at a control update (control_msgs/GripperCommand's result).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct GripperSample {
    /// The finger joint's position (m or rad).
    pub position: f64,
    /// Its effort (N or N m).
    pub effort: f64,
    /// The last command ended short of its goal, the finger not moving.
    pub stalled: bool,
    /// The last command ended at its goal.
    pub reached_goal: bool,
}

/// The arm's task at a control update, its points in the robot's base frame.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ArmSample {
    /// Which task runs.
    pub mode: rover_core::ArmMode,
    /// What reach is doing.
    pub reach: rover_core::ReachState,
    /// What pick is doing.
    pub pick: rover_core::PickState,
    /// The object point reach goes for (m, base frame).
    pub object_base_m: Option<[f64; 3]>,
    /// The pre-grasp goal (m, base frame).
    pub goal_base_m: Option<[f64; 3]>,
}

/// One moving joint's state at a control update.
#[derive(Debug, Clone, Copy)]
pub(crate) struct JointSample {
    /// The child link's frame in the parent link's, now.
    pub parent_from_child: Pose,
    /// Measured speed (rad/s).
    pub velocity_radps: f64,
    /// The joint's position (rad or m); a wheel's is its angle, from the poses.
    pub position: f64,
    /// The actuator's effort (N m or N); 0 for passive joints and wheels.
    pub effort: f64,
    /// Where the actuator holds the joint now (its target); the position for joints without
    /// one.
    pub setpoint: f64,
}

/// A camera image.
pub(crate) struct ImageFrame {
    /// Sim time it was taken (s).
    pub stamp_s: f64,
    /// The camera's frame number.
    pub seq: u64,
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// RGB8, rows top to bottom. A family may keep it and leave another buffer in its place.
    pub pixels: Vec<u8>,
    /// A depth camera's depth image as 32FC1 bytes (little-endian f32 metres along the optical
    /// axis, NaN for nothing in range, rows top to bottom); empty without one.
    pub depth: Vec<u8>,
}

/// The detector's boxes for one image.
pub(crate) struct Detections {
    /// When they are published (sim s; never before their image).
    pub stamp_s: f64,
    /// Their image's stamp (sim s).
    pub image_stamp_s: f64,
    /// Their image's frame number.
    pub image_seq: u64,
    /// The boxes, in the image's pixels.
    pub boxes: Vec<BoundingBox>,
}

/// One observer callback's worth of data, on its way to the publishing thread.
pub(crate) enum Event {
    /// [`Start`].
    Start(Start),
    /// [`ControlUpdate`].
    Control(ControlUpdate),
    /// [`ImageFrame`].
    Image(ImageFrame),
    /// [`Detections`].
    Detections(Detections),
    /// Ground-truth boxes of a detected image, shaped as [`Detections`].
    Truth(Detections),
    /// A laser scan (its ranges in a recycled buffer).
    Scan(LaserScan),
    /// An IMU reading.
    Imu(ImuReading),
    /// A p3d ground-truth reading.
    Pose(PoseReading),
    /// A GPS fix.
    Fix(FixReading),
    /// A point cloud (its data in a recycled buffer).
    Cloud(PointCloud),
    /// A bumper reading.
    Contacts(ContactsReading),
}

/// One topic family on the publishing thread: its publishers and the messages it keeps from one
/// update to the next (only their numbers change). Each method sees one kind of event, in the
/// plan's order of families; the defaults ignore it. Methods given `&mut` may swap the event's
/// buffer for one of their own (to publish without a copy, or to keep it).
pub(crate) trait TopicFamily: Send {
    /// The run starts.
    fn start(&mut self, _start: &Start) {}
    /// A control update.
    fn control(&mut self, _update: &ControlUpdate) {}
    /// A camera image.
    fn image(&mut self, _image: &mut ImageFrame) {}
    /// Detections.
    fn detections(&mut self, _detections: &mut Detections) {}
    /// The ground truth of the image the last detections came from (`--ground-truth`), as
    /// boxes.
    fn ground_truth(&mut self, _truth: &mut Detections) {}
    /// A laser scan.
    fn scan(&mut self, _scan: &mut LaserScan) {}
    /// An IMU reading.
    fn imu(&mut self, _reading: &ImuReading) {}
    /// A p3d ground-truth reading.
    fn p3d(&mut self, _reading: &PoseReading) {}
    /// A GPS fix.
    fn gps(&mut self, _fix: &FixReading) {}
    /// A point cloud.
    fn cloud(&mut self, _cloud: &mut PointCloud) {}
    /// A bumper reading.
    fn contacts(&mut self, _reading: &ContactsReading) {}
}

/// Images kept waiting for reuse: more than the detection image's ring of 4 and a few in
/// flight.
const RECYCLED_IMAGES: usize = 8;

/// The loop thread's end of the buffers coming back: each `take_*` gives a recycled buffer, or
/// a new empty one.
pub(crate) struct BufferPool {
    pixels: Receiver<Vec<u8>>,
    ranges: Receiver<Vec<f32>>,
    boxes: Receiver<Vec<BoundingBox>>,
    joints: Receiver<Vec<JointSample>>,
    runs: Receiver<Vec<RunSample>>,
    models: Receiver<Vec<rover_sim::physics::ModelState>>,
}

/// The publishing thread's end: what an event still holds after every family saw it.
pub(crate) struct BufferReturn {
    pixels: SyncSender<Vec<u8>>,
    ranges: SyncSender<Vec<f32>>,
    boxes: SyncSender<Vec<BoundingBox>>,
    joints: SyncSender<Vec<JointSample>>,
    runs: SyncSender<Vec<RunSample>>,
    models: SyncSender<Vec<rover_sim::physics::ModelState>>,
}

/// A pool and its return path.
pub(crate) fn buffer_pool() -> (BufferPool, BufferReturn) {
    let (pixels_back, pixels) = sync_channel(RECYCLED_IMAGES);
    let (ranges_back, ranges) = sync_channel(4);
    let (boxes_back, boxes) = sync_channel(4);
    let (joints_back, joints) = sync_channel(4);
    let (runs_back, runs) = sync_channel(4);
    let (models_back, models) = sync_channel(4);
    (
        BufferPool {
            pixels,
            ranges,
            boxes,
            joints,
            runs,
            models,
        },
        BufferReturn {
            pixels: pixels_back,
            ranges: ranges_back,
            boxes: boxes_back,
            joints: joints_back,
            runs: runs_back,
            models: models_back,
        },
    )
}

impl BufferPool {
    /// An image or cloud buffer (its contents are stale).
    pub fn take_pixels(&self) -> Vec<u8> {
        self.pixels.try_recv().unwrap_or_default()
    }

    /// A ranges buffer (its contents are stale).
    pub fn take_ranges(&self) -> Vec<f32> {
        self.ranges.try_recv().unwrap_or_default()
    }

    /// A boxes buffer: stale boxes whose class strings keep their capacity.
    pub fn take_boxes(&self) -> Vec<BoundingBox> {
        self.boxes.try_recv().unwrap_or_default()
    }

    /// A joints buffer (its contents are stale).
    pub fn take_joints(&self) -> Vec<JointSample> {
        self.joints.try_recv().unwrap_or_default()
    }

    /// A trajectory runs buffer (its contents are stale).
    pub fn take_runs(&self) -> Vec<RunSample> {
        self.runs.try_recv().unwrap_or_default()
    }

    /// A model states buffer (its contents are stale).
    pub fn take_models(&self) -> Vec<rover_sim::physics::ModelState> {
        self.models.try_recv().unwrap_or_default()
    }
}

impl BufferReturn {
    /// Sends the event's buffer back (unless it has no capacity to offer); dropped when the
    /// pool is full or gone.
    pub(crate) fn give_back(&self, event: Event) {
        match event {
            Event::Start(_) => {}
            Event::Control(c) => {
                send(&self.joints, c.joints);
                send(&self.runs, c.runs);
                send(&self.models, c.models);
            }
            Event::Image(i) => {
                send(&self.pixels, i.pixels);
                send(&self.pixels, i.depth);
            }
            Event::Detections(d) | Event::Truth(d) => send(&self.boxes, d.boxes),
            Event::Scan(s) => send(&self.ranges, s.ranges_m),
            Event::Cloud(c) => send(&self.pixels, c.data),
            Event::Imu(_) | Event::Pose(_) | Event::Fix(_) | Event::Contacts(_) => {}
        }
    }
}

/// Sends `buffer` back (unless it has no capacity to offer); dropped when the pool is full or
/// gone.
fn send<T>(to: &SyncSender<Vec<T>>, buffer: Vec<T>) {
    if buffer.capacity() > 0 {
        let _ = to.try_send(buffer);
    }
}
