//! [`CameraRenderer`]: the robot camera's image, rendered offscreen (a GPU, or Mesa's software
//! Vulkan where there is none) from the URDF camera's pose with gazebo_ros_camera's intrinsics,
//! read back as RGB8 at the sensor's size, then post-processed (distortion, noise).

use glam::{Mat4, Vec4};

use crate::geometry::Pose;
use crate::model::camera_info::{CameraInfo, link_from_optical};
use crate::model::robot::RobotModel;
use crate::model::sensors::CameraConfig;
use crate::model::world::World;
use crate::render::gpu::RenderError;
use crate::render::gpu::{Gpu, Readback};
use crate::render::passes::colour::{ColourPass, View};
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
        let colour = ColourPass::new(
            &gpu.device,
            w,
            h,
            world.ground.checker_color,
            world.ground.checker_size_m as f32,
        );
        let readback = Readback::new(&gpu.device, "camera readback", w, h);
        let scene = Scene::new(&gpu.device, world, robot)?;
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
        })
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

    /// Whether some SDF model link can move (so [`Self::set_model_link_poses`] matters).
    pub fn has_moving_models(&self) -> bool {
        self.scene.has_moving_models()
    }

    /// Moves the visuals of moving SDF model links to `world_from_model_links` (every model
    /// link in world order, as [`crate::Simulation::model_link_poses_into`] gives them).
    pub fn set_model_link_poses(&mut self, world_from_model_links: &[Pose]) {
        self.scene.set_model_link_poses(world_from_model_links);
    }

    /// Moves person `index` (world order) to `world_from_person` for the following renders.
    pub fn set_person_pose(&mut self, index: usize, world_from_person: Pose) {
        self.scene.set_person_pose(index, world_from_person);
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
        self.scene.upload(&self.gpu.queue);
        let view = View {
            projection: self.projection(),
            world_from_optical: world_from_camera * Pose::from_rotation(link_from_optical()),
        };
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.colour
            .encode(&self.gpu.queue, &mut encoder, &self.scene, &view);
        self.readback.copy_from(&mut encoder, &self.colour.target);
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
        Ok(&self.post.rgb)
    }
}
