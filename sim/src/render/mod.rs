//! Offscreen camera rendering with wgpu (a GPU, or Mesa's software Vulkan where there is none):
//! the world and the robot's own visuals from the URDF camera's pose, read back as RGB8 at the
//! sensor's size, with gazebo_ros_camera's intrinsics, optional gaussian noise and lens
//! distortion. No window, no surface: it runs headless.

pub mod meshes;

use crate::noise::Rng;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use glam::{Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use crate::camera::{CameraInfo, link_from_optical};
use crate::error::SimError;
use crate::gazebo::{CameraConfig, Distortion, GaussianNoise};
use crate::geometry::{Pose, Rgba};
use crate::robot::RobotModel;
use crate::world::World;
use meshes::{MeshData, Vertex, cuboid, object_mesh, person_parts, shape_mesh};

/// Why the camera cannot render.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No GPU and no software renderer.
    #[error(
        "no graphics adapter found ({0}); without a GPU rover renders with Mesa's software Vulkan: install it (Debian/Ubuntu: sudo apt-get install mesa-vulkan-drivers)"
    )]
    NoAdapter(String),
    /// The adapter refused a device.
    #[error("the graphics adapter {adapter} refused a device: {message}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// wgpu's message.
        message: String,
    },
    /// A mesh file or the scene could not be loaded.
    #[error(transparent)]
    Scene(#[from] SimError),
    /// Reading the image back failed.
    #[error("reading the camera image back failed: {0}")]
    Readback(String),
}

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    camera_pos: [f32; 4],
    sun: [f32; 4],
    ambient: [f32; 4],
    checker: [f32; 4],
    sky: [f32; 4],
}

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Instance {
    model: [[f32; 4]; 4],
    color: [f32; 4],
}

struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

/// A robot visual whose instance follows its link.
#[derive(Debug, Clone, Copy)]
struct Attached {
    instance: usize,
    link: usize,
    link_from_shape: Pose,
}

const SKY: [f32; 3] = [0.62, 0.75, 0.9];
const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Renders the robot's camera.
pub struct CameraRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    color: wgpu::Texture,
    color_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row: u32,
    meshes: Vec<GpuMesh>,
    instances: Vec<Instance>,
    instance_buffer: wgpu::Buffer,
    attached: Vec<Attached>,
    /// Parts of the people (`link` = person index, `link_from_shape` = person_from_part).
    people: Vec<Attached>,
    /// Visuals of moving SDF model links (`link` indexes model links in world order).
    models: Vec<Attached>,
    info: CameraInfo,
    checker: Rgba,
    checker_size_m: f32,
    near_m: f32,
    far_m: f32,
    ideal: Vec<u8>,
    rgb: Vec<u8>,
    noise: Option<(GaussianNoise, Rng)>,
    /// The noise seed; each frame's noise comes from it and the frame number.
    noise_seed: u64,
    distortion_map: Option<Vec<[f32; 2]>>,
    adapter: String,
    mapped: Arc<AtomicU8>,
}

const MAP_PENDING: u8 = 0;
const MAP_OK: u8 = 1;
const MAP_FAILED: u8 = 2;

impl std::fmt::Debug for CameraRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CameraRenderer")
            .field("adapter", &self.adapter)
            .field("size", &(self.info.width, self.info.height))
            .finish_non_exhaustive()
    }
}

