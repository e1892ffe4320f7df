//! An object's shape as the depth image shows it: a detection's pixels back in 3D, split into
//! what it stands on and the object above that, tell a tall upright object (a can, a bottle, a
//! cup: [`upright_extent`]) from a round one, and give its axis, radius and height. A sphere's
//! centre and radius stay [`crate::object_estimate`]'s.

use nalgebra::{Point3, Vector3};
use rover_perception::BoundingBox;

use super::depth::{DepthView, central_depth, sample_step};

/// An object is upright and tall when it stands at least this many times its width high (as
/// read: the width is read narrow, by 17 % on a can and up to 30 % on an orange the arm half
/// covers; osrf's can reads 2.1, a ball at most 1.45).
const TALL_RATIO: f64 = 1.6;
/// Points this far (m) above the support are the object's.
const ABOVE_SUPPORT_M: f64 = 0.012;
/// Most points sampled in a box.
const MAX_POINTS: usize = 512;
/// Beyond the box's front surface, points further than this many object widths (plus
/// [`DEPTH_SLACK_M`]) are background (the floor past the table's edge, a wall).
const DEPTH_WINDOW_WIDTHS: f64 = 1.2;
/// The object's width must be at least this share of the box's: else the points are not what
/// the box shows.
const MIN_BOX_SHARE: f64 = 0.6;
/// See [`DEPTH_WINDOW_WIDTHS`] (m).
const DEPTH_SLACK_M: f64 = 0.02;

/// An upright object (its axis vertical) in the arm's base frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Upright {
    /// The middle of its axis (m).
    pub centre: Vector3<f64>,
    /// Its radius across the view (m).
    pub radius_m: f64,
    /// Half its height above what it stands on (m).
    pub half_height_m: f64,
}

