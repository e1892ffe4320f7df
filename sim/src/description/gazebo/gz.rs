//! Modern Gazebo's (gz-sim; Ignition Gazebo's names too) systems in a robot: the DiffDrive and
//! JointStatePublisher systems with gz-sim's parameter names and defaults. World-level systems a
//! model may carry (physics, sensors, user commands, scene broadcaster, the IMU and NavSat
//! systems) are known and need nothing from rover; any other system is listed once as not
//! simulated.

use super::values::{Ctx, Node, text_of};
use crate::description::xml::{elements, line_of};
use crate::error::Result;
use crate::model::drive::{DiffDriveConfig, DrivePlugin, OdometrySource, SpeedLimits};
use crate::model::sensors::JointStatePublisherConfig;

/// A gz-sim system rover reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum System {
    /// `gz-sim-diff-drive-system` / `gz::sim::systems::DiffDrive`.
    DiffDrive,
    /// `gz-sim-joint-state-publisher-system` / `gz::sim::systems::JointStatePublisher`.
    JointStatePublisher,
    /// A joint controller (position, velocity, trajectory).
    Joint(super::gz_joints::JointSystem),
    /// A world-level system rover needs nothing from (its work is always done).
    World,
    /// Any other gz-sim system.
    Other,
}

/// The systems that belong to the world and that rover's simulation always does.
const WORLD_SYSTEMS: &[&str] = &[
    "physics",
    "sensors",
    "user-commands",
    "scene-broadcaster",
    "imu",
    "navsat",
    "contact",
    "forcetorque",
    "magnetometer",
    "altimeter",
    "air-pressure",
];

/// The system's short name from its file name (`gz-sim-diff-drive-system`,
/// `libgz-sim8-diff-drive-system.so`, `ignition-gazebo-diff-drive-system` -> `diff-drive`);
/// `None` when the file is no gz-sim system.
pub(crate) fn system_stem(filename: &str) -> Option<&str> {
    let base = filename.rsplit('/').next().unwrap_or(filename);
    let base = base.strip_prefix("lib").unwrap_or(base);
    let base = base.strip_suffix(".so").unwrap_or(base);
    let rest = base
        .strip_prefix("gz-sim")
        .or_else(|| base.strip_prefix("ignition-gazebo"))?;
    let rest = rest.trim_start_matches(|c: char| c.is_ascii_digit());
    let rest = rest.strip_prefix('-')?;
    Some(rest.strip_suffix("-system").unwrap_or(rest))
}

/// Whether a plugin file is one of gz-sim's world systems, whose work rover's simulation
/// always does.
pub(crate) fn is_world_system(filename: &str) -> bool {
    system_stem(filename).is_some_and(|s| WORLD_SYSTEMS.contains(&s))
}

/// Whether a plugin is a gz-sim system (by file name or `gz::sim::systems::` /
/// `ignition::gazebo::systems::` name).
pub(crate) fn is_system(filename: &str, name: &str) -> bool {
    system_stem(filename).is_some()
        || name.starts_with("gz::sim::systems::")
        || name.starts_with("ignition::gazebo::systems::")
}

/// Which system a gz-sim plugin is.
pub(super) fn system(filename: &str, name: &str) -> System {
    let class = name.rsplit("::").next().unwrap_or(name);
    let stem = system_stem(filename).unwrap_or("");
    if let Some(joint) = super::gz_joints::JointSystem::of(stem, class) {
        return System::Joint(joint);
    }
    match (stem, class) {
        ("diff-drive", _) | (_, "DiffDrive") => System::DiffDrive,
        ("joint-state-publisher", _) | (_, "JointStatePublisher") => System::JointStatePublisher,
        (stem, _) if WORLD_SYSTEMS.contains(&stem) => System::World,
        _ => System::Other,
    }
}

