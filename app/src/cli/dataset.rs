//! `rover dataset`: the command line around [`rover_core::write_dataset`] — options, a
//! progress bar, Ctrl-C (complete images kept, the same command resumes), a summary.

use std::time::Instant;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use rover_core::{
    DatasetProgress, DatasetSpec, DatasetSummary, ImageFormat, Randomization, ShardIndex,
};

use crate::cli::args::{
    DatasetArgs, DatasetFormat, DatasetImageFormat, Randomize, cores, spare_detect_threads,
};
use crate::cli::signals::{Interrupted, stop_on_signals};

impl DatasetImageFormat {
    pub(crate) fn format(self) -> ImageFormat {
        match self {
            Self::Png => ImageFormat::Png,
            Self::Jpg => ImageFormat::Jpg,
        }
    }
}

/// The randomization the options ask for.
fn randomization(args: &DatasetArgs) -> Randomization {
    let on = |what| args.randomize.contains(&what) && !args.randomize.contains(&Randomize::None);
    Randomization {
        robot: on(Randomize::Robot),
        distance_m: args.distance,
        background: args.background,
        move_m: if on(Randomize::Things) {
            args.move_m
        } else {
            0.0
        },
        turn_deg: if on(Randomize::Things) {
            args.turn_deg
        } else {
            0.0
        },
        clothes: on(Randomize::Clothes),
        bodies: on(Randomize::Bodies),
        light: on(Randomize::Light),
        noise_max: if on(Randomize::Noise) {
            args.noise_max
        } else {
            0.0
        },
    }
}

/// The progress bar of making or merging images.
fn progress_bar(images: u64) -> ProgressBar {
    let bar = ProgressBar::new(images);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} images  {per_sec}  eta {eta}  {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// `rover dataset --merge`: the shards' folders into one dataset.
fn merge(args: &DatasetArgs) -> Result<()> {
    let bar = progress_bar(0);
    let summary = rover_core::merge_dataset(&args.merge, &args.out, &mut |p: DatasetProgress| {
        bar.set_length(p.total);
        bar.set_position(p.done);
    });
    bar.finish_and_clear();
    let (spec, summary) = summary?;
    say!(
        "merged {} shard folders into {}: {} images ({} gathered now, {} there before)",
        args.merge.len(),
        summary.out.display(),
        summary.total,
        summary.made,
        summary.kept
    );
    print_contents(&summary, &spec);
    Ok(())
}

/// Runs `rover dataset`.
pub(crate) fn run(args: DatasetArgs) -> Result<()> {
    if !args.merge.is_empty() {
        return merge(&args);
    }
    let mut config = args.world.run_config(None);
    config.detector = args.detector.tool_config(spare_detect_threads())?;
    config.stop = Some(stop_on_signals()?);
    let shard = args.shard.map(|(index, count)| ShardIndex { index, count });
    let spec = DatasetSpec {
        out: match shard {
            Some(s) => args.out.join(format!("shard-{}-of-{}", s.index, s.count)),
            None => args.out.clone(),
        },
        images: args.images,
        seed: args.world.seed,
        val_fraction: args.val,
        image_format: args.image_format.format(),
        formats: formats(&args.format),
        randomization: randomization(&args),
        detect: args.detect,
        shard,
        jobs: args.jobs.unwrap_or_else(cores),
    };
    let bar = progress_bar(spec.images);
    let mut first = true;
    let summary = rover_core::write_dataset(&config, &spec, &mut |p: DatasetProgress| {
        if first {
            first = false;
            if p.kept > 0 {
                bar.suspend(|| {
                    say!(
                        "resuming {}: {} of {} images already complete",
                        spec.out.display(),
                        p.kept,
                        p.total
                    );
                });
            }
            bar.set_length(p.total);
            bar.set_position(p.done);
            bar.reset_eta();
        }
        bar.set_position(p.done);
    });
    bar.finish_and_clear();
    let summary = summary?;
    print_summary(&summary, &spec);
    if summary.interrupted {
        say!(
            "interrupted: {} of {} images complete; run the same command again to go on",
            summary.kept + summary.made,
            summary.total
        );
        return Err(Interrupted.into());
    }
    Ok(())
}

fn print_summary(s: &DatasetSummary, spec: &DatasetSpec) {
    let rate = if s.wall_s > 0.0 {
        s.made as f64 / s.wall_s
    } else {
        0.0
    };
    say!(
        "dataset {}: {} images ({} made now at {rate:.1}/s, {} kept from before)",
        s.out.display(),
        s.total,
        s.made,
        s.kept
    );
    if !s.interrupted {
        print_contents(s, spec);
    }
}

/// What the dataset (or shard) holds and which files were written.
fn print_contents(s: &DatasetSummary, spec: &DatasetSpec) {
    if let Some(shard) = spec.shard {
        say!(
            "  shard {}/{}: train {} / val {} images; {} labelled boxes, {} ignore regions; wrote images/, ground_truth/{}, {}",
            shard.index,
            shard.count,
            s.split_images[0],
            s.split_images[1],
            s.boxes,
            s.ignored,
            if spec.formats.contains(&rover_core::DatasetFormat::Yolo) {
                ", labels/"
            } else {
                ""
            },
            rover_core::SHARD_MANIFEST
        );
        say!(
            "  once every shard is finished: rover dataset --merge {}/shard-*-of-{} --out DATASET_DIR",
            spec.out
                .parent()
                .map_or_else(|| ".".into(), |p| p.display().to_string()),
            shard.count
        );
        return;
    }
    say!(
        "  train {} / val {} images; {} labelled boxes, {} ignore regions, {} images with no box",
        s.split_images[0],
        s.split_images[1],
        s.boxes,
        s.ignored,
        s.backgrounds
    );
    let wrote: Vec<&str> = spec
        .formats
        .iter()
        .map(|f| match f {
            rover_core::DatasetFormat::Yolo => "data.yaml, labels/{train,val}/ (YOLO)",
            rover_core::DatasetFormat::Coco => "annotations/instances_{train,val}.json (COCO)",
        })
        .collect();
    say!(
        "  wrote images/{{train,val}}/, {}, ground_truth/",
        wrote.join(", ")
    );
    if let Some([train, val, all]) = &s.metrics {
        let f = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.3}"));
        say!("  detector (COCO rules; metrics.json, detections/):");
        for (name, m) in [("train", train), ("val", val), ("all", all)] {
            say!(
                "    {name:<5} {} images  AP50 {}  AP50:95 {}",
                m.images,
                f(m.ap50),
                f(m.ap50_95)
            );
        }
        for c in &all.classes {
            say!(
                "    {:<14} AP50 {}  precision {}  recall {}  mean IoU {}  ({} truth, {} detections)",
                c.class,
                f(c.ap50),
                f(c.precision),
                f(c.recall),
                f(c.mean_iou),
                c.ground_truth,
                c.detections
            );
        }
    }
}

