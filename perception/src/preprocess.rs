//! Letterboxing: an RGB8 image into the model's NCHW f32 input (aspect kept, grey 114 padding,
//! RGB, /255), and the mapping of boxes back to source pixels.

use crate::error::{PerceptionError, Result};

/// A borrowed RGB8 image, rows top to bottom, no padding between rows.
#[derive(Debug, Clone, Copy)]
pub struct RgbView<'a> {
    /// Width (px).
    pub width: usize,
    /// Height (px).
    pub height: usize,
    /// `width * height * 3` bytes.
    pub pixels: &'a [u8],
}

impl<'a> RgbView<'a> {
    /// Checks the buffer size.
    pub fn new(width: usize, height: usize, pixels: &'a [u8]) -> Result<Self> {
        if width == 0 || height == 0 || pixels.len() != width * height * 3 {
            return Err(PerceptionError::Image(format!(
                "{width}x{height} RGB8 needs {} bytes, got {}",
                width * height * 3,
                pixels.len()
            )));
        }
        Ok(Self {
            width,
            height,
            pixels,
        })
    }
}

/// How a source image sits in the model input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Letterbox {
    /// Source pixels to input pixels.
    pub scale: f32,
    /// Left padding (input px).
    pub pad_x: f32,
    /// Top padding (input px).
    pub pad_y: f32,
    /// Source width (px).
    pub src_w: usize,
    /// Source height (px).
    pub src_h: usize,
}

impl Letterbox {
    /// Fits `src_w x src_h` into `dst_w x dst_h`, centred, like Ultralytics' letterbox.
    pub fn fit(src_w: usize, src_h: usize, dst_w: usize, dst_h: usize) -> Self {
        let scale = (dst_w as f32 / src_w as f32).min(dst_h as f32 / src_h as f32);
        let new_w = (src_w as f32 * scale).round();
        let new_h = (src_h as f32 * scale).round();
        Self {
            scale,
            pad_x: ((dst_w as f32 - new_w) / 2.0 - 0.1).round().max(0.0),
            pad_y: ((dst_h as f32 - new_h) / 2.0 - 0.1).round().max(0.0),
            src_w,
            src_h,
        }
    }

    /// Input-pixel coordinates to source pixels, clipped to the image.
    pub fn to_source(&self, x: f32, y: f32) -> (f32, f32) {
        (
            ((x - self.pad_x) / self.scale).clamp(0.0, self.src_w as f32),
            ((y - self.pad_y) / self.scale).clamp(0.0, self.src_h as f32),
        )
    }

    /// Source-pixel coordinates to input pixels.
    pub fn to_input(&self, x: f32, y: f32) -> (f32, f32) {
        (x * self.scale + self.pad_x, y * self.scale + self.pad_y)
    }
}

/// Grey of the padding (Ultralytics' 114).
pub const PAD_VALUE: f32 = 114.0 / 255.0;

