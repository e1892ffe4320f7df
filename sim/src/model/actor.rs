//! Gazebo actors (SDF `<actor>`) as Gazebo plays them: a `<script>` of timed waypoints the actor
//! follows, and a skinned COLLADA mesh posed by its skeleton animation.
//!
//! The script: each `<trajectory>`'s waypoints are keyframes, positions interpolated by a
//! cubic Hermite spline whose tangents follow Gazebo's Catmull-Rom rule
//! (`0.5 * (1 - tension) * (next - previous)`, the ends wrapping round when the trajectory
//! closes on itself), headings by the shortest turn between keys (a slerp about z). So, as in
//! Gazebo, an actor eases into and out of each waypoint and swings a little wide where it turns
//! in place; `tension = 1` makes it keep to the straight lines. Trajectories play in id order;
//! `loop` repeats the whole script, `delay_start` holds the first pose that long.
//!
//! The skin: linear-blend skinning of the mesh's vertices by the joints the animation moves.
//! With `<interpolate_x>` the animation's time follows the distance walked along the script
//! (the root joint's forward travel in the clip matched to it, so the feet keep pace), and the
//! root's own forward travel is dropped because the script carries the actor; without it the
//! clip plays at its own rate.

use std::sync::Arc;

use glam::{Affine3A, Mat4, Quat, Vec3};

use crate::geometry::Rgba;
use crate::model::skin;

/// Time step of the table of distance walked along a script (s).
const DISTANCE_STEP_S: f64 = 0.01;

/// A Gazebo actor: its script and, when it has one, its skin and animation.
#[derive(Debug, Clone, PartialEq)]
pub struct Actor {
    /// Where the actor goes (`None`: it stays at its `<pose>`).
    pub script: Option<Script>,
    /// The skinned mesh and its clip (`None`: drawn as a rover person).
    pub skin: Option<Arc<ActorSkin>>,
}

impl Actor {
    /// Where the actor is at sim time `t_s`: (x m, y m, heading rad), `None` without a script.
    pub fn pose_at(&self, t_s: f64) -> Option<(f64, f64, f64)> {
        self.script.as_ref().map(|s| s.pose_at(t_s))
    }

    /// The animation's time at sim time `t_s` (s, within the clip): by distance walked with
    /// `interpolate_x` and a script, else by time; `None` without a clip.
    pub fn clip_time_s(&self, t_s: f64) -> Option<f64> {
        let skin = self.skin.as_ref()?;
        let clip = skin.clip.as_ref()?;
        match (&self.script, clip.interpolate_x) {
            (Some(script), true) if clip.cycle_x > 1e-6 => {
                Some(clip.time_at_x(script.distance_m(t_s)))
            }
            _ => Some(t_s.rem_euclid(clip.duration_s.max(1e-6))),
        }
    }

    /// Whether the script moves the skin's root (its forward travel in the clip is then
    /// dropped, as Gazebo does for a translated trajectory).
    pub fn carried(&self) -> bool {
        self.script.is_some()
    }
}

/// One waypoint of a trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Waypoint {
    /// Time from the trajectory's start (s).
    pub time_s: f64,
    /// Position (m, world frame; z ignored: actors stand on the ground).
    pub position_m: [f64; 2],
    /// Heading (rad, counter-clockwise from +x).
    pub yaw_rad: f64,
}

/// One `<trajectory>`: its waypoints (sorted by time, the first at 0) and their tangents.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    waypoints: Vec<Waypoint>,
    tangents: Vec<[f64; 2]>,
}

