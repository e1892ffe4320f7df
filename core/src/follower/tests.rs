//! The follower's unit tests.

use super::tuning::*;
use super::*;
use nalgebra::Matrix2;
use rover_perception::{BoundingBox, BoundingBoxes, FrameStamp};
use rover_sim::{
    physics::{Odometry, Twist, wrap_angle},
    sensors::LaserScan,
};

fn camera() -> CameraGeometry {
    CameraGeometry {
        fx: 381.36,
        fy: 381.36,
        cx: 320.5,
        cy: 240.5,
        width_px: 640.0,
        height_px: 480.0,
        height_m: 0.18,
        forward_m: 0.15,
        left_m: 0.0,
        yaw_rad: 0.0,
        pitch_down_rad: 0.0,
    }
}

fn person_box(range_m: f64, bearing_rad: f64) -> BoundingBox {
    let c = camera();
    let along = range_m * bearing_rad.cos();
    let u = c.cx - c.fx * bearing_rad.tan();
    let h = c.fy * 1.75 / along;
    let feet = c.cy + c.fy * 0.18 / along;
    BoundingBox {
        class: "person".into(),
        probability: 0.8,
        xmin: (u - h * 0.15) as i64,
        ymin: (feet - h) as i64,
        xmax: (u + h * 0.15) as i64,
        ymax: feet as i64,
        id: 0,
    }
}

fn message(t: f64, boxes: Vec<BoundingBox>) -> BoundingBoxes {
    BoundingBoxes {
        image_stamp: FrameStamp {
            sim_time_s: t,
            frame: (t * 30.0) as u64,
        },
        frame_id: "camera_link_optical".into(),
        bounding_boxes: boxes,
        latency_ms: 0.0,
    }
}

#[test]
fn range_and_bearing_come_back_from_a_projected_box() {
    let f = Follower::new(FollowerConfig::default(), camera());
    for (range, bearing) in [(3.0, 0.0), (5.0, 0.3), (2.0, -0.4)] {
        let (r, b) = f.range_bearing(&person_box(range, bearing));
        assert!((r - range).abs() < 0.05 * range, "{r} vs {range}");
        assert!((b - bearing).abs() < 0.01, "{b} vs {bearing}");
    }
    // Cut off at the top: the feet give the range.
    let mut clipped = person_box(1.5, 0.0);
    clipped.ymin = 0;
    let (r, _) = f.range_bearing(&clipped);
    assert!((r - 1.5).abs() < 0.1, "{r}");
}

#[test]
fn range_from_the_feet_honours_a_pitched_camera() {
    // A TurtleBot3-like camera: 0.15 m up, looking 0.174 rad down. Feet at 2 m dip
    // atan(0.15 / 2) below the horizon, so atan(0.15 / 2) - 0.174 below the optical axis.
    let pitched = CameraGeometry {
        height_m: 0.15,
        pitch_down_rad: 0.174,
        ..camera()
    };
    let f = Follower::new(FollowerConfig::default(), pitched);
    for range in [1.5f64, 2.0, 3.0] {
        let dip = (0.15 / range).atan() - 0.174;
        let feet = pitched.cy + pitched.fy * dip.tan();
        let clipped = BoundingBox {
            class: "person".into(),
            probability: 0.8,
            xmin: 300,
            ymin: 0,
            xmax: 340,
            ymax: feet.round() as i64,
            id: 0,
        };
        let (r, _) = f.range_bearing(&clipped);
        assert!((r - range).abs() < 0.1 * range, "{r} vs {range}");
    }
}

#[test]
fn approaches_a_centred_target_and_stops_at_the_standoff() {
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(4.0, 0.0)]));
    let mut cmd = Twist::ZERO;
    for i in 1..200 {
        cmd = f.command(i as f64 * 0.01, odom, true);
        f.observe(&message(i as f64 * 0.01, vec![person_box(4.0, 0.0)]));
    }
    assert_eq!(f.state(), FollowState::Tracking);
    assert!(
        (cmd.linear_mps - FollowerConfig::default().max_speed_mps).abs() < 0.01,
        "{cmd:?}"
    );
    assert!(cmd.angular_radps.abs() < 0.01, "{cmd:?}");
    // At the standoff it holds still.
    let mut f = Follower::new(FollowerConfig::default(), camera());
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(1.5 - 0.15, 0.0)]));
    let cmd = f.command(0.01, odom, true);
    assert!(cmd.linear_mps.abs() < 0.01, "{cmd:?}");
}

