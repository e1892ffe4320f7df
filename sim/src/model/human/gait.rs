//! How a body stands and walks: per-bone rotations of MakeHuman's default rig.
//!
//! Walking is driven by where the feet are, not by swinging the legs: each ankle follows a
//! path in the body's frame (on the ground and moving back at exactly the walking speed while
//! the foot is planted, lifted and carried forward while it swings), and two-link inverse
//! kinematics in the sagittal plane turns that into hip and knee angles. A planted foot so
//! stays put on the ground whatever the speed; the stride is the person's
//! [`crate::model::person::Person::stride_m`]. The pelvis is lowered just enough that the
//! legs reach the furthest footfall with the knees a little bent.

use std::f32::consts::{PI, TAU};

use glam::{Quat, Vec3};

/// What a person is doing, for posing their body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Posture {
    /// Standing still, arms relaxed.
    Standing,
    /// Walking: `phase_rad` through the gait cycle (two steps), `stride_m` travelled per cycle.
    Walking {
        /// Where in the cycle (rad; the left foot touches down at 0).
        phase_rad: f64,
        /// Distance one cycle carries the person (m).
        stride_m: f64,
    },
}

impl Posture {
    /// The posture of a person at gait phase `gait_phase_rad` (0: standing, as
    /// [`crate::model::person::Person::gait_phase_rad`] gives it) with stride `stride_m`.
    pub fn from_gait(gait_phase_rad: f64, stride_m: f64) -> Self {
        if gait_phase_rad == 0.0 {
            Self::Standing
        } else {
            Self::Walking {
                phase_rad: gait_phase_rad,
                stride_m,
            }
        }
    }
}

/// Fraction of the gait cycle a foot is on the ground (both feet are, around each step).
pub const STANCE_FRACTION: f32 = 0.6;
/// How far the pelvis sinks at most while walking, for a 1.75 m person (m).
const MAX_PELVIS_DROP: f32 = 0.03;
/// How high a swinging foot is lifted at most, for a 1.75 m person (m).
const FOOT_LIFT_M: f32 = 0.07;
/// Where the ankles stand, each side of the body's centre line, for a 1.75 m person (m):
/// MakeHuman's rest pose has them 0.18 m out, a wide stance; people stand and walk with their
/// feet closer.
const ANKLE_HALF_SPACING_M: f32 = 0.08;
/// How far the arms are brought in from MakeHuman's A-pose, towards hanging (rad from
/// vertical, the angle they are left at).
const ARM_HANG_RAD: f32 = 0.28;
/// Arm swing per radian of the legs' scissor angle.
const ARM_SWING_GAIN: f32 = 0.5;
/// Elbow bend standing: the forearm's angle forward of the upper arm (rad).
const ELBOW_BEND_RAD: f32 = 0.2;
/// Elbow bend while walking (rad), more as the arm swings forward.
const ELBOW_WALK_BEND_RAD: f32 = 0.35;

/// One leg: the bones that turn and the rest positions of their joints (body frame, m).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Leg {
    pub(crate) hip_bone: usize,
    pub(crate) knee_bone: usize,
    pub(crate) ankle_bone: usize,
    pub(crate) hip: Vec3,
    pub(crate) knee: Vec3,
    pub(crate) ankle: Vec3,
}

/// One arm: the bones that turn and the rest positions of their joints (body frame, m).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Arm {
    pub(crate) shoulder_bone: usize,
    pub(crate) elbow_bone: usize,
    pub(crate) shoulder: Vec3,
    pub(crate) elbow: Vec3,
    pub(crate) wrist: Vec3,
    /// +1 for the left arm (+y), -1 for the right.
    pub(crate) side: f32,
}

/// The rig's limbs, left first.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limbs {
    pub(crate) legs: [Leg; 2],
    pub(crate) arms: [Arm; 2],
    /// Standing height of the body (m), for scaling the foot lift.
    pub(crate) height_m: f32,
}

/// Direction of a vector in the sagittal (x-z) plane: 0 straight down, positive forward.
fn sagittal_angle(v: Vec3) -> f32 {
    v.x.atan2(-v.z)
}

fn xz_len(v: Vec3) -> f32 {
    v.x.hypot(v.z)
}

impl Leg {
    /// The leg brought in towards the centre line (turned about the body's forward axis at
    /// the hip): the turn, and the knee and ankle where it puts them.
    fn brought_in(&self, height_m: f32) -> (Quat, Vec3, Vec3) {
        let side = self.ankle.y.signum();
        let target_y = side * ANKLE_HALF_SPACING_M * height_m / 1.75;
        let drop = self.hip.z - self.ankle.z;
        let turn = (target_y - self.hip.y).atan2(drop) - (self.ankle.y - self.hip.y).atan2(drop);
        let q = Quat::from_rotation_x(turn);
        (
            q,
            self.hip + q * (self.knee - self.hip),
            self.hip + q * (self.ankle - self.hip),
        )
    }
}

