//! `rover dataset`: labelled images from any world. Every image is a scene laid out anew from
//! the seed and the image's number ([`Randomization`]), rendered by the robot's camera with
//! its ground truth, and written as an image, a YOLO label and rover's record; at the end the
//! records become COCO JSON and Ultralytics' `data.yaml`. Deterministic (same seed, same
//! files), resumable (a stopped run goes on where it stopped), and stopped cleanly by a full
//! disk ([`store`] says how the folder is kept consistent).

mod export;
mod finish;
mod format;
mod merge;
mod randomize;
mod store;

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use rover_perception::{Detector, FrameStamp, RgbView};
use rover_sim::{
    model::{RobotModel, World},
    physics::{SimOptions, Simulation},
    sensors::CameraSensor,
};

pub use export::{
    COCO_CATEGORY_IDS, DetectedBox, ImageRecord, LabelledBox, coco_category, coco_json,
    coco_results, data_yaml, yolo_class,
};
pub use finish::{DatasetProgress, DatasetSpec, DatasetSummary};
pub use format::DatasetFormat;
pub use merge::{SHARD_MANIFEST, merge_dataset};
pub use randomize::{PersonShot, Randomization, Shot};
pub use store::{ImageFormat, MANIFEST, MANIFEST_FORMAT, Manifest, Split, Store, write_whole};

use crate::error::{CoreError, Result};
use crate::headless::RunConfig;
use crate::shard::sha256_of;
use finish::{count, disk_error, finish, read_records};
use randomize::{BaseLayout, Rng, lay_out};

/// One image on its way to the disk.
struct Job {
    split: Split,
    index: u64,
    rgb: Vec<u8>,
    width: u32,
    height: u32,
    label: Option<String>,
    record: String,
}

/// One lane of image making: its own simulation, camera (with ground truth) and detector.
/// `--jobs N` runs N lanes on threads of their own, each over every Nth image still to make.
struct Lane {
    sim: Simulation,
    camera: CameraSensor,
    detector: Option<Detector>,
}

impl Lane {
    fn new(
        config: &RunConfig,
        spec: &DatasetSpec,
        world: World,
        robot: RobotModel,
    ) -> Result<Self> {
        let options = SimOptions {
            seed: spec.seed,
            ..config.options.clone()
        };
        let sim = Simulation::new(world, robot, &options)?;
        let mut camera = CameraSensor::new(&sim).map_err(CoreError::Camera)?;
        camera
            .enable_ground_truth(&sim)
            .map_err(CoreError::Camera)?;
        let detector = match spec.detect {
            true => Some(Detector::load(config.detector.clone())?),
            false => None,
        };
        Ok(Self {
            sim,
            camera,
            detector,
        })
    }
}

/// What every lane shares.
struct Shared<'a> {
    config: &'a RunConfig,
    spec: &'a DatasetSpec,
    store: &'a Store,
    base: &'a BaseLayout,
    /// Set when a lane fails: the others stop at their next image.
    failed: &'a AtomicBool,
}

/// Makes `indices` with `lane`, hearing of each image on `made`. Returns whether it stopped
/// on request (Ctrl-C); errors set `failed` so that the other lanes stop too.
fn run_lane(
    lane: &mut Lane,
    shared: &Shared,
    indices: &[u64],
    made: &mpsc::Sender<()>,
) -> Result<bool> {
    let result = std::thread::scope(|scope| -> Result<bool> {
        let (jobs, inbox) = mpsc::sync_channel::<Job>(2);
        let (returns, recycled) = mpsc::channel::<Vec<u8>>();
        let writer_store = shared.store.clone();
        let format = shared.spec.image_format;
        let writer = scope.spawn(move || write_jobs(&writer_store, inbox, format, returns));
        let mut interrupted = false;
        for &index in indices {
            if shared.config.stop_requested() {
                interrupted = true;
                break;
            }
            if shared.failed.load(Ordering::Relaxed) {
                break;
            }
            let rgb = recycled.try_recv().unwrap_or_default();
            let job = make_image(lane, (shared.base, shared.spec, shared.store), index, rgb)?;
            if jobs.send(job).is_err() {
                break; // the writer stopped on an error, joined below
            }
            let _ = made.send(());
        }
        drop(jobs);
        match writer.join() {
            Ok(Ok(())) => Ok(interrupted),
            Ok(Err((path, e))) => Err(disk_error(&path, e, shared.store, shared.spec.images)),
            Err(_) => Err(CoreError::Option(
                "the dataset writer thread panicked".into(),
            )),
        }
    });
    if result.is_err() {
        shared.failed.store(true, Ordering::Relaxed);
    }
    result
}

