//! A moving mesh's convex hull whose wide faces rest on all their extent.
//!
//! Why: contacts between convex shapes are built from each shape's face toward the other
//! (parry's "polygonal feature", at most four vertices). parry 0.31's `ConvexPolyhedron` gives
//! the first four vertices of a face in its loop (its own TODO: "select four vertices that
//! maximize the area"). A round foot is a face of 16-64 vertices, so a cup or a can stood on
//! four neighbouring vertices, a sliver at one side of its foot: it rocked with growing swings
//! and fell over, untouched (osrf's plastic cup on a table, in 3 s). [`WideHull`] is the same
//! hull, every query passed through, except that its faces are given as the four vertices
//! that span them: one far from the face's middle, the one farthest from it, and the farthest
//! from that line on either side, in the face's order.

use rapier3d::parry::bounding_volume::{Aabb, BoundingSphere};
use rapier3d::parry::mass_properties::MassProperties;
use rapier3d::parry::math::{Pose, Real, Vector};
use rapier3d::parry::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use rapier3d::parry::shape::{
    ConvexPolyhedron, FeatureId, PackedFeatureId, PolygonalFeature, PolygonalFeatureMap, Shape,
    ShapeType, SubShapeId, SupportMap, TypedShape,
};

/// A convex hull that gives each face's contact by the four vertices spanning it.
#[derive(Debug, Clone)]
pub(crate) struct WideHull(pub(crate) ConvexPolyhedron);

impl WideHull {
    /// The convex hull of `points`; `None` when they are flat or a single point.
    pub(crate) fn from_points(points: &[Vector]) -> Option<Self> {
        ConvexPolyhedron::from_convex_hull(points).map(Self)
    }
}

/// Of a face's `loop_points` (its vertices in order round it; `normal`, the face's), the
/// positions in the loop of at most four that span it: all of them up to four; else one far
/// from the middle, the one farthest from that, and the farthest from the line between them on
/// either side, in loop order.
pub(crate) fn spanning_four(loop_points: &[Vector], normal: Vector) -> ([usize; 4], usize) {
    let n = loop_points.len();
    if n <= 4 {
        return ([0, 1.min(n), 2.min(n), 3.min(n)], n);
    }
    let middle = loop_points.iter().copied().sum::<Vector>() / n as Real;
    let farthest_from = |p: Vector| {
        (0..n)
            .max_by(|&i, &j| {
                let (di, dj) = (
                    loop_points[i].distance_squared(p),
                    loop_points[j].distance_squared(p),
                );
                di.total_cmp(&dj)
            })
            .unwrap_or(0)
    };
    let a = farthest_from(middle);
    let c = farthest_from(loop_points[a]);
    let ac = loop_points[c] - loop_points[a];
    // Signed distance from the line a-c, in the face's plane.
    let side = |i: usize| ac.cross(loop_points[i] - loop_points[a]).dot(normal);
    let b = (0..n)
        .max_by(|&i, &j| side(i).total_cmp(&side(j)))
        .unwrap_or(a);
    let d = (0..n)
        .min_by(|&i, &j| side(i).total_cmp(&side(j)))
        .unwrap_or(c);
    let mut picked = [a, b, c, d];
    picked.sort_unstable();
    let mut unique = [0; 4];
    let mut count = 0;
    for i in picked {
        if count == 0 || unique[count - 1] != i {
            unique[count] = i;
            count += 1;
        }
    }
    (unique, count)
}

impl PolygonalFeatureMap for WideHull {
    fn local_support_feature(&self, dir: Vector, out: &mut PolygonalFeature) {
        let hull = &self.0;
        let faces = hull.faces();
        let Some((face_id, face)) = faces
            .iter()
            .enumerate()
            .max_by(|(_, f1), (_, f2)| f1.normal.dot(dir).total_cmp(&f2.normal.dot(dir)))
        else {
            return;
        };
        let first = face.first_vertex_or_edge as usize;
        let len = face.num_vertices_or_edges as usize;
        let vertex_ids = &hull.vertices_adj_to_face()[first..first + len];
        let edge_ids = &hull.edges_adj_to_face()[first..first + len];
        let points = hull.points();
        let mut loop_points = [Vector::ZERO; 64];
        let (picked, count) = if len <= loop_points.len() {
            for (slot, &v) in loop_points.iter_mut().zip(vertex_ids) {
                *slot = points[v as usize];
            }
            spanning_four(&loop_points[..len], face.normal)
        } else {
            // A face of more vertices than that: evenly round its loop.
            let step = |k: usize| k * len / 4;
            ([step(0), step(1), step(2), step(3)], 4)
        };
        for (k, &i) in picked[..count].iter().enumerate() {
            out.vertices[k] = points[vertex_ids[i] as usize];
            out.vids[k] = PackedFeatureId::vertex(vertex_ids[i]);
            // The hull's edge leaving this vertex stands for the side to the next one picked.
            out.eids[k] = PackedFeatureId::edge(edge_ids[i]);
        }
        out.fid = PackedFeatureId::face(face_id as u32);
        out.num_vertices = count;
    }

