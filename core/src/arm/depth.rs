//! What a depth image says about a detection: the object's centre and size
//! ([`object_estimate`]), and which of its pixels are the robot's own (a self filter, as
//! MoveIt's robot_self_filter and mesh filter keep the robot out of what it senses): how much
//! of a box the robot covers ([`robot_share`]) and whether an object no longer detected is
//! hidden behind the robot's own links ([`hidden_by_robot`]) rather than gone.

use nalgebra::{Isometry3, Point3, Vector3};
use rover_perception::BoundingBox;

/// A box the robot covers this share of or more is partly hidden: its estimate is not trusted
/// (its visible part's centre is not the object's).
pub(crate) const PARTLY_HIDDEN_SHARE: f64 = 0.05;
/// At most this many pixels are sampled in a region (a box, a disc).
const MAX_SAMPLES: f64 = 400.0;
/// An object is hidden by the robot when the robot covers at least this share of where it
/// was seen last ...
const HIDDEN_SHARE: f64 = 0.2;
/// ... and the robot and the object's own surface together explain at least this share of it
/// (the rest shows what is behind: the object is gone).
const EXPLAINED_SHARE: f64 = 0.75;

/// One camera image as the arm needs it: its depth (the optical frame's z per pixel,
/// row-major, NaN where nothing was hit), which pixels show the robot itself, and where the
/// camera's optical frame was in the arm's base frame when it was taken.
#[derive(Debug, Clone, Copy)]
pub struct DepthView<'a> {
    /// Depth per pixel (m).
    pub depth_m: &'a [f32],
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// The optical frame (z forward, x right, y down) in the arm's base frame.
    pub base_from_optical: Isometry3<f64>,
    /// Per pixel, whether it shows the robot's own links (the renderer's id image, as MoveIt's
    /// mesh filter renders the robot from its joint states); empty: not known (nothing is
    /// filtered).
    pub robot_px: &'a [bool],
}

impl DepthView<'_> {
    /// Whether pixel `(x, y)` (inside the image) shows the robot.
    pub(crate) fn is_robot(&self, x: i64, y: i64) -> bool {
        let i = (y * i64::from(self.width) + x) as usize;
        self.robot_px.get(i).copied().unwrap_or(false)
    }

    /// Pixel `(x, y)`'s depth (m), NaN where none or outside the image.
    pub(crate) fn depth_at(&self, x: i64, y: i64) -> f32 {
        let i = (y * i64::from(self.width) + x) as usize;
        self.depth_m.get(i).copied().unwrap_or(f32::NAN)
    }
}

/// A box's object point in the arm's base frame: the object's centre, on the ray through the
/// box's centre pixel. The median depth of the box's central part (half its width and height
/// around the centre) is the surface the camera sees there; the centre lies one radius further
/// along the ray. The radius is the one whose silhouette fills the box: a sphere of radius `r`
/// whose centre is `d` away subtends `asin(r / d)`, and the box's larger side gives that angle
/// (the smaller may be cut by the image's edge or an occluder). Pixels showing the robot itself
/// are left out. `None` when the central part holds no depth within `max_range_m`.
pub fn object_point(
    b: &BoundingBox,
    view: &DepthView<'_>,
    intrinsics: [f64; 4],
    max_range_m: f64,
) -> Option<Vector3<f64>> {
    object_estimate(b, view, intrinsics, max_range_m).map(|(centre, _)| centre)
}

/// [`object_point`] with the radius it used (m).
pub fn object_estimate(
    b: &BoundingBox,
    view: &DepthView<'_>,
    [fx, fy, cx, cy]: [f64; 4],
    max_range_m: f64,
) -> Option<(Vector3<f64>, f64)> {
    let z = central_depth(b, view, max_range_m)?;
    let (xmin, xmax, ymin, ymax) = (b.xmin, b.xmax, b.ymin, b.ymax);
    let u = (b.xmin + b.xmax) as f64 / 2.0;
    let v = (b.ymin + b.ymax) as f64 / 2.0;
    let surface = Vector3::new((u - cx) / fx * z, (v - cy) / fy * z, z);
    let radius = radius_seen(
        (xmax - xmin) as f64 / fx,
        (ymax - ymin) as f64 / fy,
        surface.norm(),
    );
    let centre = surface + surface.normalize() * radius;
    Some((
        (view.base_from_optical * Point3::from(centre)).coords,
        radius,
    ))
}