impl Trajectory {
    /// A trajectory through `waypoints` (at least two, sorted by time, the first at time 0)
    /// with the spline's `tension` (0: Catmull-Rom, 1: straight between waypoints).
    pub fn new(waypoints: Vec<Waypoint>, tension: f64) -> Self {
        let n = waypoints.len();
        let p = |i: usize| waypoints[i].position_m;
        let closed = n > 2 && {
            let (a, b) = (p(0), p(n - 1));
            (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6
        };
        let k = 0.5 * (1.0 - tension);
        let diff = |a: [f64; 2], b: [f64; 2]| [k * (a[0] - b[0]), k * (a[1] - b[1])];
        let mut tangents = Vec::with_capacity(n);
        for i in 0..n {
            let t = if i == 0 {
                if closed {
                    diff(p(1), p(n - 2))
                } else {
                    diff(p(1), p(0))
                }
            } else if i == n - 1 {
                if closed {
                    tangents[0]
                } else {
                    diff(p(i), p(i - 1))
                }
            } else {
                diff(p(i + 1), p(i - 1))
            };
            tangents.push(t);
        }
        Self {
            waypoints,
            tangents,
        }
    }

    /// Its length in time (s).
    pub fn duration_s(&self) -> f64 {
        self.waypoints.last().map_or(0.0, |w| w.time_s)
    }

    /// Its waypoints.
    pub fn waypoints(&self) -> &[Waypoint] {
        &self.waypoints
    }

    /// Where it is `t_s` after its start (clamped to its span): (x, y, yaw).
    pub fn pose_at(&self, t_s: f64) -> (f64, f64, f64) {
        let w = &self.waypoints;
        let Some(last) = w.last() else {
            return (0.0, 0.0, 0.0);
        };
        if t_s >= last.time_s || w.len() < 2 {
            return (last.position_m[0], last.position_m[1], last.yaw_rad);
        }
        let t_s = t_s.max(0.0);
        let i = w
            .windows(2)
            .position(|pair| t_s < pair[1].time_s)
            .unwrap_or(w.len() - 2);
        let (a, b) = (&w[i], &w[i + 1]);
        let span = b.time_s - a.time_s;
        let s = if span > 0.0 {
            (t_s - a.time_s) / span
        } else {
            1.0
        };
        let (s2, s3) = (s * s, s * s * s);
        let h = [
            2.0 * s3 - 3.0 * s2 + 1.0,
            -2.0 * s3 + 3.0 * s2,
            s3 - 2.0 * s2 + s,
            s3 - s2,
        ];
        let (ta, tb) = (self.tangents[i], self.tangents[i + 1]);
        let axis = |k: usize| {
            h[0] * a.position_m[k] + h[1] * b.position_m[k] + h[2] * ta[k] + h[3] * tb[k]
        };
        let turn = (b.yaw_rad - a.yaw_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        (axis(0), axis(1), a.yaw_rad + s * turn)
    }
}

/// An actor's `<script>`: its trajectories played in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Script {
    trajectories: Vec<Trajectory>,
    /// Play the script again from its start when it ends.
    pub looped: bool,
    /// Hold the first pose this long before starting (s).
    pub delay_start_s: f64,
    /// Whether the script starts by itself (rover has no way to start it later: an actor that
    /// does not start stays at its first pose).
    pub auto_start: bool,
    /// Distance walked at each [`DISTANCE_STEP_S`] of one pass (m).
    distance_table_m: Vec<f64>,
}

impl Script {
    /// A script of `trajectories` (each with at least two waypoints).
    pub fn new(
        trajectories: Vec<Trajectory>,
        looped: bool,
        delay_start_s: f64,
        auto_start: bool,
    ) -> Self {
        let mut script = Self {
            trajectories,
            looped,
            delay_start_s,
            auto_start,
            distance_table_m: Vec::new(),
        };
        let steps = (script.duration_s() / DISTANCE_STEP_S).ceil() as usize;
        let mut walked = 0.0;
        let mut from = script.pass_pose(0.0);
        script.distance_table_m.push(0.0);
        for k in 1..=steps {
            let to = script.pass_pose((k as f64 * DISTANCE_STEP_S).min(script.duration_s()));
            walked += (to.0 - from.0).hypot(to.1 - from.1);
            script.distance_table_m.push(walked);
            from = to;
        }
        script
    }

    /// One pass's length in time (s).
    pub fn duration_s(&self) -> f64 {
        self.trajectories.iter().map(Trajectory::duration_s).sum()
    }

    /// Its trajectories, in the order they play.
    pub fn trajectories(&self) -> &[Trajectory] {
        &self.trajectories
    }