    fn is_convex_polyhedron(&self) -> bool {
        true
    }
}

impl SupportMap for WideHull {
    fn local_support_point(&self, dir: Vector) -> Vector {
        self.0.local_support_point(dir)
    }
}

impl RayCast for WideHull {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_time_of_impact: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        self.0
            .cast_local_ray_and_get_normal(ray, max_time_of_impact, solid)
    }
}

impl PointQuery for WideHull {
    fn project_local_point(&self, pt: Vector, solid: bool) -> PointProjection {
        self.0.project_local_point(pt, solid)
    }

    fn project_local_point_and_get_feature(&self, pt: Vector) -> (PointProjection, FeatureId) {
        self.0.project_local_point_and_get_feature(pt)
    }
}

impl Shape for WideHull {
    fn compute_local_aabb(&self) -> Aabb {
        self.0.compute_local_aabb()
    }

    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.0.compute_local_bounding_sphere()
    }

    fn compute_aabb(&self, position: &Pose) -> Aabb {
        self.0.compute_aabb(position)
    }

    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }

    fn scale_dyn(&self, scale: Vector, _num_subdivisions: u32) -> Option<Box<dyn Shape>> {
        Some(Box::new(Self(self.0.clone().scaled(scale)?)))
    }

    fn mass_properties(&self, density: Real) -> MassProperties {
        self.0.mass_properties(density)
    }

    fn shape_type(&self) -> ShapeType {
        ShapeType::Custom
    }

    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::Custom(self)
    }

    fn ccd_thickness(&self) -> Real {
        self.0.ccd_thickness()
    }

    fn ccd_angular_thickness(&self) -> Real {
        self.0.ccd_angular_thickness()
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn as_support_map(&self) -> Option<&dyn SupportMap> {
        Some(self as &dyn SupportMap)
    }

    fn as_polygonal_feature_map(&self) -> Option<(&dyn PolygonalFeatureMap, Real)> {
        Some((self as &dyn PolygonalFeatureMap, 0.0))
    }

    fn feature_normal_at_point(
        &self,
        subshape: SubShapeId,
        feature: FeatureId,
        point: Vector,
    ) -> Option<Vector> {
        self.0.feature_normal_at_point(subshape, feature, point)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(n: usize, radius: Real) -> Vec<Vector> {
        (0..n)
            .map(|k| {
                let a = k as Real / n as Real * std::f32::consts::TAU;
                Vector::new(radius * a.cos(), radius * a.sin(), 0.0)
            })
            .collect()
    }

    #[test]
    fn a_round_face_is_spanned_by_four_vertices_round_it() {
        let foot = ring(32, 0.0275);
        let (picked, count) = spanning_four(&foot, Vector::Z);
        assert_eq!(count, 4);
        // A quadrilateral across the circle: its area is near the inscribed square's, 2 r².
        let p: Vec<Vector> = picked.iter().map(|&i| foot[i]).collect();
        let area = 0.5 * ((p[2] - p[0]).cross(p[3] - p[1])).length();
        let square = 2.0 * 0.0275 * 0.0275;
        assert!(area > 0.95 * square, "area {area}, square {square}");
        assert!(
            picked.windows(2).all(|w| w[0] < w[1]),
            "in loop order: {picked:?}"
        );
    }

    #[test]
    fn a_small_face_keeps_its_vertices() {
        let quad = ring(4, 1.0);
        assert_eq!(spanning_four(&quad, Vector::Z), ([0, 1, 2, 3], 4));
        let triangle = ring(3, 1.0);
        assert_eq!(spanning_four(&triangle, Vector::Z).1, 3);
    }

    #[test]
    fn a_cylinders_foot_gives_a_contact_face_across_it() -> Result<(), String> {
        let mut points = ring(32, 0.03);
        points.extend(ring(32, 0.03).into_iter().map(|p| p + Vector::Z * 0.1));
        let hull = WideHull::from_points(&points).ok_or("the hull of a cylinder is flat")?;
        let mut feature = PolygonalFeature::default();
        hull.local_support_feature(-Vector::Z, &mut feature);
        assert_eq!(feature.num_vertices, 4);
        let off_axis = |f: &PolygonalFeature| {
            let middle = f.vertices.iter().copied().sum::<Vector>() / 4.0;
            Vector::new(middle.x, middle.y, 0.0).length()
        };
        assert!(off_axis(&feature) < 0.005, "{feature:?}");
        // parry's own pick, four neighbours round the loop, sits almost a radius off the
        // axis: what this shape is for (when it no longer does, it can go).
        let mut parrys = PolygonalFeature::default();
        hull.0.local_support_feature(-Vector::Z, &mut parrys);
        assert!(off_axis(&parrys) > 0.02, "{parrys:?}");
        Ok(())
    }
}