/// The median depth (m) of box `b`'s central part (half its width and height round its
/// centre): the surface the camera sees there. The robot's own pixels are left out, and depths
/// beyond `max_range_m`; `None` when none is left.
pub(crate) fn central_depth(
    b: &BoundingBox,
    view: &DepthView<'_>,
    max_range_m: f64,
) -> Option<f64> {
    let (w, h) = (i64::from(view.width), i64::from(view.height));
    let (qx, qy) = ((b.xmax - b.xmin) / 4, (b.ymax - b.ymin) / 4);
    let (x0, x1) = ((b.xmin + qx).clamp(0, w - 1), (b.xmax - qx).clamp(0, w - 1));
    let (y0, y1) = ((b.ymin + qy).clamp(0, h - 1), (b.ymax - qy).clamp(0, h - 1));
    // A box of a few pixels: at most 400 samples, so the median costs nothing.
    let step = sample_step(x1 - x0 + 1, y1 - y0 + 1);
    let mut samples = [0.0f32; 512];
    let mut n = 0;
    for y in (y0..=y1).step_by(step) {
        for x in (x0..=x1).step_by(step) {
            // The robot's own pixels never enter the estimate (a self filter).
            if view.is_robot(x, y) {
                continue;
            }
            let d = view.depth_at(x, y);
            if d.is_finite() && d > 0.0 && f64::from(d) <= max_range_m && n < samples.len() {
                samples[n] = d;
                n += 1;
            }
        }
    }
    if n == 0 {
        return None;
    }
    let samples = &mut samples[..n];
    samples.sort_unstable_by(f32::total_cmp);
    Some(f64::from(samples[n / 2]))
}

/// The radius (m) of a sphere whose silhouette spans `width` by `height` (the box's sides over
/// the focal length: tangents of the full angle, near the image centre) and whose nearest
/// point is `surface_m` away: with half-angle `a`, `sin a = r / (surface_m + r)`, so
/// `r = surface_m sin a / (1 - sin a)`.
fn radius_seen(width: f64, height: f64, surface_m: f64) -> f64 {
    let half_angle = (width.max(height) / 2.0).atan();
    let s = half_angle.sin().min(0.9);
    surface_m * s / (1.0 - s)
}

/// The share of box `b`'s pixels (inside the image) that show the robot itself: 0 when the
/// view does not know the robot's pixels.
pub fn robot_share(b: &BoundingBox, view: &DepthView<'_>) -> f64 {
    if view.robot_px.is_empty() {
        return 0.0;
    }
    let (w, h) = (i64::from(view.width), i64::from(view.height));
    let (x0, x1) = (b.xmin.clamp(0, w - 1), b.xmax.clamp(0, w - 1));
    let (y0, y1) = (b.ymin.clamp(0, h - 1), b.ymax.clamp(0, h - 1));
    let step = sample_step(x1 - x0 + 1, y1 - y0 + 1);
    let (mut robot, mut all) = (0u32, 0u32);
    for y in (y0..=y1).step_by(step) {
        for x in (x0..=x1).step_by(step) {
            all += 1;
            robot += u32::from(view.is_robot(x, y));
        }
    }
    f64::from(robot) / f64::from(all.max(1))
}

