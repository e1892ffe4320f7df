//! What the loop thread hands the publishing thread, the interface every topic family
//! implements there, and the buffers that travel back for reuse.
//!
//! One [`Event`] per observer callback carries everything any family needs from it. The
//! publishing thread shows each event to every family in turn ([`TopicFamily`]); the buffers
//! it still holds afterwards go back to the loop thread ([`BufferReturn`]), so steady running
//! allocates nothing.

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};

use rover_perception::BoundingBox;
use rover_ros1::msgs::TransformStamped;
use rover_sim::{CameraInfo, ControlSample, LaserScan, Pose};

/// The run starts.
pub(super) struct Start {
    /// Transforms that never change (`/tf_static`).
    pub static_tf: Vec<TransformStamped>,
    /// The camera's calibration, when the robot has a camera.
    pub camera: Option<CameraInfo>,
}

/// A control update.
pub(super) struct ControlUpdate {
    /// What the simulation reported.
    pub sample: ControlSample,
    /// One per joint of the plan's `joints`, in that order.
    pub joints: Vec<JointSample>,
    /// The arm's task.
    pub arm: ArmSample,
}

/// The arm's task at a control update, its points in the robot's base frame.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ArmSample {
    /// Which task runs.
    pub mode: rover_core::ArmMode,
    /// What reach is doing.
    pub reach: rover_core::ReachState,
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
    /// The joint's position (rad or m) from the simulation; wheels' angles come from the poses.
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
pub(super) enum Event {
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
}

/// One topic family on the publishing thread: its publishers and the messages it keeps from one
/// update to the next (only their numbers change). Each method sees one kind of event, in the
/// plan's order of families; the defaults ignore it. Methods given `&mut` may swap the event's
/// buffer for one of their own (to publish without a copy, or to keep it).
pub(super) trait TopicFamily: Send {
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
}

/// The publishing thread's end: what an event still holds after every family saw it.
pub(crate) struct BufferReturn {
    pixels: SyncSender<Vec<u8>>,
    ranges: SyncSender<Vec<f32>>,
    boxes: SyncSender<Vec<BoundingBox>>,
    joints: SyncSender<Vec<JointSample>>,
}

/// A pool and its return path.
pub(crate) fn buffer_pool() -> (BufferPool, BufferReturn) {
    let (pixels_back, pixels) = sync_channel(RECYCLED_IMAGES);
    let (ranges_back, ranges) = sync_channel(4);
    let (boxes_back, boxes) = sync_channel(4);
    let (joints_back, joints) = sync_channel(4);
    (
        BufferPool {
            pixels,
            ranges,
            boxes,
            joints,
        },
        BufferReturn {
            pixels: pixels_back,
            ranges: ranges_back,
            boxes: boxes_back,
            joints: joints_back,
        },
    )
}

impl BufferPool {
    /// An image buffer (its contents are stale).
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
}

impl BufferReturn {
    /// Sends the event's buffer back (unless it has no capacity to offer); dropped when the
    /// pool is full or gone.
    pub(super) fn give_back(&self, event: Event) {
        match event {
            Event::Start(_) => {}
            Event::Control(c) => self.joints(c.joints),
            Event::Image(i) => {
                self.pixels(i.pixels);
                self.pixels(i.depth);
            }
            Event::Detections(d) | Event::Truth(d) => send(&self.boxes, d.boxes),
            Event::Scan(s) => self.ranges(s.ranges_m),
        }
    }

    /// An image buffer back (the ROS 2 bridge's too).
    pub fn pixels(&self, buffer: Vec<u8>) {
        send(&self.pixels, buffer);
    }

    /// A ranges buffer back.
    pub fn ranges(&self, buffer: Vec<f32>) {
        send(&self.ranges, buffer);
    }

    /// A boxes buffer back.
    pub fn boxes(&self, buffer: Vec<BoundingBox>) {
        send(&self.boxes, buffer);
    }

    /// A joints buffer back.
    pub fn joints(&self, buffer: Vec<JointSample>) {
        send(&self.joints, buffer);
    }
}

/// Sends `buffer` back (unless it has no capacity to offer); dropped when the pool is full or
/// gone.
fn send<T>(to: &SyncSender<Vec<T>>, buffer: Vec<T>) {
    if buffer.capacity() > 0 {
        let _ = to.try_send(buffer);
    }
}
