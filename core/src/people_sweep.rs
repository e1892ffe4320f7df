//! The people sweep: is the person a `person` to the detector from every side and distance?
//!
//! The world's first person is viewed through the robot's camera from 8 headings (every 45
//! degrees round them) at 1.5, 2, 3, 5 and 8 m, the robot placed facing them, one image each;
//! standing, and walking at 4 phases of the gait. A view counts as found when a detection
//! matches the person's ground-truth box (IoU >= [`MATCH_IOU`], as `rover eval` judges). Run by
//! `rover bench people`, for MakeHuman's body and rover's own figure side by side.

use std::path::Path;

use rover_perception::{Detector, FrameStamp, RgbView};
use rover_sim::model::human::BodyShape;
use rover_sim::{
    geometry::{Pose, pose_from_position_yaw},
    model::{Labelled, Walk},
    physics::Simulation,
    sensors::CameraSensor,
};

use crate::error::{CoreError, Result};
use crate::headless::RunConfig;
use crate::judge::{LiveJudge, MATCH_IOU};

/// Viewing distances (m, robot base to the person's feet).
pub const SWEEP_DISTANCES_M: [f64; 5] = [1.5, 2.0, 3.0, 5.0, 8.0];
/// Viewing headings (deg, round the person; 0 in front of them).
pub const SWEEP_HEADINGS_DEG: [f64; 8] = [0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0];
/// Walking speed for the walking views (m/s).
const WALK_SPEED_MPS: f64 = 1.0;

/// What the person is doing in a set of views.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SweepPosture {
    /// Standing still.
    Standing,
    /// Walking, at this fraction of the gait cycle (0..1).
    Walking(f64),
}

impl std::fmt::Display for SweepPosture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Standing => write!(f, "standing"),
            Self::Walking(c) => write!(f, "walk {:.0}%", c * 100.0),
        }
    }
}

/// The postures `rover bench people` shows: standing and 4 phases of the walk.
pub const SWEEP_POSTURES: [SweepPosture; 5] = [
    SweepPosture::Standing,
    SweepPosture::Walking(0.0),
    SweepPosture::Walking(0.25),
    SweepPosture::Walking(0.5),
    SweepPosture::Walking(0.75),
];

/// One view of the sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepView {
    /// What the person was doing.
    pub posture: SweepPosture,
    /// Where the robot stood round them (deg; 0 in front).
    pub heading_deg: f64,
    /// How far (m).
    pub distance_m: f64,
    /// Whether a detection matched the person's ground truth (IoU >= 0.5).
    pub found: bool,
    /// The matching detection's IoU and confidence (0 when not found).
    pub iou: f64,
    /// Its confidence.
    pub confidence: f64,
}

/// Views the world's first person in `posture`, with body `shape` (`None`: rover's figure),
/// from every heading and distance; saves each image into `save` when given
/// (`POSTURE_HEADING_DISTANCE.png`).
pub fn sweep(
    config: &RunConfig,
    detector: &mut Detector,
    shape: Option<BodyShape>,
    posture: SweepPosture,
    save: Option<&Path>,
) -> Result<Vec<SweepView>> {
    let (mut world, robot) = config.load_world_and_robot()?;
    let Some(person) = world.people.first_mut() else {
        return Err(CoreError::Option(
            "the people sweep needs a world with a person (the first one is viewed)".into(),
        ));
    };
    person.shape = shape;
    person.walk = match posture {
        SweepPosture::Standing => None,
        SweepPosture::Walking(_) => Some(Walk {
            waypoints_m: vec![[person.position_m[0] + 1000.0, person.position_m[1]]],
            speed_mps: WALK_SPEED_MPS,
            repeat: false,
            start_after_s: 0.0,
        }),
    };
    let mut sim = Simulation::new(world, robot, &config.options)?;
    if let SweepPosture::Walking(cycle) = posture {
        // Step on until the gait is at `cycle` (within a step).
        let stride_s = sim.world().people[0].stride_m() / WALK_SPEED_MPS;
        let until_s = stride_s * (1.0 + cycle);
        while sim.sim_time_s() + 0.5 * sim.dt_s() < until_s {
            sim.step();
        }
    }
    let mut camera = CameraSensor::new(&sim).map_err(CoreError::Camera)?;
    camera.disable_depth();
    camera
        .enable_ground_truth(&sim)
        .map_err(CoreError::Camera)?;
    let world_from_person = sim.world_from_person(0);
    let (px, py) = (
        f64::from(world_from_person.translation.x),
        f64::from(world_from_person.translation.y),
    );
    let facing = rover_sim::geometry::yaw_of(world_from_person.rotation);
    let mut judge = LiveJudge::default();
    let mut views = Vec::new();
    for heading_deg in SWEEP_HEADINGS_DEG {
        for distance_m in SWEEP_DISTANCES_M {
            let round = facing + heading_deg.to_radians();
            let at = [px + distance_m * round.cos(), py + distance_m * round.sin()];
            let world_from_base: Pose =
                pose_from_position_yaw([at[0], at[1], 0.0], round + std::f64::consts::PI);
            sim.place_robot(world_from_base)?;
            let frame = camera.capture(&sim).map_err(CoreError::Camera)?;
            let image = RgbView {
                width: frame.width as usize,
                height: frame.height as usize,
                pixels: frame.rgb,
            };
            let stamp = FrameStamp {
                sim_time_s: frame.sim_time_s,
                frame: frame.seq,
            };
            let boxes = detector.detect(image, stamp)?;
            if let Some(dir) = save {
                let name = format!(
                    "{}_{:03.0}deg_{:.1}m.png",
                    posture.to_string().replace([' ', '%'], ""),
                    heading_deg,
                    distance_m
                );
                let rgb = image::RgbImage::from_raw(frame.width, frame.height, frame.rgb.to_vec());
                if let Some(rgb) = rgb {
                    let path = dir.join(name);
                    rgb.save(&path).map_err(|e| CoreError::Write {
                        path: path.clone(),
                        cause: std::io::Error::other(e),
                    })?;
                }
            }
            let truth = frame.ground_truth;
            let m = judge.judge(&boxes, truth);
            let person = truth
                .iter()
                .position(|t| t.entity == Labelled::Person(0) && !t.ignore);
            let hit = m
                .matches
                .iter()
                .find(|h| Some(h.ground_truth) == person && h.iou >= MATCH_IOU);
            views.push(SweepView {
                posture,
                heading_deg,
                distance_m,
                found: hit.is_some(),
                iou: hit.map_or(0.0, |h| h.iou),
                confidence: hit
                    .and_then(|h| boxes.bounding_boxes.get(h.detection))
                    .map_or(0.0, |b| b.probability),
            });
        }
    }
    Ok(views)
}