/// Writes `image` letterboxed into `input` (`[3, dst_h, dst_w]`, f32, RGB, 0..1) with bilinear
/// sampling (pixel centres aligned, like OpenCV's INTER_LINEAR). Allocates nothing.
pub fn letterbox_into(
    image: RgbView<'_>,
    input: &mut [f32],
    dst_w: usize,
    dst_h: usize,
) -> Result<Letterbox> {
    if input.len() != 3 * dst_w * dst_h {
        return Err(PerceptionError::Image(format!(
            "input buffer holds {} values, expected 3 x {dst_h} x {dst_w}",
            input.len()
        )));
    }
    let lb = Letterbox::fit(image.width, image.height, dst_w, dst_h);
    let plane = dst_w * dst_h;
    let (r_plane, rest) = input.split_at_mut(plane);
    let (g_plane, b_plane) = rest.split_at_mut(plane);
    let src = image.pixels;
    let sw = image.width;
    let inv = 1.0 / 255.0;
    let new_w = (image.width as f32 * lb.scale).round() as usize;
    let new_h = (image.height as f32 * lb.scale).round() as usize;
    let (px, py) = (lb.pad_x as usize, lb.pad_y as usize);
    let same_size = new_w == image.width && new_h == image.height;
    for y in 0..dst_h {
        let inside_y = y >= py && y < py + new_h;
        for x in 0..dst_w {
            let i = y * dst_w + x;
            if !inside_y || x < px || x >= px + new_w {
                r_plane[i] = PAD_VALUE;
                g_plane[i] = PAD_VALUE;
                b_plane[i] = PAD_VALUE;
                continue;
            }
            let (ix, iy) = (x - px, y - py);
            let rgb = if same_size {
                let o = (iy * sw + ix) * 3;
                [
                    f32::from(src[o]),
                    f32::from(src[o + 1]),
                    f32::from(src[o + 2]),
                ]
            } else {
                let sx = ((ix as f32 + 0.5) / lb.scale - 0.5).clamp(0.0, (image.width - 1) as f32);
                let sy = ((iy as f32 + 0.5) / lb.scale - 0.5).clamp(0.0, (image.height - 1) as f32);
                let (x0, y0) = (sx.floor() as usize, sy.floor() as usize);
                let (x1, y1) = (
                    (x0 + 1).min(image.width - 1),
                    (y0 + 1).min(image.height - 1),
                );
                let (fx, fy) = (sx - x0 as f32, sy - y0 as f32);
                let px = |xx: usize, yy: usize, c: usize| f32::from(src[(yy * sw + xx) * 3 + c]);
                [0, 1, 2].map(|c| {
                    let top = px(x0, y0, c) * (1.0 - fx) + px(x1, y0, c) * fx;
                    let bottom = px(x0, y1, c) * (1.0 - fx) + px(x1, y1, c) * fx;
                    top * (1.0 - fy) + bottom * fy
                })
            };
            r_plane[i] = rgb[0] * inv;
            g_plane[i] = rgb[1] * inv;
            b_plane[i] = rgb[2] * inv;
        }
    }
    Ok(lb)
}

/// Reads an image file (PNG, JPEG) as RGB8: (width, height, pixels).
pub fn load_rgb(path: &std::path::Path) -> Result<(usize, usize, Vec<u8>)> {
    let image = image::open(path)
        .map_err(|e| PerceptionError::Image(format!("{}: {e}", path.display())))?
        .into_rgb8();
    let (w, h) = image.dimensions();
    Ok((w as usize, h as usize, image.into_raw()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letterbox_round_trip() {
        let lb = Letterbox::fit(640, 480, 640, 640);
        assert_eq!((lb.scale, lb.pad_x, lb.pad_y), (1.0, 0.0, 80.0));
        let (x, y) = lb.to_input(100.0, 200.0);
        assert_eq!(lb.to_source(x, y), (100.0, 200.0));

        let lb = Letterbox::fit(1000, 500, 320, 320);
        assert!((lb.scale - 0.32).abs() < 1e-6);
        assert_eq!((lb.pad_x, lb.pad_y), (0.0, 80.0));
        let (x, y) = lb.to_input(500.0, 250.0);
        let (sx, sy) = lb.to_source(x, y);
        assert!((sx - 500.0).abs() < 1e-3 && (sy - 250.0).abs() < 1e-3);
        // Outside the image clips to its border.
        assert_eq!(lb.to_source(-10.0, 0.0), (0.0, 0.0));
    }

    #[test]
    fn letterbox_pads_grey_and_keeps_pixels() -> Result<()> {
        // 4x2 image into 4x4: one padded row above and below.
        let mut pixels = vec![0u8; 4 * 2 * 3];
        pixels[0] = 255; // top-left red
        let image = RgbView::new(4, 2, &pixels)?;
        let mut input = vec![0f32; 3 * 16];
        let lb = letterbox_into(image, &mut input, 4, 4)?;
        assert_eq!((lb.pad_x, lb.pad_y), (0.0, 1.0));
        assert_eq!(input[0], PAD_VALUE, "top row padded");
        assert_eq!(input[4], 1.0, "source (0,0) red lands at input (0,1)");
        assert_eq!(input[16 + 4], 0.0, "its green");
        assert_eq!(input[12], PAD_VALUE, "bottom row padded");
        // Downscaling averages.
        let flat = vec![200u8; 8 * 8 * 3];
        let mut small = vec![0f32; 3 * 4 * 4];
        letterbox_into(RgbView::new(8, 8, &flat)?, &mut small, 4, 4)?;
        assert!(small.iter().all(|v| (v - 200.0 / 255.0).abs() < 1e-6));
        assert!(RgbView::new(4, 4, &flat).is_err());
        Ok(())
    }
}