/// The DiffDrive system, gz-sim's defaults where it is silent: wheels driven at the limited
/// body speeds every physics step, odometry from the wheel joints' angles. `robot_base_frame`
/// is left empty when `<child_frame_id>` is absent: the caller fills in gz-sim's
/// `<model>/<canonical link>`.
pub(super) fn parse_diff_drive(
    ctx: &Ctx<'_, '_>,
    plugin: Node<'_, '_>,
    model: &str,
) -> Result<DiffDriveConfig> {
    let what = "the gz-sim-diff-drive-system plugin";
    let mut c = DiffDriveConfig {
        name: plugin.attribute("name").unwrap_or("DiffDrive").to_owned(),
        command_topic: format!("/model/{model}/cmd_vel"),
        odometry_topic: format!("/model/{model}/odometry"),
        odometry_frame: format!("{model}/odom"),
        robot_base_frame: String::new(),
        wheel_separation_m: 1.0,
        wheel_diameter_m: 0.4,
        update_rate_hz: 0.0,
        odometry_source: OdometrySource::Encoder,
        // rover plays robot_state_publisher for the wheels, as gz-sim robots' launch files run it.
        publish_wheel_tf: true,
        publish_odom_tf: true,
        publish_wheel_joint_state: true,
        line: Some(line_of(ctx.doc, plugin)),
        plugin: DrivePlugin::GzSim,
        odometry_rate_hz: Some(50.0),
        tf_topic: Some(format!("/model/{model}/tf")),
        ..DiffDriveConfig::default()
    };
    let (mut left, mut right) = (Vec::new(), Vec::new());
    // Speed limits as (shared, tag, value): applied shared first, so that the specific ones
    // win wherever they are written, as gz-sim reads them.
    let mut limits: Vec<(bool, &str, f64)> = Vec::new();
    let mut misnamed_rate = None;
    for p in elements(plugin) {
        let text = || text_of(p).to_owned();
        let tag = p.tag_name().name();
        match tag {
            "left_joint" => left.push(text()),
            "right_joint" => right.push(text()),
            "wheel_separation" => c.wheel_separation_m = ctx.positive(p, what, "metres")?,
            "wheel_radius" => c.wheel_diameter_m = 2.0 * ctx.positive(p, what, "metres")?,
            "topic" => c.command_topic = text(),
            "odom_topic" => c.odometry_topic = text(),
            "tf_topic" => c.tf_topic = Some(text()),
            "frame_id" => c.odometry_frame = text(),
            "child_frame_id" => c.robot_base_frame = text(),
            "odom_publish_frequency" => {
                let hz = ctx.number(p, what, "Hz, 0 or less = every step")?;
                c.odometry_rate_hz = (hz > 0.0).then_some(hz);
            }
            "odom_publisher_frequency" => misnamed_rate = Some(line_of(ctx.doc, p)),
            _ => match limit_kind(tag) {
                Some(shared) => limits.push((shared, tag, ctx.number(p, what, "a speed limit")?)),
                None => tracing::warn!(
                    "{}:{}: <{tag}> in {what}: unknown parameter, ignored",
                    ctx.path.display(),
                    line_of(ctx.doc, p)
                ),
            },
        }
    }
    if let Some(line) = misnamed_rate {
        tracing::warn!(
            "{}:{line}: <odom_publisher_frequency> in {what}: gz-sim reads <odom_publish_frequency>; ignored as gz-sim ignores it (odometry at {} Hz)",
            ctx.path.display(),
            c.odometry_rate_hz.unwrap_or(0.0)
        );
    }
    if left.is_empty() || right.is_empty() {
        return Err(ctx.err(
            plugin,
            format!(
                "{what}: expected at least one <left_joint> and one <right_joint>, found {} and {}",
                left.len(),
                right.len()
            ),
        ));
    }
    c.left_joint = left.remove(0);
    c.right_joint = right.remove(0);
    c.extra_left_joints = left;
    c.extra_right_joints = right;
    if !limits.is_empty() {
        let (mut linear, mut angular) = (SpeedLimits::default(), SpeedLimits::default());
        limits.sort_by_key(|(shared, _, _)| !shared);
        for (_, tag, v) in limits {
            for slot in limit_slots(tag, &mut linear, &mut angular) {
                *slot = v;
            }
        }
        c.linear_limits = Some(linear);
        c.angular_limits = Some(angular);
    }
    Ok(c)
}

/// Whether `tag` is a DiffDrive speed limit, and if so whether it is a shared one
/// (`max_velocity`, for both) rather than a specific one (`max_linear_velocity`).
fn limit_kind(tag: &str) -> Option<bool> {
    let (bound, rest) = tag.split_once('_')?;
    let quantity = |q: &str| matches!(q, "velocity" | "acceleration" | "jerk");
    if !matches!(bound, "min" | "max") {
        return None;
    }
    match rest.split_once('_') {
        None => quantity(rest).then_some(true),
        Some(("linear" | "angular", q)) => quantity(q).then_some(false),
        Some(_) => None,
    }
}

/// Where a DiffDrive speed limit parameter goes: `{min,max}_{linear,angular}_{velocity,
/// acceleration,jerk}` to one limiter; the shared `{min,max}_{velocity,acceleration,jerk}` to
/// both, as gz-sim reads them (the specific ones, read after, override). Empty: no such
/// parameter.
fn limit_slots<'a>(
    tag: &str,
    linear: &'a mut SpeedLimits,
    angular: &'a mut SpeedLimits,
) -> Vec<&'a mut f64> {
    let Some((bound, rest)) = tag.split_once('_') else {
        return Vec::new();
    };
    let (limits, quantity): (Vec<&'a mut SpeedLimits>, &str) = match rest.split_once('_') {
        Some(("linear", q)) => (vec![linear], q),
        Some(("angular", q)) => (vec![angular], q),
        None => (vec![linear, angular], rest),
        Some(_) => return Vec::new(),
    };
    let mut out = Vec::new();
    for limits in limits {
        let pair = match quantity {
            "velocity" => &mut limits.velocity,
            "acceleration" => &mut limits.acceleration,
            "jerk" => &mut limits.jerk,
            _ => return Vec::new(),
        };
        match bound {
            "min" => out.push(&mut pair.0),
            "max" => out.push(&mut pair.1),
            _ => return Vec::new(),
        }
    }
    out
}

