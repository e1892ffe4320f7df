//! Post-processing on the CPU after read back, as gazebo_ros_camera's output has it: lens
//! distortion (a remap table computed once per camera) and seeded gaussian noise; a depth
//! camera's depth image gets its `<noise>` in metres, as gz-sim's depth camera applies it.

use crate::model::camera_info::CameraInfo;
use crate::model::sensors::{Distortion, GaussianNoise};
use crate::noise::SplitMix64 as Rng;

/// The ideal image, the output image and what turns one into the other; buffers allocated once.
pub(crate) struct PostProcess {
    width: usize,
    height: usize,
    /// The pinhole render, RGB8.
    pub(crate) ideal: Vec<u8>,
    /// The image handed out, RGB8.
    pub(crate) rgb: Vec<u8>,
    noise: Option<(GaussianNoise, Rng)>,
    /// The depth image's noise stream (the same noise settings, in metres).
    depth_rng: Rng,
    /// The noise seed; each frame's noise comes from it and the frame number.
    noise_seed: u64,
    distortion_map: Option<Vec<[f32; 2]>>,
}

impl PostProcess {
    /// Buffers for `info`'s size; noise seeded from `seed`.
    pub(crate) fn new(
        info: &CameraInfo,
        noise: Option<GaussianNoise>,
        distortion: &Distortion,
        seed: u64,
    ) -> Self {
        let pixels = (info.width * info.height) as usize;
        let noise_seed = seed ^ 0x5EED_CA3E_5EED_CA3E;
        Self {
            width: info.width as usize,
            height: info.height as usize,
            ideal: vec![0; pixels * 3],
            rgb: vec![0; pixels * 3],
            noise: noise.map(|n| (n, Rng(noise_seed))),
            depth_rng: Rng(!noise_seed),
            noise_seed,
            distortion_map: (!distortion.is_zero()).then(|| distortion_map(info, distortion)),
        }
    }

    /// From the next image on, adds `noise` (none: a clean image). The noise stays seeded
    /// from the frame number.
    pub(crate) fn set_noise(&mut self, noise: Option<GaussianNoise>) {
        self.noise = noise.map(|n| (n, Rng(self.noise_seed)));
    }

    /// Seeds the next image's noise from the frame number.
    pub(crate) fn seed_frame(&mut self, frame: u64) {
        let mut mix = Rng(self.noise_seed ^ frame.wrapping_mul(0xA076_1D64_78BD_642F));
        let colour = mix.next_u64();
        if let Some((_, rng)) = &mut self.noise {
            *rng = Rng(colour);
        }
        self.depth_rng = Rng(mix.next_u64());
    }

    /// The camera's gaussian noise on a depth image (metres; NaN stays NaN, nothing goes
    /// below zero); nothing without noise.
    pub(crate) fn add_depth_noise(&mut self, metres: &mut [f32]) {
        let Some((noise, _)) = &self.noise else {
            return;
        };
        let rng = &mut self.depth_rng;
        for pair in metres.chunks_mut(2) {
            let (a, b) = rng.normal_pair();
            for (d, z) in pair.iter_mut().zip([a, b]) {
                if d.is_finite() {
                    *d = (f64::from(*d) + noise.mean + noise.stddev * z).max(0.0) as f32;
                }
            }
        }
    }

    /// Whether the lens distorts the image.
    pub(crate) fn distorts(&self) -> bool {
        self.distortion_map.is_some()
    }

    /// The id image through the same distortion as the colour image, sampled at the nearest
    /// pixel (ids do not blend): `ideal` (pinhole) into `out`; 0 where the lens sees past the
    /// ideal image.
    pub(crate) fn remap_ids(&self, ideal: &[u32], out: &mut [u32]) {
        let (w, h) = (self.width, self.height);
        match &self.distortion_map {
            None => out.copy_from_slice(ideal),
            Some(map) => {
                for (o, src) in out.iter_mut().zip(map) {
                    let (sx, sy) = (src[0].round(), src[1].round());
                    *o = if sx < 0.0 || sy < 0.0 || sx > (w - 1) as f32 || sy > (h - 1) as f32 {
                        0
                    } else {
                        ideal[sy as usize * w + sx as usize]
                    };
                }
            }
        }
    }

    /// Distortion (remap through the precomputed table) and noise, from `ideal` into `rgb`.
    pub(crate) fn run(&mut self) {
        let (w, h) = (self.width, self.height);
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

/// For each output (distorted) pixel, where to sample the ideal pinhole render:
/// [`Distortion::distort`] inverted by fixed-point iteration, computed once per camera.
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
        CameraInfo::from_config(&crate::model::camera_info::tests::seed_config())
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
            let (xd, yd) = d.distort((f64::from(sx) - cx) / fx, (f64::from(sy) - cy) / fx);
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
