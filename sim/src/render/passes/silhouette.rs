//! The silhouette draws: the pixels each labelled thing would cover with nothing in front of it
//! (no depth test, only labelled meshes), as one bit per pixel in a mask per entity, counted on
//! the CPU after read back. Against the id image's visible pixels this gives each thing's
//! visibility fraction. They are recorded at the end of the colour pass (its targets masked
//! off): a pass of their own cost 2.4 ms more on llvmpipe. Allocated only when ground truth is
//! asked for.

use glam::Mat4;

use crate::render::gpu::{BufferReadback, RenderError};
use crate::render::passes::colour::{COLOR_FORMAT, DEPTH_FORMAT, ID_FORMAT, View};
use crate::render::scene::{Scene, vertex_buffer_layouts};

#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    size: [u32; 4],
}

/// The pipeline, the masks and their read back, created once.
pub(crate) struct SilhouettePass {
    pipeline: wgpu::RenderPipeline,
    globals: wgpu::Buffer,
    masks: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    readback: BufferReadback,
    width: u32,
    words_per_entity: u32,
    entities: u32,
    /// Zeroes the masks each frame (allocated once).
    zeros: Vec<u8>,
}

impl SilhouettePass {
    /// Masks for `entities` labelled things in a `width` x `height` image.
    pub(crate) fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        entities: u32,
    ) -> Result<Self, RenderError> {
        let words_per_entity = (width * height).div_ceil(32);
        let mask_bytes = u64::from(words_per_entity) * u64::from(entities.max(1)) * 4;
        if mask_bytes > device.limits().max_storage_buffer_binding_size {
            return Err(RenderError::Readback(format!(
                "{entities} labelled things need {mask_bytes} bytes of silhouette masks, more than this adapter binds ({})",
                device.limits().max_storage_buffer_binding_size
            )));
        }
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("silhouette globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let masks = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("silhouette masks"),
            size: mask_bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("silhouette layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("silhouette"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: globals.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: masks.as_entire_binding(),
                },
            ],
        });
        Ok(Self {
            pipeline: pipeline(device, &layout),
            globals,
            readback: BufferReadback::new(device, "silhouette readback", mask_bytes),
            masks,
            bind_group,
            width,
            words_per_entity,
            entities,
            zeros: vec![0; mask_bytes as usize],
        })
    }

    /// Uploads this frame's uniforms and zeroes the masks (queue writes, before the frame's
    /// commands: no transfer between the passes, which would stall a software rasterizer).
    pub(crate) fn prepare(&self, queue: &wgpu::Queue, view: &View) {
        let world_from_optical = view.world_from_optical;
        let view_matrix = Mat4::from_rotation_translation(
            world_from_optical.rotation,
            world_from_optical.translation,
        )
        .inverse();
        let globals = Globals {
            view_proj: (view.projection * view_matrix).to_cols_array_2d(),
            size: [self.width, self.words_per_entity, 0, 0],
        };
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));
        queue.write_buffer(&self.masks, 0, &self.zeros);
    }

    /// Records the draws into the colour pass (after [`Self::prepare`]).
    pub(crate) fn draw(&self, pass: &mut wgpu::RenderPass<'_>, scene: &Scene) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_vertex_buffer(1, scene.instance_buffer.slice(..));
        for &i in &scene.labelled {
            let mesh = &scene.meshes[i as usize];
            pass.set_vertex_buffer(0, mesh.vertices.slice(..));
            pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.count, 0, i..i + 1);
        }
    }

    /// Records the copy of the masks for read back (after [`Self::encode`]).
    pub(crate) fn copy_out(&self, encoder: &mut wgpu::CommandEncoder) {
        self.readback.copy_from(encoder, &self.masks);
    }

    /// After the submitted frame: the number of pixels each entity covers (index `id - 1`),
    /// into `counts` (resized to the number of entities).
    pub(crate) fn read_counts(
        &self,
        device: &wgpu::Device,
        counts: &mut Vec<u32>,
    ) -> Result<(), RenderError> {
        counts.clear();
        counts.resize(self.entities as usize, 0);
        let words = self.words_per_entity as usize;
        self.readback.read(device, |bytes| {
            for (count, mask) in counts.iter_mut().zip(bytes.chunks_exact(words * 4)) {
                let mut pairs = mask.chunks_exact(8);
                let mut sum = 0;
                for pair in &mut pairs {
                    let mut word = [0u8; 8];
                    word.copy_from_slice(pair);
                    sum += u64::from_ne_bytes(word).count_ones();
                }
                for byte in pairs.remainder() {
                    sum += byte.count_ones();
                }
                *count = sum;
            }
        })
    }
}

fn pipeline(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::RenderPipeline {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("silhouette shader"),
        source: wgpu::ShaderSource::Wgsl(include_str!("silhouette.wgsl").into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("silhouette pipeline layout"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("silhouette pipeline"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &shader,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &vertex_buffer_layouts(),
        },
        primitive: wgpu::PrimitiveState {
            // Back faces culled as in the colour pass, so a silhouette is what that pass would
            // draw with nothing in front.
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: Some(wgpu::Face::Back),
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &shader,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            // The colour pass's targets, left untouched.
            targets: &[
                Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::empty(),
                }),
                Some(wgpu::ColorTargetState {
                    format: ID_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::empty(),
                }),
            ],
        }),
        multiview_mask: None,
        cache: None,
    })
}
