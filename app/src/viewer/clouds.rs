//! Point clouds as 3D points in the world: each 3D lidar's under `world/clouds/<sensor>`,
//! coloured by height (blue at the ground, through green, to red 2 m up); the depth camera's
//! under `world/clouds/depth`, in the colours its camera saw, every 4th pixel of every 4th
//! row. NaN points (nothing in range) are left out.

use rover_sim::{
    geometry::Pose,
    physics::Simulation,
    sensors::{CloudSource, PointCloud},
};

/// The depth camera's cloud's entity path.
pub(super) const DEPTH_CLOUD_PATH: &str = "world/clouds/depth";

/// Pixels between the depth cloud's drawn points, across and down.
const DEPTH_STRIDE: usize = 4;

/// Height (m) at the top of the lidar colour ramp.
const RAMP_TOP_M: f32 = 2.0;

/// Each cloud's path and the points of the newest one (world frame), reused.
#[derive(Debug, Default)]
pub(super) struct Clouds {
    lidar_paths: Vec<String>,
    points: Vec<[f32; 3]>,
    colours: Vec<rerun::Color>,
}

impl Clouds {
    /// The paths of `sim`'s robot's lidars.
    pub fn start(&mut self, sim: &Simulation) {
        self.lidar_paths = sim
            .robot()
            .lidars
            .iter()
            .map(|l| format!("world/clouds/{}", l.rays.name))
            .collect();
    }

    /// `cloud`, taken from `world_from_sensor`, as its path and points.
    pub fn points(
        &mut self,
        cloud: &PointCloud,
        world_from_sensor: Pose,
    ) -> Option<(&str, rerun::Points3D)> {
        let path = match cloud.source {
            CloudSource::Lidar(n) => self.lidar_paths.get(n)?.as_str(),
            CloudSource::DepthCamera => DEPTH_CLOUD_PATH,
        };
        self.points.clear();
        self.colours.clear();
        // A depth camera's every pixel would be 300,000 points a frame: every 4th of every 4th
        // row is plenty to see (and keeps recordings small).
        let stride = match cloud.source {
            CloudSource::DepthCamera => DEPTH_STRIDE,
            CloudSource::Lidar(_) => 1,
        };
        let width = cloud.width.max(1) as usize;
        let kept = cloud.points().filter(|(i, _)| {
            (i % width).is_multiple_of(stride) && (i / width).is_multiple_of(stride)
        });
        for (i, p) in kept {
            let w = world_from_sensor.transform_point(glam::Vec3::from(p));
            self.points.push(w.to_array());
            let colour = match cloud.rgb(i) {
                Some([r, g, b]) => rerun::Color::from_rgb(r, g, b),
                None => height_colour(w.z),
            };
            self.colours.push(colour);
        }
        let points = rerun::Points3D::new(self.points.iter().copied())
            .with_colors(self.colours.iter().copied())
            .with_radii([rerun::components::Radius::new_ui_points(1.5)]);
        Some((path, points))
    }
}

/// Blue at the ground, green at mid-height, red at [`RAMP_TOP_M`] and above.
fn height_colour(z_m: f32) -> rerun::Color {
    let t = (z_m / RAMP_TOP_M).clamp(0.0, 1.0);
    let (r, g, b) = if t < 0.5 {
        (0.0, 2.0 * t, 1.0 - 2.0 * t)
    } else {
        (2.0 * t - 1.0, 2.0 - 2.0 * t, 0.0)
    };
    rerun::Color::from_rgb((r * 255.0) as u8, (g * 255.0) as u8, (b * 255.0) as u8)
}
