//! The colour pass: the scene shaded by a sun and an ambient term, the ground checkered, the
//! sky as clear colour, into an RGBA8 target the size of the image (with its depth buffer).
//! The same draw writes each pixel's labelled-entity id into a second, R32Uint target: the
//! instance-id image the ground truth reads (same frame, same depth test, no extra draw).

use glam::{Mat4, Vec3};

use crate::geometry::{Pose, Rgba};
use crate::model::world::World;
use crate::render::passes::{Uniform, scene_pipeline, uniform};
use crate::render::scene::Scene;

const SKY: [f32; 3] = [0.62, 0.75, 0.9];
/// The colour target's format.
pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// The id target's format.
pub(crate) const ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The depth buffer's format.
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

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

/// What the colour pass needs from the frame besides the scene.
pub(crate) struct View {
    /// Projection from the optical frame to clip space.
    pub(crate) projection: Mat4,
    /// The camera's optical frame.
    pub(crate) world_from_optical: Pose,
}

/// The pipeline, its uniforms and its targets, created once.
pub(crate) struct ColourPass {
    pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// The rendered image (RGBA8), copied out by the renderer's readback.
    pub(crate) target: wgpu::Texture,
    target_view: wgpu::TextureView,
    /// Each pixel's labelled-entity id (R32Uint, 0: nothing labelled).
    pub(crate) ids: wgpu::Texture,
    ids_view: wgpu::TextureView,
    /// The depth buffer (Depth32Float, 0 at the near clip, 1 at the far clip and where
    /// nothing was drawn), copied out for a depth camera.
    pub(crate) depth: wgpu::Texture,
    depth_view: wgpu::TextureView,
    checker: Rgba,
    checker_size_m: f32,
    /// The direction sunlight travels (world frame, unit).
    sun: Vec3,
    /// The sun's and the sky's strength.
    light: Light,
}

/// How the scene is lit, besides the sun's direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Light {
    /// The sun's strength on a surface facing it (rover's default 0.75).
    pub sun: f32,
    /// The sky's (ambient) light, as a multiple of rover's default (1.0).
    pub ambient: f32,
}

impl Default for Light {
    fn default() -> Self {
        Self {
            sun: 0.75,
            ambient: 1.0,
        }
    }
}

impl ColourPass {
    /// Builds the pipeline and `width` x `height` targets for `scene`, lit by `world`'s sun,
    /// its ground checkered as the world says.
    pub(crate) fn new(
        device: &wgpu::Device,
        scene: &Scene,
        width: u32,
        height: u32,
        world: &World,
    ) -> Self {
        let checker = world.ground.checker_color;
        let checker_size_m = world.ground.checker_size_m as f32;
        let [sx, sy, sz] = world.sun_direction.map(|v| v as f32);
        let sun = Vec3::new(sx, sy, sz).try_normalize().unwrap_or(Vec3::NEG_Z);
        let Uniform {
            buffer: globals,
            layout,
            bind_group,
        } = uniform(
            device,
            "colour",
            std::mem::size_of::<Globals>() as u64,
            wgpu::ShaderStages::VERTEX_FRAGMENT,
        );
        let pipeline = pipeline(device, &layout, &scene.materials.layout);
        let target = texture(device, "camera color", width, height, COLOR_FORMAT, true);
        let depth = texture(device, "camera depth", width, height, DEPTH_FORMAT, true);
        let ids = texture(device, "camera entity ids", width, height, ID_FORMAT, true);
        Self {
            pipeline,
            globals,
            bind_group,
            target_view: target.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            depth,
            target,
            ids_view: ids.create_view(&Default::default()),
            ids,
            checker,
            checker_size_m,
            sun,
            light: Light::default(),
        }
    }

    /// Lights the following frames with a sun travelling along `direction` (world frame; a
    /// zero vector keeps the current one) and `light`'s strengths.
    pub(crate) fn set_light(&mut self, direction: Vec3, light: Light) {
        if let Some(sun) = direction.try_normalize() {
            self.sun = sun;
        }
        self.light = light;
    }

    /// Uploads this frame's uniforms and records the pass.
    pub(crate) fn encode(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        scene: &Scene,
        view: &View,
    ) {
        let world_from_optical = view.world_from_optical;
        let view_matrix = Mat4::from_rotation_translation(
            world_from_optical.rotation,
            world_from_optical.translation,
        )
        .inverse();
        let sun = self.sun;
        let globals = Globals {
            view_proj: (view.projection * view_matrix).to_cols_array_2d(),
            camera_pos: world_from_optical.translation.extend(1.0).to_array(),
            sun: sun.extend(self.light.sun).to_array(),
            ambient: [
                0.45 * self.light.ambient,
                0.47 * self.light.ambient,
                0.5 * self.light.ambient,
                self.checker_size_m,
            ],
            checker: self.checker.0,
            sky: [SKY[0], SKY[1], SKY[2], 80.0],
        };
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("camera"),
            color_attachments: &[
                Some(wgpu::RenderPassColorAttachment {
                    view: &self.target_view,
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
                }),
                Some(wgpu::RenderPassColorAttachment {
                    view: &self.ids_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                }),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    // Kept: a depth camera reads it back.
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_vertex_buffer(1, scene.instance_buffer.slice(..));
        for (i, mesh) in scene.meshes.iter().enumerate() {
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            for draw in &mesh.draws {
                pass.set_bind_group(1, &scene.materials.groups[draw.material as usize], &[]);
                let indices = draw.first_index..draw.first_index + draw.count;
                pass.draw_indexed(indices, 0, i as u32..i as u32 + 1);
            }
        }
    }
}

fn pipeline(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    materials: &wgpu::BindGroupLayout,
) -> wgpu::RenderPipeline {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("camera shader"),
        source: wgpu::ShaderSource::Wgsl(include_str!("colour.wgsl").into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("camera pipeline layout"),
        bind_group_layouts: &[Some(layout), Some(materials)],
        immediate_size: 0,
    });
    scene_pipeline(
        device,
        "camera pipeline",
        &pipeline_layout,
        &shader,
        Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        &[Some(COLOR_FORMAT.into()), Some(ID_FORMAT.into())],
    )
}

/// A 2D render target; `readable` ones can be copied out.
pub(crate) fn texture(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    readable: bool,
) -> wgpu::Texture {
    let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
    if readable {
        usage |= wgpu::TextureUsages::COPY_SRC;
    }
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}
