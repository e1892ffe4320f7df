//! Pick and place with the real renderer, physics and detector: the arm car
//! (worlds/arm_car_pick.toml, its two-finger gripper) sees the ball through its mast's depth
//! camera, plans round the table and the bin, grasps the ball, and drops it into the bin.

use anyhow::Result;
use rover_core::{Action, EventLevel, PickState, Session};
use rover_sim::geometry::Pose;
use rover_tests::Said;

/// The ball's index among the world's objects (worlds/arm_car_pick.toml).
const BALL: usize = 6;
/// The bin's inside (world frame): x and y ranges (m), and its floor's top (m).
const BIN_X: (f64, f64) = (0.195, 0.305);
const BIN_Y: (f64, f64) = (-0.205, -0.095);
const BIN_FLOOR_Z: f64 = 0.104;

/// The pick world as shipped, detecting at 5 Hz of sim time in lockstep.
fn session(seed: u64) -> Result<Session> {
    session_with(seed, |_| {})
}

/// [`session`] with the world changed by `change` first; the drive's command timeout off
/// (a teleop key holds until the next).
fn session_with(seed: u64, change: impl FnOnce(&mut rover_sim::model::World)) -> Result<Session> {
    session_in("worlds/arm_car_pick.toml", seed, change)
}

/// [`session_with`] for the world at `world` (repository path).
fn session_in(
    world: &str,
    seed: u64,
    change: impl FnOnce(&mut rover_sim::model::World),
) -> Result<Session> {
    let config = rover_core::RunConfig {
        world: Some(rover_tests::repo(world)),
        ..rover_core::RunConfig::default()
    };
    let (mut world, robot) = config.load_world_and_robot()?;
    change(&mut world);
    let options = rover_tests::lockstep_options(seed);
    Ok(Session::new(world, robot, &options, &mut Said::default())?)
}

fn object(session: &Session, index: usize) -> Pose {
    let mut poses = Vec::new();
    session.sim().object_poses_into(&mut poses);
    poses.get(index).copied().unwrap_or(Pose::IDENTITY)
}

/// How one pick went.
#[derive(Debug)]
struct Outcome {
    state: PickState,
    /// Sim seconds from the toggle to done (or the end).
    took_s: f64,
    /// The ball's centre at the end (world, m).
    ball_m: [f64; 3],
    planning_s: Option<f64>,
    /// How far the ball moved in the tool's frame while lifted and carried (m).
    slip_m: f32,
    /// What but the fingers and the table touched the ball before the grasp (before the
    /// fingers start closing).
    touched: Vec<String>,
}

impl Outcome {
    fn in_bin(&self) -> bool {
        let [x, y, z] = self.ball_m;
        (BIN_X.0..=BIN_X.1).contains(&x)
            && (BIN_Y.0..=BIN_Y.1).contains(&y)
            && z > BIN_FLOOR_Z
            && z < BIN_FLOOR_Z + 0.05
    }
}

/// Switches pick on after `settle_s`, runs until it is done or failed (then 1 s more for the
/// ball to land) or `limit_s` has passed.
fn pick(session: &mut Session, settle_s: f64, limit_s: f64, said: &mut Said) -> Result<Outcome> {
    pick_object(session, BALL, settle_s, limit_s, said)
}

/// [`pick`] of world object `object` (its index; what `ball_m` and `touched` are of).
fn pick_object(
    session: &mut Session,
    object_index: usize,
    settle_s: f64,
    limit_s: f64,
    said: &mut Said,
) -> Result<Outcome> {
    let end = session.sim().sim_time_s() + settle_s;
    while session.sim().sim_time_s() < end {
        session.step(said)?;
    }
    session.input(Action::TogglePick, said);
    let start = session.sim().sim_time_s();
    let mut finished: Option<f64> = None;
    let tool = session
        .sim()
        .robot()
        .link_id("tool_link")
        .ok_or_else(|| anyhow::anyhow!("no tool_link"))?;
    let mut held_from: Option<glam::Vec3> = None;
    let mut slip_m = 0.0f32;
    let mut touched: Vec<String> = Vec::new();
    loop {
        session.step(said)?;
        let now = session.sim().sim_time_s();
        let state = session.stats().arm.pick;
        // Before the grasp: until the fingers start closing (squeezed, a ball may roll
        // against the palm).
        if matches!(state, PickState::Seeking | PickState::Approaching) {
            for link in session.sim().object_contacts(object_index) {
                if link != "table" && !link.ends_with("_finger_link") && !touched.contains(&link) {
                    touched.push(link);
                }
            }
        }
        if matches!(state, PickState::Lifting | PickState::Carrying) {
            let sim = session.sim();
            let in_tool = sim
                .world_from_link(tool)
                .inverse()
                .transform_point(object(session, object_index).translation);
            let from = *held_from.get_or_insert(in_tool);
            slip_m = slip_m.max((in_tool - from).length());
        }
        if finished.is_none() && matches!(state, PickState::Done | PickState::Failed) {
            finished = Some(now);
        }
        if finished.is_some_and(|f| now > f + 1.0) || now - start > limit_s {
            break;
        }
    }
    let t = object(session, object_index).translation;
    Ok(Outcome {
        state: session.stats().arm.pick,
        took_s: finished.unwrap_or(session.sim().sim_time_s()) - start,
        ball_m: [f64::from(t.x), f64::from(t.y), f64::from(t.z)],
        planning_s: session.pick().and_then(|p| p.planning_s()),
        slip_m,
        touched,
    })
}

