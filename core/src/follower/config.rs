//! The follower's settings and what it knows of its sensors: the camera's geometry, the
//! laser's mount, and where a point is from the robot.

use rover_sim::{
    model::CameraInfo,
    physics::{Odometry, wrap_angle},
};

use super::avoid::AvoidConfig;

/// Follower settings.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowerConfig {
    /// Class to follow (darknet_ros `Class`).
    pub target_class: String,
    /// Minimum detection probability for a new target.
    pub min_probability: f64,
    /// Minimum detection probability for a detection inside the target's gate to keep it
    /// (a person partly out of view scores lower, and is still the same person).
    pub keep_probability: f64,
    /// Distance to keep from the target (m).
    pub standoff_m: f64,
    /// Assumed real height of the target (m), for range from box height.
    pub target_height_m: f64,
    /// Assumed width of the target's box (m: shoulders and arms), for range from box width
    /// when the box is cut off; each target's own width is learned from its whole boxes.
    pub target_width_m: f64,
    /// Forward speed limit (m/s); backing away from a target that comes too close is limited to
    /// 0.6 times this.
    pub max_speed_mps: f64,
    /// Turn rate limit (rad/s).
    pub max_turn_radps: f64,
    /// Linear acceleration limit (m/s^2).
    pub max_accel_mps2: f64,
    /// Angular acceleration limit (rad/s^2).
    pub max_turn_accel_radps2: f64,
    /// Turn rate while searching for a lost target (rad/s).
    pub search_turn_radps: f64,
    /// Stop when the newest detector message is older than this (s of sim time).
    pub stale_after_s: f64,
    /// TRACKING becomes PURSUING when the target has not been seen for this long (s).
    pub lost_after_s: f64,
    /// PURSUING becomes SEARCHING this long after arriving where the target was expected
    /// without seeing it again (s).
    pub reacquire_s: f64,
    /// ... or this long after arriving when the target is a standing person the camera cannot
    /// see whole from the standoff (s): a low camera sees only legs there and detections
    /// flicker; that is no reason to search.
    pub close_hold_s: f64,
    /// A pursuit that has not arrived after this long gives up and searches (s).
    pub pursue_for_s: f64,
    /// A target not seen by the camera for this long is forgotten: the next person of the class
    /// becomes a new target wherever it is (s).
    pub forget_after_s: f64,
    /// Laser returns keep a target only while the camera confirmed it within this long (s).
    pub laser_confirm_s: f64,
    /// Proportional gain from bearing error (rad) to turn rate (rad/s).
    pub turn_gain: f64,
    /// Proportional gain from range error (m) to speed (m/s).
    pub speed_gain: f64,
    /// Lead moving targets by this long (s): aim where the target will be.
    pub lead_s: f64,
    /// At the standoff: range errors within this band (m) and bearings within
    /// [`FollowerConfig::bearing_deadband_rad`] are left alone once settled (hysteresis: calm).
    pub standoff_band_m: f64,
    /// Bearing deadband at rest (rad).
    pub bearing_deadband_rad: f64,
    /// Obstacle avoidance (used when the robot has a laser).
    pub avoid: AvoidConfig,
}

impl Default for FollowerConfig {
    fn default() -> Self {
        Self {
            target_class: "person".into(),
            min_probability: 0.4,
            keep_probability: 0.3,
            standoff_m: 1.5,
            target_height_m: 1.75,
            target_width_m: 0.55,
            max_speed_mps: 0.8,
            max_turn_radps: 1.2,
            max_accel_mps2: 0.8,
            max_turn_accel_radps2: 3.0,
            search_turn_radps: 0.6,
            stale_after_s: 1.0,
            lost_after_s: 0.6,
            reacquire_s: 2.0,
            close_hold_s: 30.0,
            pursue_for_s: 12.0,
            forget_after_s: 8.0,
            laser_confirm_s: 10.0,
            turn_gain: 1.8,
            speed_gain: 0.8,
            lead_s: 0.5,
            standoff_band_m: 0.25,
            bearing_deadband_rad: 0.1,
            avoid: AvoidConfig::default(),
        }
    }
}

