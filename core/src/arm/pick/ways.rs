//! The ways to take hold of an object (round, or a box across its faces) and the IK that
//! checks them: a reachable, collision-free pose and straight moves of the tool.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use rover_sim::{model::IkTarget, planning::PlanningScene};

use super::plan::GRASP_YAWS_DEG;
use super::state::{Gripper, Pick, Target, Way};

/// Joint-space waypoints (the chain's joints each).
type Waypoints = Vec<Vec<f64>>;

/// How far (m) below an upright object's top the tool takes it from above: the pads' lower
/// part round it, the hand clear of its top.
const TOP_GRIP_M: f64 = 0.025;
/// How far above an upright object's middle the tool takes it from the side, as a share of
/// its half height.
const SIDE_GRIP_SHARE: f64 = 0.4;
/// Spacing of a straight move's waypoints (m).
const LINE_STEP_M: f64 = 0.01;
/// The most one joint may change between a straight move's waypoints (rad): more is IK
/// jumping to another branch.
const MAX_LINE_JUMP_RAD: f64 = 0.3;

impl Pick {
    /// The ways to take hold of `target`: a box across its faces, an upright object level
    /// across its axis at `pitches` (below horizontal, in order) and [`GRASP_YAWS_DEG`] round
    /// it, anything else round.
    pub(super) fn ways_taking(&self, target: &Target, g: &Gripper, pitches: &[f64]) -> Vec<Way> {
        match (target.cuboid, target.upright) {
            (Some((r, half)), _) => self.ways_across(
                [(r * Vector3::x(), half[0]), (r * Vector3::y(), half[1])],
                g,
            ),
            (None, Some(radius_m)) => self.ways_upright(
                target.centre,
                (radius_m, target.half_height_m),
                g,
                (pitches, &GRASP_YAWS_DEG),
            ),
            (None, None) => self.ways_round(target.centre, target.bound_m),
        }
    }

    /// The ways to take hold of something round at `point` (base frame): coming in along
    /// [`PickConfig::approach_pitches_deg`] below horizontal, away from the arm's base, the
    /// turn about the way in free; the fingers close to `grip_m`.
    pub(super) fn ways_round(&self, point: Vector3<f64>, grip_m: f64) -> Vec<Way> {
        if self.solver.chain().holds_level() {
            return vec![Way::level(grip_m, Vector3::zeros())];
        }
        let horizontal = Vector3::new(point.x, point.y, 0.0)
            .try_normalize(1e-9)
            .unwrap_or_else(Vector3::x);
        (self.config.approach_pitches_deg.iter())
            .map(|pitch_deg| {
                let pitch = pitch_deg.to_radians();
                Way {
                    label: format!("{pitch_deg:.0} deg down"),
                    along: horizontal * pitch.cos() - Vector3::z() * pitch.sin(),
                    turn: None,
                    grip_m,
                    offset: Vector3::zeros(),
                    free: false,
                }
            })
            .collect()
    }

    /// The ways to take hold of a box from above: the fingers across one pair of its faces
    /// (the narrower first), either way round; only faces the open gripper fits round (with
    /// 5 mm to spare on each side).
    pub(super) fn ways_across(&self, mut faces: [(Vector3<f64>, f64); 2], g: &Gripper) -> Vec<Way> {
        faces.sort_by(|a, b| a.1.total_cmp(&b.1));
        let down = -Vector3::z();
        let open = g.widest_m();
        let mut ways = Vec::new();
        for (k, (axis, half)) in faces.iter().enumerate() {
            let across = (axis - down * axis.dot(&down)).try_normalize(1e-6);
            let Some(across) = across.filter(|_| *half + 0.005 <= open) else {
                continue;
            };
            for sign in [1.0, -1.0] {
                if let Some(turn) = turn_taking(g.across_tool, across * sign, down) {
                    ways.push(Way {
                        label: format!(
                            "from above across its {} faces{}",
                            ["narrow", "wide"][k],
                            if sign < 0.0 { ", turned round" } else { "" }
                        ),
                        along: down,
                        turn: Some(turn),
                        grip_m: *half,
                        offset: Vector3::zeros(),
                        free: false,
                    });
                }
            }
        }
        ways
    }