    /// Time into the current pass at sim time `t_s` (s), and how many passes are done.
    fn pass_time(&self, t_s: f64) -> (f64, f64) {
        let duration = self.duration_s();
        let t = if self.auto_start {
            (t_s - self.delay_start_s).max(0.0)
        } else {
            0.0
        };
        if duration <= 0.0 {
            return (0.0, 0.0);
        }
        if self.looped {
            (t.rem_euclid(duration), (t / duration).floor())
        } else {
            (t.min(duration), 0.0)
        }
    }

    /// Pose `t_s` into a pass.
    fn pass_pose(&self, mut t_s: f64) -> (f64, f64, f64) {
        for (i, trajectory) in self.trajectories.iter().enumerate() {
            if t_s < trajectory.duration_s() || i + 1 == self.trajectories.len() {
                return trajectory.pose_at(t_s);
            }
            t_s -= trajectory.duration_s();
        }
        (0.0, 0.0, 0.0)
    }

    /// Where the actor is at sim time `t_s`: (x m, y m, heading rad).
    pub fn pose_at(&self, t_s: f64) -> (f64, f64, f64) {
        self.pass_pose(self.pass_time(t_s).0)
    }

    /// How far the actor has walked along the script by sim time `t_s` (m).
    pub fn distance_m(&self, t_s: f64) -> f64 {
        let (t, passes) = self.pass_time(t_s);
        let table = &self.distance_table_m;
        let per_pass = table.last().copied().unwrap_or(0.0);
        let f = t / DISTANCE_STEP_S;
        let k = (f.floor() as usize).min(table.len().saturating_sub(1));
        let next = table.get(k + 1).copied().unwrap_or(per_pass);
        let here = table.get(k).copied().unwrap_or(0.0);
        passes * per_pass + here + (next - here) * (f - k as f64).clamp(0.0, 1.0)
    }
}

/// A joint of an actor's skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinJoint {
    /// Its name (the node's `name`, else its `sid` or `id`).
    pub name: String,
    /// Its parent joint (`None`: the skeleton's root).
    pub parent: Option<usize>,
    /// Its transform relative to the parent at rest (the file's units and axes).
    pub rest_local: Mat4,
}

/// An actor's skinned mesh: rest vertices, triangles by material, skeleton, weights and clip.
#[derive(Debug, Clone, PartialEq)]
pub struct ActorSkin {
    /// Vertex positions with the bind shape applied (the file's units and axes).
    pub(crate) rest: Vec<Vec3>,
    /// Triangles (indices into `rest`) by material, with the material's colour.
    pub(crate) layers: Vec<(Rgba, Vec<u32>)>,
    /// Joints, parents before children; the first is the skeleton's root.
    pub(crate) joints: Vec<SkinJoint>,
    /// The transform of the nodes above the root (the file's scene).
    pub(crate) above_root: Mat4,
    /// For each skin joint: the skeleton joint it is and its inverse bind matrix.
    pub(crate) bind: Vec<(usize, Mat4)>,
    /// Per vertex: up to four (skin joint, weight) pairs, weights summing to 1.
    pub(crate) weights: Vec<[(u16, f32); 4]>,
    /// File units and axes to rover's (metres, z up), with the `<skin><scale>`.
    pub(crate) to_rover: Mat4,
    /// The animation, when the actor has one.
    pub clip: Option<Clip>,
}

/// A skeleton animation: sampled local transforms of some joints over time.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    /// Its length (s).
    pub duration_s: f64,
    /// Whether its time follows the distance walked (`<interpolate_x>`).
    pub interpolate_x: bool,
    /// Per animated joint (skeleton index): key times (s) and (translation, rotation) keys.
    pub(crate) channels: Vec<Channel>,
    /// The root's forward travel over the clip (the file's units), 0 when it does not move.
    pub(crate) cycle_x: f64,
    /// The root's forward position at each root key, with the key's time.
    pub(crate) root_x: Vec<(f64, f64)>,
}

/// One joint's keys.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Channel {
    pub(crate) joint: usize,
    pub(crate) times_s: Vec<f32>,
    pub(crate) keys: Vec<(Vec3, Quat, Vec3)>,
}

