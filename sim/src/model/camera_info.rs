//! The camera model of gazebo_ros_camera: intrinsics from the sensor's horizontal FOV and image
//! size, published as a CameraInfo-like struct. Images are in the optical frame (z forward,
//! x right, y down); the camera link is x forward.

use glam::{Mat3, Quat};

use crate::model::sensors::{CameraConfig, Distortion};

/// Like sensor_msgs/CameraInfo.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraInfo {
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// Optical frame id.
    pub frame_id: String,
    /// Distortion model name (`plumb_bob`).
    pub distortion_model: &'static str,
    /// D = [k1, k2, t1, t2, k3], ROS order.
    pub d: [f64; 5],
    /// K, row-major 3x3.
    pub k: [f64; 9],
    /// R (identity for a monocular camera), row-major 3x3.
    pub r: [f64; 9],
    /// P, row-major 3x4.
    pub p: [f64; 12],
}

impl CameraInfo {
    /// gazebo_ros_camera's intrinsics: `fx = fy = W / (2 tan(hfov / 2))`, `cx = (W + 1) / 2`,
    /// `cy = (H + 1) / 2`. rover renders with exactly this K (pixel centres at integer
    /// coordinates), so projecting with it lands on the rendered pixel.
    pub fn from_config(config: &CameraConfig) -> Self {
        let (w, h) = (f64::from(config.width_px), f64::from(config.height_px));
        let fx = w / (2.0 * (config.horizontal_fov_rad / 2.0).tan());
        let (cx, cy) = ((w + 1.0) / 2.0, (h + 1.0) / 2.0);
        let Distortion { k1, k2, k3, p1, p2 } = config.distortion;
        Self {
            width: config.width_px,
            height: config.height_px,
            frame_id: optical_frame_id(config),
            distortion_model: "plumb_bob",
            d: [k1, k2, p1, p2, k3],
            k: [fx, 0.0, cx, 0.0, fx, cy, 0.0, 0.0, 1.0],
            r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            p: [fx, 0.0, cx, 0.0, 0.0, fx, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
        }
    }

    /// Focal length (px).
    pub fn fx(&self) -> f64 {
        self.k[0]
    }

    /// Principal point (px).
    pub fn principal_point(&self) -> (f64, f64) {
        (self.k[2], self.k[5])
    }

    /// Projects a point in the optical frame (m) to pixel coordinates (no distortion).
    pub fn project(&self, x: f64, y: f64, z: f64) -> Option<(f64, f64)> {
        (z > 0.0).then(|| (self.k[0] * x / z + self.k[2], self.k[4] * y / z + self.k[5]))
    }
}

/// The frame a camera's images are in. A `frameName` naming another frame than the sensor's
/// link is that frame, as gazebo_ros_camera has it (TIAGo's `xtion_rgb_optical_frame`, a URDF
/// link turned the optical way). Left at the sensor's link (the tutorial car's `camera_link`,
/// x forward), it would put the images in a frame that does not look the way they do: rover
/// names the optical frame under it `<link>_optical` instead (REP-103: z forward, x right, y
/// down) and publishes it on /tf_static.
pub(crate) fn optical_frame_id(config: &CameraConfig) -> String {
    if config.frame_name == config.link {
        format!("{}_optical", config.frame_name)
    } else {
        config.frame_name.clone()
    }
}

/// Rotation from the optical frame (z forward, x right, y down) to the camera link (x forward,
/// y left, z up).
pub fn link_from_optical() -> Quat {
    Quat::from_mat3(&Mat3::from_cols(
        glam::Vec3::new(0.0, -1.0, 0.0),
        glam::Vec3::new(0.0, 0.0, -1.0),
        glam::Vec3::new(1.0, 0.0, 0.0),
    ))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The seed tutorial's camera: 640x480, hfov 1.3962634, 30 Hz.
    pub(crate) fn seed_config() -> CameraConfig {
        CameraConfig {
            name: "camera1".into(),
            link: "camera_link".into(),
            update_rate_hz: 30.0,
            horizontal_fov_rad: 1.3962634,
            width_px: 640,
            height_px: 480,
            format: crate::model::sensors::PixelFormat::Rgb8,
            clip_near_m: 0.02,
            clip_far_m: 300.0,
            noise: None,
            distortion: Distortion::default(),
            camera_name: "camera".into(),
            frame_name: "camera_link".into(),
            image_topic: "image_raw".into(),
            info_topic: "camera_info".into(),
            depth: None,
            line: None,
        }
    }

    #[test]
    fn seed_camera_intrinsics() {
        let info = CameraInfo::from_config(&seed_config());
        assert!((info.fx() - 381.36).abs() < 0.01, "{}", info.fx());
        assert_eq!(info.principal_point(), (320.5, 240.5));
        assert_eq!(info.p[0], info.k[0]);
        // Optical z is the link's x; optical x is the link's -y.
        let q = link_from_optical();
        assert!((q * glam::Vec3::Z - glam::Vec3::X).length() < 1e-6);
        assert!((q * glam::Vec3::X + glam::Vec3::Y).length() < 1e-6);
        assert!((q * glam::Vec3::Y + glam::Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn the_images_frame_is_the_plugins_frame_name_or_the_links_optical_frame() {
        // frameName left at the sensor's link: rover's optical frame under it.
        assert_eq!(
            CameraInfo::from_config(&seed_config()).frame_id,
            "camera_link_optical"
        );
        // TIAGo's xtion: frameName names its URDF's optical link; taken as it is.
        let xtion = CameraConfig {
            link: "xtion_rgb_frame".into(),
            frame_name: "xtion_rgb_optical_frame".into(),
            ..seed_config()
        };
        assert_eq!(
            CameraInfo::from_config(&xtion).frame_id,
            "xtion_rgb_optical_frame"
        );
    }
}