/// Where the camera is and how it projects, as the follower needs it: the robot's own
/// camera_info and mount, so a low, pitched, narrow or offset camera works.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraGeometry {
    /// Focal length (px).
    pub fx: f64,
    /// Focal length (px).
    pub fy: f64,
    /// Principal point (px).
    pub cx: f64,
    /// Principal point (px).
    pub cy: f64,
    /// Image width (px).
    pub width_px: f64,
    /// Image height (px).
    pub height_px: f64,
    /// Camera height above the ground (m).
    pub height_m: f64,
    /// Camera position ahead of the base origin (m).
    pub forward_m: f64,
    /// Camera position left of the base origin (m).
    pub left_m: f64,
    /// Where the optical axis points, counter-clockwise from the base's +x (rad).
    pub yaw_rad: f64,
    /// How far the optical axis looks below the horizon (rad; a TurtleBot3's camera: 0.174).
    pub pitch_down_rad: f64,
}

impl CameraGeometry {
    /// From a CameraInfo and the camera's mounting (height above ground, offset ahead of base),
    /// looking straight ahead and level.
    pub fn new(info: &CameraInfo, height_m: f64, forward_m: f64) -> Self {
        Self {
            fx: info.k[0],
            fy: info.k[4],
            cx: info.k[2],
            cy: info.k[5],
            width_px: f64::from(info.width),
            height_px: f64::from(info.height),
            height_m,
            forward_m,
            left_m: 0.0,
            yaw_rad: 0.0,
            pitch_down_rad: 0.0,
        }
    }

    /// How far below the horizon the ray through image row `v` points (rad; negative above).
    pub(super) fn dip_rad(&self, v: f64) -> f64 {
        ((v - self.cy) / self.fy).atan() + self.pitch_down_rad
    }

    /// Horizontal distance (m) from the camera at which a standing person of `height_m` just
    /// fills the image from its bottom edge to its top edge: nearer, some of them is cut off.
    pub fn whole_view_range_m(&self, height_m: f64) -> f64 {
        let up = -self.dip_rad(0.0);
        let down = self.dip_rad(self.height_px);
        let from_top = if up > 1e-3 {
            (height_m - self.height_m).max(0.0) / up.tan()
        } else {
            f64::INFINITY
        };
        let from_bottom = if down > 1e-3 {
            self.height_m / down.tan()
        } else {
            f64::INFINITY
        };
        from_top.max(from_bottom)
    }
}

/// Range (m) and bearing (rad, positive left) of `point` (odometry frame) from a robot at
/// `odom`: where the follower's target or goal is, as the HUD and the scenario probe show it.
pub fn range_bearing_from(odom: Odometry, point: [f64; 2]) -> (f64, f64) {
    let (dx, dy) = (point[0] - odom.x_m, point[1] - odom.y_m);
    (dx.hypot(dy), wrap_angle(dy.atan2(dx) - odom.yaw_rad))
}

/// Where a laser scanner sits on the robot, in the base frame (planar).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LaserMount {
    /// Ahead of the base origin (m).
    pub x_m: f64,
    /// Left of the base origin (m).
    pub y_m: f64,
    /// Yaw of the scan frame relative to the base (rad).
    pub yaw_rad: f64,
}

impl LaserMount {
    /// The planar part of the sensor's pose in the base frame.
    pub fn from_base_from_laser(base_from_laser: rover_sim::geometry::Pose) -> Self {
        Self {
            x_m: f64::from(base_from_laser.translation.x),
            y_m: f64::from(base_from_laser.translation.y),
            yaw_rad: wrap_angle(rover_sim::geometry::yaw_of(base_from_laser.rotation)),
        }
    }
}