#[test]
fn acceleration_is_limited() {
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(6.0, 0.5)]));
    let cmd = f.command(0.01, odom, true);
    assert!(cmd.linear_mps <= FollowerConfig::default().max_accel_mps2 * 0.01 + 1e-9);
    assert!(cmd.angular_radps <= 3.0 * 0.01 + 1e-9 && cmd.angular_radps > 0.0);
}

#[test]
fn keeps_the_same_target_among_several_people() {
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    // The nearer one is picked first...
    f.observe(&message(
        0.0,
        vec![person_box(5.0, 0.3), person_box(3.0, -0.3)],
    ));
    let first = f.target().expect("target").clone();
    assert!(first.bearing_rad < 0.0);
    // ...and kept when the other comes a little nearer.
    f.command(0.1, odom, true);
    f.observe(&message(
        0.1,
        vec![person_box(2.9, 0.3), person_box(3.05, -0.3)],
    ));
    let t = f.target().expect("target");
    assert_eq!(t.id, first.id);
    assert!(t.bearing_rad < 0.0);
}

#[test]
fn searches_toward_where_the_target_went_and_stops_when_stale() {
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let mut odom = Odometry::default();
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(3.0, -0.5)]));
    // Lost: empty messages keep coming (past the pursuit and the look around).
    let mut cmd = Twist::ZERO;
    for i in 1..=1000 {
        let t = i as f64 * 0.01;
        f.observe(&message(t, vec![]));
        cmd = f.command(t, odom, true);
        drive(&mut odom, cmd, 0.01);
    }
    assert_eq!(f.state(), FollowState::Searching);
    assert!(
        cmd.angular_radps < 0.0,
        "sweeps right, the way it went: {cmd:?}"
    );
    assert!(cmd.linear_mps.abs() < 1e-9, "never drives while searching");
    // No messages for more than a second: stop.
    let cmd = f.command(10.0 + 1.01, odom, true);
    assert_eq!(f.state(), FollowState::Stale);
    assert_eq!(cmd, Twist::ZERO);
    // No detector: stop.
    let cmd = f.command(11.1, odom, false);
    assert_eq!(cmd, Twist::ZERO);
    assert_eq!(f.state(), FollowState::NoDetector);
}

#[test]
fn uses_the_pose_at_image_time() {
    // The robot turned 0.3 rad left after the image was taken: the target, dead ahead in
    // the image, is now 0.3 rad to the right.
    let mut f = Follower::new(FollowerConfig::default(), camera());
    f.command(0.0, Odometry::default(), true);
    let turned = Odometry {
        yaw_rad: 0.3,
        ..Odometry::default()
    };
    f.command(0.2, turned, true);
    f.observe(&message(0.0, vec![person_box(4.0, 0.0)]));
    let here = f.target().expect("target").position_at(0.2);
    let (_, bearing) = range_bearing_from(turned, here);
    assert!((bearing + 0.3).abs() < 0.05, "{bearing}");
}

