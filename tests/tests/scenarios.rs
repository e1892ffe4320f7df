//! Every follower scenario on both of the tutorial's cars, each robot x scenario its own test,
//! in-process: real physics, real renderer, real default detector (pipelined on its own
//! thread, deterministic on sim time, one thread as `rover eval` runs it), the follower. The
//! laser car (`my_robot_laser.urdf.xacro`: the camera and a 360-ray laser) runs all of them;
//! the camera-only car (`my_robot.urdf`, the tutorial's own) runs every scenario it can sense,
//! the others needing a laser it has not got. A scenario file added to scenarios/ without a
//! test here fails `every_scenario_runs_on_both_cars_here`. The same suite runs with
//! `rover eval scenarios/ --robot ...` (docs/FOLLOWER.md).

use anyhow::Result;
use rover_core::{FollowState, LoopStats, NoObserver, Observer, parse_trace, range_bearing_from};
use rover_core::{Scenario, ScenarioOptions, collect_scenario_files, run_scenario};
use rover_perception::{BoundingBoxes, DetectorConfig};
use rover_sim::physics::{ControlSample, Simulation};
use rover_tests::repo;

/// The tutorial's car with the laser the obstacle scenarios need.
const LASER_CAR: &str = "assets/robots/my_robot_laser.urdf.xacro";
/// The tutorial's own car: a camera 18 cm up, nothing else.
const CAMERA_CAR: &str = "assets/robots/my_robot.urdf";

/// Runs scenario `name` (scenarios/NAME.toml) with `robot` and asserts it passes: every
/// criterion printed with its value, and the trace says what the follower was doing.
fn run_on(robot: &str, name: &str) -> Result<()> {
    let scenario =
        Scenario::load_with_robot(&repo(&format!("scenarios/{name}.toml")), Some(&repo(robot)))?;
    if let Some(why) = scenario.unmet_needs() {
        anyhow::bail!("{name} cannot run on {robot}: {why}");
    }
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let result = run_scenario(
        &scenario,
        &ScenarioOptions {
            // As `rover eval` runs it (its workers fill the cores).
            detector: DetectorConfig {
                threads: 1,
                ..DetectorConfig::default()
            },
            trace: Some(trace.clone()),
            ..ScenarioOptions::default()
        },
        &mut NoObserver,
    )?;
    let robot_name = &scenario.robot_name;
    for c in &result.checks {
        println!(
            "{name} @ {robot_name}: {} {} (want {}) {}",
            c.name,
            c.value,
            c.limit,
            if c.passed { "ok" } else { "FAILED" }
        );
    }
    assert!(
        result.passed,
        "{name} @ {robot_name} failed: {:#?}",
        result.checks
    );
    // The trace says what the follower was doing on every row.
    let rows = parse_trace(&std::fs::read_to_string(trace)?)?;
    assert!(rows.iter().any(|r| r.follow_state != "waiting"));
    Ok(())
}

/// One test per scenario and car: `both` on both cars, `laser_only` on the laser car.
macro_rules! scenario_matrix {
    (both: [$($both:ident),* $(,)?], laser_only: [$($laser:ident),* $(,)?] $(,)?) => {
        /// The scenarios both cars run.
        const BOTH: &[&str] = &[$(stringify!($both)),*];
        /// The scenarios only the laser car can run.
        const LASER_ONLY: &[&str] = &[$(stringify!($laser)),*];

        mod laser_car {
            $(#[test]
            fn $both() -> anyhow::Result<()> {
                super::run_on(super::LASER_CAR, stringify!($both))
            })*
            $(#[test]
            fn $laser() -> anyhow::Result<()> {
                super::run_on(super::LASER_CAR, stringify!($laser))
            })*
        }

        mod camera_car {
            $(#[test]
            fn $both() -> anyhow::Result<()> {
                super::run_on(super::CAMERA_CAR, stringify!($both))
            })*
        }
    };
}

scenario_matrix! {
    both: [
        child,
        circling,
        crossing,
        default_world,
        nobody,
        static_ahead_4m,
        static_behind,
        static_far_8m,
        static_left_30deg,
        static_right_90deg,
        two_people,
        walk_away,
        walk_toward,
        walking_square,
    ],
    laser_only: [corridor, crate_between, partial_occlusion, wall_between],
}