/// Makes (or resumes) the dataset `spec` asks for from the world and robot `config` names.
/// `progress` hears of every image completed. Errors: bad options, a folder that holds
/// something else, a disk that fills up (what was written stays complete and resumable).
pub fn write_dataset(
    config: &RunConfig,
    spec: &DatasetSpec,
    progress: &mut dyn FnMut(DatasetProgress),
) -> Result<DatasetSummary> {
    check_spec(spec)?;
    let (mut world, robot) = config.load_world_and_robot()?;
    for person in &mut world.people {
        // Still scenes: people stand where the layout puts them.
        person.walk = None;
    }
    let first = Lane::new(config, spec, world.clone(), robot.clone())?;
    let manifest = manifest(spec, &first.sim, &first.camera, first.detector.as_ref())?;
    let model = first
        .detector
        .as_ref()
        .map(|d| d.model_path().to_path_buf());
    let (store, done) = Store::open(&spec.out, &manifest)?;
    if spec.shard.is_some() {
        merge::forget_shard_manifest(&store)?;
    }
    let base = BaseLayout::new(&first.sim);
    if base.targets() == 0 {
        tracing::warn!(
            "{}: nothing in the world is labelled (people, objects with class = \"...\", Gazebo models of a known class): every image will be a background image",
            first.sim.world().source.display()
        );
    }
    let owned: Vec<u64> = (0..spec.images)
        .filter(|i| spec.shard.is_none_or(|s| s.owns(*i)))
        .collect();
    let todo: Vec<u64> = owned
        .iter()
        .copied()
        .filter(|i| !done.contains(i))
        .collect();
    let (total, kept) = (owned.len() as u64, owned.len() as u64 - todo.len() as u64);
    progress(DatasetProgress {
        done: kept,
        total,
        kept,
    });
    let lanes = spec.jobs.clamp(1, todo.len().max(1));
    let failed = AtomicBool::new(false);
    let shared = Shared {
        config,
        spec,
        store: &store,
        base: &base,
        failed: &failed,
    };
    let start = Instant::now();
    let mut first = Some(first);
    let (results, made) = std::thread::scope(|scope| {
        let (made_tx, made_rx) = mpsc::channel::<()>();
        let mut handles = Vec::with_capacity(lanes);
        for l in 0..lanes {
            let indices: Vec<u64> = todo.iter().copied().skip(l).step_by(lanes).collect();
            let (made_tx, shared, lane) = (made_tx.clone(), &shared, first.take());
            let (world, robot) = (&world, &robot);
            handles.push(scope.spawn(move || {
                let mut lane = match lane {
                    Some(lane) => lane,
                    None => Lane::new(config, spec, world.clone(), robot.clone())
                        .inspect_err(|_| shared.failed.store(true, Ordering::Relaxed))?,
                };
                run_lane(&mut lane, shared, &indices, &made_tx)
            }));
        }
        drop(made_tx);
        let mut made = 0;
        for () in made_rx {
            made += 1;
            progress(DatasetProgress {
                done: kept + made,
                total,
                kept,
            });
        }
        let results: Vec<Result<bool>> = handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(CoreError::Option("a dataset lane panicked".into())))
            })
            .collect();
        (results, made)
    });
    let mut interrupted = false;
    for result in results {
        interrupted |= result?;
    }
    let mut summary = DatasetSummary::new(&spec.out, [total, made, kept], start, interrupted);
    match (interrupted, spec.shard) {
        (true, _) => {}
        (false, None) => finish(&store, spec, &mut summary)?,
        (false, Some(shard)) => {
            let records = read_records(&store, owned.into_iter())?;
            count(&records, &mut summary);
            let inputs = [world.source.clone(), robot.source.clone()];
            merge::write_shard_manifest(&store, &inputs, spec, shard, model.as_deref())?;
        }
    }
    Ok(summary)
}

fn check_spec(spec: &DatasetSpec) -> Result<()> {
    if spec.images == 0 {
        return Err(CoreError::Option("ask for at least one image".into()));
    }
    if !(spec.val_fraction.is_finite() && (0.0..=1.0).contains(&spec.val_fraction)) {
        return Err(CoreError::Option(format!(
            "the validation fraction must be between 0 and 1, found {}",
            spec.val_fraction
        )));
    }
    if spec.formats.is_empty() {
        return Err(CoreError::Option(format!(
            "choose at least one output format ({})",
            format::names(&DatasetFormat::ALL)
        )));
    }
    spec.randomization.check().map_err(CoreError::Option)
}

fn manifest(
    spec: &DatasetSpec,
    sim: &Simulation,
    camera: &CameraSensor,
    detector: Option<&Detector>,
) -> Result<Manifest> {
    let detector = match detector {
        Some(d) => Some(format!(
            "{} sha256 {} threshold {}",
            d.model_path()
                .file_name()
                .unwrap_or_default()
                .to_string_lossy(),
            sha256_of(d.model_path())?,
            d.config().threshold
        )),
        None => None,
    };
    Ok(Manifest {
        format: MANIFEST_FORMAT.into(),
        rover_version: env!("CARGO_PKG_VERSION").into(),
        seed: spec.seed,
        images: spec.images,
        val_fraction: spec.val_fraction,
        image_format: spec.image_format,
        formats: spec.formats.clone(),
        world: sim.world().source.display().to_string(),
        world_sha256: sha256_of(&sim.world().source)?,
        robot: sim.robot().source.display().to_string(),
        robot_sha256: sha256_of(&sim.robot().source)?,
        camera: sim
            .robot()
            .cameras
            .first()
            .map(|c| c.name.clone())
            .unwrap_or_default(),
        width: camera.info().width,
        height: camera.info().height,
        randomization: spec.randomization.clone(),
        detector,
        shard: spec.shard,
    })
}