/// The upright object box `b` shows, when it is one: at least [`TALL_RATIO`] times as high as
/// it is wide. From the box's pixels in the depth image (the robot's own left out, depth within
/// `max_range_m`), in the arm's base frame (z up):
/// - the support is the lowest of them (3rd percentile of height), the top the highest (97th);
/// - the object is what stands more than [`ABOVE_SUPPORT_M`] above the support: its width
///   across the line of sight (5th to 95th percentile) is the diameter;
/// - the axis is one radius behind the front surface the camera sees in the middle of it.
///
/// `None` for a round or flat object, or a box with too few depth pixels.
pub fn upright_extent(
    b: &BoundingBox,
    view: &DepthView<'_>,
    [fx, fy, cx, cy]: [f64; 4],
    max_range_m: f64,
) -> Option<Upright> {
    let (w, h) = (i64::from(view.width), i64::from(view.height));
    let (x0, x1) = (b.xmin.clamp(0, w - 1), b.xmax.clamp(0, w - 1));
    let (y0, y1) = (b.ymin.clamp(0, h - 1), b.ymax.clamp(0, h - 1));
    let step = sample_step(x1 - x0 + 1, y1 - y0 + 1);
    // The nearest depth in the box's middle column: the object's front.
    let mut points = [(0.0f64, Vector3::zeros()); MAX_POINTS];
    let mut n = 0;
    for y in (y0..=y1).step_by(step) {
        for x in (x0..=x1).step_by(step) {
            let d = f64::from(view.depth_at(x, y));
            if view.is_robot(x, y) || !(d.is_finite() && d > 0.0 && d <= max_range_m) {
                continue;
            }
            if n < MAX_POINTS {
                let optical = Point3::new((x as f64 - cx) / fx * d, (y as f64 - cy) / fy * d, d);
                points[n] = (d, (view.base_from_optical * optical).coords);
                n += 1;
            }
        }
    }
    if n < 16 {
        return None;
    }
    let points = &mut points[..n];
    // What is far in front of the object (an occluder) or far behind it (the floor past the
    // table's edge) is neither it nor its support: depths round the box's middle, the
    // object's, are kept.
    let middle_m = central_depth(b, view, max_range_m)?;
    let width_m = (x1 - x0) as f64 / fx * middle_m;
    let reach_m = DEPTH_WINDOW_WIDTHS * width_m + DEPTH_SLACK_M;
    points.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let first = points.partition_point(|p| p.0 < middle_m - reach_m);
    let kept = points.partition_point(|p| p.0 <= middle_m + reach_m);
    let points = &mut points[first..kept];
    let kept = points.len();
    if kept < 16 {
        return None;
    }
    let mut heights = [0.0f64; MAX_POINTS];
    for (k, p) in points.iter().enumerate() {
        heights[k] = p.1.z;
    }
    let heights = &mut heights[..kept];
    heights.sort_unstable_by(f64::total_cmp);
    let support_z = percentile(heights, 0.03);
    let top_z = percentile(heights, 0.97);
    // Across and along the line of sight, horizontally, from the camera.
    let camera = view.base_from_optical.translation.vector;
    let centre_px = Point3::new(
        ((b.xmin + b.xmax) as f64 / 2.0 - cx) / fx,
        ((b.ymin + b.ymax) as f64 / 2.0 - cy) / fy,
        1.0,
    );
    let ray = (view.base_from_optical * centre_px).coords - camera;
    let ahead = Vector3::new(ray.x, ray.y, 0.0).try_normalize(1e-9)?;
    let across = Vector3::z().cross(&ahead);
    let mut side = [0.0f64; MAX_POINTS];
    let mut m = 0;
    for (_, p) in points
        .iter()
        .filter(|(_, p)| p.z > support_z + ABOVE_SUPPORT_M)
    {
        side[m] = (p - camera).dot(&across);
        m += 1;
    }
    if m < 8 {
        return None;
    }
    let side = &mut side[..m];
    side.sort_unstable_by(f64::total_cmp);
    let (left, right) = (percentile(side, 0.05), percentile(side, 0.95));
    // Trimmed to the 5th to 95th percentile against neighbours' pixels in the box, this reads
    // a can about 17 % narrow (its edge pixels are also lost to the stride): the axis lands a
    // few millimetres short, where the fingers centre it as they close.
    let radius_m = (right - left) / 2.0 / 0.975;
    let height_m = top_z - support_z;
    // Not tall, or not what fills the box (a rim or an edge in front of a round object).
    if height_m < TALL_RATIO * 2.0 * radius_m || 2.0 * radius_m < MIN_BOX_SHARE * width_m {
        return None;
    }
    // The front surface, in the middle half of the object's width.
    let mid = (left + right) / 2.0;
    let mut range = [0.0f64; MAX_POINTS];
    let mut k = 0;
    for (_, p) in points
        .iter()
        .filter(|(_, p)| p.z > support_z + ABOVE_SUPPORT_M)
    {
        let r = p - camera;
        if (r.dot(&across) - mid).abs() <= radius_m / 2.0 {
            range[k] = r.dot(&ahead);
            k += 1;
        }
    }
    if k == 0 {
        return None;
    }
    let range = &mut range[..k];
    range.sort_unstable_by(f64::total_cmp);
    let front = percentile(range, 0.2);
    let axis = camera + ahead * (front + radius_m) + across * mid;
    Some(Upright {
        centre: Vector3::new(axis.x, axis.y, (support_z + top_z) / 2.0),
        radius_m,
        half_height_m: height_m / 2.0,
    })
}