#[test]
fn a_detection_after_follow_off_drive_on_is_placed_with_the_current_pose() {
    // Review fix: poses are recorded in every mode. Follow on, off, drive 2 m forward by
    // hand (the session records poses but asks for no command), on again: a person seen
    // 3 m ahead is 5 m from the start, not 3 m (a phantom at the old pose).
    let mut f = Follower::new(FollowerConfig::default(), camera());
    f.command(0.0, Odometry::default(), true);
    f.reset();
    for i in 1..=200 {
        let t = f64::from(i) * 0.01;
        let odom = Odometry {
            x_m: t,
            ..Odometry::default()
        };
        f.record_pose(t, odom);
    }
    f.reset();
    let now = Odometry {
        x_m: 2.0,
        ..Odometry::default()
    };
    f.observe(&message(2.0, vec![person_box(3.0, 0.0)]));
    let here = f.target().expect("target").position_at(2.0);
    let expected_x = 2.0 + camera().forward_m + 3.0;
    assert!((here[0] - expected_x).abs() < 0.2, "{here:?}");
    f.command(2.01, now, true);
    let cmd = f.command(2.02, now, true);
    assert_eq!(f.state(), FollowState::Tracking);
    assert!(cmd.linear_mps > 0.0, "{cmd:?}");
}

#[test]
fn a_close_centred_target_that_flickers_is_held_not_searched_for() {
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    // At the standoff (1.5 m from the base: the camera is 0.15 m ahead of it), dead ahead,
    // seen once, then only empty messages for 20 s: the pursuit has arrived at once, and
    // a standing person the camera cannot see whole from here is looked at, not searched.
    f.observe(&message(0.0, vec![person_box(1.5 - 0.15, 0.0)]));
    for i in 1..=2000 {
        let t = f64::from(i) * 0.01;
        f.observe(&message(t, vec![]));
        let cmd = f.command(t, odom, true);
        if t > 0.7 {
            assert_eq!(f.state(), FollowState::Pursuing, "at {t}");
        }
        assert!(cmd.angular_radps.abs() < 0.05, "{cmd:?} at {t}");
        assert!(cmd.linear_mps.abs() < 1e-9, "{cmd:?} at {t}");
    }
}

/// Moves `odom` by `cmd` for `dt` (a unicycle): the follower's commands take effect.
fn drive(odom: &mut Odometry, cmd: Twist, dt: f64) {
    odom.yaw_rad += cmd.angular_radps * dt;
    odom.x_m += cmd.linear_mps * odom.yaw_rad.cos() * dt;
    odom.y_m += cmd.linear_mps * odom.yaw_rad.sin() * dt;
}

#[test]
fn a_lost_target_is_pursued_to_where_it_was_then_searched_for() {
    // Seen once 5 m ahead, 0.3 rad left, then never again (hidden): the car drives to the
    // standoff from where it was, looks for `reacquire_s`, and only then searches.
    let config = FollowerConfig::default();
    let mut f = Follower::new(config.clone(), camera());
    let mut odom = Odometry::default();
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(5.0, 0.3)]));
    let seen_at = f.target().expect("target").position_at(0.0);
    let mut arrived = None;
    let mut searched_at = None;
    for i in 1..=2000 {
        let t = f64::from(i) * 0.01;
        f.observe(&message(t, vec![]));
        let cmd = f.command(t, odom, true);
        drive(&mut odom, cmd, 0.01);
        match f.state() {
            FollowState::Pursuing => {
                assert_eq!(f.goal_m(), Some(seen_at), "the pursued point at {t}");
                let range = (seen_at[0] - odom.x_m).hypot(seen_at[1] - odom.y_m);
                if arrived.is_none() && range < config.standoff_m + config.standoff_band_m {
                    arrived = Some(t);
                }
            }
            FollowState::Searching => {
                searched_at.get_or_insert(t);
                assert!(cmd.linear_mps.abs() < 1e-9, "never drives while searching");
            }
            other => assert!(t < config.lost_after_s + 0.02, "{other:?} at {t}"),
        }
    }
    let arrived = arrived.expect("the pursuit reaches the standoff");
    let searched_at = searched_at.expect("then it searches");
    let range = (seen_at[0] - odom.x_m).hypot(seen_at[1] - odom.y_m);
    assert!(
        (range - config.standoff_m).abs() < config.standoff_band_m + 0.05,
        "stopped {range} m from where the target was"
    );
    assert!(
        searched_at > arrived && searched_at < arrived + config.reacquire_s + 1.0,
        "arrived at {arrived} s, searched at {searched_at} s"
    );
}

