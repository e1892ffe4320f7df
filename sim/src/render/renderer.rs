//! [`CameraRenderer`]: the robot camera's image, rendered offscreen (a GPU, or Mesa's software
//! Vulkan where there is none) from the URDF camera's pose with gazebo_ros_camera's intrinsics,
//! read back as RGB8 at the sensor's size, then post-processed (distortion, noise). On request
//! it also reads back the instance-id image and each labelled thing's silhouette (ground truth).

use glam::{Mat4, Vec4};

use crate::geometry::Pose;
use crate::model::camera_info::{CameraInfo, link_from_optical};
use crate::model::classes::EntityIds;
use crate::model::person::Person;
use crate::model::robot::RobotModel;
use crate::model::sensors::CameraConfig;
use crate::model::sensors::GaussianNoise;
use crate::model::world::World;
use crate::render::gpu::RenderError;
use crate::render::gpu::{Gpu, Readback};
use crate::render::passes::colour::{ColourPass, Light, View};
use crate::render::passes::silhouette::SilhouettePass;
use crate::render::post::PostProcess;
use crate::render::scene::Scene;

/// Renders the robot's camera.
pub struct CameraRenderer {
    gpu: Gpu,
    scene: Scene,
    colour: ColourPass,
    readback: Readback,
    post: PostProcess,
    info: CameraInfo,
    near_m: f32,
    far_m: f32,
    /// How many labelled things the scene has (ids 1..=entities).
    entities: u32,
    ids: Option<IdOutputs>,
    /// The depth image's readback and metres, once a depth image is asked for.
    depth: Option<(Readback, Vec<f32>)>,
}

/// The id image read back each frame once asked for, and the silhouettes once ground truth
/// is asked for.
struct IdOutputs {
    readback: Readback,
    silhouette: Option<SilhouettePass>,
    image: EntityImage,
}

/// Each pixel's labelled thing and each thing's unoccluded size, for one frame: what ground
/// truth is measured from. Ids are [`EntityIds`] numbers (0: nothing labelled;
/// [`EntityIds::ROBOT`]: the robot's own links, as MoveIt's mesh filter renders them).
#[derive(Debug, Clone, Default)]
pub struct EntityImage {
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// The id of every pixel of the output image (distorted like the colour image, nearest
    /// pixel), rows top to bottom.
    pub ids: Vec<u32>,
    /// The id of every pixel of the ideal pinhole image (before distortion); empty when the
    /// lens does not distort (`ids` is then the ideal image).
    pub ideal_ids: Vec<u32>,
    /// Whether the lens distorts.
    pub distorted: bool,
    /// Per entity (index `id - 1`): the pixels of the ideal image it covers with nothing in
    /// front of it.
    pub silhouette_px: Vec<u32>,
}

impl std::fmt::Debug for CameraRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CameraRenderer")
            .field("adapter", &self.gpu.adapter)
            .field("size", &(self.info.width, self.info.height))
            .finish_non_exhaustive()
    }
}

impl CameraRenderer {
    /// Sets up the GPU (or software Vulkan), uploads every mesh once and allocates the image
    /// buffers once.
    pub fn new(
        world: &World,
        robot: &RobotModel,
        camera: &CameraConfig,
        seed: u64,
    ) -> Result<Self, RenderError> {
        let gpu = Gpu::new()?;
        let info = CameraInfo::from_config(camera);
        let (w, h) = (info.width, info.height);
        let entity_ids = EntityIds::new(world);
        let scene = Scene::new(&gpu.device, &gpu.queue, world, robot, &entity_ids)?;
        let colour = ColourPass::new(&gpu.device, &scene, w, h, world);
        let readback = Readback::new(&gpu.device, "camera readback", w, h);
        let post = PostProcess::new(&info, camera.noise, &camera.distortion, seed);
        Ok(Self {
            gpu,
            scene,
            colour,
            readback,
            post,
            info,
            near_m: camera.clip_near_m as f32,
            far_m: camera.clip_far_m as f32,
            entities: entity_ids.len() as u32,
            ids: None,
            depth: None,
        })
    }

    /// From the next render on, also reads back the instance-id image and every labelled
    /// thing's silhouette ([`Self::entity_image`]). Allocates their buffers once.
    pub fn enable_entity_image(&mut self) -> Result<(), RenderError> {
        self.enable_id_image();
        let Some(ids) = self.ids.as_mut() else {
            return Ok(());
        };
        if ids.silhouette.is_none() {
            let (w, h) = (self.info.width, self.info.height);
            ids.silhouette = Some(SilhouettePass::new(&self.gpu.device, w, h, self.entities)?);
            ids.image.silhouette_px = vec![0; self.entities as usize];
        }
        Ok(())
    }