/// Whether an object last estimated at `centre_m` (the arm's base frame) with `radius_m`, no
/// longer detected, is hidden by the robot's own links in `view`: over the disc its sphere
/// covers in the image, the robot covers at least [`HIDDEN_SHARE`], and the robot plus what
/// lies at the object's front surface (its depth within the sphere's front half) explain at
/// least [`EXPLAINED_SHARE`]. An object taken away leaves what was behind it (further than its
/// surface): gone, not hidden. `false` when the view does not know the robot's pixels, or the
/// object is behind the camera or out of the image.
pub fn hidden_by_robot(
    view: &DepthView<'_>,
    [fx, fy, cx, cy]: [f64; 4],
    centre_m: Vector3<f64>,
    radius_m: f64,
) -> bool {
    if view.robot_px.is_empty() {
        return false;
    }
    let c = view.base_from_optical.inverse() * Point3::from(centre_m);
    if c.z <= radius_m {
        return false;
    }
    let (u, v) = (fx * c.x / c.z + cx, fy * c.y / c.z + cy);
    let r_px = (fx.max(fy) * radius_m / c.z).max(1.0);
    let (w, h) = (i64::from(view.width), i64::from(view.height));
    let x0 = ((u - r_px).floor() as i64).clamp(0, w - 1);
    let x1 = ((u + r_px).ceil() as i64).clamp(0, w - 1);
    let y0 = ((v - r_px).floor() as i64).clamp(0, h - 1);
    let y1 = ((v + r_px).ceil() as i64).clamp(0, h - 1);
    let step = sample_step(x1 - x0 + 1, y1 - y0 + 1);
    // The sphere's front half, along the optical axis, with a little slack for noise.
    let (near, far) = (c.z - 1.5 * radius_m, c.z + 0.25 * radius_m);
    let (mut all, mut robot, mut surface) = (0u32, 0u32, 0u32);
    for y in (y0..=y1).step_by(step) {
        for x in (x0..=x1).step_by(step) {
            let (dx, dy) = (x as f64 + 0.5 - u, y as f64 + 0.5 - v);
            if dx * dx + dy * dy > r_px * r_px {
                continue;
            }
            all += 1;
            if view.is_robot(x, y) {
                robot += 1;
            } else if (near..=far).contains(&f64::from(view.depth_at(x, y))) {
                surface += 1;
            }
        }
    }
    if all == 0 {
        return false;
    }
    let share = |n: u32| f64::from(n) / f64::from(all);
    share(robot) >= HIDDEN_SHARE && share(robot + surface) >= EXPLAINED_SHARE
}