#[test]
fn a_second_person_does_not_take_over_while_the_target_is_lost() {
    // The target (4 m ahead) is lost; 1 s later a second person shows up 2.2 m from where
    // it was, nearer the car: the follower keeps pursuing its own target.
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(4.0, 0.0)]));
    let id = f.target().expect("target").id;
    for i in 1..=200 {
        let t = f64::from(i) * 0.01;
        let boxes = if t > 1.0 {
            vec![person_box(2.5, 0.5)]
        } else {
            vec![]
        };
        f.observe(&message(t, boxes));
        f.command(t, odom, true);
    }
    let t = f.target().expect("target");
    assert_eq!(t.id, id, "a new person took over");
    assert_eq!(f.state(), FollowState::Pursuing);
    assert!(
        t.position_at(2.0)[1].abs() < 0.1,
        "{:?}",
        t.position_at(2.0)
    );
}

#[test]
fn boxes_cut_off_or_hidden_still_give_the_range() {
    let f = Follower::new(FollowerConfig::default(), camera());
    let c = camera();
    // A person 1.3 m away seen by the low camera: the box runs from the image's top edge
    // down to the torso (the legs are not detected), 0.55 m wide: range from the width.
    let depth = 1.3;
    let torso = BoundingBox {
        class: "person".into(),
        probability: 0.5,
        xmin: (c.cx - c.fx * 0.275 / depth) as i64,
        ymin: 0,
        xmax: (c.cx + c.fx * 0.275 / depth) as i64,
        ymax: (c.cy - c.fy * (0.85 - c.height_m) / depth) as i64,
        id: 0,
    };
    let (r, _) = f.range_bearing(&torso);
    assert!((r - depth).abs() < 0.1, "torso box: {r} m");
    // A person 4.5 m away behind a crate: the box ends above the horizon (no feet), so
    // its top (the head) gives the range, not its short height (which said 11 m).
    let depth = 4.5;
    let hidden = BoundingBox {
        ymax: (c.cy - c.fy * (0.5 - c.height_m) / depth) as i64,
        ..person_box(depth, 0.0)
    };
    let (r, _) = f.range_bearing(&hidden);
    assert!((r - depth).abs() < 0.3, "legs hidden: {r} m");
}

fn scan_with_person_at(range_m: f32, bearing_rad: f32, t: f64) -> LaserScan {
    // 360 rays; the person's 0.13 m body hides a few of them.
    let mut ranges = vec![f32::INFINITY; 360];
    for (i, r) in ranges.iter_mut().enumerate() {
        let a = (i as f32).to_radians();
        let off = rover_sim::physics::wrap_angle(f64::from(a - bearing_rad)) as f32;
        if (off * range_m).abs() < 0.13 {
            *r = range_m - 0.1;
        }
    }
    LaserScan {
        stamp_s: t,
        seq: 0,
        frame_id: "base_scan".into(),
        angle_min_rad: 0.0,
        angle_max_rad: 359f32.to_radians(),
        angle_increment_rad: 1f32.to_radians(),
        time_increment_s: 0.0,
        scan_time_s: 0.1,
        range_min_m: 0.12,
        range_max_m: 3.5,
        ranges_m: ranges,
    }
}

#[test]
fn laser_returns_keep_a_target_the_camera_no_longer_sees() {
    let mut f =
        Follower::new(FollowerConfig::default(), camera()).with_laser(LaserMount::default());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    f.observe(&message(0.0, vec![person_box(2.0, 0.0)]));
    // The person steps 0.5 m to the left over 2 s; only the laser sees it.
    for i in 1..=200 {
        let t = f64::from(i) * 0.01;
        f.observe(&message(t, vec![]));
        if i % 10 == 0 {
            let y = 0.5 * (t / 2.0);
            let range = (2.15f64.powi(2) + y * y).sqrt() as f32;
            let bearing = (y / 2.15).atan() as f32;
            f.observe_scan(&scan_with_person_at(range, bearing, t));
        }
        f.command(t, odom, true);
    }
    assert_eq!(f.state(), FollowState::Tracking);
    let here = f.target().expect("target").position_at(2.0);
    assert!((here[1] - 0.5).abs() < 0.15, "{here:?}");
}