/// The matrix above is the whole suite: every file in scenarios/ is listed once, and a
/// scenario is laser-only exactly when the camera-only car lacks a sensor it needs.
#[test]
fn every_scenario_runs_on_both_cars_here() -> Result<()> {
    let files = collect_scenario_files(&[repo("scenarios")])?;
    let mut listed: Vec<&str> = BOTH.iter().chain(LASER_ONLY).copied().collect();
    listed.sort_unstable();
    let mut stems: Vec<String> = files
        .iter()
        .filter_map(|f| f.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    stems.sort();
    assert_eq!(listed, stems, "scenarios/ and the test matrix differ");
    for f in &files {
        let on_camera_car = Scenario::load_with_robot(f, Some(&repo(CAMERA_CAR)))?;
        let laser_only = LASER_ONLY.contains(&on_camera_car.name.as_str());
        assert_eq!(
            on_camera_car.unmet_needs().is_some(),
            laser_only,
            "{}: {:?}",
            on_camera_car.name,
            on_camera_car.unmet_needs()
        );
        let on_laser_car = Scenario::load_with_robot(f, Some(&repo(LASER_CAR)))?;
        assert_eq!(on_laser_car.unmet_needs(), None, "{}", on_laser_car.name);
    }
    Ok(())
}

/// Scenarios tagged "fast" (`rover eval --tag fast`): a quick subset for a local check.
#[test]
fn the_suite_has_a_fast_subset() -> Result<()> {
    let files = collect_scenario_files(&[repo("scenarios")])?;
    let mut fast = 0;
    for f in files {
        fast += usize::from(Scenario::load(&f)?.tags.iter().any(|t| t == "fast"));
    }
    assert!(fast >= 3, "{fast} fast scenarios");
    Ok(())
}

/// Watches a run: the true range to the target at the last camera detection of a person, and
/// how the follower ended.
#[derive(Default)]
struct CameraReach {
    target: usize,
    true_range_m: f64,
    last_person_range_m: Option<f64>,
    final_state: Option<FollowState>,
}

impl Observer for CameraReach {
    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        let (px, py, _) = sim.world().people[self.target].pose_at(sample.sim_time_s);
        self.true_range_m = range_bearing_from(sample.ground_truth, [px, py]).0;
        self.final_state = Some(stats.follow_state);
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        if boxes.bounding_boxes.iter().any(|b| b.class == "person") {
            self.last_person_range_m = Some(self.true_range_m);
        }
    }
}

/// The follower on a robot rover did not design: ROBOTIS' turtlebot3_burger_for_autorace (its
/// 320x240 lane camera looks 10 degrees down from 15 cm; its LDS reaches 3.5 m). A person 8 m
/// ahead is seen whole only from ~6 m; the follower pursues where they were, the LDS picks them
/// up, and the car stops at the standoff. Real xacro, real renderer, real detector, real
/// physics; skipped without ../shared.
#[test]
fn turtlebot3_autorace_reaches_a_person_8m_ahead_its_lds_taking_over() -> Result<()> {
    let Some(dir) = rover_tests::shared("corpus/turtlebot3_description") else {
        return Ok(());
    };
    let robot = dir.join("urdf/turtlebot3_burger_for_autorace.urdf.xacro");
    let mut scenario =
        Scenario::load_with_robot(&repo("scenarios/static_far_8m.toml"), Some(&robot))?;
    assert_eq!(scenario.robot_name, "turtlebot3_burger_for_autorace");
    // The scenario's detector criterion is not this robot's to meet: its lane camera cannot
    // see a person nearer than ~6 m (recall 0.14 here). What is checked is the pursuit.
    scenario.criteria.min_recall = None;
    // The hand-over is what this shows, so the person is rover's figure, which this camera
    // loses from ~6 m on: MakeHuman's body it still sees as a person at 1.6 m (measured), and
    // the LDS never has to take over.
    for person in &mut scenario.world.people {
        person.shape = None;
    }
    let mut reach = CameraReach {
        target: scenario.target.unwrap_or(0),
        ..CameraReach::default()
    };
    let result = run_scenario(&scenario, &ScenarioOptions::default(), &mut reach)?;
    let final_range = result.metrics.final_range_m.unwrap_or(f64::NAN);
    println!(
        "final range {final_range:.2} m; the camera last saw a person {:?} m away; {:?}",
        reach.last_person_range_m, reach.final_state
    );
    assert!(
        (final_range - 1.5).abs() <= 0.3,
        "stopped {final_range} m from the person: {:#?}",
        result.checks
    );
    let last_seen = reach.last_person_range_m.unwrap_or(0.0);
    assert!(
        last_seen > 3.5,
        "the camera saw the person until {last_seen} m: within the LDS's reach, so the laser's \
         hand-over is not what this shows"
    );
    assert_eq!(
        reach.final_state,
        Some(FollowState::Tracking),
        "the LDS keeps them"
    );
    assert!(result.passed, "{:#?}", result.checks);
    Ok(())
}

