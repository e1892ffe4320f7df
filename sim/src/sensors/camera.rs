//! The camera as a sensor: renders the robot's camera at its `update_rate` on sim time, with
//! the frame's ground truth when asked for.

use crate::error::SimError;
use crate::geometry::Pose;
use crate::model::camera_info::CameraInfo;
use crate::model::robot::LinkId;
use crate::model::sensors::GaussianNoise;
use crate::physics::simulation::Simulation;
use crate::render::gpu::RenderError;
use crate::render::passes::colour::Light;
use crate::render::renderer::{CameraRenderer, EntityImage};
use crate::sensors::ground_truth::{GroundTruth, GroundTruthBox};
use crate::sensors::schedule::Schedule;

/// One camera image.
#[derive(Debug, Clone, Copy)]
pub struct CameraFrame<'a> {
    /// Sim time the image was taken (s).
    pub sim_time_s: f64,
    /// Sequence number, from 0.
    pub seq: u64,
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// RGB8 pixels, rows top to bottom.
    pub rgb: &'a [u8],
    /// Every labelled thing in view (empty unless [`CameraSensor::enable_ground_truth`]).
    pub ground_truth: &'a [GroundTruthBox],
    /// The instance-id image of the same frame (`None` unless ground truth or the id image is
    /// enabled); the robot's own pixels are [`crate::model::EntityIds::ROBOT`].
    pub entities: Option<&'a EntityImage>,
    /// The depth image of the same frame (`None` unless [`CameraSensor::enable_depth`]: a
    /// `<sensor type="depth">` has it on): per pixel, rows top to bottom, the distance along
    /// the optical axis (m; the optical frame's z, as a ROS 32FC1 depth image holds it), NaN
    /// where nothing is within the clip range. The ideal pinhole image (no distortion), with the
    /// camera's gaussian `<noise>` in metres when it has one.
    pub depth_m: Option<&'a [f32]>,
}

/// A robot camera rendering at its update rate.
#[derive(Debug)]
pub struct CameraSensor {
    renderer: CameraRenderer,
    link: LinkId,
    schedule: Schedule,
    seq: u64,
    link_poses: Vec<Pose>,
    model_poses: Vec<Pose>,
    object_poses: Vec<Pose>,
    /// The sim's layout the renderer's copies were last moved to.
    layout_seen: u64,
    truth: Option<(GroundTruth, Vec<GroundTruthBox>)>,
}

impl CameraSensor {
    /// The robot's first camera (`<sensor type="camera">`), rendered with the sim's seed.
    pub fn new(sim: &Simulation) -> Result<Self, RenderError> {
        let robot = sim.robot();
        let config = robot.cameras.first().ok_or_else(|| {
            RenderError::Scene(SimError::Setup(format!(
                "{}: the robot has no <sensor type=\"camera\">",
                robot.source.display()
            )))
        })?;
        let link = robot.link_id(&config.link).ok_or_else(|| {
            RenderError::Scene(SimError::Setup(format!(
                "camera link {} missing",
                config.link
            )))
        })?;
        let mut renderer = CameraRenderer::new(sim.world(), robot, config, sim.seed())?;
        if config.depth.is_some() {
            renderer.enable_depth();
        }
        Ok(Self {
            renderer,
            link,
            schedule: Schedule::new(config.update_rate_hz),
            seq: 0,
            link_poses: Vec::with_capacity(robot.links.len()),
            model_poses: Vec::new(),
            object_poses: Vec::new(),
            layout_seen: sim.layout_version(),
            truth: None,
        })
    }

    /// From the next image on, every frame carries its ground truth: the renderer also writes
    /// the instance-id image and the silhouettes, and each labelled thing's boxes, pixel counts
    /// and visibility are measured from them.
    pub fn enable_ground_truth(&mut self, sim: &Simulation) -> Result<(), RenderError> {
        if self.truth.is_none() {
            self.renderer.enable_entity_image()?;
            self.truth = Some((GroundTruth::new(sim.world(), &self.renderer)?, Vec::new()));
        }
        Ok(())
    }

    /// From the next image on, every frame carries its instance-id image
    /// ([`CameraFrame::entities`]), in which the robot's own links are
    /// [`crate::model::EntityIds::ROBOT`]: what a self filter needs. Cheaper than ground truth
    /// (no silhouettes, no boxes).
    pub fn enable_id_image(&mut self) {
        self.renderer.enable_id_image();
    }