/// Lays out, renders and labels image `index`.
fn make_image(
    lane: &mut Lane,
    (base, spec, store): (&BaseLayout, &DatasetSpec, &Store),
    index: u64,
    mut rgb: Vec<u8>,
) -> Result<Job> {
    let Lane {
        sim,
        camera,
        detector,
    } = lane;
    let mut rng = Rng::for_image(spec.seed, index);
    let split = if rng.uniform() < spec.val_fraction {
        Split::Val
    } else {
        Split::Train
    };
    let shot = lay_out(sim, camera, base, &spec.randomization, &mut rng)?;
    camera.set_frame_number(index);
    let frame = camera.capture(sim).map_err(CoreError::Camera)?;
    rgb.clear();
    rgb.extend_from_slice(frame.rgb);
    let (width, height) = (frame.width, frame.height);
    let objects = frame
        .ground_truth
        .iter()
        .map(LabelledBox::from_truth)
        .collect();
    let detections = match detector.as_mut() {
        Some(d) => {
            let view = RgbView::new(width as usize, height as usize, &rgb)?;
            let stamp = FrameStamp {
                sim_time_s: 0.0,
                frame: index,
            };
            Some(DetectedBox::from_result(&d.detect(view, stamp)?))
        }
        None => None,
    };
    let record = ImageRecord {
        index,
        split,
        file_name: store.file_name(index),
        width,
        height,
        objects,
        detections,
        shot,
    };
    Ok(Job {
        split,
        index,
        rgb,
        width,
        height,
        label: spec
            .formats
            .contains(&DatasetFormat::Yolo)
            .then(|| record.yolo_label()),
        record: serde_json::to_string(&record)
            .map_err(|e| CoreError::Option(format!("image record: {e}")))?,
    })
}

/// The writer thread: encodes and writes every job's files (the record last), hands the
/// image buffers back. Stops at the first error, with the file it concerned.
fn write_jobs(
    store: &Store,
    inbox: mpsc::Receiver<Job>,
    format: ImageFormat,
    returns: mpsc::Sender<Vec<u8>>,
) -> std::result::Result<(), (PathBuf, std::io::Error)> {
    for job in inbox {
        let image = store.image_path(job.split, job.index);
        store::write_whole_with(&image, |w| encode(w, &job, format)).map_err(|e| (image, e))?;
        if let Some(label) = &job.label {
            let path = store.label_path(job.split, job.index);
            write_whole(&path, label.as_bytes()).map_err(|e| (path, e))?;
        }
        let path = store.record_path(job.split, job.index);
        write_whole(&path, job.record.as_bytes()).map_err(|e| (path, e))?;
        let _ = returns.send(job.rgb);
    }
    Ok(())
}

fn encode(w: &mut impl std::io::Write, job: &Job, format: ImageFormat) -> std::io::Result<()> {
    use image::ImageEncoder;
    // The encoders wrap write errors in their own; keep the first one as it was (a full disk
    // must read as one).
    let mut w = KeepError {
        inner: w,
        first: None,
    };
    let (rgb, width, height) = (&job.rgb, job.width, job.height);
    let color = image::ExtendedColorType::Rgb8;
    let result = match format {
        ImageFormat::Png => image::codecs::png::PngEncoder::new_with_quality(
            &mut w,
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Adaptive,
        )
        .write_image(rgb, width, height, color),
        ImageFormat::Jpg => image::codecs::jpeg::JpegEncoder::new_with_quality(&mut w, 95)
            .write_image(rgb, width, height, color),
    };
    match (result, w.first) {
        (Ok(()), _) => Ok(()),
        (Err(_), Some(io)) => Err(io),
        (Err(image::ImageError::IoError(io)), None) => Err(io),
        (Err(other), None) => Err(std::io::Error::other(other)),
    }
}

/// A writer that remembers the first error of the writer it wraps.
struct KeepError<W> {
    inner: W,
    first: Option<std::io::Error>,
}

impl<W: std::io::Write> KeepError<W> {
    fn keep<T>(&mut self, r: std::io::Result<T>) -> std::io::Result<T> {
        r.map_err(|e| {
            let copy = std::io::Error::new(e.kind(), e.to_string());
            self.first.get_or_insert(e);
            copy
        })
    }
}

impl<W: std::io::Write> std::io::Write for KeepError<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let r = self.inner.write(buf);
        self.keep(r)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        let r = self.inner.flush();
        self.keep(r)
    }
}