fn instance(pose: Pose, color: Rgba) -> Instance {
    Instance {
        model: Mat4::from_rotation_translation(pose.rotation, pose.translation).to_cols_array_2d(),
        color: color.0,
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
        // Native APIs first (Vulkan covers Mesa's software lavapipe); OpenGL only as a fallback,
        // because probing EGL without a display prints errors.
        let request = |backends: wgpu::Backends| {
            let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
                backends,
                ..wgpu::InstanceDescriptor::new_without_display_handle()
            });
            pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter: false,
                compatible_surface: None,
                ..Default::default()
            }))
        };
        let adapter =
            request(wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12)
                .or_else(|_| request(wgpu::Backends::GL))
                .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        let adapter_name = adapter.get_info().name;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("rover camera"),
            ..Default::default()
        }))
        .map_err(|e| RenderError::Device {
            adapter: adapter_name.clone(),
            message: e.to_string(),
        })?;

        let info = CameraInfo::from_config(camera);
        let (w, h) = (info.width, info.height);
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("camera shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shader.wgsl").into()),
        });
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("globals layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("globals"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("camera pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let vertex_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
        };
        let instance_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Instance>() as u64,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &wgpu::vertex_attr_array![2 => Float32x4, 3 => Float32x4, 4 => Float32x4, 5 => Float32x4, 6 => Float32x4],
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("camera pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout), Some(instance_layout)],
            },
            primitive: wgpu::PrimitiveState {
                // Meshes wind counter-clockwise seen from outside. Culling back faces also hides
                // the inside of the camera's own link visual, which the camera sits in (as in
                // Gazebo).
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: Some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(COLOR_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let extent = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        let color = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("camera color"),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: COLOR_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("camera depth"),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let padded_row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("camera readback"),
            size: u64::from(padded_row) * u64::from(h),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });

        // Scene: every mesh uploaded once; one instance per mesh.
        let mut meshes = Vec::new();
        let mut instances = Vec::new();
        let mut attached = Vec::new();
        let mut add = |mesh: &MeshData, inst: Instance| {
            meshes.push(GpuMesh {
                vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: None,
                    contents: bytemuck::cast_slice(&mesh.vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: None,
                    contents: bytemuck::cast_slice(&mesh.indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
                count: mesh.indices.len() as u32,
            });
            instances.push(inst);
            instances.len() - 1
        };
        let [gx, gy] = world.ground.size_m;
        let ground = cuboid(Vec3::new(gx as f32, gy as f32, 0.02));
        let mut ground_color = world.ground.color;
        ground_color.0[3] = -1.0;
        add(
            &ground,
            instance(
                Pose::from_translation(Vec3::new(0.0, 0.0, -0.01)),
                ground_color,
            ),
        );
        for object in &world.objects {
            let mesh = object_mesh(&object.shape);
            add(&mesh, instance(object.world_from_object(), object.color));
        }
        let mut model_parts_at = Vec::new();
        let model_links = world
            .models
            .iter()
            .flat_map(|m| m.links.iter().map(move |l| (m, l)));
        for (link_index, (model, link)) in model_links.enumerate() {
            for visual in &link.visuals {
                let mesh = shape_mesh(&visual.shape)?;
                let pose = link.world_from_link * visual.link_from_shape;
                let index = add(&mesh, instance(pose, visual.display_color(&mesh)));
                if link.is_dynamic(model) {
                    model_parts_at.push(Attached {
                        instance: index,
                        link: link_index,
                        link_from_shape: visual.link_from_shape,
                    });
                }
            }
        }
        let mut person_parts_at = Vec::new();
        for (person_index, person) in world.people.iter().enumerate() {
            let world_from_person = person.world_from_person(0.0);
            for part in person_parts(person) {
                let index = add(
                    &part.mesh,
                    instance(world_from_person * part.pose, part.color),
                );
                person_parts_at.push(Attached {
                    instance: index,
                    link: person_index,
                    link_from_shape: part.pose,
                });
            }
        }
        for (link_index, link) in robot.links.iter().enumerate() {
            for visual in &link.visuals {
                let mesh = shape_mesh(&visual.shape)?;
                let index = add(
                    &mesh,
                    instance(visual.link_from_shape, visual.display_color(&mesh)),
                );
                attached.push(Attached {
                    instance: index,
                    link: link_index,
                    link_from_shape: visual.link_from_shape,
                });
            }
        }
        let instance_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("instances"),
            contents: bytemuck::cast_slice(&instances),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });

        let pixels = (w * h) as usize;
        let mut renderer = Self {
            color_view: color.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            color,
            device,
            queue,
            pipeline,
            globals,
            bind_group,
            readback,
            padded_row,
            meshes,
            instances,
            instance_buffer,
            attached,
            people: person_parts_at,
            models: model_parts_at,
            checker: world.ground.checker_color,
            checker_size_m: world.ground.checker_size_m as f32,
            near_m: camera.clip_near_m as f32,
            far_m: camera.clip_far_m as f32,
            ideal: vec![0; pixels * 3],
            rgb: vec![0; pixels * 3],
            noise: camera.noise.map(|n| (n, Rng(seed ^ 0x5EED_CA3E_5EED_CA3E))),
            noise_seed: seed ^ 0x5EED_CA3E_5EED_CA3E,
            distortion_map: None,
            adapter: adapter_name,
            mapped: Arc::new(AtomicU8::new(MAP_PENDING)),
            info,
        };
        if !camera.distortion.is_zero() {
            renderer.distortion_map = Some(distortion_map(&renderer.info, &camera.distortion));
        }
        Ok(renderer)
    }

    /// The intrinsics (CameraInfo) images are rendered with.
    pub fn info(&self) -> &CameraInfo {
        &self.info
    }

    /// The graphics adapter in use (e.g. "llvmpipe" for Mesa's software Vulkan).
    pub fn adapter(&self) -> &str {
        &self.adapter
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
        !self.models.is_empty()
    }

    /// Moves the visuals of moving SDF model links to `world_from_model_links` (every model
    /// link in world order, as [`crate::Simulation::model_link_poses_into`] gives them).
    pub fn set_model_link_poses(&mut self, world_from_model_links: &[Pose]) {
        for a in &self.models {
            if let Some(link) = world_from_model_links.get(a.link) {
                let pose = *link * a.link_from_shape;
                self.instances[a.instance].model =
                    Mat4::from_rotation_translation(pose.rotation, pose.translation)
                        .to_cols_array_2d();
            }
        }
    }

    /// Moves person `index` (world order) to `world_from_person` for the following renders.
    pub fn set_person_pose(&mut self, index: usize, world_from_person: Pose) {
        for a in self.people.iter().filter(|a| a.link == index) {
            let pose = world_from_person * a.link_from_shape;
            self.instances[a.instance].model =
                Mat4::from_rotation_translation(pose.rotation, pose.translation).to_cols_array_2d();
        }
    }

    /// Seeds the next image's noise from the frame number, so that an image's noise does not
    /// depend on which earlier frames were rendered (headless runs skip the ones nobody uses).
    pub fn seed_frame(&mut self, frame: u64) {
        if let Some((_, rng)) = &mut self.noise {
            let mut mix = Rng(self.noise_seed ^ frame.wrapping_mul(0xA076_1D64_78BD_642F));
            *rng = Rng(mix.next_u64());
        }
    }

    /// Renders one image: `world_from_links` are the robot's link poses (URDF order),
    /// `world_from_camera` the pose of the camera's link. Returns RGB8 rows, top to bottom.
    pub fn render(
        &mut self,
        world_from_links: &[Pose],
        world_from_camera: Pose,
    ) -> Result<&[u8], RenderError> {
        for a in &self.attached {
            if let Some(link) = world_from_links.get(a.link) {
                let pose = *link * a.link_from_shape;
                self.instances[a.instance].model =
                    Mat4::from_rotation_translation(pose.rotation, pose.translation)
                        .to_cols_array_2d();
            }
        }
        self.queue.write_buffer(
            &self.instance_buffer,
            0,
            bytemuck::cast_slice(&self.instances),
        );
        let world_from_optical = world_from_camera * Pose::from_rotation(link_from_optical());
        let view = Mat4::from_rotation_translation(
            world_from_optical.rotation,
            world_from_optical.translation,
        )
        .inverse();
        // Late-morning sun from behind-left of a car facing +x.
        let sun = Vec3::new(0.45, -0.35, -0.82).normalize();
        let globals = Globals {
            view_proj: (self.projection() * view).to_cols_array_2d(),
            camera_pos: world_from_optical.translation.extend(1.0).to_array(),
            sun: sun.extend(0.75).to_array(),
            ambient: [0.45, 0.47, 0.5, self.checker_size_m],
            checker: self.checker.0,
            sky: [SKY[0], SKY[1], SKY[2], 80.0],
        };
        self.queue
            .write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));

        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("camera"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.color_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color {
                            r: f64::from(SKY[0]),
                            g: f64::from(SKY[1]),
                            b: f64::from(SKY[2]),
                            a: 1.0,
                        }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.set_vertex_buffer(1, self.instance_buffer.slice(..));
            for (i, mesh) in self.meshes.iter().enumerate() {
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.count, 0, i as u32..i as u32 + 1);
            }
        }
        encoder.copy_texture_to_buffer(
            self.color.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.info.height),
                },
            },
            wgpu::Extent3d {
                width: self.info.width,
                height: self.info.height,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([encoder.finish()]);
        let slice = self.readback.slice(..);
        // One flag for the renderer's life (no channel per frame): the callback has run once
        // the blocking poll below returns.
        self.mapped.store(MAP_PENDING, Ordering::Release);
        let mapped = Arc::clone(&self.mapped);
        slice.map_async(wgpu::MapMode::Read, move |r| {
            mapped.store(
                if r.is_ok() { MAP_OK } else { MAP_FAILED },
                Ordering::Release,
            );
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        match self.mapped.load(Ordering::Acquire) {
            MAP_OK => {}
            MAP_FAILED => {
                return Err(RenderError::Readback(
                    "the readback buffer could not be mapped".into(),
                ));
            }
            _ => {
                return Err(RenderError::Readback(
                    "the GPU finished without mapping the readback buffer".into(),
                ));
            }
        }
        {
            let data = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Readback(e.to_string()))?;
            let (w, h) = (self.info.width as usize, self.info.height as usize);
            for y in 0..h {
                let row = &data[y * self.padded_row as usize..][..w * 4];
                let out = &mut self.ideal[y * w * 3..][..w * 3];
                for (o, px) in out.chunks_exact_mut(3).zip(row.chunks_exact(4)) {
                    o.copy_from_slice(&px[..3]);
                }
            }
        }
        self.readback.unmap();
        self.post_process();
        Ok(&self.rgb)
    }

    /// Distortion (remap through the precomputed table) and noise, into `self.rgb`.
    fn post_process(&mut self) {
        let (w, h) = (self.info.width as usize, self.info.height as usize);
        match &self.distortion_map {
            None => self.rgb.copy_from_slice(&self.ideal),
            Some(map) => {
                for (i, src) in map.iter().enumerate() {
                    let (sx, sy) = (src[0], src[1]);
                    let out = &mut self.rgb[i * 3..i * 3 + 3];
                    if sx < 0.0 || sy < 0.0 || sx > (w - 1) as f32 || sy > (h - 1) as f32 {
                        out.copy_from_slice(&[0, 0, 0]);
                        continue;
                    }
                    let (x0, y0) = (sx.floor() as usize, sy.floor() as usize);
                    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                    let (fx, fy) = (sx - x0 as f32, sy - y0 as f32);
                    for (c, o) in out.iter_mut().enumerate() {
                        let p = |x: usize, y: usize| f32::from(self.ideal[(y * w + x) * 3 + c]);
                        let v = (p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx) * (1.0 - fy)
                            + (p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx) * fy;
                        *o = v.round().clamp(0.0, 255.0) as u8;
                    }
                }
            }
        }
        if let Some((noise, rng)) = &mut self.noise {
            let mut chunks = self.rgb.chunks_exact_mut(2);
            for pair in &mut chunks {
                let (a, b) = rng.normal_pair();
                for (v, z) in pair.iter_mut().zip([a, b]) {
                    let x = f64::from(*v) / 255.0 + noise.mean + noise.stddev * z;
                    *v = (x * 255.0).round().clamp(0.0, 255.0) as u8;
                }
            }
            for v in chunks.into_remainder() {
                let x = f64::from(*v) / 255.0 + noise.mean + noise.stddev * rng.normal_pair().0;
                *v = (x * 255.0).round().clamp(0.0, 255.0) as u8;
            }
        }
    }
}