    /// From the next render on, also reads back the instance-id image alone
    /// ([`Self::entity_image`], its `silhouette_px` all zero): which pixels show which labelled
    /// thing and which the robot itself. Allocates its buffers once.
    pub fn enable_id_image(&mut self) {
        if self.ids.is_some() {
            return;
        }
        let (w, h) = (self.info.width, self.info.height);
        let pixels = (w * h) as usize;
        self.ids = Some(IdOutputs {
            readback: Readback::new(&self.gpu.device, "entity id readback", w, h),
            silhouette: None,
            image: EntityImage {
                width: w,
                height: h,
                ids: vec![0; pixels],
                ideal_ids: if self.post.distorts() {
                    vec![0; pixels]
                } else {
                    Vec::new()
                },
                distorted: self.post.distorts(),
                silhouette_px: vec![0; self.entities as usize],
            },
        });
    }

    /// From the next render on, also reads back the depth buffer as a depth image
    /// ([`Self::depth_m`]). Allocates its buffers once.
    pub fn enable_depth(&mut self) {
        if self.depth.is_none() {
            let (w, h) = (self.info.width, self.info.height);
            self.depth = Some((
                Readback::new(&self.gpu.device, "depth readback", w, h),
                vec![f32::NAN; (w * h) as usize],
            ));
        }
    }

    /// Stops reading the depth buffer back (and frees its buffers).
    pub fn disable_depth(&mut self) {
        self.depth = None;
    }

    /// The last render's depth image, once [`Self::enable_depth`] was called: per pixel of
    /// the ideal pinhole image (no distortion; the camera's gaussian `<noise>` in metres, when
    /// it has one), rows top to bottom, the distance
    /// along the optical axis (the optical frame's z, as ROS depth images hold it) to what
    /// the pixel shows (m); NaN where nothing is within the clip range.
    pub fn depth_m(&self) -> Option<&[f32]> {
        self.depth.as_ref().map(|(_, metres)| metres.as_slice())
    }

    /// The last rendered image (RGB8 rows, top to bottom, after distortion and noise).
    pub fn rgb(&self) -> &[u8] {
        &self.post.rgb
    }

    /// The last render's entity image, once [`Self::enable_entity_image`] was called.
    pub fn entity_image(&self) -> Option<&EntityImage> {
        self.ids.as_ref().map(|ids| &ids.image)
    }

    /// The intrinsics (CameraInfo) images are rendered with.
    pub fn info(&self) -> &CameraInfo {
        &self.info
    }

    /// The graphics adapter in use (e.g. "llvmpipe" for Mesa's software Vulkan).
    pub fn adapter(&self) -> &str {
        &self.gpu.adapter
    }

    /// Projection from the optical frame to wgpu clip space that reproduces K exactly
    /// (pixel centres at integer coordinates), with depth in [0, 1] between near and far.
    fn projection(&self) -> Mat4 {
        let (w, h) = (self.info.width as f32, self.info.height as f32);
        let fx = self.info.k[0] as f32;
        let fy = self.info.k[4] as f32;
        let (cx, cy) = (self.info.k[2] as f32, self.info.k[5] as f32);
        let (n, f) = (self.near_m, self.far_m);
        Mat4::from_cols(
            Vec4::new(2.0 * fx / w, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -2.0 * fy / h, 0.0, 0.0),
            Vec4::new(
                (2.0 * cx + 1.0) / w - 1.0,
                1.0 - (2.0 * cy + 1.0) / h,
                f / (f - n),
                1.0,
            ),
            Vec4::new(0.0, 0.0, -f * n / (f - n), 0.0),
        )
    }

    /// Turns the read-back depth buffer into metres along the optical axis: the projection
    /// maps z in [near, far] to d = f (z - n) / (z (f - n)), so z = f n / (f - d (f - n)).
    fn read_depth(&mut self) -> Result<(), RenderError> {
        let Some((readback, metres)) = &mut self.depth else {
            return Ok(());
        };
        let (n, f) = (self.near_m, self.far_m);
        let w = self.info.width as usize;
        readback.read_rows(&self.gpu.device, |y, row| {
            for (out, d) in metres[y * w..][..w].iter_mut().zip(row.chunks_exact(4)) {
                let d = f32::from_le_bytes([d[0], d[1], d[2], d[3]]);
                *out = if d < 1.0 {
                    f * n / (f - d * (f - n))
                } else {
                    f32::NAN
                };
            }
        })?;
        self.post.add_depth_noise(metres);
        Ok(())
    }

    /// Whether some SDF model link can move (so [`Self::set_model_link_poses`] matters).
    pub fn has_moving_models(&self) -> bool {
        self.scene.has_moving_models()
    }

    /// Moves the visuals of moving SDF model links to `world_from_model_links` (every model
    /// link in world order, as [`crate::physics::Simulation::model_link_poses_into`] gives them).
    pub fn set_model_link_poses(&mut self, world_from_model_links: &[Pose]) {
        self.scene.set_model_link_poses(world_from_model_links);
    }