impl Channel {
    /// The joint's local transform at `t_s` (linear between keys, clamped at the ends).
    fn at(&self, t_s: f32) -> Mat4 {
        let n = self.times_s.len();
        let key = |i: usize| self.keys[i];
        let (s, r, t) = if n == 0 {
            (Vec3::ONE, Quat::IDENTITY, Vec3::ZERO)
        } else if t_s <= self.times_s[0] {
            key(0)
        } else if t_s >= self.times_s[n - 1] {
            key(n - 1)
        } else {
            let i = self
                .times_s
                .windows(2)
                .position(|w| t_s < w[1])
                .unwrap_or(n - 2);
            let (a, b) = (key(i), key(i + 1));
            let span = self.times_s[i + 1] - self.times_s[i];
            let f = if span > 0.0 {
                (t_s - self.times_s[i]) / span
            } else {
                1.0
            };
            (a.0.lerp(b.0, f), a.1.slerp(b.1, f), a.2.lerp(b.2, f))
        };
        Mat4::from_scale_rotation_translation(s, r, t)
    }
}

impl Clip {
    /// How far the root walks forward over the clip (m), 0 when it walks in place.
    pub fn cycle_m(&self) -> f64 {
        self.cycle_x
    }

    /// The clip's time at which the root has walked `x` forward (s), wrapping round the cycle.
    pub fn time_at_x(&self, x: f64) -> f64 {
        let (Some(first), Some(last)) = (self.root_x.first(), self.root_x.last()) else {
            return 0.0;
        };
        let x = first.0 + x.rem_euclid(self.cycle_x.max(1e-9));
        for pair in self.root_x.windows(2) {
            let ((x0, t0), (x1, t1)) = (pair[0], pair[1]);
            if x <= x1 {
                let f = if x1 > x0 {
                    ((x - x0) / (x1 - x0)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                return t0 + f * (t1 - t0);
            }
        }
        last.1
    }
}

/// A bone as a capsule for range sensors: between two joints of a posed skeleton.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoneCapsule {
    /// The joint it starts at (index into the posed joints).
    pub from: usize,
    /// The joint it ends at.
    pub to: usize,
    /// Its radius (m).
    pub radius_m: f32,
}

/// Smallest and largest capsule radius (m): a bone with almost no skin of its own still
/// stops a ray, and a loose vertex does not make a barrel.
const CAPSULE_RADIUS_M: [f32; 2] = [0.02, 0.2];

/// Capsules for a skeleton's bones, from its rest pose: each bone from a joint to one of its
/// children, as thick as the skin it moves — the 70th percentile of the distances to the bone
/// of the rest vertices whose strongest joint is the bone's own and that lie alongside it.
/// Bones without such skin (fingers, twist bones, the eyes) get none.
pub(crate) fn bone_capsules(
    rest: &[Vec3],
    main_joint: &[usize],
    joints: &[Vec3],
    parents: &[Option<usize>],
) -> Vec<BoneCapsule> {
    let mut by_joint: Vec<Vec<Vec3>> = vec![Vec::new(); joints.len()];
    for (v, &j) in rest.iter().zip(main_joint) {
        if let Some(list) = by_joint.get_mut(j) {
            list.push(*v);
        }
    }
    let mut capsules = Vec::new();
    for (to, parent) in parents.iter().enumerate() {
        let Some(from) = *parent else { continue };
        let (Some(a), Some(b)) = (joints.get(from), joints.get(to)) else {
            continue;
        };
        let axis = *b - *a;
        let length_sq = axis.length_squared();
        if length_sq < 1e-6 {
            continue;
        }
        let mut distances: Vec<f32> = by_joint[from]
            .iter()
            .filter_map(|v| {
                let t = (*v - *a).dot(axis) / length_sq;
                (0.0..=1.0).contains(&t).then(|| v.distance(*a + t * axis))
            })
            .collect();
        if distances.len() < 8 {
            continue;
        }
        distances.sort_by(f32::total_cmp);
        let radius_m = distances[distances.len() * 7 / 10];
        capsules.push(BoneCapsule {
            from,
            to,
            radius_m: radius_m.clamp(CAPSULE_RADIUS_M[0], CAPSULE_RADIUS_M[1]),
        });
    }
    capsules
}

/// Scratch and result of posing an actor's skin.
#[derive(Debug, Clone, Default)]
pub struct PosedSkin {
    /// Vertex positions (m, the actor's frame: z up, x its heading).
    pub positions: Vec<Vec3>,
    /// Vertex normals (unit).
    pub normals: Vec<Vec3>,
    /// Each skeleton joint's transform in the actor's frame (m).
    pub joints: Vec<Affine3A>,
    world: Vec<Mat4>,
    skinning: Vec<Affine3A>,
}

impl ActorSkin {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.rest.len()
    }