    /// The ways to take hold of an upright cylinder of `radius_m` and `half_height_m` whose
    /// centre is at `point` (base frame), so that it stays upright: coming in `pitches_deg`
    /// below horizontal (in order), from the arm's side and `yaws_deg` round it, the fingers
    /// level, closing across its axis to `radius_m`. From the side the tool is above its centre ([`SIDE_GRIP_SHARE`]); from above
    /// (60 degrees down or more) near its top, the fingers round its upper part and the hand
    /// clear of it.
    pub(super) fn ways_upright(
        &self,
        point: Vector3<f64>,
        (radius_m, half_height_m): (f64, f64),
        g: &Gripper,
        (pitches_deg, yaws_deg): (&[f64], &[f64]),
    ) -> Vec<Way> {
        if self.solver.chain().holds_level() {
            // Its only way: level, above the middle, at whatever turn the arm reaches it.
            let offset = Vector3::z() * SIDE_GRIP_SHARE * half_height_m;
            return vec![Way::level(radius_m, offset)];
        }
        // Away from the arm's pan axis when it has one (a 5-joint arm holds the hand level
        // only in the plane through it), else from the base's origin.
        let pan = (self.solver.chain().first_axis())
            .filter(|(_, axis)| axis.z.abs() > 0.99)
            .map_or_else(Vector3::zeros, |(origin, _)| origin);
        let radial = Vector3::new(point.x - pan.x, point.y - pan.y, 0.0)
            .try_normalize(1e-9)
            .unwrap_or_else(Vector3::x);
        let mut ways = Vec::new();
        for pitch_deg in pitches_deg {
            for yaw_deg in yaws_deg {
                let (pitch, yaw) = (pitch_deg.to_radians(), yaw_deg.to_radians());
                let horizontal = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw) * radial;
                let along = horizontal * pitch.cos() - Vector3::z() * pitch.sin();
                let level = Vector3::z().cross(&horizontal);
                let Some(turn) = turn_taking(g.across_tool, level, along) else {
                    continue;
                };
                // Above its middle, so it hangs from the fingers rather than turning about
                // them; from above (60 degrees down or more), near its top.
                let offset = Vector3::z()
                    * if *pitch_deg >= 60.0 {
                        (half_height_m - TOP_GRIP_M).max(0.0)
                    } else {
                        SIDE_GRIP_SHARE * half_height_m
                    };
                ways.push(Way {
                    label: format!(
                        "{:.0} deg down, {:+.0} deg round",
                        pitch_deg + 0.0,
                        yaw_deg + 0.0
                    ),
                    along,
                    turn: Some(turn),
                    grip_m: radius_m,
                    offset,
                    free: false,
                });
            }
        }
        ways
    }

    /// Joint positions putting the tool at `point` (base frame) the first of `ways` IK
    /// reaches there without a collision (with `back_m`, the straight way back out along it
    /// free too, returned), and that way (a free one with the turn the arm reached it with);
    /// else why not each way.
    pub(super) fn reachable(
        &mut self,
        scene: &mut PlanningScene,
        point: Vector3<f64>,
        seed: &[f64],
        what: &str,
        back_m: Option<f64>,
        ways: &[Way],
    ) -> Result<(Vec<f64>, Waypoints, Way), String> {
        let mut why: Vec<String> = Vec::new();
        for way in ways {
            let label = &way.label;
            let point = point + way.offset;
            let solution = self
                .solver
                .solve(&way.target(point), seed)
                .map_err(|e| e.to_string())?;
            if !ik_close(solution.position_error_m, solution.orientation_error_rad) {
                why.push(format!(
                    "{label}: out of reach by {:.3} m",
                    solution.position_error_m
                ));
                continue;
            }
            if let Some(hit) = scene.collision(&solution.q) {
                why.push(format!("{label}: {hit}"));
                continue;
            }
            let way = match way.free {
                true => self.as_reached(way, &solution.q)?,
                false => way.clone(),
            };
            // The straight way in, `back_m` long, must be there too.
            let back = match back_m {
                Some(back_m) => {
                    let to = point - way.along * back_m;
                    match self.line_at_least(scene, &solution.q, (point, to), Some(&way), 1.0) {
                        Ok(line) => line,
                        Err(e) => {
                            why.push(format!("{label}: {e}"));
                            continue;
                        }
                    }
                }
                None => Vec::new(),
            };
            return Ok((solution.q, back, way));
        }
        Err(format!("{what}, coming in {}", why.join("; ")))
    }

    /// A free way ([`Way::free`]) as the arm reached it at `q`: the tool's z and turn there.
    fn as_reached(&self, way: &Way, q: &[f64]) -> Result<Way, String> {
        let tool = self
            .solver
            .chain()
            .base_from_tip(q)
            .map_err(|e| e.to_string())?;
        Ok(Way {
            along: tool.rotation * Vector3::z(),
            turn: Some(tool.rotation),
            ..way.clone()
        })
    }

    /// A straight line of the tool from `from` (at `from_q`) to `to` (base frame), held to
    /// `way`'s direction when given: joint waypoints every centimetre, each by IK from the
    /// last, each free. It may stop short where IK or the scene ends it once `share` of the way
    /// is done (a lift or a retreat at the edge of the arm's reach).
    pub(super) fn line_at_least(
        &mut self,
        scene: &mut PlanningScene,
        from_q: &[f64],
        (from, to): (Vector3<f64>, Vector3<f64>),
        way: Option<&Way>,
        share: f64,
    ) -> Result<Vec<Vec<f64>>, String> {
        let n = ((to - from).norm() / LINE_STEP_M).ceil().max(1.0) as usize;
        let mut waypoints = vec![from_q.to_vec()];
        for k in 1..=n {
            let p = from + (to - from) * (k as f64 / n as f64);
            let last = waypoints.last().cloned().unwrap_or_default();
            let target = way.map_or(IkTarget::point(p), |w| w.target(p));
            let s = self
                .solver
                .solve(&target, &last)
                .map_err(|e| e.to_string())?;
            let jump =
                s.q.iter()
                    .zip(&last)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
            let done = (k - 1) as f64 / n as f64;
            let blocked = !ik_close(s.position_error_m, s.orientation_error_rad)
                || jump > MAX_LINE_JUMP_RAD
                || scene.collision(&s.q).is_some();
            if blocked && done >= share && k > 1 {
                break;
            }
            if !ik_close(s.position_error_m, s.orientation_error_rad) || jump > MAX_LINE_JUMP_RAD {
                return Err(format!(
                    "no straight move from ({:.3}, {:.3}, {:.3}) to ({:.3}, {:.3}, {:.3}) m: IK {:.3} m off, a {jump:.2} rad jump",
                    from.x, from.y, from.z, to.x, to.y, to.z, s.position_error_m
                ));
            }
            if let Some(hit) = scene.collision(&s.q) {
                return Err(format!("the straight move collides: {hit}"));
            }
            waypoints.push(s.q);
        }
        Ok(waypoints)
    }
}

/// Whether an IK solution is close enough to use: 3 mm and about 2 degrees.
pub(super) fn ik_close(position_m: f64, orientation_rad: f64) -> bool {
    position_m <= 0.003 && orientation_rad <= 0.035
}

/// The tool's orientation (base frame) whose z is `along` and whose finger direction
/// (`across_tool`, in the tool's frame) is `across`; `None` when either pair is parallel.
fn turn_taking(
    across_tool: Vector3<f64>,
    across: Vector3<f64>,
    along: Vector3<f64>,
) -> Option<UnitQuaternion<f64>> {
    let frame = |x: Vector3<f64>, z: Vector3<f64>| -> Option<Matrix3<f64>> {
        let z = z.try_normalize(1e-9)?;
        let x = (x - z * x.dot(&z)).try_normalize(1e-6)?;
        Some(Matrix3::from_columns(&[x, z.cross(&x), z]))
    };
    let in_tool = frame(across_tool, Vector3::z())?;
    let in_base = frame(across, along)?;
    let rotation = Rotation3::from_matrix_unchecked(in_base * in_tool.transpose());
    Some(UnitQuaternion::from_rotation_matrix(&rotation))
}
