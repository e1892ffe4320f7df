//! Surfaces on the GPU: each mesh file's diffuse textures uploaded once (with mipmaps made on
//! the CPU, so a far textured model does not shimmer), and the bind group a draw uses: a
//! texture, its sampler and whether to show it. Untextured draws share one bind group whose
//! flag says "use the instance colour".

use std::sync::Arc;

use wgpu::util::DeviceExt;

use crate::model::mesh::TextureImage;

/// Group 1 of the colour pass: the draw's texture and its flag.
pub(crate) struct Materials {
    pub(crate) layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// Bind group 0 is the untextured one; the others follow `textures`.
    pub(crate) groups: Vec<wgpu::BindGroup>,
    textures: Vec<Arc<TextureImage>>,
}

impl Materials {
    pub(crate) fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("material layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("texture sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let mut materials = Self {
            layout,
            sampler,
            groups: Vec::new(),
            textures: Vec::new(),
        };
        let white = TextureImage {
            path: "white".into(),
            width: 1,
            height: 1,
            rgba: vec![255; 4],
        };
        let group = materials.bind_group(device, queue, &white, false);
        materials.groups.push(group);
        materials
    }

    /// The bind group index of `texture`, uploading it the first time it is seen.
    pub(crate) fn textured(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &Arc<TextureImage>,
    ) -> u32 {
        if let Some(i) = self.textures.iter().position(|t| Arc::ptr_eq(t, texture)) {
            return i as u32 + 1;
        }
        let group = self.bind_group(device, queue, texture, true);
        self.groups.push(group);
        self.textures.push(Arc::clone(texture));
        self.textures.len() as u32
    }

    fn bind_group(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        image: &TextureImage,
        textured: bool,
    ) -> wgpu::BindGroup {
        let levels = mip_chain(image);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("diffuse texture"),
            size: wgpu::Extent3d {
                width: image.width,
                height: image.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (level, (w, h, rgba)) in levels.iter().enumerate() {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: level as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                rgba,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * w),
                    rows_per_image: Some(*h),
                },
                wgpu::Extent3d {
                    width: *w,
                    height: *h,
                    depth_or_array_layers: 1,
                },
            );
        }
        let flag = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("material flag"),
            contents: bytemuck::cast_slice(&[if textured { 1.0f32 } else { 0.0 }, 0.0, 0.0, 0.0]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = texture.create_view(&Default::default());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("material"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: flag.as_entire_binding(),
                },
            ],
        })
    }
}

/// The image and its mipmaps down to 1 x 1, each level the 2 x 2 average of the one before
/// (an odd last row or column is dropped): (width, height, RGBA8).
fn mip_chain(image: &TextureImage) -> Vec<(u32, u32, Vec<u8>)> {
    let mut levels = vec![(image.width, image.height, image.rgba.clone())];
    while let Some((w, h, rgba)) = levels.last() {
        let (w, h) = (*w as usize, *h as usize);
        if w <= 1 && h <= 1 {
            break;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = vec![0u8; nw * nh * 4];
        for y in 0..nh {
            for x in 0..nw {
                for c in 0..4 {
                    let mut sum = 0u32;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let sx = (2 * x + dx).min(w - 1);
                        let sy = (2 * y + dy).min(h - 1);
                        sum += u32::from(rgba[(sy * w + sx) * 4 + c]);
                    }
                    next[(y * nw + x) * 4 + c] = ((sum + 2) / 4) as u8;
                }
            }
        }
        levels.push((nw as u32, nh as u32, next));
    }
    levels
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mipmaps_halve_down_to_one_pixel_and_average() {
        let image = TextureImage {
            path: "t".into(),
            width: 4,
            height: 2,
            rgba: [[0u8, 0, 0, 255], [200, 100, 50, 255]]
                .iter()
                .cycle()
                .take(8)
                .flatten()
                .copied()
                .collect(),
        };
        let levels = mip_chain(&image);
        let sizes: Vec<(u32, u32)> = levels.iter().map(|(w, h, _)| (*w, *h)).collect();
        assert_eq!(sizes, [(4, 2), (2, 1), (1, 1)]);
        assert_eq!(levels[2].2, vec![100, 50, 25, 255]);
    }
}
