//! `rover dataset`'s options ([`DatasetArgs`]) and their value enums.

use std::path::PathBuf;

use clap::Args;

use super::detector::DetectorArgs;
use super::parsers::parse_shard;
use super::world::WorldArgs;

/// `rover dataset`'s options.
#[derive(Debug, Args)]
pub(crate) struct DatasetArgs {
    #[command(flatten)]
    pub(crate) world: WorldArgs,

    /// The dataset's folder (new, empty, or one this command made before: it resumes)
    #[arg(long, value_name = "DIR")]
    pub(crate) out: PathBuf,

    /// How many images
    #[arg(long, default_value_t = 100, value_name = "N")]
    pub(crate) images: u64,

    /// Fraction of images in the validation split
    #[arg(long, default_value_t = 0.1, value_name = "FRACTION")]
    pub(crate) val: f64,

    /// Output formats: yolo (Ultralytics layout, data.yaml), coco (COCO JSON), or both
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "yolo,coco",
        value_name = "FORMAT,..."
    )]
    pub(crate) format: Vec<DatasetFormat>,

    /// Image files: png (lossless) or jpg (quality 95)
    #[arg(long, default_value = "png", value_name = "png|jpg")]
    pub(crate) image_format: DatasetImageFormat,

    /// What to randomize: robot, things (people's and labelled things' poses), clothes,
    /// bodies (people's shapes, heights, skin, hair, gait phase), light, noise; `none` for none
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "robot,things,clothes,bodies,light,noise",
        value_name = "WHAT,..."
    )]
    pub(crate) randomize: Vec<Randomize>,

    /// Distances from the robot to the thing it faces (m)
    #[arg(long, default_value = "1.5,8", value_name = "MIN,MAX", value_parser = parse_range)]
    pub(crate) distance: [f64; 2],

    /// Fraction of background images (the robot anywhere, facing anywhere)
    #[arg(long, default_value_t = 0.05, value_name = "FRACTION")]
    pub(crate) background: f64,

    /// How far people and labelled things move from where the world puts them (m, in x and y)
    #[arg(long, default_value_t = 0.5, value_name = "M")]
    pub(crate) move_m: f64,

    /// How far labelled objects and models turn (deg, either way); people face any way
    #[arg(long, default_value_t = 180.0, value_name = "DEG")]
    pub(crate) turn_deg: f64,

    /// Largest camera noise standard deviation (0..1 of full scale)
    #[arg(long, default_value_t = 0.02, value_name = "STDDEV")]
    pub(crate) noise_max: f64,

    /// Also run the detector on every image: its boxes in the records, COCO results in
    /// OUT/detections/, and its COCO metrics (AP50, AP50:95, per class) in OUT/metrics.json
    #[arg(long)]
    pub(crate) detect: bool,

    /// Images to make at once, each on a thread of its own with its own simulation, camera
    /// and detector; the files do not depend on it [default: the number of CPU cores]
    #[arg(long, short = 'j', value_name = "N")]
    pub(crate) jobs: Option<usize>,

    /// Make only shard I of N (counted from 0), e.g. one Slurm array task: the images whose
    /// number modulo N is I, into OUT/shard-I-of-N/ (resumable like any dataset). Merge the N
    /// folders with --merge once all are finished (docs/SCALE.md)
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    pub(crate) shard: Option<(usize, usize)>,

    /// Merge the folders of finished shards (OUT/shard-I-of-N/ of --shard) into the dataset
    /// folder OUT, with one COCO JSON and data.yaml, instead of making images. Refuses an
    /// incomplete set (naming the missing shards) or shards made differently (naming the field)
    #[arg(long, value_name = "SHARD_DIR", num_args = 1.., conflicts_with_all = ["shard", "detect", "images", "world", "robot"])]
    pub(crate) merge: Vec<PathBuf>,

    #[command(flatten)]
    pub(crate) detector: DetectorArgs,
}

/// A dataset output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DatasetFormat {
    /// Ultralytics YOLO: images/, labels/, data.yaml
    Yolo,
    /// COCO JSON: annotations/instances_{train,val}.json
    Coco,
}

/// A dataset image format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum DatasetImageFormat {
    /// Lossless PNG
    Png,
    /// JPEG, quality 95
    Jpg,
}

/// Something `rover dataset` can randomize.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Randomize {
    /// Where the robot (its camera) stands and looks
    Robot,
    /// Where people and labelled things stand and face
    Things,
    /// People's shirt and trousers colours
    Clothes,
    /// People's bodies (shape sliders, height, children too), skin tones, hair colours and
    /// styles, trousers or skirts, and half of them caught mid-stride
    Bodies,
    /// The sun's direction and strength, the sky's light
    Light,
    /// The camera's noise
    Noise,
    /// Nothing
    None,
}

fn parse_range(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [lo, hi] = parts.as_slice() else {
        return Err(format!("expected MIN,MAX, found '{text}'"));
    };
    let number = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("expected a number, found '{t}'"))
    };
    Ok([number(lo)?, number(hi)?])
}
