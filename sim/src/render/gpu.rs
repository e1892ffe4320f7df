//! The GPU context the renderer's passes share: adapter and device (a GPU, or Mesa's software
//! Vulkan where there is none; no window, no surface) and the read back of a rendered texture
//! into reused CPU memory.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use crate::error::SimError;

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

/// A device and its queue, with the adapter's name for messages.
pub(crate) struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) adapter: String,
}

impl Gpu {
    /// Native APIs first (Vulkan covers Mesa's software lavapipe); OpenGL only as a fallback,
    /// because probing EGL without a display prints errors.
    pub(crate) fn new() -> Result<Self, RenderError> {
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
        Ok(Self {
            device,
            queue,
            adapter: adapter_name,
        })
    }
}

const MAP_PENDING: u8 = 0;
const MAP_OK: u8 = 1;
const MAP_FAILED: u8 = 2;

/// A mappable buffer a texture (all its array layers) is copied into, allocated once.
pub(crate) struct Readback {
    buffer: wgpu::Buffer,
    padded_row: u32,
    /// Bytes of a row's texels.
    row_bytes: u32,
    width: u32,
    height: u32,
    layers: u32,
    /// One flag for the renderer's life (no channel per frame): the map callback has run once
    /// the blocking poll returns.
    mapped: Arc<AtomicU8>,
}

impl Readback {
    /// A buffer for `width` x `height` texels of 4 bytes.
    pub(crate) fn new(device: &wgpu::Device, label: &str, width: u32, height: u32) -> Self {
        Self::layered(device, label, [width, height, 1], 4)
    }

    /// A buffer for the first `size[2]` layers of a `size[0]` x `size[1]` texture array of
    /// `texel_bytes`-byte texels.
    pub(crate) fn layered(
        device: &wgpu::Device,
        label: &str,
        [width, height, layers]: [u32; 3],
        texel_bytes: u32,
    ) -> Self {
        let row_bytes = width * texel_bytes;
        let padded_row = row_bytes.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
            * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: u64::from(padded_row) * u64::from(height) * u64::from(layers.max(1)),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            buffer,
            padded_row,
            row_bytes,
            width,
            height,
            layers,
            mapped: Arc::new(AtomicU8::new(MAP_PENDING)),
        }
    }

    /// Records the copy of `texture` (same size, at least as many layers) into the buffer.
    pub(crate) fn copy_from(&self, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture) {
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: self.layers,
            },
        );
    }

    /// Waits for the submitted copy and hands each row's texel bytes to `row`, top to bottom
    /// and layer after layer: row `y` is row `y % height` of layer `y / height`.
    pub(crate) fn read_rows(
        &self,
        device: &wgpu::Device,
        mut row: impl FnMut(usize, &[u8]),
    ) -> Result<(), RenderError> {
        let (bytes, padded) = (self.row_bytes as usize, self.padded_row as usize);
        read_mapped(device, &self.buffer, &self.mapped, |data| {
            for y in 0..(self.height * self.layers) as usize {
                row(y, &data[y * padded..][..bytes]);
            }
        })
    }
}

/// Maps `buffer` for reading, waits for the submitted work, hands its bytes to `read` and
/// unmaps it; `mapped` is the buffer's reusable flag.
fn read_mapped(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    mapped: &Arc<AtomicU8>,
    read: impl FnOnce(&[u8]),
) -> Result<(), RenderError> {
    let slice = buffer.slice(..);
    mapped.store(MAP_PENDING, Ordering::Release);
    let flag = Arc::clone(mapped);
    slice.map_async(wgpu::MapMode::Read, move |r| {
        flag.store(
            if r.is_ok() { MAP_OK } else { MAP_FAILED },
            Ordering::Release,
        );
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    match mapped.load(Ordering::Acquire) {
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
        read(&data);
    }
    buffer.unmap();
    Ok(())
}
