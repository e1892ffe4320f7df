//! `rover detect`: run the detector on image files — the quick check of a model.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use image::RgbImage;
use rover_perception::{
    BoundingBox, Detector, DetectorConfig, FrameStamp, RgbView, draw_box_rgb8, load_rgb,
};
use serde::Serialize;

/// Options of `rover detect`.
#[derive(Debug, Clone)]
pub struct DetectOptions {
    /// Images to read.
    pub images: Vec<PathBuf>,
    /// Detector settings.
    pub detector: DetectorConfig,
    /// Print darknet_ros-shaped JSON (one object per image per line) instead of text.
    pub json: bool,
    /// Write the image(s) with boxes drawn: a file for one image, a folder for several.
    pub out: Option<PathBuf>,
}

#[derive(Serialize)]
struct JsonLine<'a> {
    image: &'a Path,
    width: usize,
    height: usize,
    #[serde(flatten)]
    result: &'a rover_perception::BoundingBoxes,
}

/// Runs `rover detect`, printing to stdout.
pub fn run(options: &DetectOptions) -> Result<()> {
    anyhow::ensure!(!options.images.is_empty(), "no images given");
    let mut detector = Detector::load(options.detector.clone())?;
    let (w, h) = detector.input_size();
    if !options.json {
        say!(
            "model {} ({}x{}, {}, {} classes), threshold {}, NMS IoU {}, {} on {} thread(s)",
            detector.model_path().display(),
            w,
            h,
            detector.head().name(),
            detector.labels().len(),
            options.detector.threshold,
            options.detector.nms_iou,
            options.detector.runtime.name(),
            options.detector.threads
        );
    }
    if let Some(out) = &options.out
        && options.images.len() > 1
    {
        std::fs::create_dir_all(out)
            .with_context(|| format!("cannot create folder {}", out.display()))?;
    }
    for (i, path) in options.images.iter().enumerate() {
        let (width, height, mut pixels) = load_rgb(path)?;
        let view = RgbView::new(width, height, &pixels)?;
        let stamp = FrameStamp {
            sim_time_s: 0.0,
            frame: i as u64,
        };
        let result = detector.detect(view, stamp)?;
        if options.json {
            let line = JsonLine {
                image: path,
                width,
                height,
                result: &result,
            };
            say!("{}", serde_json::to_string(&line)?);
        } else {
            say!(
                "{}: {} object(s), {:.0} ms",
                path.display(),
                result.bounding_boxes.len(),
                result.latency_ms
            );
            for b in &result.bounding_boxes {
                say!(
                    "{} {:.3} {} {} {} {}",
                    b.class,
                    b.probability,
                    b.xmin,
                    b.ymin,
                    b.xmax,
                    b.ymax
                );
            }
        }
        if let Some(out) = &options.out {
            let target = if options.images.len() > 1 {
                let stem = path.file_stem().unwrap_or_default().to_string_lossy();
                out.join(format!("{stem}.boxes.png"))
            } else {
                out.clone()
            };
            draw_boxes(
                &mut pixels,
                width as u32,
                height as u32,
                &result.bounding_boxes,
            );
            let canvas = RgbImage::from_raw(width as u32, height as u32, pixels)
                .context("image buffer size mismatch")?;
            canvas
                .save(&target)
                .with_context(|| format!("cannot write {}", target.display()))?;
            if !options.json {
                say!("wrote {}", target.display());
            }
        }
    }
    Ok(())
}

/// Draws 2-px box outlines in the class colours into a packed RGB8 image, by
/// [`draw_box_rgb8`]'s rule (the ROS detection image's too).
fn draw_boxes(rgb: &mut [u8], width: u32, height: u32, boxes: &[BoundingBox]) {
    for b in boxes {
        let colour = crate::palette::class_color(b.id).0;
        draw_box_rgb8(rgb, width, height, b, 2, colour);
    }
}
