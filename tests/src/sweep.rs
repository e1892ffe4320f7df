//! The person-visibility sweep (issue 4): the default world's person seen from the car's
//! camera at several distances and bearings, rendered by the real renderer and labelled by the
//! real default detector.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;
use rover_perception::{Detector, DetectorConfig, FrameStamp, RgbView};
use rover_sim::{
    geometry::Pose,
    model::{CameraInfo, World},
    physics::{SimOptions, Simulation},
    render::CameraRenderer,
};

/// Confidence a frame must reach to count as "labelled person".
pub const PASS_CONFIDENCE: f64 = 0.5;

/// One frame of the sweep.
#[derive(Debug, Clone, Copy)]
pub struct SweepCell {
    /// Best `person` confidence (0 when none above the detector's threshold).
    pub confidence: f64,
    /// Whether the whole person (feet to the top of the head, arms) projects inside the image.
    pub fully_in_view: bool,
}

/// The result of a sweep: one row per distance, one cell per bearing.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// Bearings of the person as seen from the camera (deg, positive to the left).
    pub bearings_deg: Vec<f64>,
    /// (distance in m, cells in `bearings_deg` order).
    pub rows: Vec<(f64, Vec<SweepCell>)>,
    /// Height of the camera above the ground (m), from the car settled on flat ground.
    pub camera_height_m: f64,
}

impl Sweep {
    /// (frames with the person fully in view and labelled >= [`PASS_CONFIDENCE`],
    /// frames with the person fully in view).
    pub fn score(&self) -> (usize, usize) {
        let cells = self
            .rows
            .iter()
            .flat_map(|(_, c)| c)
            .filter(|c| c.fully_in_view);
        let counted: Vec<_> = cells.collect();
        let ok = counted
            .iter()
            .filter(|c| c.confidence >= PASS_CONFIDENCE)
            .count();
        (ok, counted.len())
    }

    /// The table as Markdown (cells not fully in view are shown in parentheses).
    pub fn markdown(&self) -> String {
        let mut out = String::from("| distance |");
        for b in &self.bearings_deg {
            let _ = write!(out, " {b:+.0} deg |");
        }
        out.push_str("\n|---|");
        out.push_str(&"---|".repeat(self.bearings_deg.len()));
        out.push('\n');
        for (d, cells) in &self.rows {
            let _ = write!(out, "| {d:.1} m |");
            for c in cells {
                if c.fully_in_view {
                    let _ = write!(out, " {:.2} |", c.confidence);
                } else {
                    let _ = write!(out, " ({:.2}) |", c.confidence);
                }
            }
            out.push('\n');
        }
        out
    }
}

/// Renders the default world's first person from the car's camera `distance` metres in front
/// of it (person facing the camera) for every distance x bearing, and runs the detector with
/// `input_size` (None = its default). The car's own body is hidden; everything else in the world
/// is drawn. Frames are written to `save_dir` as PNGs when given.
pub fn person_sweep(
    distances_m: &[f64],
    bearings_deg: &[f64],
    input_size: Option<(usize, usize)>,
    save_dir: Option<&Path>,
) -> anyhow::Result<Sweep> {
    let world = World::load(&crate::repo("worlds/playground.toml"))?;
    let robot = crate::my_robot()?;
    let camera = robot
        .cameras
        .first()
        .cloned()
        .ok_or_else(|| anyhow::anyhow!("my_robot.urdf has no camera"))?;
    let info = CameraInfo::from_config(&camera);
    let camera_link = robot
        .link_id(&camera.link)
        .ok_or_else(|| anyhow::anyhow!("camera link {} missing", camera.link))?;
    // Camera height of the car at rest on flat ground.
    let mut sim = Simulation::new(World::flat()?, robot.clone(), &SimOptions::default())?;
    for _ in 0..200 {
        sim.step();
    }
    let camera_height_m = f64::from(sim.world_from_link(camera_link).translation.z);

    let person = world
        .people
        .first()
        .ok_or_else(|| anyhow::anyhow!("the default world has no person"))?;
    let mut renderer = CameraRenderer::new(&world, &robot, &camera, 0)?;
    let mut detector = Detector::load(DetectorConfig {
        input_size,
        ..DetectorConfig::default()
    })?;
    let parked = vec![Pose::from_translation(Vec3::new(0.0, 0.0, -100.0)); robot.links.len()];
    let (w, h) = (info.width, info.height);
    let mut rows = Vec::new();
    for &d in distances_m {
        let mut cells = Vec::new();
        for &bearing in bearings_deg {
            // The person faces the camera: put the camera `d` m along the person's heading.
            let heading = person.heading_rad;
            let (px, py) = (person.position_m[0], person.position_m[1]);
            let cam = [px + d * heading.cos(), py + d * heading.sin()];
            let look_yaw = (py - cam[1]).atan2(px - cam[0]);
            let yaw = look_yaw - bearing.to_radians();
            let world_from_camera =
                rover_sim::geometry::pose_from_position_yaw([cam[0], cam[1], camera_height_m], yaw);
            let rgb = renderer.render(&parked, world_from_camera)?;
            let boxes = detector.detect(
                RgbView::new(w as usize, h as usize, rgb)?,
                FrameStamp::default(),
            )?;
            let confidence = boxes
                .bounding_boxes
                .iter()
                .filter(|b| b.class == "person")
                .map(|b| b.probability)
                .fold(0.0, f64::max);
            let fully_in_view = person_in_view(
                &info,
                world_from_camera,
                [px, py],
                person.height_m,
                person.body_radius_m() * 2.3,
            );
            if let Some(dir) = save_dir {
                let path = dir.join(format!("person_{d:.1}m_{bearing:+.0}deg.png"));
                image::save_buffer(path, rgb, w, h, image::ExtendedColorType::Rgb8)?;
            }
            cells.push(SweepCell {
                confidence,
                fully_in_view,
            });
        }
        rows.push((d, cells));
    }
    Ok(Sweep {
        bearings_deg: bearings_deg.to_vec(),
        rows,
        camera_height_m,
    })
}

/// Whether an upright box around the person (`half_width_m` around its axis, from the ground to
/// `height_m`) projects entirely inside the image.
fn person_in_view(
    info: &CameraInfo,
    world_from_camera: Pose,
    feet: [f64; 2],
    height_m: f64,
    half_width_m: f64,
) -> bool {
    let camera_from_world = world_from_camera.inverse();
    let mut inside = true;
    for dx in [-half_width_m, half_width_m] {
        for dy in [-half_width_m, half_width_m] {
            for z in [0.0, height_m] {
                let p_world = Vec3::new((feet[0] + dx) as f32, (feet[1] + dy) as f32, z as f32);
                let p = camera_from_world * p_world;
                // Camera link (x forward, y left, z up) -> optical (x right, y down, z forward).
                let projected = info.project(f64::from(-p.y), f64::from(-p.z), f64::from(p.x));
                inside &= projected.is_some_and(|(u, v)| {
                    u >= 0.0
                        && v >= 0.0
                        && u <= f64::from(info.width)
                        && v <= f64::from(info.height)
                });
            }
        }
    }
    inside
}
