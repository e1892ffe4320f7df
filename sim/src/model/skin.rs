//! Linear-blend skinning, once for every skinned body rover draws: MakeHuman's people
//! (`human`) and Gazebo's actors (`actor`).

use glam::{Affine3A, Vec3};

/// Where linear-blend skinning puts a vertex: the sum of its bones' transforms of its rest
/// position `rest`, each scaled by the bone's weight in `influences` ((bone, weight) pairs,
/// indices into `bones`). A bone `bones` lacks is left out.
pub(crate) fn blend_point(bones: &[Affine3A], influences: &[(u16, f32)], rest: Vec3) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for &(bone, weight) in influences {
        if let Some(m) = bones.get(usize::from(bone)) {
            sum += weight * m.transform_point3(rest);
        }
    }
    sum
}

/// [`blend_point`] for a direction (a normal): the bones' rotations and scales only, not yet
/// of unit length.
pub(crate) fn blend_vector(bones: &[Affine3A], influences: &[(u16, f32)], rest: Vec3) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for &(bone, weight) in influences {
        if let Some(m) = bones.get(usize::from(bone)) {
            sum += weight * m.transform_vector3(rest);
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vertex_follows_its_bones_by_their_weights() {
        let bones = [
            Affine3A::IDENTITY,
            Affine3A::from_translation(Vec3::new(0.0, 2.0, 0.0)),
            Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ];
        let rest = Vec3::new(1.0, 0.0, 0.0);
        assert_eq!(blend_point(&bones, &[(0, 1.0)], rest), rest);
        let halfway = blend_point(&bones, &[(0, 0.5), (1, 0.5)], rest);
        assert!((halfway - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        // Directions ignore translation; a bone past the list is left out.
        let turned = blend_vector(&bones, &[(1, 0.5), (2, 0.5), (9, 1.0)], rest);
        assert!(
            (turned - Vec3::new(0.5, 0.5, 0.0)).length() < 1e-6,
            "{turned}"
        );
    }
}