/// The JointStatePublisher system: its `<topic>` and `<joint_name>`s.
pub(super) fn parse_joint_state_publisher(
    plugin: Node<'_, '_>,
    doc: &roxmltree::Document<'_>,
    model: &str,
) -> JointStatePublisherConfig {
    let mut c = JointStatePublisherConfig {
        topic: format!("/world/default/model/{model}/joint_state"),
        joints: Vec::new(),
        line: Some(line_of(doc, plugin)),
    };
    for p in elements(plugin) {
        match p.tag_name().name() {
            "topic" => c.topic = text_of(p).to_owned(),
            "joint_name" => c.joints.push(text_of(p).to_owned()),
            _ => {}
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn system_names_from_files_and_classes() {
        assert_eq!(system_stem("gz-sim-diff-drive-system"), Some("diff-drive"));
        assert_eq!(
            system_stem("libgz-sim8-joint-state-publisher-system.so"),
            Some("joint-state-publisher")
        );
        assert_eq!(
            system_stem("ignition-gazebo-diff-drive-system"),
            Some("diff-drive")
        );
        assert_eq!(system_stem("libgazebo_ros_diff_drive.so"), None);
        assert_eq!(
            system("x", "gz::sim::systems::DiffDrive"),
            System::DiffDrive
        );
        assert_eq!(system("gz-sim-sensors-system", ""), System::World);
        assert_eq!(system("gz-sim-buoyancy-system", ""), System::Other);
    }

    #[test]
    fn specific_limits_win_over_shared_ones_wherever_written() -> Result<()> {
        let text = "<plugin filename=\"gz-sim-diff-drive-system\" name=\"gz::sim::systems::DiffDrive\">\
            <left_joint>l</left_joint><right_joint>r</right_joint>\
            <max_linear_acceleration>1</max_linear_acceleration>\
            <max_acceleration>3</max_acceleration>\
            <odom_publish_frequency>20</odom_publish_frequency></plugin>";
        let doc = roxmltree::Document::parse(text).map_err(|e| {
            crate::error::SimError::invalid(std::path::Path::new("x"), None, e.to_string())
        })?;
        let ctx = Ctx {
            doc: &doc,
            path: std::path::Path::new("x.urdf"),
            modern: true,
            model: "m",
        };
        let c = parse_diff_drive(&ctx, doc.root_element(), "m")?;
        let (lin, ang) = (
            c.linear_limits.unwrap_or_default(),
            c.angular_limits.unwrap_or_default(),
        );
        assert_eq!((lin.acceleration.1, ang.acceleration.1), (1.0, 3.0));
        assert_eq!(c.odometry_rate_hz, Some(20.0));
        assert_eq!(c.command_topic, "/model/m/cmd_vel");
        assert_eq!(limit_kind("max_jerk"), Some(true));
        assert_eq!(limit_kind("min_angular_velocity"), Some(false));
        assert_eq!(limit_kind("max_wheel_torque"), None);
        Ok(())
    }

    #[test]
    fn speed_limits_bound_jerk_then_acceleration_then_velocity() {
        let l = SpeedLimits {
            velocity: (-0.5, 0.5),
            acceleration: (-1.0, 1.0),
            ..SpeedLimits::default()
        };
        // From rest, 0.1 s: at most 0.1 m/s more.
        assert!((l.limit(2.0, 0.0, 0.0, 0.1) - 0.1).abs() < 1e-12);
        // Near the top speed the velocity bound wins.
        assert!((l.limit(2.0, 0.45, 0.4, 0.1) - 0.5).abs() < 1e-12);
        // Unlimited is the command itself.
        assert_eq!(SpeedLimits::default().limit(0.3, 0.0, 0.0, 0.01), 0.3);
        let mut lin = SpeedLimits::default();
        let mut ang = SpeedLimits::default();
        for (tag, v) in [
            ("max_acceleration", 1.0),
            ("max_linear_acceleration", 2.0),
            ("min_angular_velocity", -1.0),
            ("max_jerk", 3.0),
        ] {
            for slot in limit_slots(tag, &mut lin, &mut ang) {
                *slot = v;
            }
        }
        assert_eq!(lin.acceleration.1, 2.0);
        assert_eq!(ang.acceleration.1, 1.0);
        assert_eq!((lin.jerk.1, ang.jerk.1), (3.0, 3.0));
        assert_eq!(ang.velocity.0, -1.0);
        assert_eq!(lin.velocity.0, f64::NEG_INFINITY);
        assert!(limit_slots("max_wheel_torque", &mut lin, &mut ang).is_empty());
        assert!(limit_slots("max_linear_speed", &mut lin, &mut ang).is_empty());
    }
}
