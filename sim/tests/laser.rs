//! The 2D laser on real physics: ranges to walls at known distances and angles, REP-117
//! out-of-range values, the scan rate on sim time, determinism, and the URDF's parameters.

use std::path::Path;

use glam::{Quat, Vec3};
use rover_sim::{
    model::{RobotModel, World},
    physics::{SimOptions, Simulation},
    sensors::LaserSensor,
};

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn laser_robot() -> Result<RobotModel> {
    Ok(RobotModel::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/robots/my_robot_laser.urdf.xacro"),
    )?)
}

/// A wall straight ahead whose near face is at x = 2.0 m, and one to the left turned by 30 deg.
const WORLD: &str = r#"
[[box]]
name = "ahead"
size_m = [0.2, 6.0, 1.0]
position_m = [2.1, 0.0]

[[box]]
name = "slanted"
size_m = [4.0, 0.2, 1.0]
position_m = [-0.5, 2.5]
yaw_deg = 30.0
"#;

fn sim(seed: u64) -> Result<Simulation> {
    let world = World::from_str(WORLD, Path::new("laser-test.toml"))?;
    Ok(Simulation::new(
        world,
        laser_robot()?,
        &SimOptions {
            seed,
            ..SimOptions::default()
        },
    )?)
}

/// Where a ray from `origin` along `dir` meets the nearer local-y face of a box centred at
/// `centre` with yaw `yaw` and half-size `half` (x, y), if it does `margin` m inside the face's
/// ends (negative: outside).
fn hit_box_face(
    origin: Vec3,
    dir: Vec3,
    centre: Vec3,
    yaw: f32,
    half: [f32; 2],
    margin: f32,
) -> Option<f32> {
    let inv = Quat::from_rotation_z(-yaw);
    let o = inv * (origin - centre);
    let d = inv * dir;
    // The face nearer to the origin.
    let face_y = if o.y < 0.0 { -half[1] } else { half[1] };
    if d.y.abs() < 1e-6 {
        return None;
    }
    let t = (face_y - o.y) / d.y;
    let x = o.x + t * d.x;
    (t > 0.0 && x.abs() < half[0] - margin).then_some(t)
}

#[test]
fn walls_read_back_within_the_range_resolution_and_noise() -> Result<()> {
    let mut sim = sim(7)?;
    // Let the car settle on its wheels.
    for _ in 0..200 {
        sim.step();
    }
    let mut laser = LaserSensor::new(&sim, 0)?;
    let config = laser.config().clone();
    assert_eq!(config.samples, 360);
    assert!((config.range_max_m - 3.5).abs() < 1e-9);
    assert!((config.range_resolution_m - 0.015).abs() < 1e-9);
    let noise = config
        .noise
        .ok_or("the laser car's scanner has gaussian noise")?;
    let tolerance = config.range_resolution_m / 2.0 + 4.5 * noise.stddev;
    let pose = laser.world_from_sensor(&sim);
    let scan = laser.scan_now(&sim).clone();
    assert_eq!(scan.ranges_m.len(), 360);
    let (mut ahead, mut slanted, mut open) = (0, 0, 0);
    for (i, &r) in scan.ranges_m.iter().enumerate() {
        let a = scan.angle_rad(i);
        let dir = pose.rotation * Vec3::new(a.cos(), a.sin(), 0.0);
        let expected = |margin: f32| {
            [
                // Turned by 90 deg, the box's local y faces are its x faces in the world.
                hit_box_face(
                    pose.translation,
                    dir,
                    Vec3::new(2.1, 0.0, 0.5),
                    90f32.to_radians(),
                    [3.0, 0.1],
                    margin,
                )
                .map(|t| (t, "ahead")),
                hit_box_face(
                    pose.translation,
                    dir,
                    Vec3::new(-0.5, 2.5, 0.5),
                    30f32.to_radians(),
                    [2.0, 0.1],
                    margin,
                )
                .map(|t| (t, "slanted")),
            ]
            .into_iter()
            .flatten()
            .min_by(|a, b| a.0.total_cmp(&b.0))
        };
        // Rays that graze a wall's end are not checked.
        let (sure, maybe) = (expected(0.05), expected(-0.05));
        match sure {
            Some((t, which)) if t < 3.4 => {
                let err = (f64::from(r) - f64::from(t)).abs();
                assert!(
                    err <= tolerance,
                    "ray {i} ({:.1} deg) on the {which} wall: read {r:.3} m, expected {t:.3} m (tolerance {tolerance:.3})",
                    a.to_degrees()
                );
                // Ranges come in steps of the resolution.
                let steps = f64::from(r) / config.range_resolution_m;
                assert!(
                    (steps - steps.round()).abs() < 1e-3,
                    "{r} is not a multiple"
                );
                if which == "ahead" {
                    ahead += 1;
                } else {
                    slanted += 1;
                }
            }
            Some(_) => {}
            None if maybe.is_some() => {}
            None => {
                assert!(r == f32::INFINITY, "ray {i}: nothing there, read {r}");
                open += 1;
            }
        }
    }
    assert!(ahead > 80, "{ahead} rays on the wall ahead");
    assert!(slanted > 20, "{slanted} rays on the slanted wall");
    assert!(open > 50, "{open} rays into open space");
    Ok(())
}

#[test]
fn scans_follow_the_update_rate_on_sim_time_and_repeat_with_the_seed() -> Result<()> {
    let mut a = sim(3)?;
    let mut b = sim(3)?;
    // The scene's ray index is built by the first physics step.
    a.step();
    b.step();
    let mut la = LaserSensor::new(&a, 0)?;
    let mut lb = LaserSensor::new(&b, 0)?;
    let rate = la.config().update_rate_hz;
    let mut times = Vec::new();
    // 2 s of sim time at the world's step rate.
    let steps = (2.0 / a.dt_s()).round() as usize;
    for _ in 0..steps {
        if let Some(scan) = la.scan_if_due(&a) {
            times.push(scan.stamp_s);
            let other = lb.scan_if_due(&b).ok_or("the twin laser is due too")?;
            assert_eq!(scan.ranges_m, other.ranges_m, "same seed, same scan");
        }
        a.step();
        b.step();
    }
    // The first scan when the sensor starts (after the first step), then one per period.
    assert_eq!(times.len(), (2.0 * rate).round() as usize + 1, "{times:?}");
    for w in times[1..].windows(2) {
        assert!((w[1] - w[0] - 1.0 / rate).abs() < 1e-9, "{times:?}");
    }
    // Another seed: other noise.
    let mut c = sim(4)?;
    let mut d = sim(3)?;
    c.step();
    d.step();
    let mut lc = LaserSensor::new(&c, 0)?;
    let mut ld = LaserSensor::new(&d, 0)?;
    assert_ne!(lc.scan_now(&c).ranges_m, ld.scan_now(&d).ranges_m);
    Ok(())
}
