//! Picking objects of other shapes with the real renderer, physics and detector: osrf's Coke
//! can (../shared/corpus/gazebo_models, what YOLO calls a "bottle") stands upright on a table
//! beside a plastic cup and a tennis ball (tests/worlds/arm_car_shapes.toml). The arm car
//! sees how tall it is in the depth image, takes it across its axis, and sets it down upright
//! on the tray; nothing else on the table moves.

use anyhow::{Result, anyhow};
use glam::Vec3;
use rover_core::{Action, PickState, Session};
use rover_sim::geometry::Pose;
use rover_tests::Said;

/// The world's objects (tests/worlds/arm_car_shapes.toml): the tray, the ball.
const TRAY: usize = 1;
const BALL: usize = 6;
/// The world's models (one link each): the can, the cup.
const CAN: usize = 0;
const CUP: usize = 1;
/// How many model links come before the objects in [`poses`].
const MODEL_LINKS: usize = 2;
/// The detector's and the pick's threshold.
const DETECTION_THRESHOLD: f32 = 0.15;
/// The tray's top (world z, m) and half its side.
const TRAY_TOP_Z: f32 = 0.106;
const TRAY_HALF_M: f32 = 0.075;

/// The shapes world, its models from the corpus, detecting at 5 Hz of sim time in lockstep,
/// the arm after `class`; `None` (skipped, with the reason) where ../shared is absent.
fn session(seed: u64, class: &str) -> Result<Option<Session>> {
    let Some(models) = rover_tests::shared("corpus/gazebo_models") else {
        return Ok(None);
    };
    let mut config = rover_core::RunConfig {
        world: Some(rover_tests::repo("tests/worlds/arm_car_shapes.toml")),
        ..rover_core::RunConfig::default()
    };
    config.robot_options.resources.model_search.push(models);
    let loaded = config.load_world_and_robot()?;
    // YOLO scores the can "bottle" 0.16-0.47 across the layouts (darknet_ros's 0.3 misses
    // it in most): the detector's threshold and the pick's at 0.15, as `--threshold 0.15`.
    Ok(Some(rover_tests::pick_session(
        loaded,
        seed,
        (class, DETECTION_THRESHOLD),
    )?))
}

/// Where everything on the table is now: the models' links, then the world's objects.
fn poses(session: &Session) -> Vec<Pose> {
    let mut models = Vec::new();
    session.sim().model_link_poses_into(&mut models);
    let mut objects = Vec::new();
    session.sim().object_poses_into(&mut objects);
    models.extend(objects);
    models
}

/// How far (deg) a pose's z axis leans from the vertical.
fn tilt_deg(pose: &Pose) -> f32 {
    (pose.rotation * Vec3::Z)
        .angle_between(Vec3::Z)
        .to_degrees()
}

/// How one pick went.
#[derive(Debug)]
struct Outcome {
    state: PickState,
    /// Sim seconds from the toggle to done (or the end).
    took_s: f64,
    /// The object's pose at the end.
    end: Pose,
    /// The most it leant (deg) while in the hand.
    carried_tilt_deg: f32,
    /// The most anything else moved (m), and what.
    others_moved: (f32, String),
    /// Whether the pick saw it (planned).
    seen: bool,
    planning_s: Option<f64>,
}

/// Switches pick on after 1 s with `class`, runs until it is done or failed (then 1 s more)
/// or 30 s have passed; `object` is the picked thing's index in [`poses`].
fn pick(session: &mut Session, object: usize, said: &mut Said) -> Result<Outcome> {
    let names = [
        "can", "cup", "table", "tray", "rim", "rim", "rim", "rim", "ball",
    ];
    while session.sim().sim_time_s() < 1.0 {
        session.step(said)?;
    }
    let before = poses(session);
    session.input(Action::TogglePick, said);
    let start = session.sim().sim_time_s();
    let mut finished: Option<f64> = None;
    let mut carried_tilt_deg = 0.0f32;
    let mut last = PickState::Seeking;
    loop {
        session.step(said)?;
        let now = session.sim().sim_time_s();
        let state = session.stats().arm.pick;
        let tilt = tilt_deg(&poses(session)[object]);
        if matches!(state, PickState::Lifting | PickState::Carrying) {
            carried_tilt_deg = carried_tilt_deg.max(tilt);
        }
        if state != last {
            println!("    {now:6.2} s {state:?}: it leans {tilt:.1} deg");
            last = state;
        }
        if finished.is_none() && matches!(state, PickState::Done | PickState::Failed) {
            finished = Some(now);
        }
        if finished.is_some_and(|f| now > f + 1.0) || now - start > 30.0 {
            break;
        }
    }
    let after = poses(session);
    let others_moved = (before.iter().zip(&after).enumerate())
        .filter(|(i, _)| *i != object)
        .map(|(i, (a, b))| {
            let moved = (a.translation - b.translation).length();
            (moved, names.get(i).copied().unwrap_or("?").to_owned())
        })
        .fold((0.0, String::new()), |a, b| if b.0 > a.0 { b } else { a });
    Ok(Outcome {
        state: session.stats().arm.pick,
        took_s: finished.unwrap_or(session.sim().sim_time_s()) - start,
        end: after[object],
        carried_tilt_deg,
        others_moved,
        seen: said.0.iter().any(|(_, _, t)| t.contains("planned in")),
        planning_s: session.pick().and_then(|p| p.planning_s()),
    })
}