    /// From the next image on, every frame carries its depth image
    /// ([`CameraFrame::depth_m`]).
    pub fn enable_depth(&mut self) {
        self.renderer.enable_depth();
    }

    /// From the next image on, no depth image (a depth camera's colour image only).
    pub fn disable_depth(&mut self) {
        self.renderer.disable_depth();
    }

    /// The intrinsics.
    pub fn info(&self) -> &CameraInfo {
        self.renderer.info()
    }

    /// Lights the following images: the sun travelling along `sun_direction` (world frame)
    /// with `light`'s strengths (the world's sun and rover's default strengths until then).
    pub fn set_light(&mut self, sun_direction: [f64; 3], light: Light) {
        self.renderer.set_light(sun_direction, light);
    }

    /// Gaussian noise on the following images instead of the camera's own `<noise>` (none:
    /// clean images).
    pub fn set_noise(&mut self, noise: Option<GaussianNoise>) {
        self.renderer.set_noise(noise);
    }

    /// The renderer (adapter name, ...).
    pub fn renderer(&self) -> &CameraRenderer {
        &self.renderer
    }

    /// True when an image is due at the sim's current time.
    pub fn due(&self, sim: &Simulation) -> bool {
        self.schedule.due(sim.sim_time_s())
    }

    /// Renders an image if one is due (schedule accumulated like Gazebo's sensors).
    pub fn capture_if_due(
        &mut self,
        sim: &Simulation,
    ) -> Result<Option<CameraFrame<'_>>, RenderError> {
        if !self.schedule.take(sim.sim_time_s()) {
            return Ok(None);
        }
        self.capture(sim).map(Some)
    }

    /// Takes the image due now, if one is, without rendering it (nobody would look at it):
    /// the schedule and frame numbers advance exactly as [`Self::capture_if_due`] would.
    /// Returns the skipped frame's number.
    pub fn skip_if_due(&mut self, sim: &Simulation) -> Option<u64> {
        if !self.schedule.take(sim.sim_time_s()) {
            return None;
        }
        let seq = self.seq;
        self.seq += 1;
        Some(seq)
    }

    /// Numbers the next image `seq` (its noise is seeded from its number): images made out
    /// of order, such as a dataset's, get the same noise however they are made.
    pub fn set_frame_number(&mut self, seq: u64) {
        self.seq = seq;
    }

    /// Renders an image now.
    pub fn capture(&mut self, sim: &Simulation) -> Result<CameraFrame<'_>, RenderError> {
        sim.link_poses_into(&mut self.link_poses);
        let camera = self.link_poses[self.link.index()];
        let seq = self.seq;
        self.seq += 1;
        self.renderer.seed_frame(seq);
        let (width, height) = (self.renderer.info().width, self.renderer.info().height);
        let relaid = self.layout_seen != sim.layout_version();
        self.layout_seen = sim.layout_version();
        for (index, person) in sim.world().people.iter().enumerate() {
            if person.moves() || relaid {
                self.renderer.set_person_pose(
                    index,
                    sim.world_from_person(index),
                    sim.person_gait_phase_rad(index),
                );
            }
            if relaid {
                self.renderer.dress_person(index, person);
            }
        }
        if relaid || sim.world().objects.iter().any(|o| o.mass_kg.is_some()) {
            // Placed objects, and objects physics moves (a pushed crate) drawn where they are.
            sim.object_poses_into(&mut self.object_poses);
            self.renderer.set_object_poses(&self.object_poses);
        }
        if self.renderer.has_moving_models() || relaid {
            sim.model_link_poses_into(&mut self.model_poses);
            self.renderer.set_model_link_poses(&self.model_poses);
        }
        self.renderer.render(&self.link_poses, camera)?;
        let entities = self.renderer.entity_image();
        let ground_truth = match (&mut self.truth, entities) {
            (Some((truth, boxes)), Some(image)) => {
                truth.measure(sim, &self.renderer, camera, image, boxes);
                boxes.as_slice()
            }
            _ => &[],
        };
        Ok(CameraFrame {
            sim_time_s: sim.sim_time_s(),
            seq,
            width,
            height,
            rgb: self.renderer.rgb(),
            ground_truth,
            entities,
            depth_m: self.renderer.depth_m(),
        })
    }
}
