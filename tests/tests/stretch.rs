//! Hello Robot's Stretch as a picker, with the real renderer, physics and detector: the PyPI
//! package hello-robot-stretch-urdf's RE2V0 gripper robot (included unchanged by
//! assets/robots/stretch_gripper.urdf.xacro), osrf's Coke can on a table beside it and a second
//! table 1.2 m further on (tests/worlds/stretch_pick.toml). The head camera sees the can
//! ("bottle" to YOLO) and the lift and the telescoping arm bring the gripper round it from
//! the side; the grasp assist (gazebo_grasp_fix's rule, on the can's model link) holds it, the
//! base carries it to the other table and the arm sets it down there, upright, judged from the
//! world's model states.

use anyhow::Result;
use glam::Vec3;
use rover_core::{Action, PickState, Session};
use rover_sim::geometry::Pose;
use rover_sim::physics::Grasped;
use rover_tests::Said;

/// The detector's and the pick's threshold.
const DETECTION_THRESHOLD: f32 = 0.15;

/// The Stretch world, its can from the corpus, detecting at 5 Hz of sim time in lockstep, the
/// arm after "bottle"; `None` (skipped, with the reason) where ../shared or the PyPI package
/// is absent.
fn session(seed: u64) -> Result<Option<Session>> {
    let Some(models) = rover_tests::shared("corpus/gazebo_models") else {
        return Ok(None);
    };
    let Some(wheel) = rover_tests::pypi("hello-robot-stretch-urdf", "0.1.2") else {
        return Ok(None);
    };
    let mut config = rover_core::RunConfig {
        world: Some(rover_tests::repo("tests/worlds/stretch_pick.toml")),
        ..rover_core::RunConfig::default()
    };
    config.robot_options.resources.model_search.push(models);
    config.robot_options.resources =
        (config.robot_options.resources).with_package("stretch_urdf", wheel.join("stretch_urdf"));
    let loaded = config.load_world_and_robot()?;
    Ok(Some(rover_tests::pick_session(
        loaded,
        seed,
        ("bottle", DETECTION_THRESHOLD),
    )?))
}

/// How far (deg) a pose's z axis leans from the vertical.
fn tilt_deg(pose: &Pose) -> f32 {
    (pose.rotation * Vec3::Z)
        .angle_between(Vec3::Z)
        .to_degrees()
}

/// The can's pose (its frame at its bottom) and the world's objects' poses now.
fn poses(session: &Session) -> (Pose, Vec<Pose>) {
    let mut models = Vec::new();
    session.sim().model_link_poses_into(&mut models);
    let mut objects = Vec::new();
    session.sim().object_poses_into(&mut objects);
    (models[0], objects)
}

