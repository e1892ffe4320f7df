//! Offscreen camera rendering with wgpu: the GPU context (`gpu.rs`), the scene uploaded once
//! (`scene.rs`, from the triangles of `mesh.rs`, textures in `material.rs`), one file per render pass (`passes/`), CPU
//! post-processing (`post.rs`: distortion, noise) and the renderer that runs them
//! (`renderer.rs`). No window, no surface: it runs headless.

pub(crate) mod body;
pub(crate) mod gpu;
pub(crate) mod material;
pub(crate) mod mesh;
pub(crate) mod passes;
pub(crate) mod post;
pub(crate) mod renderer;
pub(crate) mod scene;

pub use body::{BodyLayer, SkinnedBody};
pub use gpu::RenderError;
pub use mesh::{
    LEG_SWING_RAD, Paint, PersonPart, Swing, object_mesh, person_parts, shape_mesh, visual_mesh,
};
pub use passes::colour::Light;
pub use renderer::{CameraRenderer, EntityImage};