#[test]
fn the_laser_picks_up_a_lost_track_along_the_cameras_line_of_sight() {
    // A track from a far camera box: long along the line of sight (1.1 m sigma), narrow
    // across it (0.14 m). Lost a second ago, it is predicted at `expected`; one compact
    // laser cluster shows a person at `person`.
    let pick_up = |expected: [f64; 2], person: [f64; 2]| {
        let mut f =
            Follower::new(FollowerConfig::default(), camera()).with_laser(LaserMount::default());
        let odom = Odometry::default();
        f.command(0.0, odom, true);
        f.observe(&message(0.0, vec![person_box(2.0, 0.0)]));
        let t = f.target.as_mut().expect("target");
        let cov = Matrix2::new(1.2, 0.0, 0.0, 0.02);
        t.filter = TargetFilter::new(0.0, expected, cov);
        f.observe(&message(1.0, vec![]));
        let range = person[0].hypot(person[1]);
        let bearing = person[1].atan2(person[0]);
        f.observe_scan(&scan_with_person_at(range as f32, bearing as f32, 1.0));
        f.target().expect("target").position_at(1.0)
    };
    // 1.5 m short of the prediction, straight ahead: the camera's range was long. Taken.
    let here = pick_up([4.0, 0.0], [2.5, 0.0]);
    assert!(
        (here[0] - 2.5).abs() < 0.3 && here[1].abs() < 0.1,
        "{here:?}"
    );
    // 1.2 m to the side of the prediction, where the track is certain: not taken.
    let here = pick_up([3.0, 0.0], [3.0, 1.2]);
    assert!(
        (here[0] - 3.0).abs() < 0.1 && here[1].abs() < 0.1,
        "{here:?}"
    );
}

/// The box the test camera sees of a person standing at `person` (odometry frame) from a
/// robot at `odom`, cut off at the image's top edge as a low camera sees a near person.
fn seen_box(odom: Odometry, person: [f64; 2]) -> BoundingBox {
    let (s, c) = odom.yaw_rad.sin_cos();
    let camera_xy = [
        odom.x_m + c * camera().forward_m,
        odom.y_m + s * camera().forward_m,
    ];
    let (dx, dy) = (person[0] - camera_xy[0], person[1] - camera_xy[1]);
    let mut b = person_box(dx.hypot(dy), wrap_angle(dy.atan2(dx) - odom.yaw_rad));
    b.ymin = b.ymin.max(0);
    b
}

#[test]
fn a_walker_lost_in_the_blind_zone_who_does_not_walk_out_of_it_has_stopped() {
    // The camera sees the person whole from 2.49 m. They walk away at 0.5 m/s from 1.6 m to
    // 2.2 m in front of the camera, seen at 5 Hz, then stop there and are never detected
    // again (a detector's blind spot): their prediction would carry them on into plain view
    // (0.8 m further), where the camera sees nobody. The track stops where it was last.
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    f.command(0.0, odom, true);
    let forward = camera().forward_m;
    for i in 0..=6 {
        let t = f64::from(i) * 0.2;
        f.observe(&message(
            t,
            vec![seen_box(odom, [forward + 1.6 + 0.5 * t, 0.0])],
        ));
        f.command(t + 0.01, odom, true);
    }
    let [vx, _] = f.target().expect("target").filter.velocity_mps();
    assert!(vx > 0.3, "walking away: {vx} m/s");
    for i in 7..=40 {
        let t = f64::from(i) * 0.2;
        f.observe(&message(t, vec![]));
        f.command(t + 0.01, odom, true);
    }
    let t = f.target().expect("target");
    let here = t.position_at(8.0);
    assert!(
        (here[0] - (forward + 2.2)).abs() < 0.25 && here[1].abs() < 0.1,
        "the track should stop near where the person was last seen: {here:?}"
    );
    let [vx, vy] = t.filter.predicted_velocity_mps(8.0, PREDICTION_HORIZON_S);
    assert!(vx.hypot(vy) < 1e-9);

    // A walker lost in plain view (hidden, or gone out of the side) is not taken to have
    // stopped: the prediction walks on for its horizon.
    let mut f = Follower::new(FollowerConfig::default(), camera());
    f.command(0.0, odom, true);
    for i in 0..=6 {
        let t = f64::from(i) * 0.2;
        f.observe(&message(
            t,
            vec![seen_box(odom, [forward + 3.0 + 0.5 * t, 0.0])],
        ));
        f.command(t + 0.01, odom, true);
    }
    for i in 7..=40 {
        let t = f64::from(i) * 0.2;
        f.observe(&message(t, vec![]));
        f.command(t + 0.01, odom, true);
    }
    let here = f.target().expect("target").position_at(8.0);
    assert!(here[0] > forward + 3.6 + 0.5, "{here:?}");
}

