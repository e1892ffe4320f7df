//! Measuring: where a box says a person is (range from the box's height or its feet, bearing,
//! width, and how sure), from the camera's geometry.

use rover_perception::BoundingBox;
use rover_sim::physics::Odometry;

use super::state::Follower;
use super::target::Measured;
use super::tuning::*;

impl Follower {
    /// Whether the ground [`REVERSE_LOOK_M`] behind the base is ground the robot has driven
    /// over (within [`TRAIL_WIDTH_M`] of its trail): the only ground a robot without a range
    /// sensor knows to be free behind it.
    pub(super) fn driven_behind(&self, odom: Odometry) -> bool {
        let (s, c) = odom.yaw_rad.sin_cos();
        let behind = [odom.x_m - REVERSE_LOOK_M * c, odom.y_m - REVERSE_LOOK_M * s];
        self.trail
            .iter()
            .any(|p| (p[0] - behind[0]).hypot(p[1] - behind[1]) <= TRAIL_WIDTH_M)
    }

    /// Range (m, horizontal, from the camera) and bearing (rad, positive left, from the
    /// camera's optical axis) of a box, for a person of the configured height and width.
    pub fn range_bearing(&self, b: &BoundingBox) -> (f64, f64) {
        let seen = self.measure(b, self.config.target_width_m);
        (seen.range_m, seen.bearing_rad)
    }

    /// Where a box puts a person whose box is `width_m` wide in the world.
    ///
    /// Range: for a whole box, from the person's height between the rays through its top and
    /// bottom (exact for a pitched camera too). For a box cut off at the top or bottom (a low
    /// camera near a person sees the torso or the legs), from where the feet meet the ground
    /// (the camera's height and pitch) when the box's bottom is below the horizon, else from
    /// its width. A box whose bottom is above the horizon (legs hidden) takes its range from
    /// the top of the head.
    pub(super) fn measure(&self, b: &BoundingBox, width_m: f64) -> Measured {
        let c = &self.camera;
        let u = (b.xmin + b.xmax) as f64 / 2.0;
        let (top, bottom) = (b.ymin as f64, b.ymax as f64);
        // The ray through the box's bottom centre, turned from the optical frame into a level
        // frame: forward is the axis tipped by the pitch.
        let (x_right, y_down) = ((u - c.cx) / c.fx, (bottom - c.cy) / c.fy);
        let (sp, cp) = c.pitch_down_rad.sin_cos();
        let forward = cp - sp * y_down;
        let bearing_rad = (-x_right).atan2(forward.max(1e-6));
        // Rows and columns measure depth along the optical axis: a person off the axis is
        // further than that.
        let off_axis = bearing_rad.cos().max(0.2);
        let up = -c.dip_rad(top);
        let down = c.dip_rad(bottom);
        let span = up.tan() + down.tan();
        let from_height = (span > 1e-6).then(|| self.config.target_height_m / span);
        let clipped_bottom = bottom >= c.height_px - 1.0 - EDGE_PX as f64;
        let clipped_side = b.xmin <= EDGE_PX || b.xmax as f64 >= c.width_px - 1.0 - EDGE_PX as f64;
        let width_px = (b.xmax - b.xmin).max(1) as f64;
        let from_width = (!clipped_side).then(|| c.fx * width_m / width_px);
        let from_feet =
            (!clipped_bottom && down > (1.0 / c.fy).atan()).then(|| c.height_m / down.tan());
        // A detector's box edge at the image's border wanders a few pixels: a top edge near
        // the top border is cut off there when, at the range the feet give, the head would be
        // above the image (taking it for the head put a person 1.6 m away at 3 m).
        let head_out_of_view = from_feet.is_some_and(|d| {
            let head_up = ((self.config.target_height_m - c.height_m) / d).atan();
            head_up > -c.dip_rad(0.0)
        });
        let clipped_top =
            b.ymin <= EDGE_PX || (head_out_of_view && top <= TOP_EDGE_SLACK * c.height_px);
        // A bottom edge above the horizon is not a person's feet (the camera is above the
        // ground): something hides their legs, and the top of their head gives the range.
        let feet_hidden = down <= 0.0 && !clipped_top;
        let from_head = (feet_hidden && up > 1e-3)
            .then(|| (self.config.target_height_m - c.height_m).max(0.1) / up.tan());
        let whole = !clipped_top && !clipped_bottom && !feet_hidden;
        // Each way's 1-sigma error (m) at depth d: a box edge is good to ~2 px; people's
        // heights vary by ~5%, and how wide they look by far more (arms, turned sideways).
        let pixel_rad = 2.0 / c.fy;
        let (depth_m, sigma_m) = match (whole, from_height, from_feet, from_head, from_width) {
            (true, Some(d), ..) => (
                d,
                0.05 + 0.05 * d + d * d * pixel_rad / self.config.target_height_m,
            ),
            // A box's bottom below the horizon is the feet (the hem of a torso box is above a
            // low camera): the feet are exact, the width depends on how the person stands.
            // A box cut off at a side may have lost the nearer foot: the bottom is then the
            // other one's, up to a step further.
            (false, _, Some(d), ..) => (
                d,
                0.05 + d * d * pixel_rad / c.height_m.max(0.05)
                    + if clipped_side {
                        SIDE_CUT_FEET_SIGMA_M
                    } else {
                        0.0
                    },
            ),
            (false, _, None, Some(d), _) => (
                d,
                0.05 + 0.1 * d + d * d * pixel_rad / self.config.target_height_m,
            ),
            (false, _, None, None, Some(d)) => (d, 0.05 + 0.3 * d),
            _ => {
                let d = from_height
                    .unwrap_or(self.config.standoff_m)
                    .min(self.config.standoff_m);
                (d, 0.05 + 0.5 * d)
            }
        };
        let range_m = depth_m / off_axis;
        Measured {
            range_m,
            range_sigma_m: sigma_m / off_axis,
            bearing_rad,
            // The width a whole, uncut box shows, for boxes cut off later.
            width_m: (whole && !clipped_side).then(|| width_px * depth_m / c.fx),
        }
    }
}