/// `rover bench dataset`: images per second into a temporary folder, after one warm-up image.
pub(crate) fn bench(
    world: crate::cli::args::WorldArgs,
    images: u64,
    format: DatasetImageFormat,
    jobs: Option<usize>,
) -> Result<()> {
    let config = world.run_config(None);
    let scratch = tempfile::tempdir()?;
    let spec = DatasetSpec {
        out: scratch.path().join("dataset"),
        images: 1,
        seed: world.seed,
        val_fraction: 0.1,
        image_format: format.format(),
        formats: rover_core::DatasetFormat::ALL.to_vec(),
        randomization: Randomization::default(),
        detect: false,
        shard: None,
        jobs: 1,
    };
    rover_core::write_dataset(&config, &spec, &mut |_| {})?;
    let spec = DatasetSpec {
        images: images.max(1) + 1,
        jobs: jobs.unwrap_or_else(cores),
        ..spec
    };
    let start = Instant::now();
    let summary = rover_core::write_dataset(&config, &spec, &mut |_| {})?;
    let total_s = start.elapsed().as_secs_f64();
    say!(
        "dataset benchmark: {} labelled {} images, {} at once: {:.1} images/s while making them ({:.1} ms each), {:.1}/s including set-up and the COCO/YOLO files ({:.2} s in all)",
        summary.made,
        match format {
            DatasetImageFormat::Png => "PNG",
            DatasetImageFormat::Jpg => "JPEG",
        },
        spec.jobs,
        summary.made as f64 / summary.wall_s,
        1e3 * summary.wall_s / summary.made.max(1) as f64,
        summary.made as f64 / total_s,
        total_s
    );
    say!(
        "  {} labelled boxes, {} ignore regions in {} images",
        summary.boxes,
        summary.ignored,
        summary.total
    );
    Ok(())
}

/// `--format`'s choices as the dataset's formats, each once, in `--help`'s order.
fn formats(chosen: &[DatasetFormat]) -> Vec<rover_core::DatasetFormat> {
    let mut formats: Vec<rover_core::DatasetFormat> = chosen
        .iter()
        .map(|f| match f {
            DatasetFormat::Yolo => rover_core::DatasetFormat::Yolo,
            DatasetFormat::Coco => rover_core::DatasetFormat::Coco,
        })
        .collect();
    formats.sort();
    formats.dedup();
    formats
}
