//! Pick settings ([`PickConfig`]): what to pick, how to come at it, where to put it and
//! whether the base drives.

use rover_sim::{model::Place, planning::PlannerOptions};

/// Pick settings.
#[derive(Debug, Clone, PartialEq)]
pub struct PickConfig {
    /// Class to pick (darknet_ros `Class`).
    pub class: String,
    /// Minimum detection probability.
    pub min_probability: f64,
    /// Sightings in a row that must agree before planning.
    pub sightings: u32,
    /// How close (m) sightings must be to agree.
    pub agree_m: f64,
    /// Approach directions tried, degrees below horizontal, in order.
    pub approach_pitches_deg: Vec<f64>,
    /// How far back along the approach the pre-grasp is (m).
    pub approach_m: f64,
    /// How high the object is lifted after the grasp (m).
    pub lift_m: f64,
    /// How far above the place's top the object's bottom is let go (m).
    pub drop_height_m: f64,
    /// The gripper's most effort while closing (N or N m).
    pub squeeze_n: f64,
    /// ... on an upright object (a can, a bottle): held by its side above its centre of mass,
    /// it needs a firmer grip not to turn in the hand (a 390 g can leant 30 degrees and fell at
    /// 5 N; at 10 N it is set down within 8 degrees of upright).
    pub squeeze_upright_n: f64,
    /// Each joint's speed as a share of its velocity limit.
    pub speed_scale: f64,
    /// Closer than this (m) to anything is a collision for the planner.
    pub margin_m: f64,
    /// Depth beyond this (m) is not trusted.
    pub max_range_m: f64,
    /// Where to put it (a world object it is dropped on or in, or a point it is set down
    /// at); `None`: the world's `[robot] place`.
    pub place: Option<Place>,
    /// A world object to take by its known pose, no camera needed (as a MoveIt pick node is
    /// given a collision object); `None`: the world's `[robot] pick`, else what the detector
    /// sees of [`Self::class`].
    pub object: Option<String>,
    /// Where (m, x forward and y left in the arm's base frame) the object should be when the
    /// car stops to pick it; set, the pick drives the base to within reach of the object and
    /// then to the place. `None`: the world's `[robot] fetch`, else the base is not moved.
    pub fetch_at: Option<[f64; 2]>,
    /// Planner settings.
    pub planner: PlannerOptions,
}

impl Default for PickConfig {
    fn default() -> Self {
        Self {
            class: "sports ball".into(),
            // darknet_ros's own threshold is 0.3: a small ball at arm's length scores ~0.32.
            min_probability: 0.25,
            sightings: 3,
            agree_m: 0.015,
            approach_pitches_deg: vec![90.0, 75.0, 60.0, 45.0, 30.0, 15.0],
            approach_m: 0.07,
            lift_m: 0.08,
            drop_height_m: 0.07,
            squeeze_n: 5.0,
            squeeze_upright_n: 10.0,
            speed_scale: 0.5,
            margin_m: 0.01,
            max_range_m: 4.0,
            place: None,
            object: None,
            fetch_at: None,
            planner: PlannerOptions::default(),
        }
    }
}