/// The `share` percentile of sorted `values` (not empty).
fn percentile(values: &[f64], share: f64) -> f64 {
    let i = ((values.len() - 1) as f64 * share).round() as usize;
    values[i.min(values.len() - 1)]
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion};

    use super::*;

    /// What stands on the table (the plane z = 0 of the base frame).
    enum Thing {
        /// An upright cylinder: axis x, y, radius, height.
        Cylinder([f64; 4]),
        /// A sphere resting on the table: x, y, radius.
        Sphere([f64; 3]),
    }

    /// The nearest hit along `o + t d` (t > 0) on `thing` and on the table, and whether it is
    /// the thing's.
    fn cast(o: Vector3<f64>, d: Vector3<f64>, thing: &Thing) -> Option<(f64, bool)> {
        let table = (d.z < 0.0).then(|| -o.z / d.z);
        let hit = match *thing {
            Thing::Cylinder([x, y, r, h]) => {
                let (px, py) = (o.x - x, o.y - y);
                let a = d.x * d.x + d.y * d.y;
                let b = 2.0 * (px * d.x + py * d.y);
                let c = px * px + py * py - r * r;
                let disc = b * b - 4.0 * a * c;
                let side = (disc >= 0.0)
                    .then(|| (-b - disc.sqrt()) / (2.0 * a))
                    .filter(|t| (0.0..=h).contains(&(o.z + t * d.z)));
                let top = (d.z < 0.0).then(|| (h - o.z) / d.z).filter(|t| {
                    let p = o + d * *t;
                    (p.x - x).hypot(p.y - y) <= r
                });
                [side, top].into_iter().flatten().reduce(f64::min)
            }
            Thing::Sphere([x, y, r]) => {
                let p = o - Vector3::new(x, y, r);
                let (a, b, c) = (d.dot(&d), 2.0 * p.dot(&d), p.dot(&p) - r * r);
                let disc = b * b - 4.0 * a * c;
                (disc >= 0.0).then(|| (-b - disc.sqrt()) / (2.0 * a))
            }
        };
        match (hit.filter(|t| *t > 0.0), table.filter(|t| *t > 0.0)) {
            (Some(t), Some(u)) if t <= u => Some((t, true)),
            (Some(t), None) => Some((t, true)),
            (_, Some(u)) => Some((u, false)),
            (None, None) => None,
        }
    }

    /// A 160x120 depth image (fx = fy = 150) from 0.5 m up, pitched 0.6 rad down along the
    /// base's x, of `thing` on the table; the box round the thing's pixels.
    fn picture(thing: &Thing) -> (Vec<f32>, Isometry3<f64>, BoundingBox) {
        let (w, h, f) = (160i64, 120i64, 150.0);
        let (s, c) = 0.6f64.sin_cos();
        let columns = Matrix3::from_columns(&[
            Vector3::new(0.0, -1.0, 0.0),
            Vector3::new(-s, 0.0, -c),
            Vector3::new(c, 0.0, -s),
        ]);
        let pose = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 0.5),
            UnitQuaternion::from_matrix(&columns),
        );
        let mut depth = vec![f32::NAN; (w * h) as usize];
        let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
        for y in 0..h {
            for x in 0..w {
                let ray =
                    pose.rotation * Vector3::new((x as f64 - 80.0) / f, (y as f64 - 60.0) / f, 1.0);
                if let Some((t, mine)) = cast(pose.translation.vector, ray, thing) {
                    depth[(y * w + x) as usize] = t as f32;
                    if mine {
                        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
                    }
                }
            }
        }
        let b = BoundingBox {
            class: "bottle".into(),
            probability: 0.5,
            xmin: x0 - 1,
            ymin: y0 - 1,
            xmax: x1 + 1,
            ymax: y1 + 1,
            id: 39,
        };
        (depth, pose, b)
    }

    fn extent(thing: &Thing) -> Option<Upright> {
        let (depth, pose, b) = picture(thing);
        let view = DepthView {
            depth_m: &depth,
            width: 160,
            height: 120,
            base_from_optical: pose,
            robot_px: &[],
        };
        upright_extent(&b, &view, [150.0, 150.0, 80.0, 60.0], 4.0)
    }

    /// osrf's Coke can (6.6 cm across, 12.4 cm tall) 0.45 m ahead and a little to the left:
    /// upright, its axis within 1 cm and its half height within 5 mm; its radius is read 5.6 mm
    /// narrow (27.4 mm), within 7 mm.
    #[test]
    fn a_can_on_the_table_reads_as_upright_with_its_size() {
        let can = Thing::Cylinder([0.45, 0.04, 0.033, 0.124]);
        let Some(u) = extent(&can) else {
            panic!("the can is not read as upright");
        };
        let axis = Vector3::new(0.45, 0.04, 0.062);
        assert!((u.centre - axis).norm() < 0.01, "{u:?}");
        assert!((u.radius_m - 0.033).abs() < 0.007, "{u:?}");
        assert!((u.half_height_m - 0.062).abs() < 0.005, "{u:?}");
    }

    /// A tennis ball and a flat puck are not upright objects.
    #[test]
    fn a_ball_or_a_puck_is_not_upright() {
        assert_eq!(extent(&Thing::Sphere([0.45, -0.03, 0.0335])), None);
        assert_eq!(extent(&Thing::Cylinder([0.45, 0.0, 0.05, 0.03])), None);
    }
}
