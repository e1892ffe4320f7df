//! The scenario suite's fast subset (scenarios tagged "fast"), in-process: real physics, real
//! renderer, real default detector in lockstep, the follower with its laser. The whole suite
//! runs with `rover eval scenarios/` (see docs/FOLLOWER.md).

use anyhow::Result;
use rover_core::{FollowState, LoopStats, NoObserver, Observer, parse_trace, range_bearing_from};
use rover_core::{Scenario, ScenarioOptions, collect_scenario_files, run_scenario};
use rover_perception::BoundingBoxes;
use rover_sim::{ControlSample, Simulation};
use rover_tests::repo;

fn fast_scenarios() -> Result<Vec<Scenario>> {
    let files = collect_scenario_files(&[repo("scenarios")])?;
    let mut all = Vec::new();
    for f in files {
        all.push(Scenario::load(&f)?);
    }
    assert!(all.len() >= 15, "the suite has {} scenarios", all.len());
    Ok(all
        .into_iter()
        .filter(|s| s.tags.iter().any(|t| t == "fast"))
        .collect())
}

fn run_named(name: &str) -> Result<()> {
    let scenarios = fast_scenarios()?;
    let s = scenarios
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| anyhow::anyhow!("no fast scenario {name}"))?;
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let result = run_scenario(
        s,
        &ScenarioOptions {
            trace: Some(trace.clone()),
            ..ScenarioOptions::default()
        },
        &mut NoObserver,
    )?;
    for c in &result.checks {
        println!(
            "{name}: {} {} (want {}) {}",
            c.name,
            c.value,
            c.limit,
            if c.passed { "ok" } else { "FAILED" }
        );
    }
    assert!(result.passed, "{name} failed: {:#?}", result.checks);
    // The trace says what the follower was doing on every row.
    let rows = parse_trace(&std::fs::read_to_string(trace)?)?;
    assert!(rows.iter().any(|r| r.follow_state != "waiting"));
    Ok(())
}

#[test]
fn the_suite_has_a_fast_subset() -> Result<()> {
    let fast = fast_scenarios()?;
    assert!(fast.len() >= 3, "{} fast scenarios", fast.len());
    Ok(())
}

#[test]
fn fast_static_ahead_4m() -> Result<()> {
    run_named("static_ahead_4m")
}

#[test]
fn fast_crossing() -> Result<()> {
    run_named("crossing")
}

#[test]
fn fast_crate_between() -> Result<()> {
    run_named("crate_between")
}

/// The must-show of the follower issue: in the default world, once at the standoff the car stays
/// there, |angular cmd| < 0.05 rad/s and no SEARCHING for the last 10 s (the scenario's
/// `calm_last_s`), read back here from the trace's `follow_state` column too.
#[test]
fn fast_default_world() -> Result<()> {
    run_named("default_world")
}

#[test]
fn fast_nobody() -> Result<()> {
    run_named("nobody")
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

/// The tutorial's own car (a camera 18 cm up, no laser): a person who walks away 6.5 m and
/// stops is kept where the camera sees them whole while walking (the car does not fall more
/// than 3 m behind), and once they stop in the camera's blind zone the track halts there and
/// the car closes in to the standoff (it stopped 1.98 m short, pursuing a prediction past them,
/// before). With two people it approaches the nearer and finishes at the standoff on the
/// track. Real physics, renderer and default detector.
#[test]
fn the_tutorials_camera_only_car_follows_a_walker_who_stops_and_keeps_its_person() -> Result<()> {
    let robot = repo("assets/robots/my_robot.urdf");
    for name in ["walk_away", "two_people"] {
        let scenario =
            Scenario::load_with_robot(&repo(&format!("scenarios/{name}.toml")), Some(&robot))?;
        assert_eq!(scenario.robot_name, "my_robot");
        assert!(scenario.unmet_needs().is_none(), "{name} needs no laser");
        let result = run_scenario(&scenario, &ScenarioOptions::default(), &mut NoObserver)?;
        for c in &result.checks {
            println!(
                "{name} @ my_robot: {} {} (want {}) {}",
                c.name, c.value, c.limit, c.passed
            );
        }
        assert!(result.passed, "{name} failed: {:#?}", result.checks);
    }
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
