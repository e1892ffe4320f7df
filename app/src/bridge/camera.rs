//! The camera's image (sensor_msgs/Image, `rgb8`) and its calibration (sensor_msgs/CameraInfo)
//! on `/<cameraName>/<imageTopicName>` and `/<cameraName>/<cameraInfoTopicName>`, with every
//! image; a depth camera's depth image (`32FC1`, metres along the optical axis, NaN where
//! nothing is in range, as gazebo_ros_openni_kinect publishes it) and its camera_info (the
//! colour camera's: the depth image is rendered with the same intrinsics) on
//! `/<cameraName>/<depthImageTopicName>` and `/<cameraName>/<depthImageCameraInfoTopicName>`.

use rover_sim::model::CameraInfo;

use super::events::{ImageFrame, Start, TopicFamily};

/// Which of a camera's images.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Channel {
    /// The colour image, `rgb8`.
    Colour,
    /// A depth camera's depth image, `32FC1`.
    Depth,
}

/// One thing per channel (a topic, its publisher), looked up by channel.
#[derive(Debug, Default)]
pub(crate) struct Channels<T> {
    /// The colour image's.
    pub colour: T,
    /// The depth image's.
    pub depth: T,
}

impl<T> Channels<T> {
    /// `channel`'s.
    pub fn get_mut(&mut self, channel: Channel) -> &mut T {
        match channel {
            Channel::Colour => &mut self.colour,
            Channel::Depth => &mut self.depth,
        }
    }
}

/// The camera's topics on one transport (publishing nothing the robot has no topic for).
pub(crate) trait CameraWire: Send {
    /// The camera's calibration, at the start.
    fn calibrate(&mut self, camera: &CameraInfo);
    /// Publishes the calibration stamped as `image`, for `channel`.
    fn info(&mut self, channel: Channel, image: &ImageFrame);
    /// Publishes `channel`'s image of `image` (its buffer may be lent to the message and stays
    /// with the frame).
    fn image(&mut self, channel: Channel, image: &mut ImageFrame);
}

/// The camera family.
pub(crate) struct Camera {
    wire: Box<dyn CameraWire>,
    /// Whether the run has a camera calibration.
    calibrated: bool,
}

impl Camera {
    /// The family on `wire`.
    pub fn new(wire: Box<dyn CameraWire>) -> Self {
        Self {
            wire,
            calibrated: false,
        }
    }
}

impl TopicFamily for Camera {
    fn start(&mut self, start: &Start) {
        if let Some(c) = &start.camera {
            self.wire.calibrate(c);
        }
        self.calibrated = start.camera.is_some();
    }

    fn image(&mut self, image: &mut ImageFrame) {
        if self.calibrated {
            self.wire.info(Channel::Colour, image);
        }
        self.wire.image(Channel::Colour, image);
        if !image.depth.is_empty() {
            if self.calibrated {
                self.wire.info(Channel::Depth, image);
            }
            self.wire.image(Channel::Depth, image);
        }
    }
}