impl Limbs {
    /// Sets `rotations` (one per bone, in the body's rest frame, about each bone's head) and
    /// returns how far the whole body moves (m) for `posture`.
    pub(crate) fn pose(&self, posture: Posture, rotations: &mut [Quat]) -> Vec3 {
        rotations.fill(Quat::IDENTITY);
        let legs = self.legs.map(|leg| {
            let (turn, knee, ankle) = leg.brought_in(self.height_m);
            (leg, turn, Leg { knee, ankle, ..leg })
        });
        // Legs brought in reach a little lower: the body rises as much, feet on the ground.
        let lift = self.legs[0].ankle.z - legs[0].2.ankle.z;
        let mut offset = Vec3::new(0.0, 0.0, lift);
        // How far each thigh and shank turn forward (rad); standing, not at all.
        let mut turns = [(0.0f32, 0.0f32); 2];
        let (mut arm_swing, mut elbow) = ([0.0f32; 2], ELBOW_BEND_RAD);
        if let Posture::Walking {
            phase_rad,
            stride_m,
        } = posture
        {
            let stride = stride_m as f32;
            let leg = &legs[0].2;
            let (a, b) = (xz_len(leg.knee - leg.hip), xz_len(leg.ankle - leg.knee));
            let reach = 0.98 * (a + b);
            // Half the ground a planted foot covers, limited so the legs can reach it.
            let half = (0.5 * STANCE_FRACTION * stride).min(0.55 * reach);
            // The pelvis sinks a little (at most MAX_PELVIS_DROP); where the legs still cannot
            // reach a planted ankle (heel strike ahead, push-off behind) the heel rises
            // instead, as a foot rolls over its heel and toes.
            let rest_drop = leg.hip.z + lift - self.legs[0].ankle.z;
            let drop = (rest_drop - (reach * reach - half * half).sqrt())
                .clamp(0.0, MAX_PELVIS_DROP * self.height_m / 1.75);
            offset.z -= drop;
            let foot_lift = FOOT_LIFT_M * self.height_m / 1.75;
            for (side, (rest, _, leg)) in legs.iter().enumerate() {
                let cycle = (phase_rad as f32 / TAU + 0.5 * side as f32).rem_euclid(1.0);
                let (x, z) = if cycle < STANCE_FRACTION {
                    (half - 2.0 * half * cycle / STANCE_FRACTION, 0.0)
                } else {
                    let s = (cycle - STANCE_FRACTION) / (1.0 - STANCE_FRACTION);
                    let smooth = s * s * (3.0 - 2.0 * s);
                    (-half + 2.0 * half * smooth, foot_lift * (PI * s).sin())
                };
                let hip = leg.hip + offset;
                // Planted, the ankle is where it stands at rest: on the ground.
                let mut target = Vec3::new(leg.ankle.x + x, 0.0, rest.ankle.z + z);
                let across = target.x - hip.x;
                let lowest = hip.z - (reach * reach - across * across).max(0.0).sqrt();
                target.z = target.z.max(lowest);
                turns[side] = leg_ik(leg, target - hip);
            }
            let scissor = 0.5 * (turns[0].0 - turns[1].0);
            arm_swing = [-ARM_SWING_GAIN * scissor, ARM_SWING_GAIN * scissor];
            elbow = ELBOW_WALK_BEND_RAD;
        }
        for ((rest, turn, _), (d_thigh, d_shank)) in legs.iter().zip(turns) {
            // Bring the leg in, then swing it in the sagittal plane: the knee and foot turn
            // about the brought-in axes, and the foot stays level.
            rotations[rest.hip_bone] = Quat::from_rotation_y(-d_thigh) * *turn;
            rotations[rest.knee_bone] =
                turn.inverse() * Quat::from_rotation_y(-(d_shank - d_thigh)) * *turn;
            rotations[rest.ankle_bone] = turn.inverse() * Quat::from_rotation_y(d_shank);
        }
        for (arm, swing) in self.arms.iter().zip(arm_swing) {
            let down = arm.elbow - arm.shoulder;
            let from_vertical = (down.y * arm.side).atan2(-down.z);
            let hang = Quat::from_rotation_x(-arm.side * (from_vertical - ARM_HANG_RAD).max(0.0));
            rotations[arm.shoulder_bone] = Quat::from_rotation_y(-swing) * hang;
            // MakeHuman's rest pose bends the forearms ~50 degrees forward: set the bend.
            let bend = elbow + 0.3 * swing.max(0.0);
            let rest_bend = sagittal_angle(arm.wrist - arm.elbow);
            rotations[arm.elbow_bone] = Quat::from_rotation_y(-(bend - rest_bend));
        }
        offset
    }
}