/// `rover eval` judges the detector too: every result against the renderer's ground truth of
/// its image, with COCO's rules (real renderer, real default detector). With the person behind
/// the car it turns, finds them and drives up: the person is seen whole and recall and
/// precision are high; `min_recall` / `min_precision` criteria pass or fail on them.
#[test]
fn eval_judges_the_detector_against_ground_truth() -> Result<()> {
    let mut scenario = Scenario::load(&repo("scenarios/static_behind.toml"))?;
    scenario.criteria.min_recall = Some(0.9);
    scenario.criteria.min_precision = Some(0.9);
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let options = ScenarioOptions {
        trace: Some(trace.clone()),
        ..ScenarioOptions::default()
    };
    let result = run_scenario(&scenario, &options, &mut NoObserver)?;
    let detector = result
        .metrics
        .detector
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("no detector metrics"))?;
    let person = detector
        .class("person")
        .ok_or_else(|| anyhow::anyhow!("no person class: {detector:?}"))?;
    println!("person: {person:?}");
    for c in &result.checks {
        println!("{}: {} (want {}) {}", c.name, c.value, c.limit, c.passed);
    }
    // The detector takes an image every 0.2 s of the 30 s run; ground truth lists the person
    // in each image where any of them is in view.
    assert!(person.ground_truth > 50, "{person:?}");
    assert!(person.recall.is_some_and(|r| r >= 0.9), "{person:?}");
    assert!(person.mean_iou.is_some_and(|iou| iou > 0.9), "{person:?}");
    assert!(person.ap50.is_some_and(|ap| ap > 0.85), "{person:?}");
    // The trace's ground-truth columns hold each result's match, row by row, and add up to
    // the metrics: every judged image appears, in order.
    let text = std::fs::read_to_string(&trace)?;
    assert!(
        text.starts_with(&format!(
            "{},{}",
            rover_core::TRACE_HEADER,
            rover_core::TRACE_TRUTH_COLUMNS
        )),
        "{}",
        text.lines().next().unwrap_or("")
    );
    let rows = parse_trace(&text)?;
    let mut judged: Vec<rover_core::TruthColumns> = Vec::new();
    for t in rows.iter().filter_map(|r| r.truth) {
        if judged.last().is_none_or(|last| last.image != t.image) {
            assert!(judged.last().is_none_or(|last| last.image < t.image));
            judged.push(t);
        }
    }
    let sum = |f: fn(&rover_core::TruthColumns) -> u32| judged.iter().map(f).sum::<u32>();
    println!(
        "trace: {} results judged, {} things, {} found, {} missed, {} false",
        judged.len(),
        sum(|t| t.things),
        sum(|t| t.found),
        sum(|t| t.missed),
        sum(|t| t.false_positives)
    );
    assert!(judged.len() > 50, "{} results in the trace", judged.len());
    assert!(judged.iter().all(|t| t.found + t.missed == t.things));
    assert!(judged.iter().all(|t| t.mean_iou.is_some() == (t.found > 0)
        && t.mean_iou.is_none_or(|iou| (0.5..=1.0).contains(&iou))));
    let found = f64::from(sum(|t| t.found));
    let recall = found / f64::from(sum(|t| t.things));
    assert!(
        person.recall.is_some_and(|r| (r - recall).abs() < 0.05),
        "trace recall {recall} vs {person:?}"
    );
    let check = |name: &str| {
        result
            .checks
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.passed)
    };
    assert_eq!(
        (check("min_recall"), check("min_precision")),
        (Some(true), Some(true))
    );
    // A bound the detector does not reach fails, naming the class: the same metrics had it
    // missed a tenth of the person's images (it finds all of them here).
    let mut missed = detector.clone();
    for c in missed.classes.iter_mut().filter(|c| c.class == "person") {
        c.recall = c.recall.map(|r| r * 0.9);
    }
    scenario.criteria.min_recall = Some(0.95);
    let strict = rover_core::ScenarioMetrics {
        detector: Some(missed),
        ..result.metrics.clone()
    };
    let checks = rover_core::judge_scenario(&scenario, &strict);
    let failed = checks
        .iter()
        .find(|c| c.name == "min_recall")
        .ok_or_else(|| anyhow::anyhow!("no min_recall check"))?;
    assert!(
        !failed.passed && failed.value.contains("person"),
        "{failed:?}"
    );
    Ok(())
}