    /// Moves person `index` (world order) to `world_from_person`, their limbs to gait phase
    /// `gait_phase_rad` ([`crate::physics::Simulation::person_gait_phase_rad`]; 0: standing), for the
    /// following renders.
    pub fn set_person_pose(&mut self, index: usize, world_from_person: Pose, gait_phase_rad: f64) {
        self.scene
            .set_person_pose(index, world_from_person, gait_phase_rad);
    }

    /// The vertices of person `index` (world order) as last posed (m, their own frame), when
    /// they are drawn with MakeHuman's body; `None` for rover's figure.
    pub(crate) fn posed_person(&self, index: usize) -> Option<&[glam::Vec3]> {
        self.scene.posed_person(index)
    }

    /// Paints person `index` (world order) in `person`'s clothes for the following renders.
    pub fn dress_person(&mut self, index: usize, person: &Person) {
        self.scene.dress_person(&self.gpu.device, index, person);
    }

    /// Moves the world objects (every object in world order) for the following renders.
    pub fn set_object_poses(&mut self, world_from_objects: &[Pose]) {
        self.scene.set_object_poses(world_from_objects);
    }

    /// Lights the following renders: the sun travelling along `sun_direction` (world frame)
    /// with `light`'s strengths.
    pub fn set_light(&mut self, sun_direction: [f64; 3], light: Light) {
        let [x, y, z] = sun_direction.map(|v| v as f32);
        self.colour.set_light(glam::Vec3::new(x, y, z), light);
    }

    /// Gaussian noise on the following images (none: clean images).
    pub fn set_noise(&mut self, noise: Option<GaussianNoise>) {
        self.post.set_noise(noise);
    }

    /// Seeds the next image's noise from the frame number, so that an image's noise does not
    /// depend on which earlier frames were rendered (headless runs skip the ones nobody uses).
    pub fn seed_frame(&mut self, frame: u64) {
        self.post.seed_frame(frame);
    }

    /// Renders one image: `world_from_links` are the robot's link poses (URDF order),
    /// `world_from_camera` the pose of the camera's link. Returns RGB8 rows, top to bottom.
    pub fn render(
        &mut self,
        world_from_links: &[Pose],
        world_from_camera: Pose,
    ) -> Result<&[u8], RenderError> {
        self.scene.set_robot_link_poses(world_from_links);
        self.scene.choose_detail(world_from_camera.translation);
        self.scene.upload(&self.gpu.queue);
        let view = View {
            projection: self.projection(),
            world_from_optical: world_from_camera * Pose::from_rotation(link_from_optical()),
        };
        // Both passes first, then every copy: a transfer between passes would stall a
        // software rasterizer.
        let silhouette = (self.ids.as_ref())
            .and_then(|ids| ids.silhouette.as_ref())
            .filter(|_| self.entities > 0);
        if let Some(silhouette) = silhouette {
            silhouette.prepare(&self.gpu.queue, &view);
        }
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.colour
            .encode(&self.gpu.queue, &mut encoder, &self.scene, &view);
        if let Some(silhouette) = silhouette {
            silhouette.encode(&mut encoder, &self.scene);
        }
        self.readback.copy_from(&mut encoder, &self.colour.target);
        if let Some(ids) = &self.ids {
            ids.readback.copy_from(&mut encoder, &self.colour.ids);
        }
        if let Some((readback, _)) = &self.depth {
            readback.copy_from(&mut encoder, &self.colour.depth);
        }
        if let Some(silhouette) = silhouette {
            silhouette.copy_out(&mut encoder);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let w = self.info.width as usize;
        let ideal = &mut self.post.ideal;
        self.readback.read_rows(&self.gpu.device, |y, row| {
            let out = &mut ideal[y * w * 3..][..w * 3];
            for (o, px) in out.chunks_exact_mut(3).zip(row.chunks_exact(4)) {
                o.copy_from_slice(&px[..3]);
            }
        })?;
        self.post.run();
        self.read_depth()?;
        if let Some(ids) = &mut self.ids {
            let image = &mut ids.image;
            // Without distortion the pinhole image is the output: read straight into it.
            let ideal = if image.distorted {
                &mut image.ideal_ids
            } else {
                &mut image.ids
            };
            ids.readback.read_rows(&self.gpu.device, |y, row| {
                let out: &mut [u8] = bytemuck::cast_slice_mut(&mut ideal[y * w..][..w]);
                out.copy_from_slice(row);
            })?;
            if image.distorted {
                self.post.remap_ids(&image.ideal_ids, &mut image.ids);
            }
            if let Some(silhouette) = ids.silhouette.as_ref().filter(|_| self.entities > 0) {
                silhouette.read_counts(&self.gpu.device, &mut image.silhouette_px)?;
            }
        }
        Ok(&self.post.rgb)
    }
}