/// Hip and knee: how far the thigh and shank turn forward from rest (rad) so the ankle is at
/// `hip_to_ankle` (x-z plane), the knee bending forward.
fn leg_ik(leg: &Leg, hip_to_ankle: Vec3) -> (f32, f32) {
    let (thigh, shank) = (leg.knee - leg.hip, leg.ankle - leg.knee);
    let (a, b) = (xz_len(thigh), xz_len(shank));
    let d = xz_len(hip_to_ankle).clamp((a - b).abs() + 1e-4, a + b - 1e-4);
    let towards = sagittal_angle(hip_to_ankle);
    let at_hip = ((a * a + d * d - b * b) / (2.0 * a * d))
        .clamp(-1.0, 1.0)
        .acos();
    let at_ankle = ((b * b + d * d - a * a) / (2.0 * b * d))
        .clamp(-1.0, 1.0)
        .acos();
    (
        towards + at_hip - sagittal_angle(thigh),
        towards - at_ankle - sagittal_angle(shank),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limbs() -> Limbs {
        let leg = |y: f32, i: usize| Leg {
            hip_bone: i,
            knee_bone: i + 1,
            ankle_bone: i + 2,
            hip: Vec3::new(0.0, y, 0.9),
            knee: Vec3::new(0.01, y, 0.5),
            ankle: Vec3::new(0.0, y, 0.08),
        };
        let arm = |side: f32, i: usize| Arm {
            shoulder_bone: i,
            elbow_bone: i + 1,
            shoulder: Vec3::new(0.0, 0.18 * side, 1.4),
            elbow: Vec3::new(0.0, 0.38 * side, 1.2),
            wrist: Vec3::new(0.15, 0.45 * side, 1.08),
            side,
        };
        Limbs {
            legs: [leg(0.1, 0), leg(-0.1, 3)],
            arms: [arm(1.0, 6), arm(-1.0, 8)],
            height_m: 1.75,
        }
    }

    /// Where the ankle ends up with the hip and knee turned as `pose` says.
    fn ankle(leg: &Leg, r: &[Quat], offset: Vec3) -> Vec3 {
        let knee = leg.hip + r[leg.hip_bone] * (leg.knee - leg.hip);
        let ankle = knee + r[leg.hip_bone] * r[leg.knee_bone] * (leg.ankle - leg.knee);
        ankle + offset
    }

    #[test]
    fn a_planted_foot_moves_back_at_the_walking_speed_and_stays_down() {
        let limbs = limbs();
        let mut r = vec![Quat::IDENTITY; 10];
        let stride = 1.0;
        let mut last: Option<Vec3> = None;
        // Through the left foot's stance: from touch-down to lift-off.
        let steps = 30;
        for k in 0..=steps {
            let cycle = STANCE_FRACTION * k as f32 / steps as f32;
            let posture = Posture::Walking {
                phase_rad: f64::from(cycle * TAU),
                stride_m: stride,
            };
            let offset = limbs.pose(posture, &mut r);
            let a = ankle(&limbs.legs[0], &r, offset);
            // Down through mid-stance; the heel may rise only at the ends (strike, push-off).
            if (0.35..=0.65).contains(&(cycle / STANCE_FRACTION)) {
                assert!((a.z - 0.08).abs() < 1e-3, "planted ankle at {a}");
            }
            assert!(a.z < 0.08 + 0.06, "the heel rises a little at most: {a}");
            if let Some(l) = last {
                let back = l.x - a.x;
                let expected = stride as f32 * STANCE_FRACTION / steps as f32;
                assert!((back - expected).abs() < 1e-3, "{back} vs {expected}");
            }
            last = Some(a);
            // The feet are opposite: the right one is mid-swing when the left is planted.
            let foot = r[limbs.legs[0].hip_bone] * r[limbs.legs[0].knee_bone] * r[2];
            let level = (foot * Vec3::X - Vec3::X).length() + (foot * Vec3::Z - Vec3::Z).length();
            assert!(level < 1e-3, "the foot stays level ({foot})");
        }
    }

    #[test]
    fn standing_lets_the_arms_hang_and_brings_the_feet_in_level_on_the_ground() {
        let mut limbs = limbs();
        // Legs splayed as MakeHuman's rest pose has them: ankles 0.18 m out.
        for leg in &mut limbs.legs {
            leg.ankle.y = 0.18 * leg.ankle.y.signum();
        }
        let mut r = vec![Quat::IDENTITY; 10];
        let offset = limbs.pose(Posture::Standing, &mut r);
        for leg in &limbs.legs {
            let a = ankle(leg, &r, offset);
            assert!(
                (a.y.abs() - ANKLE_HALF_SPACING_M).abs() < 1e-4,
                "ankle at {a}"
            );
            assert!((a.z - leg.ankle.z).abs() < 1e-4, "ankle height {a}");
            let foot = r[leg.hip_bone] * r[leg.knee_bone] * r[leg.ankle_bone];
            let level = (foot * Vec3::X - Vec3::X).length() + (foot * Vec3::Z - Vec3::Z).length();
            assert!(level < 1e-4, "the foot stays level ({foot})");
        }
        for arm in &limbs.arms {
            let down = r[arm.shoulder_bone] * (arm.elbow - arm.shoulder);
            let from_vertical = (down.y * arm.side).atan2(-down.z);
            assert!(
                (from_vertical - ARM_HANG_RAD).abs() < 1e-4,
                "{from_vertical}"
            );
        }
    }
}
