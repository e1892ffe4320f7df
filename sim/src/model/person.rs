//! People in a world: standing or walking a path, drawn as a human figure, obstacles for
//! physics.

use std::sync::Arc;

use crate::geometry::{Pose, Rgba, pose_from_position_yaw};
use crate::model::actor::Actor;
use crate::model::human::{BodyShape, Outfit};

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
    /// MakeHuman's body in this shape, or `None` for rover's own figure of primitives (the
    /// default for now: the camera-only follower is still tuned to it; also drawn when
    /// MakeHuman's body cannot be fetched).
    pub shape: Option<BodyShape>,
    /// What MakeHuman's body wears besides its colours: hair style, trousers or a skirt.
    pub outfit: Outfit,
    /// A Gazebo actor's script and skin (SDF `<actor>`): it moves by the script instead of
    /// `walk`, and is drawn with its own skin when it has one.
    pub actor: Option<Arc<Actor>>,
    /// A person without a walk caught mid-stride at this gait phase (rad; 0: standing), as a
    /// still scene (a dataset's image) may show them.
    pub still_gait_phase_rad: f64,
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
    /// Whether rover draws this person with MakeHuman's body: a shape, and no skin of an
    /// actor's own.
    pub fn needs_makehuman(&self) -> bool {
        self.shape.is_some() && self.actor.as_ref().is_none_or(|a| a.skin.is_none())
    }

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
            shape: Some(BodyShape::default()),
            outfit: Outfit::default(),
            actor: None,
            still_gait_phase_rad: 0.0,
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
        if let Some(pose) = self.actor.as_ref().and_then(|a| a.pose_at(t_s)) {
            return pose;
        }
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
        let length = self.walk_length_m();
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

    /// Where the person is in their gait at sim time `t_s` (rad): 0 while standing (before
    /// the walk starts, at the end of a single walk), [`Person::still_gait_phase_rad`] without
    /// a walk; walking, the legs go through one cycle — two steps — per stride,
    /// [`Person::stride_m`]. An actor with an animation: where its clip is, as a fraction of a
    /// turn (see [`Actor::clip_time_s`]).
    pub fn gait_phase_rad(&self, t_s: f64) -> f64 {
        if let Some(actor) = &self.actor {
            let clip = actor.skin.as_ref().and_then(|s| s.clip.as_ref());
            return match (clip, actor.clip_time_s(t_s)) {
                (Some(clip), Some(time_s)) if clip.duration_s > 0.0 => {
                    std::f64::consts::TAU * time_s / clip.duration_s
                }
                _ => 0.0,
            };
        }
        let Some(walk) = &self.walk else {
            return self.still_gait_phase_rad;
        };
        if t_s < walk.start_after_s {
            return 0.0;
        }
        let walked = walk.speed_mps * (t_s - walk.start_after_s);
        if !walk.repeat && walked >= self.walk_length_m() {
            return 0.0;
        }
        std::f64::consts::TAU * (walked / self.stride_m()).fract()
    }

    /// How far one gait cycle (two steps) carries the person (m): longer for taller people
    /// and faster walks (1.0 m for a 1.75 m person at 0.4 m/s, 1.3 m at 1 m/s).
    pub fn stride_m(&self) -> f64 {
        let speed_mps = self.walk.as_ref().map_or(0.0, |w| w.speed_mps);
        self.height_m * (0.45 + 0.3 * speed_mps.min(1.5))
    }

    /// The length of the walk's path (m): start, waypoints, and back to the start when it
    /// repeats; 0 without a walk.
    fn walk_length_m(&self) -> f64 {
        let Some(walk) = &self.walk else {
            return 0.0;
        };
        let back = walk.repeat.then_some(self.position_m);
        let mut from = self.position_m;
        walk.waypoints_m
            .iter()
            .copied()
            .chain(back)
            .map(|to| {
                let leg_m = (to[0] - from[0]).hypot(to[1] - from[1]);
                from = to;
                leg_m
            })
            .sum()
    }

    /// Whether the person moves (a walk or an actor's script).
    pub fn moves(&self) -> bool {
        self.walk.is_some() || self.actor.as_ref().is_some_and(|a| a.script.is_some())
    }

    /// Radius of the upright capsule that stands in for the person in physics (m).
    pub fn body_radius_m(&self) -> f64 {
        0.13 * self.height_m / 1.75
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gait_turns_once_per_stride_and_rests_while_standing() {
        let mut p = Person::standing("p", [0.0, 0.0], 0.0);
        assert_eq!(p.gait_phase_rad(3.0), 0.0);
        p.walk = Some(Walk {
            waypoints_m: vec![[4.0, 0.0]],
            speed_mps: 0.5,
            repeat: false,
            start_after_s: 1.0,
        });
        let stride_s = p.stride_m() / 0.5;
        assert!((p.stride_m() - 1.75 * 0.6).abs() < 1e-9);
        assert_eq!(p.gait_phase_rad(0.5), 0.0, "before the walk starts");
        let quarter = p.gait_phase_rad(1.0 + stride_s / 4.0);
        assert!((quarter - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        let again = p.gait_phase_rad(1.0 + stride_s * 1.25);
        assert!((again - quarter).abs() < 1e-9, "one stride later");
        // 4 m at 0.5 m/s: standing again from 9 s.
        assert_eq!(p.gait_phase_rad(9.5), 0.0, "after a single walk");
        if let Some(walk) = p.walk.as_mut() {
            walk.repeat = true;
        }
        assert!(p.gait_phase_rad(9.5) > 0.0, "a repeated walk goes on");
    }
}