#[test]
fn a_walker_at_the_kept_range_is_followed_without_stopping() {
    // A person walks away at 0.4 m/s; the car drives as commanded. Once it has caught up
    // to the range it keeps, the range error crosses zero again and again: the walker's
    // speed must stay fed forward. (The range used to settle at each crossing and the car
    // slowed, here to 0.33 m/s; in the walk_away scenario it stopped and fell 3.01 m
    // behind.)
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let mut odom = Odometry::default();
    let forward = camera().forward_m;
    let mut slowest_mps = f64::INFINITY;
    let (mut nearest_m, mut furthest_m) = (f64::INFINITY, 0.0f64);
    for i in 0..1500 {
        let t = f64::from(i) * 0.02;
        let person = [forward + 3.0 + 0.4 * t, 0.0];
        if i % 10 == 0 {
            f.observe(&message(t, vec![seen_box(odom, person)]));
        }
        let cmd = f.command(t + 0.001, odom, true);
        odom.x_m += cmd.linear_mps * 0.02;
        if t > 10.0 {
            slowest_mps = slowest_mps.min(cmd.linear_mps);
            nearest_m = nearest_m.min(person[0] - odom.x_m);
            furthest_m = furthest_m.max(person[0] - odom.x_m);
        }
    }
    // The speed wanders with the boxes' pixel rounding (5 Hz), the range barely.
    assert!(slowest_mps > 0.3, "it slowed to {slowest_mps} m/s");
    assert!(
        furthest_m - nearest_m < 0.05,
        "the range wandered {nearest_m}..{furthest_m} m"
    );
    // A receding walker is followed at the walking distance.
    let walking_m = camera().whole_view_range_m(1.75) + forward;
    assert!(
        (nearest_m - walking_m).abs() < 0.1,
        "followed at {nearest_m} m, not {walking_m} m"
    );
}

#[test]
fn a_box_top_at_the_border_is_cut_off_when_the_feet_put_the_head_out_of_view() {
    // A person 1.6 m away: the 18 cm camera sees them from the chest down, but a detector's
    // box top wanders a few pixels below the border. Taken for the head, that box put
    // them at ~3 m; the feet say 1.6 m and that the head is out of view.
    let f = Follower::new(FollowerConfig::default(), camera());
    let mut b = person_box(1.6, 0.0);
    assert!(b.ymin < 0, "the head is out of view at 1.6 m");
    b.ymin = 3;
    let (range_m, _) = f.range_bearing(&b);
    assert!((range_m - 1.6).abs() < 0.1, "range {range_m} m");
    // A person just far enough to be seen whole, their head a few pixels below the border,
    // is still ranged from their height.
    let whole_m = camera().whole_view_range_m(1.75);
    let b = person_box(whole_m + 0.05, 0.0);
    assert!(
        b.ymin > 0 && f64::from(b.ymin as i32) < 0.02 * 480.0,
        "top {}",
        b.ymin
    );
    let (range_m, _) = f.range_bearing(&b);
    assert!(
        (range_m - (whole_m + 0.05)).abs() < 0.1,
        "range {range_m} m"
    );
}

