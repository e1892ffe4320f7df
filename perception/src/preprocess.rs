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
const PAD_VALUE: f32 = 114.0 / 255.0;

/// Where one output column (or row) samples the source: the two neighbours and the weight of
/// the second.
#[derive(Debug, Clone, Copy, Default)]
struct Tap {
    first: usize,
    second: usize,
    weight: f32,
}

/// The letterbox's sampling tables for one source and input size, computed once and reused:
/// per-pixel work is then four loads and a few multiply-adds per channel. Values are the same,
/// bit for bit, as computing each pixel's position on its own.
#[derive(Debug, Clone, Default)]
pub(crate) struct LetterboxPlan {
    key: Option<(usize, usize, usize, usize)>,
    cols: Vec<Tap>,
    rows: Vec<Tap>,
}

impl LetterboxPlan {
    fn prepare(&mut self, src_w: usize, src_h: usize, dst_w: usize, dst_h: usize) -> Letterbox {
        let lb = Letterbox::fit(src_w, src_h, dst_w, dst_h);
        let key = (src_w, src_h, dst_w, dst_h);
        if self.key == Some(key) {
            return lb;
        }
        let new_w = (src_w as f32 * lb.scale).round() as usize;
        let new_h = (src_h as f32 * lb.scale).round() as usize;
        let taps = |n: usize, src_n: usize| -> Vec<Tap> {
            (0..n)
                .map(|i| {
                    let s = ((i as f32 + 0.5) / lb.scale - 0.5).clamp(0.0, (src_n - 1) as f32);
                    let first = s.floor() as usize;
                    Tap {
                        first,
                        second: (first + 1).min(src_n - 1),
                        weight: s - first as f32,
                    }
                })
                .collect()
        };
        self.cols = taps(new_w, src_w);
        self.rows = taps(new_h, src_h);
        self.key = Some(key);
        lb
    }

