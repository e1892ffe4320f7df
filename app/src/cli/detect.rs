//! `rover detect`: run the detector on image files — the quick check of a model.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use image::RgbImage;
use rover_perception::{BoundingBox, Detector, DetectorConfig, FrameStamp, RgbView, load_rgb};
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
        println!(
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
        let (width, height, pixels) = load_rgb(path)?;
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
            println!("{}", serde_json::to_string(&line)?);
        } else {
            println!(
                "{}: {} object(s), {:.0} ms",
                path.display(),
                result.bounding_boxes.len(),
                result.latency_ms
            );
            for b in &result.bounding_boxes {
                println!(
                    "{} {:.3} {} {} {} {}",
                    b.class, b.probability, b.xmin, b.ymin, b.xmax, b.ymax
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
            let mut canvas = RgbImage::from_raw(width as u32, height as u32, pixels)
                .context("image buffer size mismatch")?;
            draw_boxes(&mut canvas, &result.bounding_boxes);
            canvas
                .save(&target)
                .with_context(|| format!("cannot write {}", target.display()))?;
            if !options.json {
                println!("wrote {}", target.display());
            }
        }
    }
    Ok(())
}

/// Draws 2-px box outlines.
pub fn draw_boxes(canvas: &mut RgbImage, boxes: &[BoundingBox]) {
    let (w, h) = (i64::from(canvas.width()), i64::from(canvas.height()));
    for b in boxes {
        let color = crate::palette::class_color(b.id);
        for t in 0..2 {
            let (x0, y0) = ((b.xmin + t).clamp(0, w - 1), (b.ymin + t).clamp(0, h - 1));
            let (x1, y1) = (
                (b.xmax - 1 - t).clamp(0, w - 1),
                (b.ymax - 1 - t).clamp(0, h - 1),
            );
            for x in x0..=x1 {
                canvas.put_pixel(x as u32, y0 as u32, color);
                canvas.put_pixel(x as u32, y1 as u32, color);
            }
            for y in y0..=y1 {
                canvas.put_pixel(x0 as u32, y as u32, color);
                canvas.put_pixel(x1 as u32, y as u32, color);
            }
        }
    }
}