/// The stride that samples a `width` x `height` region at about [`MAX_SAMPLES`] pixels.
pub(crate) fn sample_step(width: i64, height: i64) -> usize {
    (((width.max(1) * height.max(1)) as f64 / MAX_SAMPLES)
        .sqrt()
        .ceil() as usize)
        .max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball_box(xmin: i64, ymin: i64, xmax: i64, ymax: i64) -> BoundingBox {
        BoundingBox {
            class: "sports ball".into(),
            probability: 0.8,
            xmin,
            ymin,
            xmax,
            ymax,
            id: 32,
        }
    }

    #[test]
    fn the_object_point_is_the_box_centre_at_its_median_depth() {
        // 40x30 image, fx = fy = 20, centre (20, 15); background at 3 m, a 10x10 px patch
        // at 1 m centred on (30, 15); the camera 0.5 m above the base, looking along +x.
        let (w, h) = (40u32, 30u32);
        let mut depth = vec![3.0f32; (w * h) as usize];
        for y in 10..20 {
            for x in 25..35 {
                depth[y * w as usize + x] = 1.0;
            }
        }
        // Optical z forward -> base x, optical x right -> base -y, optical y down -> base -z.
        let rotation = nalgebra::UnitQuaternion::from_matrix(&nalgebra::Matrix3::new(
            0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0,
        ));
        let view = DepthView {
            depth_m: &depth,
            width: w,
            height: h,
            base_from_optical: Isometry3::from_parts(
                nalgebra::Translation3::new(0.0, 0.0, 0.5),
                rotation,
            ),
            robot_px: &[],
        };
        // The box is a little larger than the patch: its edges see the background.
        let p = object_point(
            &ball_box(23, 8, 37, 22),
            &view,
            [20.0, 20.0, 20.0, 15.0],
            4.0,
        );
        let p = p.unwrap_or_else(Vector3::zeros);
        // The surface at 1 m along the ray through (30, 15), then one radius on: the 14 px box
        // spans 0.7 rad-tangents, a sphere of r = d sin(a) / (1 - sin(a)) with a = atan(0.35).
        let surface: Vector3<f64> = Vector3::new(1.0, -0.5, 0.5);
        let sin_a = 0.35f64.atan().sin();
        let r = surface.xy().norm() * sin_a / (1.0 - sin_a);
        let along: Vector3<f64> = Vector3::new(1.0, -0.5, 0.0).normalize();
        let want = surface + along * r;
        assert!((p - want).norm() < 1e-9, "{p:?}, want {want:?}");
        // Nothing within range: no point.
        assert!(object_point(&ball_box(23, 8, 37, 22), &view, [20.0; 4], 0.5).is_none());
        // A box off the image is clamped to it, not read out of bounds.
        let _ = object_point(&ball_box(-50, -50, 500, 500), &view, [20.0; 4], 4.0);
    }

    /// A sphere seen straight on: the estimate puts the centre where it is.
    #[test]
    fn a_spheres_centre_is_one_radius_beyond_its_surface() {
        // A 6 cm ball 0.5 m ahead (its surface at 0.44 m), fx = 300: its silhouette's half
        // angle is asin(0.06 / 0.5), tangent 0.1209, so the box is 72.5 px wide.
        let r = 0.06f64;
        let tan = (r / 0.5).asin().tan();
        let radius = radius_seen(2.0 * tan, 2.0 * tan, 0.44);
        assert!((radius - r).abs() < 1e-9, "{radius}");
    }

    /// A 40x30 view looking straight down the base's x from 0.5 m up, everything 3 m away
    /// but a ball of radius 0.1 m 1 m ahead (its front surface a disc at 0.9 m), with the
    /// robot covering the columns `robot_cols`.
    fn ball_view(ball: bool, robot_cols: std::ops::Range<usize>) -> (Vec<f32>, Vec<bool>) {
        let (w, h) = (40usize, 30usize);
        let mut depth = vec![3.0f32; w * h];
        let mut robot = vec![false; w * h];
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as f64 + 0.5 - 20.0, y as f64 + 0.5 - 15.0);
                if ball && dx * dx + dy * dy <= 2.0f64 * 2.0 * 4.0 {
                    depth[y * w + x] = 0.92;
                }
                if robot_cols.contains(&x) {
                    robot[y * w + x] = true;
                    depth[y * w + x] = 0.4;
                }
            }
        }
        (depth, robot)
    }

    fn looking_ahead<'a>(depth: &'a [f32], robot: &'a [bool]) -> DepthView<'a> {
        let rotation = nalgebra::UnitQuaternion::from_matrix(&nalgebra::Matrix3::new(
            0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0,
        ));
        DepthView {
            depth_m: depth,
            width: 40,
            height: 30,
            base_from_optical: Isometry3::from_parts(
                nalgebra::Translation3::new(0.0, 0.0, 0.5),
                rotation,
            ),
            robot_px: robot,
        }
    }

    /// The ball (fx = 40: 4 px across its radius at 1 m) half behind the robot is hidden; the
    /// ball taken away with the robot in the same place is gone; the ball in plain view with
    /// no detection is not hidden by the robot either; a view without the robot's pixels never
    /// says hidden.
    #[test]
    fn an_object_behind_the_robot_is_hidden_and_one_taken_away_is_not() {
        let k = [40.0, 40.0, 20.0, 15.0];
        let centre = Vector3::new(1.0, 0.0, 0.5);
        let (depth, robot) = ball_view(true, 14..20);
        let view = looking_ahead(&depth, &robot);
        assert!(hidden_by_robot(&view, k, centre, 0.1));
        let (depth, robot) = ball_view(false, 14..20);
        assert!(!hidden_by_robot(
            &looking_ahead(&depth, &robot),
            k,
            centre,
            0.1
        ));
        let (depth, robot) = ball_view(true, 0..2);
        assert!(!hidden_by_robot(
            &looking_ahead(&depth, &robot),
            k,
            centre,
            0.1
        ));
        let (depth, _) = ball_view(true, 14..20);
        assert!(!hidden_by_robot(
            &looking_ahead(&depth, &[]),
            k,
            centre,
            0.1
        ));
    }

    /// The robot's pixels are left out of the estimate and counted by `robot_share`.
    #[test]
    fn the_robots_pixels_never_enter_the_estimate() {
        let k = [40.0, 40.0, 20.0, 15.0];
        let (depth, robot) = ball_view(true, 14..20);
        let view = looking_ahead(&depth, &robot);
        let b = ball_box(16, 11, 24, 19);
        let share = robot_share(&b, &view);
        assert!((share - 4.0 / 9.0).abs() < 1e-9, "{share}");
        let (p, _) = object_estimate(&b, &view, k, 4.0).unwrap_or_default();
        // The robot stands at 0.4 m: had it entered the median, the point would be far short.
        assert!(p.x > 0.9, "{p:?}");
        assert_eq!(robot_share(&b, &looking_ahead(&depth, &[])), 0.0);
    }
}