/// Stretch sees the can with its head camera, reads it as upright and its size from the
/// depth image, plans a level grasp (its arm holds the hand level: lift, telescope and wrist
/// yaw) and brings the gripper round it: when the fingers start to close, the tool is within
/// 1 cm of the can's axis and within its height, the can still standing where it was, all
/// within 10 s of sim time of the toggle. Then the grasp assist holds the can's model link, the
/// arm lifts it and the base drives off with it: 12 s of sim time after the fingers started to
/// close, the can is at least 0.5 m further along towards the other table, at least 3 cm above
/// the counter, leaning no more than 15 degrees. The pick then sets it down on the other
/// table: done within 60 s of the toggle, and 2 s later the can stands on table_b's top
/// (its axis at least its radius inside the edges, its bottom within 1 cm of the top),
/// leaning no more than 15 degrees, let go.
#[test]
fn stretch_sees_the_can_takes_it_and_sets_it_down_on_the_other_table() -> Result<()> {
    let Some(mut session) = session(1)? else {
        return Ok(());
    };
    let mut said = Said::default();
    // The world's start pose turns the head to the counter and raises the lift.
    while session.sim().sim_time_s() < 3.0 {
        session.step(&mut said)?;
    }
    let (before, _) = poses(&session);
    session.input(Action::TogglePick, &mut said);
    let start = session.sim().sim_time_s();
    while session.stats().arm.pick != PickState::Grasping {
        session.step(&mut said)?;
        let state = session.stats().arm.pick;
        anyhow::ensure!(
            state != PickState::Failed && session.sim().sim_time_s() - start < 10.0,
            "no grasp within 10 s: {state:?}, {:?}",
            said.0.last()
        );
    }
    let took_s = session.sim().sim_time_s() - start;
    let planned = (said.0.iter())
        .find(|(_, _, t)| t.contains("planned in"))
        .map(|(_, _, t)| t.clone())
        .unwrap_or_default();
    let number_before = |unit: &str| -> Option<f64> {
        let end = planned.find(unit)?;
        planned[..end].rsplit(' ').next()?.parse().ok()
    };
    let (across, tall) = (number_before(" m across"), number_before(" m tall"));
    let (can, _) = poses(&session);
    let sim = session.sim();
    let tool = (sim.robot().link_id("link_grasp_tool"))
        .map(|l| sim.world_from_link(l).translation)
        .ok_or_else(|| anyhow::anyhow!("no link_grasp_tool"))?;
    let off_axis = (tool - can.translation).truncate().length();
    let above_bottom = tool.z - can.translation.z;
    println!(
        "stretch: grasping {took_s:.1} s after the toggle; read {across:?} m across, {tall:?} m tall; the tool {off_axis:.4} m off the can's axis, {above_bottom:.3} m above its bottom; the can moved {:.4} m, leans {:.1} deg; planned in {:?} s",
        (can.translation - before.translation).length(),
        tilt_deg(&can),
        session.pick().and_then(|p| p.planning_s())
    );
    assert!(
        planned.contains("upright") && planned.contains("level"),
        "{planned}"
    );
    // osrf's can: 6.6 cm across, 12.4 cm tall (the width reads a little narrow).
    assert!(
        across.is_some_and(|a| (0.05..=0.075).contains(&a)),
        "{planned}"
    );
    assert!(
        tall.is_some_and(|t| (0.11..=0.14).contains(&t)),
        "{planned}"
    );
    assert!(
        off_axis <= 0.01,
        "the tool is {off_axis} m off the can's axis"
    );
    assert!(
        (0.0..=0.124).contains(&above_bottom),
        "the tool is {above_bottom} m above the can's bottom"
    );
    assert!(
        (can.translation - before.translation).length() <= 0.01 && tilt_deg(&can) <= 5.0,
        "the hand pushed the can: {:?} -> {:?}",
        before.translation,
        can.translation
    );
    // Held, lifted and carried.
    let grasping_s = session.sim().sim_time_s();
    let mut held = None;
    while session.sim().sim_time_s() - grasping_s < 12.0 {
        session.step(&mut said)?;
        held = held.or(session.sim().grasp_assist_holds());
        anyhow::ensure!(
            session.stats().arm.pick != PickState::Failed,
            "the pick failed: {:?}",
            said.0.last()
        );
    }
    let (carried, _) = poses(&session);
    let along_m = carried.translation.x - before.translation.x;
    let above_m = carried.translation.z - before.translation.z;
    println!(
        "stretch: the assist held {held:?}; 12 s after the grip the can is {along_m:.3} m along, {above_m:.3} m above the counter, leaning {:.1} deg; the pick is {:?}",
        tilt_deg(&carried),
        session.stats().arm.pick
    );
    assert_eq!(held, Some(Grasped::ModelLink(0)), "{:?}", said.0.last());
    assert!(
        along_m >= 0.5 && above_m >= 0.03 && tilt_deg(&carried) <= 15.0,
        "the can is at {:?} (from {:?}), leaning {} deg",
        carried.translation,
        before.translation,
        tilt_deg(&carried)
    );
    // Set down on the other table: the pick done, then 2 s for anything to settle.
    while session.stats().arm.pick != PickState::Done {
        session.step(&mut said)?;
        let state = session.stats().arm.pick;
        anyhow::ensure!(
            state != PickState::Failed && session.sim().sim_time_s() - start < 60.0,
            "not set down within 60 s of the toggle: {state:?}, {:?}",
            said.0.last()
        );
    }
    let done_s = session.sim().sim_time_s();
    while session.sim().sim_time_s() - done_s < 2.0 {
        session.step(&mut said)?;
    }
    let (placed, objects) = poses(&session);
    let world_objects = &session.sim().world().objects;
    let (table, half_height_m) = (world_objects.iter())
        .position(|o| o.name == "table_b")
        .and_then(|i| Some((objects.get(i)?, world_objects[i].shape.half_height_m()?)))
        .ok_or_else(|| anyhow::anyhow!("no table_b"))?;
    // From the middle of table_b's top (0.5 m square).
    let on_top = placed.translation - (table.translation + Vec3::Z * half_height_m);
    let stopped: Vec<&str> = (said.0.iter())
        .filter(|(_, _, t)| {
            t.contains("reaches the place from here") || t.contains("setting it down at")
        })
        .map(|(_, _, t)| t.as_str())
        .collect();
    println!(
        "stretch: done {:.1} s after the toggle; the can is ({:.3}, {:.3}) m from table_b's middle, its bottom {:.4} m off its top, leaning {:.1} deg; the assist holds {:?}; {stopped:?}",
        done_s - start,
        on_top.x,
        on_top.y,
        on_top.z,
        tilt_deg(&placed),
        session.sim().grasp_assist_holds()
    );
    // Standing on it whole: its axis the can's radius (3.3 cm) inside table_b's edges.
    let half_m = 0.25 - 0.033;
    assert!(
        on_top.x.abs() <= half_m && on_top.y.abs() <= half_m,
        "the can is not over table_b: {on_top:?} from its middle"
    );
    assert!(
        on_top.z.abs() <= 0.01,
        "the can's bottom is not on table_b's top: {on_top:?}"
    );
    assert!(
        tilt_deg(&placed) <= 15.0,
        "the can leans {} deg",
        tilt_deg(&placed)
    );
    assert_eq!(session.sim().grasp_assist_holds(), None, "still held");
    Ok(())
}
