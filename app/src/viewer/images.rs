//! Camera images for Rerun: at a chosen rate, downscaled and/or JPEG-encoded for long runs.

use rerun::RecordingStream;
use rover_sim::sensors::CameraFrame;

/// Entity path of the camera image.
pub(super) const IMAGE_PATH: &str = "world/robot/camera/image";
/// Entity path of a depth camera's depth image (metres, under the camera's pinhole).
pub(super) const DEPTH_PATH: &str = "world/robot/camera/image/depth";

/// How camera images are logged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageOptions {
    /// Images per sim second (None = every camera frame).
    pub rate_hz: Option<f64>,
    /// Downscale factor (1 = full size, 2 = half width and height, ...).
    pub downscale: u32,
    /// JPEG quality (None = raw RGB).
    pub jpeg_quality: Option<u8>,
}

impl Default for ImageOptions {
    fn default() -> Self {
        Self {
            rate_hz: None,
            downscale: 1,
            jpeg_quality: None,
        }
    }
}

impl ImageOptions {
    /// The logged size of a `w` x `h` camera image.
    pub fn scaled_size(&self, w: u32, h: u32) -> (u32, u32) {
        let f = self.downscale.max(1);
        (w / f, h / f)
    }

    /// Pixels of the camera image per logged pixel.
    pub fn scale(&self) -> f32 {
        self.downscale.max(1) as f32
    }
}

/// Logs camera images as [`ImageOptions`] say. Buffers are reused; each logged image hands
/// Rerun one buffer it owns (no copy of an encoded JPEG).
#[derive(Debug)]
pub(super) struct ImageLogger {
    options: ImageOptions,
    next_image_s: f64,
    scaled: Vec<u8>,
    jpeg_capacity: usize,
}

impl ImageLogger {
    pub fn new(options: ImageOptions) -> Self {
        Self {
            options,
            next_image_s: 0.0,
            scaled: Vec::new(),
            jpeg_capacity: 0,
        }
    }

    /// The options it logs with.
    pub fn options(&self) -> &ImageOptions {
        &self.options
    }

    /// True when `frame` is due under the image rate; advances the schedule.
    pub fn due(&mut self, sim_time_s: f64) -> bool {
        if sim_time_s + 1e-9 < self.next_image_s {
            return false;
        }
        if let Some(hz) = self.options.rate_hz.filter(|hz| *hz > 0.0) {
            self.next_image_s = sim_time_s + 1.0 / hz - 1e-6;
        }
        true
    }

    /// Logs `frame` at the current time of `rec`.
    pub fn log(&mut self, rec: &RecordingStream, frame: &CameraFrame<'_>) {
        let factor = self.options.downscale.max(1);
        let (w, h) = self.options.scaled_size(frame.width, frame.height);
        let pixels: &[u8] = if factor == 1 {
            frame.rgb
        } else {
            downscale_into(
                frame.rgb,
                frame.width,
                frame.height,
                factor,
                &mut self.scaled,
            );
            &self.scaled
        };
        let result = match self.options.jpeg_quality {
            None => rec.log(
                IMAGE_PATH,
                &rerun::Image::from_rgb24(pixels.to_vec(), [w, h]),
            ),
            Some(q) => {
                // Encoded straight into the buffer Rerun takes over, sized from the last one.
                let mut jpeg = Vec::with_capacity(self.jpeg_capacity);
                let mut encoder = image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, q);
                if let Err(e) = encoder.encode(pixels, w, h, image::ExtendedColorType::Rgb8) {
                    tracing::warn!("rerun: JPEG encoding failed: {e}");
                    return;
                }
                self.jpeg_capacity = jpeg.len() + jpeg.len() / 8;
                rec.log(
                    IMAGE_PATH,
                    &rerun::EncodedImage::new(jpeg).with_media_type(rerun::MediaType::JPEG),
                )
            }
        };
        if let Err(e) = result {
            tracing::warn!("rerun: {IMAGE_PATH}: {e}");
        }
        // A depth camera's depth image, full size only (the pinhole is the logged size's).
        if let Some(depth) = frame.depth_m.filter(|_| factor == 1) {
            let bytes: Vec<u8> = depth.iter().flat_map(|m| m.to_le_bytes()).collect();
            let image = rerun::DepthImage::from_data_type_and_bytes(
                bytes,
                [frame.width, frame.height],
                rerun::datatypes::ChannelDatatype::F32,
            )
            .with_meter(1.0);
            if let Err(e) = rec.log(DEPTH_PATH, &image) {
                tracing::warn!("rerun: {DEPTH_PATH}: {e}");
            }
        }
    }
}

/// Box-filter downscale of RGB8 by an integer factor into `out` (reused).
fn downscale_into(rgb: &[u8], w: u32, h: u32, factor: u32, out: &mut Vec<u8>) {
    let f = factor.max(1) as usize;
    let (w, h) = (w as usize, h as usize);
    let (ow, oh) = (w / f, h / f);
    out.clear();
    out.resize(ow * oh * 3, 0);
    for y in 0..oh {
        for x in 0..ow {
            let mut sum = [0u32; 3];
            for dy in 0..f {
                let row = (y * f + dy) * w;
                for dx in 0..f {
                    let i = (row + x * f + dx) * 3;
                    if let Some(px) = rgb.get(i..i + 3) {
                        for (s, v) in sum.iter_mut().zip(px) {
                            *s += u32::from(*v);
                        }
                    }
                }
            }
            let o = (y * ow + x) * 3;
            for (dst, s) in out[o..o + 3].iter_mut().zip(sum) {
                *dst = (s / (f * f) as u32) as u8;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downscale_averages_blocks() {
        // 4x2 image, two 2x2 blocks: black/white checker -> grey, all 100 -> 100.
        let rgb: Vec<u8> = [0u8, 255, 100, 100, 255, 0, 100, 100]
            .iter()
            .flat_map(|v| [*v, *v, *v])
            .collect();
        let mut out = Vec::new();
        downscale_into(&rgb, 4, 2, 2, &mut out);
        assert_eq!(out, vec![127, 127, 127, 100, 100, 100]);
    }

    #[test]
    fn the_image_rate_skips_frames_on_sim_time() {
        let mut logger = ImageLogger::new(ImageOptions {
            rate_hz: Some(10.0),
            ..ImageOptions::default()
        });
        let due: Vec<bool> = (0..10).map(|i| logger.due(f64::from(i) / 30.0)).collect();
        // 30 Hz camera, 10 Hz images: every third frame.
        assert_eq!(
            due,
            [
                true, false, false, true, false, false, true, false, false, true
            ]
        );
    }
}
