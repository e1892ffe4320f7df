//! People in a world: standing or walking a path, drawn as a human figure, obstacles for
//! physics.

use crate::geometry::{Pose, Rgba, pose_from_position_yaw};

/// Height of a person whose world file gives none (m).
pub const DEFAULT_PERSON_HEIGHT_M: f64 = 1.75;

/// A person (`[[person]]`): a standing human figure, an obstacle for physics.
#[derive(Debug, Clone, PartialEq)]
pub struct Person {
    /// Name (unique within the world).
    pub name: String,
    /// Position of the feet on the ground (x, y in m).
    pub position_m: [f64; 2],
    /// Facing direction (rad, counter-clockwise from +x).
    pub heading_rad: f64,
    /// Standing height (m).
    pub height_m: f64,
    /// Shirt colour.
    pub shirt_color: Rgba,
    /// Trousers colour.
    pub trousers_color: Rgba,
    /// Skin colour.
    pub skin_color: Rgba,
    /// Hair colour.
    pub hair_color: Rgba,
    /// A walk: `position_m`, then each waypoint, then back to `position_m`, repeated.
    pub walk: Option<Walk>,
}

/// A person's walk: a path at a constant speed, closed and repeated (the default) or walked
/// once.
#[derive(Debug, Clone, PartialEq)]
pub struct Walk {
    /// Waypoints after the start position (m, world frame).
    pub waypoints_m: Vec<[f64; 2]>,
    /// Walking speed (m/s).
    pub speed_mps: f64,
    /// Back to the start and round again (true), or stop at the last waypoint (false).
    pub repeat: bool,
    /// Stand at the start this long before walking (s).
    pub start_after_s: f64,
}

impl Person {
    /// A 1.75 m person in rover's default clothes, standing at `position_m` facing
    /// `heading_rad`.
    pub fn standing(name: impl Into<String>, position_m: [f64; 2], heading_rad: f64) -> Self {
        Self {
            name: name.into(),
            position_m,
            heading_rad,
            height_m: DEFAULT_PERSON_HEIGHT_M,
            shirt_color: Rgba::rgb(0.75, 0.15, 0.12),
            trousers_color: Rgba::rgb(0.15, 0.2, 0.35),
            skin_color: Rgba::rgb(0.87, 0.67, 0.53),
            hair_color: Rgba::rgb(0.2, 0.13, 0.08),
            walk: None,
        }
    }

    /// The person's pose at sim time `t_s`: feet on the ground, x facing where they look.
    pub fn world_from_person(&self, t_s: f64) -> Pose {
        let (x, y, heading) = self.pose_at(t_s);
        pose_from_position_yaw([x, y, 0.0], heading)
    }

    /// Where the person is at sim time `t_s`: (x m, y m, heading rad). Standing people stay
    /// put; walking people follow their closed path at their speed, facing where they go.
    pub fn pose_at(&self, t_s: f64) -> (f64, f64, f64) {
        let [x0, y0] = self.position_m;
        let Some(walk) = &self.walk else {
            return (x0, y0, self.heading_rad);
        };
        let n = walk.waypoints_m.len() + 1;
        let corner = |i: usize| {
            if i.is_multiple_of(n) {
                self.position_m
            } else {
                walk.waypoints_m[i % n - 1]
            }
        };
        // Legs: corner i to corner i + 1; a repeated walk closes the loop, a single one does not.
        let legs = if walk.repeat { n } else { n - 1 };
        let leg = |i: usize| {
            let (a, b) = (corner(i), corner(i + 1));
            (a, b, (b[0] - a[0]).hypot(b[1] - a[1]))
        };
        let length: f64 = (0..legs).map(|i| leg(i).2).sum();
        if length <= 1e-9 {
            return (x0, y0, self.heading_rad);
        }
        let walked = walk.speed_mps * (t_s - walk.start_after_s).max(0.0);
        if t_s < walk.start_after_s {
            let (a, b, _) = leg(0);
            return (x0, y0, (b[1] - a[1]).atan2(b[0] - a[0]));
        }
        let mut s = if walk.repeat {
            walked.rem_euclid(length)
        } else {
            walked.min(length)
        };
        for i in 0..legs {
            let (a, b, l) = leg(i);
            if s <= l || i + 1 == legs {
                let f = if l > 0.0 { (s / l).min(1.0) } else { 0.0 };
                let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
                return (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f, heading);
            }
            s -= l;
        }
        (x0, y0, self.heading_rad)
    }

    /// Radius of the upright capsule that stands in for the person in physics (m).
    pub fn body_radius_m(&self) -> f64 {
        0.13 * self.height_m / 1.75
    }
}
