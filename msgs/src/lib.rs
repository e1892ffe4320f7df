//! The ROS message types rover's two wires share field for field: geometry_msgs' `Vector3`
//! (also `Point`), `Quaternion`, `Pose` and `Twist` are defined alike in ROS 1 and ROS 2, so
//! they are written once, here. How each travels is its wire's: `rover-ros1` encodes them in
//! ROS 1's serialization (`Message`), `rover-ros2` in CDR through serde (`RosMessage`); both
//! crates re-export them in their `msgs`.
//!
//! The messages whose fields differ between ROS 1 and ROS 2 (std_msgs/Header's `seq`, Time's
//! layout, darknet_ros's `Class`) stay in each wire's crate.

use serde::{Deserialize, Serialize};

/// `geometry_msgs/Vector3`, and `geometry_msgs/Point` (the same three `float64`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl From<[f64; 3]> for Vector3 {
    fn from([x, y, z]: [f64; 3]) -> Self {
        Self { x, y, z }
    }
}

/// `geometry_msgs/Quaternion` (the identity by default).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

impl From<[f64; 4]> for Quaternion {
    fn from([x, y, z, w]: [f64; 4]) -> Self {
        Self { x, y, z, w }
    }
}

impl Quaternion {
    /// A rotation about z by `yaw_rad`.
    pub fn from_yaw(yaw_rad: f64) -> Self {
        let (s, c) = (yaw_rad / 2.0).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position (m).
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity (m/s).
    pub linear: Vector3,
    /// Angular velocity (rad/s).
    pub angular: Vector3,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_yaw_is_a_rotation_about_z() {
        let q = Quaternion::from_yaw(std::f64::consts::FRAC_PI_2);
        let half = std::f64::consts::FRAC_1_SQRT_2;
        assert!((q.z - half).abs() < 1e-12 && (q.w - half).abs() < 1e-12);
        assert_eq!((q.x, q.y), (0.0, 0.0));
        assert_eq!(Quaternion::default(), Quaternion::from_yaw(0.0));
    }
}
