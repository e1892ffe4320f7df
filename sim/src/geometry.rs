//! Poses, shapes and colours shared by robots and worlds.

use glam::{EulerRot, Quat, Vec3};

/// Largest position coordinate rover accepts from a file (m): 100 km from the origin. Physics
/// runs in f32; beyond this, millimetre contacts are lost to rounding and parry's contact code
/// can fail on absurd values, so such a file is refused with its location instead.
pub(crate) const MAX_COORDINATE_M: f64 = 1.0e5;
/// Largest size (box side, radius, length, ground side) rover accepts from a file (m).
pub(crate) const MAX_SIZE_M: f64 = 1.0e5;
/// Largest mass rover accepts from a file (kg): a loaded freight wagon is ~1e5 kg.
pub(crate) const MAX_MASS_KG: f64 = 1.0e6;
/// Largest moment of inertia component rover accepts from a file (kg m^2).
pub(crate) const MAX_INERTIA_KGM2: f64 = 1.0e6;
/// Largest magnitude of any other number rover reads from a file (gravity, friction, mesh
/// scale, ...).
pub(crate) const MAX_MAGNITUDE: f64 = 1.0e6;

/// A rigid transform (rotation then translation), f32 like the physics engine.
///
/// Named by convention `a_from_b`: it maps coordinates in frame `b` into frame `a`.
pub type Pose = rapier3d::math::Pose;

/// Builds a pose from a URDF-style `xyz` (m) and `rpy` (rad, fixed-axis roll, pitch, yaw).
pub fn pose_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Pose {
    Pose::from_parts(vec3(xyz), quat_from_rpy(rpy))
}

/// URDF roll-pitch-yaw (applied about fixed X, then Y, then Z) as a quaternion.
pub(crate) fn quat_from_rpy(rpy: [f64; 3]) -> Quat {
    Quat::from_euler(EulerRot::ZYX, rpy[2] as f32, rpy[1] as f32, rpy[0] as f32)
}

/// Converts an `[f64; 3]` into the engine's vector type.
pub(crate) fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// A pose at `position_m` (world frame) turned `yaw_rad` about +z: how world files place
/// objects, people and the robot.
pub fn pose_from_position_yaw(position_m: [f64; 3], yaw_rad: f64) -> Pose {
    Pose::from_parts(
        glam::Vec3::new(
            position_m[0] as f32,
            position_m[1] as f32,
            position_m[2] as f32,
        ),
        glam::Quat::from_rotation_z(yaw_rad as f32),
    )
}

/// Heading (rotation about +z) of a rotation, in radians in (-pi, pi].
pub fn yaw_of(rotation: Quat) -> f64 {
    let forward = rotation * Vec3::X;
    f64::from(forward.y).atan2(f64::from(forward.x))
}

/// A primitive or mesh shape, in its own frame (URDF conventions: cylinders along z).
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Axis-aligned box with full side lengths.
    Box {
        /// Side lengths along x, y, z (m).
        size_m: Vec3,
    },
    /// Cylinder along the local z axis.
    Cylinder {
        /// Radius (m).
        radius_m: f32,
        /// Length along z (m).
        length_m: f32,
    },
    /// Sphere.
    Sphere {
        /// Radius (m).
        radius_m: f32,
    },
    /// Capsule along the local z axis (length excludes the caps).
    Capsule {
        /// Radius (m).
        radius_m: f32,
        /// Length of the cylindrical part along z (m).
        length_m: f32,
    },
    /// A triangle mesh file (STL or OBJ), scaled per axis.
    Mesh {
        /// Resolved path of the mesh file.
        path: std::path::PathBuf,
        /// Per-axis scale.
        scale: Vec3,
    },
}

impl Shape {
    /// Half its extent along its own z (m): how far its centre is above what it stands on,
    /// upright. `None` for a mesh.
    pub fn half_height_m(&self) -> Option<f32> {
        match self {
            Shape::Box { size_m } => Some(size_m.z / 2.0),
            Shape::Cylinder { length_m, .. } => Some(length_m / 2.0),
            Shape::Sphere { radius_m } => Some(*radius_m),
            Shape::Capsule { radius_m, length_m } => Some(radius_m + length_m / 2.0),
            Shape::Mesh { .. } => None,
        }
    }
}

/// Linear RGBA colour, components in 0..=1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rgba(pub [f32; 4]);

impl Rgba {
    /// Opaque colour from 0..=1 components.
    pub const fn rgb(r: f32, g: f32, b: f32) -> Self {
        Self([r, g, b, 1.0])
    }

    /// Parses `#rrggbb` or `#rrggbbaa`.
    pub fn from_hex(text: &str) -> Option<Self> {
        let hex = text.strip_prefix('#')?;
        if !(hex.len() == 6 || hex.len() == 8) || !hex.is_ascii() {
            return None;
        }
        let mut out = [1.0f32; 4];
        for (i, chunk) in hex.as_bytes().chunks(2).enumerate() {
            let s = std::str::from_utf8(chunk).ok()?;
            out[i] = f32::from(u8::from_str_radix(s, 16).ok()?) / 255.0;
        }
        Some(Self(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_matches_urdf_convention() {
        // Yaw of 90 degrees turns x into y.
        let q = quat_from_rpy([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let x = q * Vec3::X;
        assert!((x - Vec3::Y).length() < 1e-6);
        // Roll of -90 degrees turns z into +y (how wheel cylinders are laid on their side).
        let q = quat_from_rpy([-std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
        assert!((q * Vec3::Z - Vec3::Y).length() < 1e-6);
        assert!((yaw_of(quat_from_rpy([0.3, -0.2, 1.0])) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn hex_colours() {
        assert_eq!(Rgba::from_hex("#ff0000"), Some(Rgba([1.0, 0.0, 0.0, 1.0])));
        assert_eq!(
            Rgba::from_hex("#00000080").map(|c| c.0[3] > 0.5),
            Some(true)
        );
        assert_eq!(Rgba::from_hex("red"), None);
        assert_eq!(Rgba::from_hex("#12345"), None);
    }
}