    /// Triangles by material, with the material's colour.
    pub fn layers(&self) -> &[(Rgba, Vec<u32>)] {
        &self.layers
    }

    /// The skeleton's joints.
    pub fn joints(&self) -> &[SkinJoint] {
        &self.joints
    }

    /// The skeleton's bones as capsules for range sensors (indices into
    /// [`PosedSkin::joints`]), as thick as the skin they move.
    pub fn bone_capsules(&self) -> Vec<BoneCapsule> {
        let mut rest_world: Vec<Mat4> = Vec::with_capacity(self.joints.len());
        for (j, joint) in self.joints.iter().enumerate() {
            let parent = match joint.parent {
                Some(p) if p < j => rest_world[p],
                _ => self.above_root,
            };
            rest_world.push(parent * joint.rest_local);
        }
        let heads: Vec<Vec3> = rest_world
            .iter()
            .map(|m| self.to_rover.transform_point3(m.w_axis.truncate()))
            .collect();
        let rest: Vec<Vec3> = self
            .rest
            .iter()
            .map(|p| self.to_rover.transform_point3(*p))
            .collect();
        let main_joint: Vec<usize> = self
            .weights
            .iter()
            .map(|w| {
                let k = w
                    .iter()
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map_or(0, |p| usize::from(p.0));
                self.bind.get(k).map_or(0, |b| b.0)
            })
            .collect();
        let parents: Vec<Option<usize>> = self.joints.iter().map(|j| j.parent).collect();
        bone_capsules(&rest, &main_joint, &heads, &parents)
    }

    /// Poses the skeleton only (no skinning) at the clip's time: [`PosedSkin::joints`].
    pub fn pose_joints(&self, clip_time_s: f64, carried: bool, out: &mut PosedSkin) {
        let n = self.joints.len();
        out.world.clear();
        out.world.extend(self.joints.iter().map(|j| j.rest_local));
        if let Some(clip) = &self.clip {
            for c in &clip.channels {
                if let Some(m) = out.world.get_mut(c.joint) {
                    *m = c.at(clip_time_s as f32);
                }
            }
        }
        if carried && let Some(root) = out.world.first_mut() {
            root.w_axis.x = 0.0;
        }
        for j in 0..n {
            let parent = match self.joints[j].parent {
                Some(p) if p < j => out.world[p],
                _ => self.above_root,
            };
            out.world[j] = parent * out.world[j];
        }
        out.joints.clear();
        out.joints.extend(
            out.world
                .iter()
                .map(|m| Affine3A::from_mat4(self.to_rover * *m)),
        );
    }