    /// Writes `image` letterboxed into `input` (`[3, dst_h, dst_w]`, f32, RGB, 0..1) with
    /// bilinear sampling (pixel centres aligned, like OpenCV's INTER_LINEAR), using this plan's
    /// tables (rebuilt only when a size changes): the detector keeps one plan and allocates
    /// nothing per frame.
    pub(crate) fn letterbox_into(
        &mut self,
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
        let lb = self.prepare(image.width, image.height, dst_w, dst_h);
        let plane = dst_w * dst_h;
        let (r_plane, rest) = input.split_at_mut(plane);
        let (g_plane, b_plane) = rest.split_at_mut(plane);
        let src = image.pixels;
        let sw = image.width;
        let inv = 1.0 / 255.0;
        let new_w = self.cols.len();
        let new_h = self.rows.len();
        let (px, py) = (lb.pad_x as usize, lb.pad_y as usize);
        let same_size = new_w == image.width && new_h == image.height;
        for y in 0..dst_h {
            let row = y * dst_w;
            let (r_row, g_row, b_row) = (
                &mut r_plane[row..row + dst_w],
                &mut g_plane[row..row + dst_w],
                &mut b_plane[row..row + dst_w],
            );
            if y < py || y >= py + new_h {
                r_row.fill(PAD_VALUE);
                g_row.fill(PAD_VALUE);
                b_row.fill(PAD_VALUE);
                continue;
            }
            let right = (px + new_w).min(dst_w);
            for out in [&mut *r_row, &mut *g_row, &mut *b_row] {
                out[..px].fill(PAD_VALUE);
                out[right..].fill(PAD_VALUE);
            }
            let iy = y - py;
            if same_size {
                let line = &src[iy * sw * 3..(iy + 1) * sw * 3];
                for (ix, p) in line.chunks_exact(3).enumerate() {
                    r_row[px + ix] = f32::from(p[0]) * inv;
                    g_row[px + ix] = f32::from(p[1]) * inv;
                    b_row[px + ix] = f32::from(p[2]) * inv;
                }
                continue;
            }
            let t = self.rows[iy];
            let (fy, gy) = (t.weight, 1.0 - t.weight);
            let top = &src[t.first * sw * 3..(t.first + 1) * sw * 3];
            let bottom = &src[t.second * sw * 3..(t.second + 1) * sw * 3];
            for (ix, c) in self.cols.iter().enumerate() {
                let (fx, gx) = (c.weight, 1.0 - c.weight);
                let (a, b) = (c.first * 3, c.second * 3);
                let mut rgb = [0.0f32; 3];
                for (k, v) in rgb.iter_mut().enumerate() {
                    let t0 = f32::from(top[a + k]) * gx + f32::from(top[b + k]) * fx;
                    let b0 = f32::from(bottom[a + k]) * gx + f32::from(bottom[b + k]) * fx;
                    *v = t0 * gy + b0 * fy;
                }
                r_row[px + ix] = rgb[0] * inv;
                g_row[px + ix] = rgb[1] * inv;
                b_row[px + ix] = rgb[2] * inv;
            }
        }
        Ok(lb)
    }
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
        let lb = LetterboxPlan::default().letterbox_into(image, &mut input, 4, 4)?;
        assert_eq!((lb.pad_x, lb.pad_y), (0.0, 1.0));
        assert_eq!(input[0], PAD_VALUE, "top row padded");
        assert_eq!(input[4], 1.0, "source (0,0) red lands at input (0,1)");
        assert_eq!(input[16 + 4], 0.0, "its green");
        assert_eq!(input[12], PAD_VALUE, "bottom row padded");
        // Downscaling averages.
        let flat = vec![200u8; 8 * 8 * 3];
        let mut small = vec![0f32; 3 * 4 * 4];
        LetterboxPlan::default().letterbox_into(RgbView::new(8, 8, &flat)?, &mut small, 4, 4)?;
        assert!(small.iter().all(|v| (v - 200.0 / 255.0).abs() < 1e-6));
        assert!(RgbView::new(4, 4, &flat).is_err());
        Ok(())
    }

    /// The tables give exactly what computing each pixel's position on its own gives.
    #[test]
    fn the_plan_matches_per_pixel_bilinear_sampling() -> Result<()> {
        let (w, h) = (64usize, 48usize);
        let pixels: Vec<u8> = (0..w * h * 3).map(|i| (i * 37 % 251) as u8).collect();
        let view = RgbView::new(w, h, &pixels)?;
        for (dw, dh) in [(51usize, 38usize), (64, 64), (80, 40), (32, 32)] {
            let mut got = vec![0.0; 3 * dw * dh];
            let mut plan = LetterboxPlan::default();
            let lb = plan.letterbox_into(view, &mut got, dw, dh)?;
            // Twice through the same plan: the cached tables give the same again.
            let mut again = vec![0.0; 3 * dw * dh];
            plan.letterbox_into(view, &mut again, dw, dh)?;
            assert_eq!(got, again);
            let new_w = (w as f32 * lb.scale).round() as usize;
            let new_h = (h as f32 * lb.scale).round() as usize;
            let (px, py) = (lb.pad_x as usize, lb.pad_y as usize);
            for y in 0..dh {
                for x in 0..dw {
                    for c in 0..3 {
                        let want = if y < py || y >= py + new_h || x < px || x >= px + new_w {
                            PAD_VALUE
                        } else if new_w == w && new_h == h {
                            f32::from(pixels[((y - py) * w + x - px) * 3 + c]) * (1.0 / 255.0)
                        } else {
                            let sx = (((x - px) as f32 + 0.5) / lb.scale - 0.5)
                                .clamp(0.0, (w - 1) as f32);
                            let sy = (((y - py) as f32 + 0.5) / lb.scale - 0.5)
                                .clamp(0.0, (h - 1) as f32);
                            let (x0, y0) = (sx.floor() as usize, sy.floor() as usize);
                            let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                            let (fx, fy) = (sx - x0 as f32, sy - y0 as f32);
                            let p = |xx: usize, yy: usize| f32::from(pixels[(yy * w + xx) * 3 + c]);
                            let top = p(x0, y0) * (1.0 - fx) + p(x1, y0) * fx;
                            let bottom = p(x0, y1) * (1.0 - fx) + p(x1, y1) * fx;
                            (top * (1.0 - fy) + bottom * fy) * (1.0 / 255.0)
                        };
                        let have = got[c * dw * dh + y * dw + x];
                        assert!(
                            have.to_bits() == want.to_bits(),
                            "{dw}x{dh} at ({x}, {y}) channel {c}: {have} vs {want}"
                        );
                    }
                }
            }
        }
        Ok(())
    }
}
