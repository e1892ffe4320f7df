//! The arm's options ([`ArmArgs`]: look, reach, pick and fetch), with their value parsers.

use std::path::PathBuf;

use clap::Args;

/// The arm's look, reach and pick (docs/ARM.md): switched on by `toggle = "look"` / `"reach"` /
/// `"pick"` in a script, the station's keys, or ROS.
#[derive(Debug, Args)]
pub(crate) struct ArmArgs {
    /// Arm: the end effector that reaches (e.g. TIAGo's arm_tool_link) [default: the world's
    /// [robot] ee_link]
    #[arg(long, value_name = "LINK")]
    pub(crate) ee_link: Option<String>,

    /// Arm: the link look and reach work from; IK moves the joints between it and --ee-link
    /// (e.g. TIAGo's torso_lift_link, so the head looks while the arm reaches) [default: the
    /// world's [robot] arm_base, else the robot's root link]
    #[arg(long, value_name = "LINK")]
    pub(crate) arm_base: Option<String>,

    /// Arm: a MoveIt SRDF whose planning group (--arm-group) gives --arm-base and --ee-link
    /// when they are not given [default: the world's [robot] srdf]
    #[arg(long, value_name = "FILE")]
    pub(crate) srdf: Option<PathBuf>,

    /// Arm: the SRDF's planning group that is the arm [default: the world's [robot] arm_group,
    /// else `arm`, else the only group]
    #[arg(long, value_name = "NAME")]
    pub(crate) arm_group: Option<String>,

    /// Arm: the class look turns to and reach goes for (a darknet_ros `Class`)
    #[arg(long, default_value = "sports ball", value_name = "CLASS")]
    pub(crate) arm_class: String,

    /// Arm: how far short of the object's centre (estimated from its box and the depth image)
    /// the tool stops (m)
    #[arg(long, default_value_t = 0.10, value_name = "M")]
    pub(crate) reach_standoff: f64,

    /// Pick: where pick puts what it picked: a world object's name (e.g. worlds/
    /// arm_car_pick.toml's `bin`; dropped on or in it) or a point X,Y,Z in the world frame (m;
    /// set down there) [default: the world's [robot] place]
    #[arg(long, value_name = "NAME|X,Y,Z", allow_hyphen_values = true)]
    pub(crate) place: Option<String>,

    /// Pick: take this world object by its known pose (as a MoveIt node adds the object to
    /// its planning scene), no camera or detector needed [default: the world's [robot] pick,
    /// else what the detector sees of --arm-class]
    #[arg(long, value_name = "NAME")]
    pub(crate) pick_object: Option<String>,

    /// Pick: fetch: the car drives to within reach of the object (until it is at X,Y, m, x
    /// forward and y left in the arm's base frame: where the arm takes it best), picks it,
    /// backs off and drives to the --place, and puts it there (e.g. worlds/
    /// arm_car_fetch.toml) [default: the world's [robot] fetch, else the base stays put]
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true)]
    pub(crate) fetch: Option<String>,
}

/// `--fetch X,Y`: two finite numbers (m).
fn parse_fetch(text: &str) -> anyhow::Result<[f64; 2]> {
    let numbers: Result<Vec<f64>, _> = text.split(',').map(|p| p.trim().parse::<f64>()).collect();
    match numbers.as_deref() {
        Ok(&[x, y]) if x.is_finite() && y.is_finite() => Ok([x, y]),
        _ => anyhow::bail!(
            "--fetch {text}: expected X,Y: where the object should be when the car stops to pick it (two finite numbers, m, in the arm's base frame)"
        ),
    }
}

/// `--place`: three comma-separated finite numbers are a point, anything else an object's name.
fn parse_place(text: &str) -> anyhow::Result<rover_sim::model::Place> {
    let numbers: Result<Vec<f64>, _> = text.split(',').map(|p| p.trim().parse::<f64>()).collect();
    if let Ok(point) = numbers
        && let [x, y, z] = point[..]
    {
        anyhow::ensure!(
            point.iter().all(|v| v.is_finite()),
            "--place {text}: a point must be three finite numbers X,Y,Z (m)"
        );
        return Ok(rover_sim::model::Place::Point([x, y, z]));
    }
    anyhow::ensure!(
        !text.trim().is_empty(),
        "--place: expected a world object's name or a point X,Y,Z (m), found nothing"
    );
    Ok(rover_sim::model::Place::Object(text.to_owned()))
}

impl ArmArgs {
    /// The arm's settings; the pick takes boxes down to the detector's `threshold` when that is
    /// under its own (0.25): `--threshold 0.15` lets it pick a can YOLO scores 0.2.
    pub(crate) fn arm(&self, threshold: f32) -> anyhow::Result<rover_core::ArmConfig> {
        anyhow::ensure!(
            self.reach_standoff.is_finite() && self.reach_standoff >= 0.0,
            "--reach-standoff must be a distance of 0 m or more, found {}",
            self.reach_standoff
        );
        Ok(rover_core::ArmConfig {
            base_link: self.arm_base.clone(),
            ee_link: self.ee_link.clone(),
            srdf: self.srdf.clone(),
            group: self.arm_group.clone(),
            look: rover_core::LookConfig {
                class: self.arm_class.clone(),
                ..rover_core::LookConfig::default()
            },
            reach: rover_core::ReachConfig {
                class: self.arm_class.clone(),
                standoff_m: self.reach_standoff,
                ..rover_core::ReachConfig::default()
            },
            pick: rover_core::PickConfig {
                class: self.arm_class.clone(),
                place: self.place.as_deref().map(parse_place).transpose()?,
                object: self.pick_object.clone(),
                fetch_at: self.fetch.as_deref().map(parse_fetch).transpose()?,
                min_probability: rover_core::PickConfig::default()
                    .min_probability
                    .min(f64::from(threshold)),
                ..rover_core::PickConfig::default()
            },
        })
    }
}