#[test]
fn a_camera_only_car_turns_its_back_to_its_trail_to_give_way() {
    // The car drove 3 m along +x, then turned 0.5 rad left to face a person who now walks
    // straight at it. Its trail is not behind it, so it may not back up as it stands: it
    // turns toward the heading that puts the trail behind (keeping them in view) and backs.
    let config = FollowerConfig::default();
    let mut f = Follower::new(config, camera());
    for i in 0..=100 {
        let pose = Odometry {
            x_m: -3.0 * (1.0 - f64::from(i) / 100.0),
            ..Odometry::default()
        };
        f.record_pose(-1.0 + f64::from(i) * 0.01, pose);
    }
    let mut odom = Odometry {
        yaw_rad: 0.5,
        ..Odometry::default()
    };
    let start = [2.2 * 0.5f64.cos(), 2.2 * 0.5f64.sin()];
    let (mut widest_rad, mut nearest_m) = (0.0f64, f64::INFINITY);
    for i in 0..=600 {
        let t = f64::from(i) * 0.01;
        let walked = (0.4 * t).min(1.4);
        let person = [
            start[0] * (1.0 - walked / 2.2),
            start[1] * (1.0 - walked / 2.2),
        ];
        let (range_m, bearing_rad) = range_bearing_from(odom, person);
        if i % 20 == 0 {
            f.observe(&message(t, vec![seen_box(odom, person)]));
            widest_rad = widest_rad.max(bearing_rad.abs());
        }
        nearest_m = nearest_m.min(range_m);
        let cmd = f.command(t, odom, true);
        drive(&mut odom, cmd, 0.01);
    }
    assert!(odom.x_m < -0.5, "backed to x = {} m", odom.x_m);
    assert!(odom.y_m.abs() < 0.15, "left its trail: y = {} m", odom.y_m);
    assert!(
        widest_rad < 0.5,
        "turned them to {widest_rad} rad off the axis"
    );
    assert!(nearest_m > 1.2, "let them within {nearest_m} m");
}

#[test]
fn a_walker_whose_estimate_dips_below_walking_speed_stays_a_walker_for_a_while() {
    // A person walking across 4 m ahead, then standing still where they are. The car
    // stands: only the estimate moves. (A walking body's boxes make the estimate dip below
    // walking speed for a moment now and then; that must not make the car close in to
    // the standoff and back off again at each dip.)
    let mut f = Follower::new(FollowerConfig::default(), camera());
    let odom = Odometry::default();
    let person = |t: f64| [4.0, -1.0 + 0.6 * t.min(3.0)];
    let mut walked = false;
    let mut first_slow: Option<(f64, bool)> = None;
    for i in 0..=300 {
        let t = f64::from(i) * 0.02;
        f.record_pose(t, odom);
        if i % 10 == 0 {
            f.observe(&message(t, vec![seen_box(odom, person(t))]));
        }
        let Some(target) = f.target() else { continue };
        let [vx, vy] = target.filter.velocity_mps();
        let fast = vx.hypot(vy) > MOVING_MPS;
        walked |= fast && target.last_seen_walking();
        if walked && !fast && first_slow.is_none() {
            first_slow = Some((t, target.last_seen_walking()));
        }
    }
    assert!(walked, "the walk was never seen as walking");
    let Some((slow_s, still_walker)) = first_slow else {
        panic!("the estimate never slowed down");
    };
    assert!(
        still_walker,
        "let go as soon as the estimate slowed ({slow_s} s)"
    );
    // Three seconds of standing: they stand.
    let standing = f.target().map(|t| !t.last_seen_walking());
    assert_eq!(standing, Some(true), "still a walker after 3 s of standing");
}

