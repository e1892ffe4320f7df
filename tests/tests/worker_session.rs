//! The window's path through the loop, without a window: a session with the detector on its
//! worker thread (always the newest frame), stepped until real detections of the real person
//! arrive. No wall-clock assertions: the loop just runs until the worker has answered.

use std::time::{Duration, Instant};

use anyhow::Result;
use rover_core::{DetectorMode, EventLevel, FollowState, Mode, Observer, Session, SessionOptions};
use rover_perception::{BoundingBoxes, DetectorConfig};
use rover_sim::model::{RobotModel, World};
use rover_tests::repo;

#[derive(Default)]
struct Events {
    warnings: Vec<String>,
    detections: u64,
}

impl Observer for Events {
    fn detections(&mut self, _boxes: &BoundingBoxes, _labels: &[String]) {
        self.detections += 1;
    }
    fn event(&mut self, _t: f64, level: EventLevel, text: &str) {
        if level == EventLevel::Warn {
            self.warnings.push(text.to_owned());
        }
    }
}

fn session(detector: DetectorConfig, events: &mut Events) -> Result<Session> {
    Ok(Session::new(
        World::load(&repo("worlds/playground.toml"))?,
        RobotModel::load(&repo("assets/robots/my_robot.urdf"))?,
        &SessionOptions {
            camera: true,
            detector: DetectorMode::Worker,
            detector_config: detector,
            ..SessionOptions::default()
        },
        events,
    )?)
}

#[test]
fn the_worker_detector_sees_the_person_and_the_follower_tracks_them() -> Result<()> {
    let mut events = Events::default();
    let mut session = session(DetectorConfig::default(), &mut events)?;
    assert!(session.stats().detector_ok, "{:?}", events.warnings);
    session.input(rover_core::Action::ToggleFollow, &mut events);
    assert_eq!(session.pilot().mode(), Mode::Follow);
    // Paced like the window (here at half real time, for slow machines' sake): the worker's
    // results arrive on the wall clock, and the follower judges their age on sim time. A
    // machine slower than that just lags behind the pace. The deadline only catches a hung
    // worker.
    let started = Instant::now();
    let deadline = started + Duration::from_secs(300);
    while session
        .last_boxes()
        .is_none_or(|b| !b.bounding_boxes.iter().any(|b| b.class == "person"))
    {
        if session.sim().sim_time_s() > started.elapsed().as_secs_f64() * 0.5 {
            std::thread::sleep(Duration::from_millis(1));
        } else {
            session.step(&mut events)?;
        }
        assert!(
            Instant::now() < deadline,
            "no detection of the person from the worker"
        );
    }
    let stats = session.stats();
    assert!(stats.detector_ok && stats.frames > 0);
    assert!(events.detections > 0);
    let boxes = session.last_boxes().map(|b| b.image_stamp);
    assert!(
        boxes.is_some_and(|s| s.frame <= stats.frames),
        "boxes are stamped with a frame the camera rendered"
    );
    // With a person detected, the follower is tracking (not searching, not stale) after the
    // next control update.
    while session.step(&mut events)?.is_none() {}
    assert_eq!(session.stats().follow_state, FollowState::Tracking);
    assert!(events.warnings.is_empty(), "{:?}", events.warnings);
    Ok(())
}

#[test]
fn a_model_that_cannot_load_is_a_warning_and_manual_driving_works() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let bad = dir.path().join("bad.onnx");
    std::fs::write(&bad, b"not a model")?;
    let mut events = Events::default();
    let mut session = session(
        DetectorConfig {
            model: Some(bad),
            ..DetectorConfig::default()
        },
        &mut events,
    )?;
    assert!(!session.stats().detector_ok);
    assert!(
        events.warnings.iter().any(|w| w.contains("no detector")),
        "{:?}",
        events.warnings
    );
    session.input(
        rover_core::Action::CmdVel(rover_sim::physics::Twist::new(0.5, 0.0)),
        &mut events,
    );
    while session.sim().sim_time_s() < 1.0 {
        session.step(&mut events)?;
    }
    assert!(session.sim().world_from_base().translation.x > 0.2);
    Ok(())
}