/// Brown-Conrady lens distortion as gazebo_ros_camera applies it, on normalised image
/// coordinates (x = (u - cx) / fx, y = (v - cy) / fy): the distorted point of an ideal one.
/// The renderer needs only its inverse ([`distortion_map`]); the tests check one against the
/// other.
#[cfg(test)]
pub(crate) fn distort(d: &Distortion, x: f64, y: f64) -> (f64, f64) {
    let r2 = x * x + y * y;
    let radial = 1.0 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
    let dx = 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x);
    let dy = d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y;
    (x * radial + dx, y * radial + dy)
}

/// For each output (distorted) pixel, where to sample the ideal pinhole render: [`distort`]
/// inverted by fixed-point iteration, computed once per camera.
pub(crate) fn distortion_map(info: &CameraInfo, d: &Distortion) -> Vec<[f32; 2]> {
    let (fx, cx, cy) = (info.k[0], info.k[2], info.k[5]);
    let (w, h) = (info.width as usize, info.height as usize);
    let mut map = Vec::with_capacity(w * h);
    for v in 0..h {
        for u in 0..w {
            let (xd, yd) = ((u as f64 - cx) / fx, (v as f64 - cy) / fx);
            let (mut x, mut y) = (xd, yd);
            for _ in 0..20 {
                let r2 = x * x + y * y;
                let radial = 1.0 + d.k1 * r2 + d.k2 * r2 * r2 + d.k3 * r2 * r2 * r2;
                let dx = 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x);
                let dy = d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y;
                x = (xd - dx) / radial;
                y = (yd - dy) / radial;
            }
            map.push([(x * fx + cx) as f32, (y * fx + cy) as f32]);
        }
    }
    map
}