#[test]
fn a_camera_only_car_pursues_a_lost_walker_to_the_walking_distance() {
    // A person walking away 4.5 m ahead is lost from view at 1 s (hidden), long before the
    // car is near. The prediction walks them on and stops; that it stopped does not mean
    // they did: the camera-only car ends where its camera would see them whole, not at
    // the standoff, and then looks for them.
    let config = FollowerConfig::default();
    let whole_m = camera().whole_view_range_m(config.target_height_m) + camera().forward_m;
    let mut f = Follower::new(config.clone(), camera());
    let mut odom = Odometry::default();
    for i in 0..=1000 {
        let t = f64::from(i) * 0.01;
        if i % 20 == 0 {
            let person = [4.5 + 0.5 * t, 0.0];
            let boxes = if t <= 1.0 {
                vec![seen_box(odom, person)]
            } else {
                vec![]
            };
            f.observe(&message(t, boxes));
        }
        let cmd = f.command(t, odom, true);
        drive(&mut odom, cmd, 0.01);
    }
    let target = f.target().expect("the target is kept");
    let (range_m, _) = range_bearing_from(odom, target.position_at(10.0));
    assert!(target.last_seen_walking());
    assert!(
        range_m > whole_m - config.standoff_band_m - 0.1,
        "closed in to {range_m} m of a walker it lost (walking distance {whole_m} m)"
    );
}

#[test]
fn a_camera_only_car_gives_way_to_a_walker_coming_closer() {
    // A person walks straight at the car at 0.4 m/s from 4 m. Without a laser, the car keeps
    // them where its camera sees them whole (2.49 m from the camera): it backs away instead
    // of letting them walk into its blind zone, over the 3 m it drove to get here; where it
    // has not driven it does not back up blind.
    let config = FollowerConfig::default();
    let whole_m = camera().whole_view_range_m(config.target_height_m) + camera().forward_m;
    let run = |came_from_m: f64| {
        let mut f = Follower::new(config.clone(), camera());
        for i in 0..=100 {
            let x = -came_from_m * (1.0 - f64::from(i) / 100.0);
            let pose = Odometry {
                x_m: x,
                ..Odometry::default()
            };
            f.record_pose(-1.0 + f64::from(i) * 0.01, pose);
        }
        let mut odom = Odometry::default();
        f.command(0.0, odom, true);
        let (mut nearest_m, mut backed_m) = (f64::INFINITY, 0.0f64);
        for i in 1..=1200 {
            let t = f64::from(i) * 0.01;
            let person = [4.0 - 0.4 * t, 0.0];
            if i % 20 == 0 && person[0] - odom.x_m > 1.0 {
                f.observe(&message(t, vec![seen_box(odom, person)]));
            }
            let cmd = f.command(t, odom, true);
            drive(&mut odom, cmd, 0.01);
            backed_m = backed_m.min(odom.x_m);
            // While its trail lasts (it ends 3 m back, reached after ~10 s).
            if t > 4.0 && t <= 9.0 {
                nearest_m = nearest_m.min(person[0] - odom.x_m);
            }
        }
        (backed_m, nearest_m)
    };
    let (backed_m, nearest_m) = run(3.0);
    assert!(backed_m < -2.0, "backed away {backed_m} m");
    assert!(
        backed_m > -3.0 - REVERSE_LOOK_M,
        "backed off its trail: {backed_m} m"
    );
    assert!(
        nearest_m > whole_m - 0.5,
        "let the person within {nearest_m} m (sees them whole from {whole_m} m)"
    );
    let (blind_m, _) = run(0.0);
    assert!(
        blind_m > -0.05,
        "backed {blind_m} m over ground it never drove"
    );
    // With a laser the standoff is kept instead: the laser sees them at any range.
    let mut f = Follower::new(config.clone(), camera()).with_laser(LaserMount::default());
    let mut odom = Odometry::default();
    f.command(0.0, odom, true);
    for i in 1..=300 {
        let t = f64::from(i) * 0.01;
        if i % 20 == 0 {
            f.observe(&message(t, vec![seen_box(odom, [4.0 - 0.4 * t, 0.0])]));
        }
        let cmd = f.command(t, odom, true);
        drive(&mut odom, cmd, 0.01);
    }
    assert!(
        odom.x_m > 0.0,
        "the laser car drove toward them: {}",
        odom.x_m
    );
}