/// Whether `end` (a model's frame: its bottom) stands upright on the tray at `tray`; a ball
/// (`round`, `end` its centre `radius_m` up) has only to be on it.
fn upright_on_tray(end: &Pose, tray: &Pose, round: Option<f32>) -> bool {
    let d = end.translation - tray.translation;
    let bottom_z = end.translation.z - round.unwrap_or(0.0);
    (round.is_some() || tilt_deg(end) <= 15.0)
        && d.x.abs() <= TRAY_HALF_M
        && d.y.abs() <= TRAY_HALF_M
        && (bottom_z - TRAY_TOP_Z).abs() <= 0.01
}

/// The can as the shipped world has it: YOLO calls it a "bottle"; the pick reads it as upright
/// (6 cm across, 12 cm tall), takes it, and it ends upright on the tray, nothing else on the
/// table moved more than 1 cm.
#[test]
fn the_arm_car_sets_the_can_upright_on_the_tray() -> Result<()> {
    let Some(mut session) = session(1, "bottle")? else {
        return Ok(());
    };
    let mut said = Said::default();
    let outcome = pick(&mut session, CAN, &mut said)?;
    let all = poses(&session);
    let tray = all[MODEL_LINKS + TRAY];
    println!("{outcome:?}");
    let planned = said.0.iter().find(|(_, _, t)| t.contains("planned in"));
    let planned = planned.ok_or_else(|| anyhow!("no plan was said"))?;
    assert!(planned.2.contains("upright"), "{}", planned.2);
    assert_eq!(outcome.state, PickState::Done);
    assert!(
        upright_on_tray(&outcome.end, &tray, None),
        "{:?} (tilt {:.1} deg) on the tray at {:?}",
        outcome.end.translation,
        tilt_deg(&outcome.end),
        tray.translation
    );
    assert!(outcome.others_moved.0 <= 0.01, "{:?}", outcome.others_moved);
    Ok(())
}

/// A seeded layout of the table: where the can, the cup (their frames, on the table) and the
/// ball (its centre) are. Each in its own patch, so the hand has room round the one it takes.
fn layout(seed: u64) -> [[f64; 3]; 3] {
    let mut rng = rover_sim::SplitMix64(0x5ba9e5 ^ seed.wrapping_mul(0x9e37_79b9));
    let mut at = |x: f64, y: f64, dx: f64, dy: f64, z: f64| {
        [x + dx * (rng.unit() - 0.5), y + dy * (rng.unit() - 0.5), z]
    };
    [
        at(0.30, 0.02, 0.06, 0.06, 0.10),
        at(0.44, 0.04, 0.04, 0.06, 0.10),
        at(0.38, -0.07, 0.04, 0.04, 0.1335),
    ]
}

/// Ten seeded layouts of the table, `--arm-class` for the object YOLO calls `class` (its
/// index `object` in [`poses`]; `round`: a ball of that radius). Of the layouts where YOLO
/// sees it, at least 9 in 10 end with it upright (within 15 degrees) on the tray and nothing
/// else on the table moved more than 1 cm; YOLO sees it in at least `seen_at_least` of them.
/// Prints each layout, and the planning time's median and slowest.
fn ten_layouts(
    (class, object, round): (&str, usize, Option<f32>),
    seen_at_least: usize,
) -> Result<()> {
    let mut results = Vec::new();
    let only: Option<u64> = std::env::var("SHAPES_TRIAL")
        .ok()
        .and_then(|t| t.parse().ok());
    for seed in (0..10).filter(|s| only.is_none_or(|o| o == *s)) {
        let Some(mut session) = session(seed, class)? else {
            return Ok(());
        };
        let [can, cup, ball] = layout(seed);
        for (model, at) in [(CAN, can), (CUP, cup)] {
            let at = at.map(|v| v as f32);
            session.place_model(model, Pose::from_translation(Vec3::from(at)))?;
        }
        session.place_object(BALL, ball, 0.0)?;
        let mut said = Said::default();
        let outcome = pick(&mut session, object, &mut said)?;
        let tray = poses(&session)[MODEL_LINKS + TRAY];
        let ok = outcome.state == PickState::Done
            && upright_on_tray(&outcome.end, &tray, round)
            && outcome.others_moved.0 <= 0.01;
        println!(
            "layout {seed}: {}: ends at {:.3?} leaning {:.1} deg; carried leaning {:.1} deg at most; others moved {:?}; {:.1} s",
            match (outcome.seen, ok) {
                (false, _) => "not seen",
                (true, true) => "on the tray",
                (true, false) => "FAILED",
            },
            outcome.end.translation,
            tilt_deg(&outcome.end),
            outcome.carried_tilt_deg,
            outcome.others_moved,
            outcome.took_s
        );
        results.push((outcome.seen, ok, outcome.planning_s));
    }
    let seen = results.iter().filter(|r| r.0).count();
    let placed = results.iter().filter(|r| r.0 && r.1).count();
    let (median, slowest) = rover_tests::median_and_slowest(results.iter().filter_map(|r| r.2));
    println!(
        "{class}: seen in {seen}/{}, on the tray in {placed}/{seen} of those; planning median {median:.4} s, slowest {slowest:.4} s",
        results.len()
    );
    if only.is_none() {
        assert!(seen >= seen_at_least, "YOLO saw the {class} in {seen}/10");
    }
    assert!(placed * 10 >= seen * 9, "{placed}/{seen} seen layouts");
    Ok(())
}

/// The can ("bottle" to YOLO) in ten seeded layouts: YOLO sees it in 9 (in the other it scores
/// 0.06-0.07, under the 0.15 threshold), and all 9 end upright on the tray, nothing else moved.
#[test]
fn ten_layouts_of_the_can_end_upright_on_the_tray() -> Result<()> {
    ten_layouts(("bottle", CAN, None), 9)
}