#[cfg(test)]
mod distortion_tests {
    use super::*;

    fn info() -> CameraInfo {
        CameraInfo::from_config(&crate::camera::tests::seed_config())
    }

    #[test]
    fn no_distortion_samples_every_pixel_where_it_is() {
        let info = info();
        let map = distortion_map(&info, &Distortion::default());
        let w = info.width as usize;
        for (u, v) in [(0usize, 0usize), (320, 240), (639, 479), (17, 401)] {
            let [sx, sy] = map[v * w + u];
            assert!(
                (sx - u as f32).abs() < 1e-3 && (sy - v as f32).abs() < 1e-3,
                "{u},{v}"
            );
        }
    }

    #[test]
    fn the_map_inverts_brown_conrady() {
        let info = info();
        let d = Distortion {
            k1: -0.25,
            k2: 0.12,
            k3: -0.02,
            p1: 0.001,
            p2: -0.0015,
        };
        let map = distortion_map(&info, &d);
        let (fx, cx, cy) = (info.k[0], info.k[2], info.k[5]);
        let w = info.width as usize;
        for (u, v) in [
            (0usize, 0usize),
            (320, 240),
            (639, 479),
            (100, 400),
            (600, 30),
        ] {
            let [sx, sy] = map[v * w + u];
            // Distorting the ideal point we sample must land back on the output pixel.
            let (xd, yd) = distort(&d, (f64::from(sx) - cx) / fx, (f64::from(sy) - cy) / fx);
            let (ud, vd) = (xd * fx + cx, yd * fx + cy);
            assert!(
                (ud - u as f64).abs() < 0.01 && (vd - v as f64).abs() < 0.01,
                "{u},{v}: {ud},{vd}"
            );
        }
        // Barrel distortion (k1 < 0): a corner of the image sees further out than a pinhole.
        let [sx, sy] = map[0];
        assert!(
            sx < 0.0 && sy < 0.0,
            "corner samples outside the ideal image: {sx},{sy}"
        );
    }
}