/// The shipped world: the ball ends in the bin, the pick done in under 30 s of sim time, and
/// nothing but the fingers touched the ball before the grasp.
#[test]
fn the_arm_car_picks_the_ball_and_drops_it_in_the_bin() -> Result<()> {
    let mut said = Said::default();
    let mut session = session(0)?;
    let outcome = pick(&mut session, 1.0, 40.0, &mut said)?;
    println!("{outcome:?}");
    assert_eq!(outcome.state, PickState::Done, "{:?}", said.0.last());
    assert!(outcome.took_s < 30.0, "{outcome:?}");
    assert!(outcome.in_bin(), "{outcome:?}");
    assert!(outcome.touched.is_empty(), "{outcome:?}");
    Ok(())
}

/// Self-occlusion in a pick (worlds/arm_car_orange.toml, where the arm passes between the mast
/// camera and the orange: reach's test sees it hidden): the orange is picked and set on the
/// tray, nothing but the hand (the palm meets a 7.4 cm orange on the
/// way in, where a 6.7 cm ball clears it) and its table touching it first.
#[test]
fn the_arm_car_picks_the_orange_its_arm_passes_in_front_of_onto_the_tray() -> Result<()> {
    const ORANGE: usize = 2;
    let mut said = Said::default();
    let config = rover_core::RunConfig {
        world: Some(rover_tests::repo("worlds/arm_car_orange.toml")),
        ..rover_core::RunConfig::default()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let options = rover_core::SessionOptions {
        arm: rover_core::ArmConfig::default().with_class("orange"),
        ..rover_tests::lockstep_options(0)
    };
    let mut session = Session::new(world, robot, &options, &mut said)?;
    let outcome = pick_object(&mut session, ORANGE, 1.0, 30.0, &mut said)?;
    println!("{outcome:?}");
    assert_eq!(outcome.state, PickState::Done, "{:?}", said.0.last());
    // On the tray (0.14 m square at (0.25, 0.16), 4 mm thick): the orange's centre over it,
    // one radius above its top.
    let [x, y, z] = outcome.ball_m;
    assert!(
        (x - 0.25).abs() < 0.07 && (y - 0.16).abs() < 0.07,
        "{outcome:?}"
    );
    assert!((z - (0.004 + 0.037)).abs() < 0.01, "{outcome:?}");
    assert!(
        outcome.touched.iter().all(|link| link == "hand_link"),
        "{outcome:?}"
    );
    Ok(())
}

/// The mobile pick (worlds/arm_car_fetch.toml): from one toggle the car drives to the ball
/// YOLO sees on a low table 1.5 m ahead, picks it, drives to the bin on the floor 1 m to its
/// right and drops it in; no part of the car touches the table or the bin's walls.
#[test]
fn the_arm_car_fetches_the_ball_from_a_table_into_a_bin_1_m_away() -> Result<()> {
    const TABLE: usize = 0;
    let mut said = Said::default();
    let mut session = session_in("worlds/arm_car_fetch.toml", 0, |_| {})?;
    let links: Vec<String> = (session.sim().robot().links.iter())
        .map(|l| l.name.clone())
        .collect();
    let mut bumped: Vec<String> = Vec::new();
    let start = session.sim().sim_time_s();
    session.input(Action::TogglePick, &mut said);
    let mut finished: Option<f64> = None;
    while finished.is_none_or(|f| session.sim().sim_time_s() - start < f + 1.0) {
        session.step(&mut said)?;
        let now = session.sim().sim_time_s() - start;
        for index in TABLE..BALL {
            for what in session.sim().object_contacts(index) {
                let finger = what.ends_with("_finger_link");
                if links.contains(&what) && !finger && !bumped.contains(&what) {
                    println!("{now:.2}: {what} touches object {index}");
                    bumped.push(what);
                }
            }
        }
        let state = session.stats().arm.pick;
        if finished.is_none() && matches!(state, PickState::Done | PickState::Failed) {
            finished = Some(now);
        }
        anyhow::ensure!(now < 90.0, "not done in 90 s: {:?}", said.0.last());
    }
    let took_s = finished.unwrap_or_default();
    let ball = object(&session, BALL).translation;
    println!("fetched in {took_s:.1} s of sim time; the ball at {ball:.3?}");
    assert_eq!(
        session.stats().arm.pick,
        PickState::Done,
        "{:?}",
        said.0.last()
    );
    let texts: Vec<&str> = said.0.iter().map(|(_, _, t)| t.as_str()).collect();
    for step in [
        "pick: seeking -> fetching",
        "pick: lifting -> delivering",
        "pick: delivering -> carrying",
    ] {
        assert!(texts.contains(&step), "never said {step:?}: {texts:#?}");
    }
    // The bin's inside: 11 cm square round (0, -1), its floor's top 4 mm up.
    assert!(
        ball.x.abs() < 0.055 && (ball.y + 1.0).abs() < 0.055 && ball.z > 0.004 && ball.z < 0.054,
        "the ball is not in the bin: {ball:?}"
    );
    assert!(
        bumped.is_empty(),
        "the car touched the table or the bin: {bumped:?}"
    );
    Ok(())
}

/// A key pressed while a fetch drives takes the base back: the pick stops, saying so, and the
/// key's command drives the car (no stop from the fetch comes after it). The same for a drive
/// to a stance chosen from the arm's reachability (no fetch point).
#[test]
fn a_key_takes_the_base_back_from_a_fetch() -> Result<()> {
    for world in ["worlds/arm_car_fetch.toml", "worlds/arm_car_stance.toml"] {
        println!("{world}:");
        key_takes_the_base_back(world)?;
    }
    Ok(())
}

/// [`a_key_takes_the_base_back_from_a_fetch`] in `world`.
fn key_takes_the_base_back(world: &str) -> Result<()> {
    use rover_core::KeyAction;
    let mut said = Said::default();
    let mut session = session_in(world, 0, |_| {})?;
    session.input(Action::TogglePick, &mut said);
    let run = |session: &mut Session, seconds: f64, said: &mut Said| -> Result<()> {
        let end = session.sim().sim_time_s() + seconds;
        while session.sim().sim_time_s() < end {
            session.step(said)?;
        }
        Ok(())
    };
    run(&mut session, 2.0, &mut said)?;
    assert_eq!(
        session.stats().arm.pick,
        PickState::Fetching,
        "{:?}",
        said.0
    );
    assert!(
        session.sim().odometry().linear_mps > 0.1,
        "the fetch is not driving"
    );
    session.input(Action::Key(KeyAction::Move { x: -1.0, th: 0.0 }), &mut said);
    run(&mut session, 1.0, &mut said)?;
    assert_eq!(session.stats().arm.pick, PickState::Failed);
    assert!(
        said.0
            .iter()
            .any(|(_, _, t)| t == "pick: stopped: the base was driven by another input"),
        "{:?}",
        said.0
    );
    let backing = session.sim().odometry().linear_mps;
    assert!(
        backing < -0.3,
        "the key's command did not hold: {backing} m/s"
    );
    Ok(())
}

/// Where trial `seed` puts the ball on the table (world frame, its centre): x 0.23-0.29 m,
/// y 0.05-0.125 m: left of the bin, within the arm's reach, and where the mast's camera sees
/// all of it and YOLO (yolov12n) calls it a sports ball at 0.44-0.82. Nearer the middle the
/// car's own front camera hides the ball's lower half (the depth under its box is then the
/// front camera's), and beside it YOLO calls the ball an apple.
fn ball_place(seed: u64) -> [f64; 3] {
    let mut rng = rover_sim::SplitMix64(0x5eed_0000 + seed);
    [0.23 + 0.06 * rng.unit(), 0.05 + 0.075 * rng.unit(), 0.1335]
}

/// The ball at 20 seeded random places on the table: all 20 picks end with the ball in the bin
/// within 30 s of sim time (docs/ARM.md's "20 of 20"), nothing but the fingers touching it
/// before the grasp, and the ball moving less than 5 mm in the hand while it is lifted and
/// carried (3.7 mm at most, measured). Prints each trial, the planning time's median and
/// slowest.
#[test]
fn twenty_seeded_picks_put_the_ball_in_the_bin() -> Result<()> {
    /// Most the ball may move in the hand between the grasp and the release (m).
    const MAX_CARRY_SLIP_M: f32 = 0.005;
    let mut results = Vec::new();
    let only: Option<u64> = std::env::var("PICK_TRIAL")
        .ok()
        .and_then(|t| t.parse().ok());
    for seed in (0..20).filter(|s| only.is_none_or(|o| o == *s)) {
        let mut said = Said::default();
        let mut session = session(seed)?;
        let at = ball_place(seed);
        session.place_object(BALL, at, 0.0)?;
        let outcome = pick(&mut session, 1.0, 35.0, &mut said)?;
        let ok = outcome.state == PickState::Done
            && outcome.took_s < 30.0
            && outcome.in_bin()
            && outcome.touched.is_empty()
            && outcome.slip_m < MAX_CARRY_SLIP_M;
        println!("trial {seed:2}: ball at {at:.3?}: {ok} {outcome:?}");
        if !ok {
            for (t, level, text) in said.0.iter().filter(|(_, l, _)| *l == EventLevel::Warn) {
                println!("    {t:.2} {level:?} {text}");
            }
        }
        results.push((ok, outcome));
    }
    let successes = results.iter().filter(|(ok, _)| *ok).count();
    let planned = results.iter().filter_map(|(_, o)| o.planning_s);
    let (median, slowest) = rover_tests::median_and_slowest(planned.clone());
    let took: Vec<f64> = results.iter().map(|(_, o)| o.took_s).collect();
    println!(
        "{successes}/20 in the bin; planning median {median:.4} s, slowest {slowest:.4} s ({} planned); sim seconds per pick: {took:.1?}",
        planned.count()
    );
    let trials = results.len();
    assert_eq!(successes, trials, "{successes}/{trials} picks");
    Ok(())
}

/// The ball's centre in the tool's frame now (m).
fn ball_in_tool(session: &Session) -> Result<glam::Vec3> {
    let sim = session.sim();
    let tool = sim
        .robot()
        .link_id("tool_link")
        .ok_or_else(|| anyhow::anyhow!("no tool_link"))?;
    Ok(sim
        .world_from_link(tool)
        .inverse()
        .transform_point(object(session, BALL).translation))
}

/// Holding: with no place the pick lifts the ball and keeps it. Then the car drives 2 m at
/// 0.5 m/s, turns 90 degrees at 1 rad/s and brakes to a stop (teleop's `,`, `j`, `k`): the
/// ball moves less than 1 cm in the tool's frame from where it sat when the car set off, held
/// by friction (the default; the pads' friction anchors keep it from creeping, without them it
/// slid 2 cm) and by the grasp assist. It backs away, as the table is in front of it.
#[test]
fn the_held_ball_stays_in_the_hand_while_the_car_drives_turns_and_brakes() -> Result<()> {
    use rover_core::KeyAction;
    let modes = [
        rover_sim::model::GraspMode::Friction,
        rover_sim::model::GraspMode::Assist,
    ];
    let only = std::env::var("PICK_GRASP").ok();
    for mode in modes
        .into_iter()
        .filter(|m| only.as_deref().is_none_or(|o| format!("{m:?}") == o))
    {
        let mut said = Said::default();
        let mut session = session_with(0, |w| {
            w.robot.place = None;
            w.robot.grasp = mode;
        })?;
        let outcome = pick(&mut session, 1.0, 30.0, &mut said)?;
        assert_eq!(outcome.state, PickState::Done, "{mode:?}: {outcome:?}");
        let start = ball_in_tool(&session)?;
        let fingers = |session: &Session| -> Vec<_> {
            ["left_finger_joint", "right_finger_joint"]
                .iter()
                .map(|n| {
                    let sim = session.sim();
                    sim.robot()
                        .joint_id(n)
                        .and_then(|j| sim.joint_state(j))
                        .map(|s| (s.position, s.effort))
                })
                .collect()
        };
        println!(
            "{mode:?}: holding, fingers (position, effort) {:.4?}",
            fingers(&session)
        );
        let heading = |s: &Session| s.sim().ground_truth().yaw_rad;
        let (x0, yaw0) = (session.sim().ground_truth().x_m, heading(&session));
        let mut worst = 0.0f32;
        let legs = [
            // Backwards: the table is in front.
            (KeyAction::Move { x: -1.0, th: 0.0 }, 4.0),
            (
                KeyAction::Move { x: 0.0, th: 1.0 },
                std::f64::consts::FRAC_PI_2,
            ),
            (KeyAction::Stop, 2.0),
        ];
        for (key, seconds) in legs {
            session.input(Action::Key(key), &mut said);
            let end = session.sim().sim_time_s() + seconds;
            let turning = matches!(key, KeyAction::Move { x, .. } if x == 0.0);
            // The turn goes on until the car has turned 90 degrees.
            while session.sim().sim_time_s() < end
                || (turning && (heading(&session) - yaw0).abs() < std::f64::consts::FRAC_PI_2)
            {
                session.step(&mut said)?;
                worst = worst.max((ball_in_tool(&session)? - start).length());
                if std::env::var_os("PICK_DEBUG_HOLD").is_some()
                    && session.sim().step_index() % 10 == 0
                {
                    println!(
                        "    {:.2} ball {:.4?} fingers {:.4?} x {:.3}",
                        session.sim().sim_time_s(),
                        ball_in_tool(&session)?,
                        fingers(&session),
                        session.sim().ground_truth().x_m
                    );
                }
            }
            println!(
                "  after {key:?}: the ball moved at most {worst:.4} m; now at {:.4?} in the tool (from {start:.4?}); fingers {:.4?}",
                ball_in_tool(&session)?,
                fingers(&session)
            );
        }
        let pose = session.sim().ground_truth();
        println!(
            "{mode:?}: drove {:.2} m, turned {:.1} deg; the ball moved at most {:.4} m in the hand ({:.4} m while lifted and carried); held by the assist: {:?}",
            x0 - pose.x_m,
            (pose.yaw_rad - yaw0).to_degrees(),
            worst,
            outcome.slip_m,
            session.sim().grasp_assist_holds()
        );
        assert!(
            worst < 0.01,
            "{mode:?}: the ball moved {worst} m in the hand"
        );
        assert!(x0 - pose.x_m > 1.8, "{mode:?}: drove {} m", x0 - pose.x_m);
    }
    Ok(())
}

/// A board on the table between the ball and the bin, 20 cm high: the joints' straight way
/// from the lift to the bin goes through it, so the carry is planned round it. Over the whole
/// run no link of the robot touches the board, the table or the bin (contacts read from
/// rapier every step), and the ball still ends in the bin.
#[test]
fn the_arm_carries_the_ball_round_a_board_touching_nothing() -> Result<()> {
    let mut said = Said::default();
    let mut session = session_with(0, |w| {
        w.objects.push(rover_sim::model::Object {
            name: "board".into(),
            shape: rover_sim::geometry::Shape::Box {
                size_m: glam::Vec3::new(0.2, 0.01, 0.2),
            },
            position_m: [0.30, -0.055, 0.2],
            yaw_rad: 0.0,
            color: rover_sim::geometry::Rgba([0.9, 0.9, 0.9, 1.0]),
            mass_kg: None,
            friction: 1.0,
            class: None,
        });
    })?;
    let names: Vec<String> = session
        .sim()
        .world()
        .objects
        .iter()
        .map(|o| o.name.clone())
        .collect();
    let watched: Vec<usize> = (0..names.len()).filter(|&i| i != BALL).collect();
    // Where YOLO, with the board in view, still calls the ball a sports ball (0.70).
    session.place_object(BALL, [0.23, 0.10, 0.1335], 0.0)?;
    // The pick, stepped here so every step's contacts are read.
    let end = session.sim().sim_time_s() + 1.0;
    while session.sim().sim_time_s() < end {
        session.step(&mut said)?;
    }
    session.input(Action::TogglePick, &mut said);
    let start = session.sim().sim_time_s();
    let mut hits: Vec<(String, String)> = Vec::new();
    let mut done_at = None;
    while session.sim().sim_time_s() - start < 35.0
        && done_at.is_none_or(|t| session.sim().sim_time_s() < t + 1.0)
    {
        session.step(&mut said)?;
        for &i in &watched {
            for link in session.sim().object_contacts(i) {
                let pair = (names[i].clone(), link);
                if session.sim().robot().link_id(&pair.1).is_some() && !hits.contains(&pair) {
                    hits.push(pair);
                }
            }
        }
        if done_at.is_none()
            && matches!(
                session.stats().arm.pick,
                PickState::Done | PickState::Failed
            )
        {
            done_at = Some(session.sim().sim_time_s());
        }
    }
    let ball = object(&session, BALL).translation;
    println!(
        "board: {:?} after {:.1} s; the ball at {ball:.3?}; robot links touching the table, bin or board: {hits:?}",
        session.stats().arm.pick,
        done_at.unwrap_or(f64::NAN) - start
    );
    let points = session.pick().and_then(|p| p.path_points());
    println!("waypoints of the paths to the pre-grasp, the carry and home: {points:?}");
    assert_eq!(
        session.stats().arm.pick,
        PickState::Done,
        "{:?}",
        said.0.last()
    );
    assert!(hits.is_empty(), "{hits:?}");
    // The carry could not go straight in joint space: the board was in the way.
    assert!(points.is_some_and(|p| p[1] > 2), "{points:?}");
    let outcome = Outcome {
        state: PickState::Done,
        took_s: 0.0,
        ball_m: [f64::from(ball.x), f64::from(ball.y), f64::from(ball.z)],
        planning_s: None,
        slip_m: 0.0,
        touched: Vec::new(),
    };
    assert!(outcome.in_bin(), "{outcome:?}");
    Ok(())
}

/// Warnings a session says.
#[derive(Default)]
struct Warnings(Vec<String>);

impl rover_core::Observer for Warnings {
    fn event(&mut self, _t: f64, level: EventLevel, text: &str) {
        if level == EventLevel::Warn {
            self.0.push(text.to_owned());
        }
    }
}

/// A tool point inside the table (scripts' `tool = [...]`, the station's jog keys) is refused
/// with the reason, naming what the arm would hit; a point above it is taken.
#[test]
fn a_tool_point_inside_the_table_is_refused_naming_the_table() -> Result<()> {
    let mut session = session(0)?;
    let mut warnings = Warnings::default();
    for _ in 0..100 {
        session.step(&mut warnings)?;
    }
    let tool = |position_m| {
        Action::Joint(rover_core::JointAction::Tool {
            position_m,
            relative: false,
        })
    };
    // base_link is 8 cm above the ground; the table's top is at 10 cm.
    session.input(tool([0.30, -0.05, -0.02]), &mut warnings);
    println!("{:?}", warnings.0);
    assert!(
        warnings.0.len() == 1
            && warnings.0[0].contains("refused")
            && warnings.0[0].contains("table"),
        "{:?}",
        warnings.0
    );
    session.input(tool([0.28, 0.05, 0.15]), &mut warnings);
    assert_eq!(warnings.0.len(), 1, "{:?}", warnings.0);
    Ok(())
}

/// Franka's panda (PyPI example-robot-data, bolted to a table: worlds/panda_pick.toml) takes
/// the 4 cm cube by its known pose (no camera), from above with the fingers across two of its
/// faces, and sets it down at the world's place point, 20 cm to the left: the cube ends within
/// 2 cm of it, resting on the table, the pick done in under 30 s of sim time.
#[test]
fn the_panda_picks_a_cube_and_sets_it_down_20_cm_away() -> Result<()> {
    /// The cube's index among the world's objects (the table is first), where it starts and
    /// where it is to be set down (its centre, world frame, m).
    const CUBE: usize = 1;
    const FROM: [f64; 3] = [0.5, 0.0, 0.42];
    const TO: [f64; 3] = [0.5, 0.2, 0.42];
    let Some(robot_options) = rover_tests::example_robot_data_options() else {
        return Ok(());
    };
    let config = rover_core::RunConfig {
        world: Some(rover_tests::repo("worlds/panda_pick.toml")),
        robot_options,
        ..rover_core::RunConfig::default()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let options = rover_core::SessionOptions {
        camera: false,
        ..rover_tests::lockstep_options(0)
    };
    let mut said = Said::default();
    let mut session = Session::new(world, robot, &options, &mut said)?;
    // Franka's ready pose (the controllers file's `home`), then pick.
    session.input(
        Action::Joint(rover_core::JointAction::Pose("home".into())),
        &mut said,
    );
    let end = session.sim().sim_time_s() + 3.0;
    while session.sim().sim_time_s() < end {
        session.step(&mut said)?;
    }
    session.input(Action::TogglePick, &mut said);
    let start = session.sim().sim_time_s();
    let mut finished: Option<f64> = None;
    loop {
        session.step(&mut said)?;
        let now = session.sim().sim_time_s();
        let state = session.stats().arm.pick;
        if finished.is_none() && matches!(state, PickState::Done | PickState::Failed) {
            finished = Some(now);
        }
        if finished.is_some_and(|f| now > f + 1.0) || now - start > 40.0 {
            break;
        }
    }
    let t = object(&session, CUBE).translation;
    let at = [f64::from(t.x), f64::from(t.y), f64::from(t.z)];
    let off = |p: [f64; 3]| ((at[0] - p[0]).powi(2) + (at[1] - p[1]).powi(2)).sqrt();
    let took_s = finished.unwrap_or(session.sim().sim_time_s()) - start;
    println!(
        "panda: {:?} in {took_s:.1} s; the cube at {at:.4?}: {:.4} m from the place, moved {:.4} m; planned in {:?} s",
        session.stats().arm.pick,
        off(TO),
        off(FROM),
        session.pick().and_then(|p| p.planning_s()),
    );
    assert_eq!(
        session.stats().arm.pick,
        PickState::Done,
        "{:?}",
        said.0.last()
    );
    assert!(took_s < 30.0, "took {took_s} s");
    assert!(off(TO) < 0.02, "the cube is {} m from the place", off(TO));
    assert!(
        (at[2] - TO[2]).abs() < 0.005,
        "the cube's centre is at z {} m, not resting on the table",
        at[2]
    );
    Ok(())
}

/// The planner checks the arm against itself, as MoveIt does. Straight up the arm car's arm is
/// clear; folded (elbow 2.4 rad, wrist pitch 1.8 rad) its fingers come back down through its
/// shoulder and the planning scene names the pair. An SRDF (`[robot] srdf`) whose
/// `<disable_collisions>` lists the shoulder's and upper arm's pairs with the links beyond the
/// elbow takes them out of the checks; a `<disable_collisions>` without `link2` is refused naming the file
/// and line; pairs naming links the robot does not have are left out.
#[test]
fn the_planning_scene_checks_the_arm_against_itself_and_reads_the_srdfs_pairs() -> Result<()> {
    let config = rover_core::RunConfig {
        world: Some(rover_tests::repo("worlds/arm_car_pick.toml")),
        ..rover_core::RunConfig::default()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let chain = rover_sim::model::KinematicChain::new(&robot, "base_link", "tool_link")?;
    let folded = [0.0, 0.0, 2.4, 1.8, 0.0];
    let hit =
        |world: rover_sim::model::World| -> Result<[Option<rover_sim::planning::SceneContact>; 2]> {
            let sim = rover_sim::physics::Simulation::new(
                world,
                robot.clone(),
                &rover_sim::physics::SimOptions::default(),
            )?;
            let mut scene = sim.planning_scene(&chain, 0.01)?;
            Ok([scene.collision(&[0.0; 5]), scene.collision(&folded)])
        };
    let [straight, bent] = hit(world.clone())?;
    println!("straight up: {straight:?}; folded: {bent:?}");
    assert_eq!(straight, None);
    let bent = bent.ok_or_else(|| anyhow::anyhow!("the folded arm hits nothing"))?;
    let (near, far) = (
        ["shoulder_link", "upper_arm_link"],
        [
            "forearm_link",
            "wrist_link",
            "hand_link",
            "left_finger_link",
            "right_finger_link",
        ],
    );
    let robots = |l: &str| format!("{l} (the robot's)");
    let disabled = |c: &rover_sim::planning::SceneContact| {
        near.iter().any(|n| {
            far.iter().any(|f| {
                (c.link == *n && c.obstacle == robots(f))
                    || (c.link == *f && c.obstacle == robots(n))
            })
        })
    };
    assert!(disabled(&bent), "{bent}");
    let dir = tempfile::tempdir()?;
    let pairs: String = near
        .iter()
        .flat_map(|n| far.iter().map(move |f| (n, f)))
        .map(|(n, f)| {
            format!("  <disable_collisions link1=\"{n}\" link2=\"{f}\" reason=\"Never\"/>\n")
        })
        .collect();
    let srdf = dir.path().join("arm_car.srdf");
    std::fs::write(
        &srdf,
        format!(
            "<robot name=\"my_robot\">\n{pairs}  <disable_collisions link1=\"gripper_palm\" link2=\"upper_arm_link\" reason=\"Never\"/>\n</robot>\n"
        ),
    )?;
    let mut with_srdf = world.clone();
    with_srdf.robot.srdf = Some(srdf.clone());
    let [_, bent] = hit(with_srdf)?;
    println!("folded, with the SRDF's pairs: {bent:?}");
    assert!(bent.as_ref().is_none_or(|c| !disabled(c)), "{bent:?}");
    std::fs::write(
        &srdf,
        "<robot name=\"my_robot\">\n  <disable_collisions link1=\"hand_link\" reason=\"Never\"/>\n</robot>\n",
    )?;
    let mut bad = world;
    bad.robot.srdf = Some(srdf);
    let err = rover_sim::physics::Simulation::new(
        bad,
        robot.clone(),
        &rover_sim::physics::SimOptions::default(),
    )
    .err()
    .ok_or_else(|| anyhow::anyhow!("a <disable_collisions> without link2 was taken"))?
    .to_string();
    println!("{err}");
    assert!(
        err.contains("arm_car.srdf:2") && err.contains("link2"),
        "{err}"
    );
    Ok(())
}

/// Where trial `seed` of worlds/arm_car_stance.toml puts the ball (on its table, 0.68-0.72 m
/// ahead) and the bin's middle (on the floor to the right: x 0.56-0.64 m, y -0.34 to -0.44
/// m), world frame.
fn stance_layout(seed: u64) -> ([f64; 3], [f64; 2]) {
    let mut rng = rover_sim::SplitMix64(0x57a2_0000 + seed);
    let ball = [0.68 + 0.04 * rng.unit(), -0.04 + 0.08 * rng.unit(), 0.1335];
    let bin = [0.56 + 0.08 * rng.unit(), -0.34 - 0.10 * rng.unit()];
    (ball, bin)
}

/// Out of reach, the base moves (worlds/arm_car_stance.toml: the ball on a table 0.7 m ahead
/// of the arm car, a bin on the floor beside the table, no `fetch` point anywhere): in 10
/// seeded layouts the pick chooses a stance from the arm's reachability, drives there, picks
/// the ball, chooses the bin's stance, drives there and drops it in; at least 9 of 10 end with
/// the ball in the bin within 60 s of sim time. Prints each trial and the planning times.
#[test]
fn out_of_reach_the_base_moves_and_9_of_10_layouts_end_in_the_bin() -> Result<()> {
    const BIN_PARTS: std::ops::RangeInclusive<usize> = 1..=5;
    let only: Option<u64> = std::env::var("PICK_TRIAL")
        .ok()
        .and_then(|t| t.parse().ok());
    let mut results = Vec::new();
    for seed in (0..10).filter(|s| only.is_none_or(|o| o == *s)) {
        let mut said = Said::default();
        let mut session = session_in("worlds/arm_car_stance.toml", seed, |_| {})?;
        let (ball, [bx, by]) = stance_layout(seed);
        session.place_object(BALL, ball, 0.0)?;
        // The bin's floor and walls keep their places relative to its middle (0.60, -0.40).
        for part in BIN_PARTS {
            let at = object(&session, part).translation;
            let moved = [
                f64::from(at.x) + bx - 0.60,
                f64::from(at.y) + by + 0.40,
                f64::from(at.z),
            ];
            session.place_object(part, moved, 0.0)?;
        }
        let outcome = pick(&mut session, 1.0, 60.0, &mut said)?;
        let [x, y, z] = outcome.ball_m;
        let in_bin = (x - bx).abs() < 0.055 && (y - by).abs() < 0.055 && z > 0.004 && z < 0.054;
        let ok = outcome.state == PickState::Done && outcome.took_s <= 60.0 && in_bin;
        println!("trial {seed}: ball at {ball:.3?}, bin at ({bx:.3}, {by:.3}): {ok} {outcome:?}");
        for (t, _, text) in said.0.iter().filter(|(_, _, t)| {
            t.contains("stance") || t.contains("stands") || t.contains("not detected")
        }) {
            println!("    {t:.2} {text}");
        }
        results.push((ok, outcome));
    }
    let successes = results.iter().filter(|(ok, _)| *ok).count();
    let (median, slowest) =
        rover_tests::median_and_slowest(results.iter().filter_map(|(_, o)| o.planning_s));
    println!(
        "{successes}/{} in the bin; planning median {median:.4} s, slowest {slowest:.4} s",
        results.len()
    );
    if only.is_none() {
        assert!(successes >= 9, "{successes}/10 in the bin");
    }
    Ok(())
}

/// The arm car's arm and finger joints' positions now.
fn joint_positions(session: &Session) -> Vec<f64> {
    let sim = session.sim();
    [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_pitch_joint",
        "wrist_roll_joint",
        "left_finger_joint",
        "right_finger_joint",
    ]
    .iter()
    .map(|name| {
        (sim.robot().joint_id(name))
            .and_then(|id| sim.joint_state(id))
            .map_or(f64::NAN, |s| s.position)
    })
    .collect()
}

/// A bad-input case: the world, what is wrong, how the options are changed, the warning.
type BadCase = (
    &'static str,
    &'static str,
    Box<dyn Fn(&mut rover_core::SessionOptions)>,
    &'static str,
);

/// Bad input for a pick, each one clear warning and an arm that holds (no joint moves more
/// than 5 mrad over 3 s): a class the detector does not know (the nearest named), a place the
/// world does not have (its objects listed), and a ball wider than the open gripper.
#[test]
fn bad_pick_input_says_one_thing_and_the_arm_holds() -> Result<()> {
    let cases: [BadCase; 3] = [
        (
            "worlds/arm_car_pick.toml",
            "an unknown class",
            Box::new(|o| o.arm = rover_core::ArmConfig::default().with_class("tennis ball")),
            "arm: pick stays off: \"tennis ball\" is not a class the detector knows (80 classes); the nearest: \"tennis racket\", \"sports ball\"",
        ),
        (
            "worlds/arm_car_pick.toml",
            "a missing place",
            Box::new(|o| {
                o.arm.pick.place = Some(rover_sim::model::Place::Object("shelf".into()));
            }),
            "no pick: no world object \"shelf\" to place on; the world's objects: table, bin, bin_wall_front, bin_wall_back, bin_wall_left, bin_wall_right, ball",
        ),
        (
            "worlds/arm_car_reach.toml",
            "a ball too wide",
            Box::new(|_| {}),
            "wider than the open gripper (0.090 m)",
        ),
    ];
    for (world, what, change, expected) in cases {
        let config = rover_core::RunConfig {
            world: Some(rover_tests::repo(world)),
            ..rover_core::RunConfig::default()
        };
        let (world, robot) = config.load_world_and_robot()?;
        let mut options = rover_tests::lockstep_options(0);
        change(&mut options);
        let mut said = Said::default();
        let mut session = Session::new(world, robot, &options, &mut said)?;
        let end = session.sim().sim_time_s() + 1.0;
        while session.sim().sim_time_s() < end {
            session.step(&mut said)?;
        }
        let before = joint_positions(&session);
        session.input(Action::TogglePick, &mut said);
        let end = session.sim().sim_time_s() + 3.0;
        while session.sim().sim_time_s() < end {
            session.step(&mut said)?;
        }
        let moved = (joint_positions(&session).iter())
            .zip(&before)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let warnings: Vec<&str> = (said.0.iter())
            .filter(|(_, level, _)| *level == EventLevel::Warn)
            .map(|(_, _, text)| text.as_str())
            .collect();
        println!("{what}: {warnings:?}; joints moved at most {moved:.5} rad");
        assert_eq!(warnings.len(), 1, "{what}: {warnings:?}");
        assert!(warnings[0].contains(expected), "{what}: {}", warnings[0]);
        assert!(moved < 0.005, "{what}: a joint moved {moved} rad");
    }
    Ok(())
}

/// The stance world with the car 1.5 m back from the table and a low brick (8 cm high, 40 cm
/// wide) across the straight way: the pick routes the base round the brick (the planning
/// scene's objects), picks the ball and puts it in the bin, and no part of the car touches the
/// brick.
#[test]
fn the_base_drives_round_a_brick_in_the_way_to_its_stance() -> Result<()> {
    let text = std::fs::read_to_string(rover_tests::repo("worlds/arm_car_stance.toml"))?;
    let assets = rover_tests::repo("assets");
    let text = text
        .replace("\"../assets", &format!("\"{}", assets.display()))
        .replace(
            "position_m = [0.0, 0.0]\nyaw_deg = 0.0",
            "position_m = [-0.8, 0.0]\nyaw_deg = 0.0",
        )
        + "\n[[box]]\nname = \"brick\"\nsize_m = [0.10, 0.40, 0.08]\nposition_m = [-0.2, 0.0, 0.04]\ncolor = \"#a04030\"\n";
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("stance_brick.toml");
    std::fs::write(&path, text)?;
    let config = rover_core::RunConfig {
        world: Some(path),
        ..rover_core::RunConfig::default()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let index = |name: &str| {
        (world.objects.iter())
            .position(|o| o.name == name)
            .ok_or_else(|| anyhow::anyhow!("no {name}"))
    };
    let (brick, ball, bin) = (index("brick")?, index("ball")?, index("bin")?);
    let mut said = Said::default();
    let mut session = Session::new(world, robot, &rover_tests::lockstep_options(0), &mut said)?;
    let mut touched: Vec<String> = Vec::new();
    session.input(Action::TogglePick, &mut said);
    let start = session.sim().sim_time_s();
    while session.sim().sim_time_s() < start + 70.0 {
        session.step(&mut said)?;
        for link in session.sim().object_contacts(brick) {
            if !touched.contains(&link) {
                touched.push(link);
            }
        }
        if matches!(
            session.stats().arm.pick,
            PickState::Done | PickState::Failed
        ) {
            break;
        }
    }
    let end = session.sim().sim_time_s() + 1.0;
    while session.sim().sim_time_s() < end {
        session.step(&mut said)?;
    }
    let ball = object(&session, ball).translation;
    let bin = object(&session, bin).translation;
    println!("ball {ball:?}, bin {bin:?}, brick touched by {touched:?}");
    assert_eq!(
        session.stats().arm.pick,
        PickState::Done,
        "{:?}",
        said.0.last()
    );
    assert!(
        said.0
            .iter()
            .any(|(_, _, t)| t.starts_with("pick: fetch: round what stands between")),
        "the base was not routed round the brick"
    );
    assert!(
        (ball.x - bin.x).abs() < 0.055 && (ball.y - bin.y).abs() < 0.055,
        "the ball is not in the bin"
    );
    assert!(
        touched
            .iter()
            .all(|link| link == "ground" || link.is_empty()),
        "the brick was touched by {touched:?}"
    );
    Ok(())
}
