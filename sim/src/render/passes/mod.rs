//! Render passes, one per file. Each owns its pipeline and targets and draws the shared
//! [`crate::render::scene::Scene`]; a new output (depth, ...) is a new file here plus one line
//! where the renderer records its passes. The colour pass also writes the instance-id image
//! (same draw); the silhouette pass gives each labelled thing's unoccluded pixel count.

pub(crate) mod colour;
pub(crate) mod silhouette;

use crate::render::scene::vertex_buffer_layouts;

/// A pipeline that draws the scene's meshes with `shader` (`vs_main`, `fs_main`) into
/// `targets`. Every pass culls the same back faces as the colour pass, so what another pass
/// draws of a thing is what the colour pass would (meshes wind counter-clockwise seen from
/// outside; culling back faces also hides the inside of the camera's own link visual, which the
/// camera sits in, as in Gazebo).
pub(crate) fn scene_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    depth_stencil: Option<wgpu::DepthStencilState>,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &vertex_buffer_layouts(),
        },
        primitive: wgpu::PrimitiveState {
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: Some(wgpu::Face::Back),
            ..Default::default()
        },
        depth_stencil,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: shader,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// A pass's uniform buffer and the bind group (one buffer at binding 0) that hands it to the
/// pass's shaders.
pub(crate) struct Uniform {
    /// The buffer, written before each draw.
    pub(crate) buffer: wgpu::Buffer,
    /// The bind group's layout, for the pass's pipeline layout.
    pub(crate) layout: wgpu::BindGroupLayout,
    /// The bind group.
    pub(crate) bind_group: wgpu::BindGroup,
}

/// A uniform buffer of `size` bytes seen by the shader stages `visibility`, labelled `label`.
pub(crate) fn uniform(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    visibility: wgpu::ShaderStages,
) -> Uniform {
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(&format!("{label} globals")),
        size,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(&format!("{label} layout")),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    });
    Uniform {
        buffer,
        layout,
        bind_group,
    }
}