    /// Poses the skin at the clip's time `clip_time_s` into `out`; `carried`: the script
    /// moves the actor, so the root's forward travel in the clip is dropped.
    pub fn pose(&self, clip_time_s: f64, carried: bool, out: &mut PosedSkin) {
        self.pose_joints(clip_time_s, carried, out);
        out.skinning.clear();
        out.skinning.extend(
            self.bind
                .iter()
                .map(|&(joint, inverse_bind)| Affine3A::from_mat4(out.world[joint] * inverse_bind)),
        );
        out.positions.resize(self.rest.len(), Vec3::ZERO);
        for ((p, rest), weights) in out.positions.iter_mut().zip(&self.rest).zip(&self.weights) {
            let sum = skin::blend_point(&out.skinning, weights, *rest);
            *p = self.to_rover.transform_point3(sum);
        }
        out.normals.clear();
        out.normals.resize(self.rest.len(), Vec3::ZERO);
        for (_, indices) in &self.layers {
            for t in indices.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| out.positions[i as usize]);
                let normal = (b - a).cross(c - a);
                for &i in t {
                    out.normals[i as usize] += normal;
                }
            }
        }
        for normal in &mut out.normals {
            *normal = normal.normalize_or_zero();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wp(time_s: f64, x: f64, y: f64, yaw_rad: f64) -> Waypoint {
        Waypoint {
            time_s,
            position_m: [x, y],
            yaw_rad,
        }
    }

    #[test]
    fn the_spline_passes_its_waypoints_and_swings_wide_where_it_turns_in_place() {
        use std::f64::consts::FRAC_PI_2;
        // walking_actor.world's first corner: up the left side, a turn in place, along the top.
        let t = Trajectory::new(
            vec![
                wp(0.0, 3.0, -1.5, FRAC_PI_2),
                wp(3.75, 3.0, 1.5, FRAC_PI_2),
                wp(4.5, 3.0, 1.5, 0.0),
                wp(9.5, 7.0, 1.5, 0.0),
            ],
            0.0,
        );
        for w in t.waypoints() {
            let (x, y, _) = t.pose_at(w.time_s);
            assert!((x - w.position_m[0]).abs() < 1e-9 && (y - w.position_m[1]).abs() < 1e-9);
        }
        // Between the two keys at the corner the Hermite curve leaves it: tangents (0, 1.5)
        // and (2, 0); at a third of the way s(1-s)^2 T1 - s^2(1-s) T2 = (-4/27, 6/27) m.
        let (x, y, yaw) = t.pose_at(3.75 + 0.75 / 3.0);
        assert!((x - (3.0 - 4.0 / 27.0)).abs() < 1e-9, "{x}");
        assert!((y - (1.5 + 6.0 / 27.0)).abs() < 1e-9, "{y}");
        assert!(
            (yaw - FRAC_PI_2 * 2.0 / 3.0).abs() < 1e-9,
            "turning right: {yaw}"
        );
        // Full tension: straight lines between the waypoints.
        let taut = Trajectory::new(t.waypoints().to_vec(), 1.0);
        let (x, y, _) = taut.pose_at(3.75 + 0.25);
        assert!((x - 3.0).abs() < 1e-12 && (y - 1.5).abs() < 1e-12);
    }

    #[test]
    fn a_script_loops_waits_and_measures_the_distance_walked() {
        let line = Trajectory::new(vec![wp(0.0, 0.0, 0.0, 0.0), wp(2.0, 2.0, 0.0, 0.0)], 1.0);
        let script = Script::new(vec![line], true, 1.0, true);
        assert_eq!(script.pose_at(0.5), (0.0, 0.0, 0.0), "waiting to start");
        let (x, ..) = script.pose_at(2.0);
        assert!((x - 1.0).abs() < 1e-9, "halfway: {x}");
        assert!((script.distance_m(3.0) - 2.0).abs() < 1e-6);
        assert!(
            (script.distance_m(4.0) - 3.0).abs() < 1e-6,
            "the second pass"
        );
        let once = Script::new(script.trajectories().to_vec(), false, 0.0, true);
        assert_eq!(once.pose_at(10.0).0, 2.0, "stays at the end");
        let never = Script::new(script.trajectories().to_vec(), true, 0.0, false);
        assert_eq!(never.pose_at(10.0).0, 0.0, "not started");
    }

    #[test]
    fn a_clip_finds_the_time_the_root_has_walked_a_distance() {
        let clip = Clip {
            duration_s: 2.0,
            interpolate_x: true,
            channels: Vec::new(),
            cycle_x: 1.0,
            root_x: vec![(0.0, 0.0), (0.5, 0.5), (1.0, 2.0)],
        };
        assert!((clip.time_at_x(0.25) - 0.25).abs() < 1e-12);
        assert!((clip.time_at_x(0.75) - 1.25).abs() < 1e-12);
        assert!((clip.time_at_x(1.25) - 0.25).abs() < 1e-12, "wraps round");
    }
}
