//! The sensor benchmarks: camera frame time (`rover bench camera`), laser scan time with the
//! follower's command on it (`rover bench laser`), the depth cloud's build time, and the IMU's,
//! p3d's, GPS's cost per reading and the 3D lidar's per scan (`rover bench sensors`).

use std::time::Instant;

use anyhow::Result;
use rover_core::RunConfig;
use rover_sim::physics::{Simulation, Twist};
use rover_sim::sensors::{CloudLayout, CloudSource, DepthCloudBuilder, LidarSensor, PointCloud};

use super::stats::median;
use crate::cli::args::WorldArgs;

/// Result of the camera benchmark.
#[derive(Debug, Clone)]
pub struct CameraBench {
    /// Graphics adapter used.
    pub adapter: String,
    /// Image size (px).
    pub size: (u32, u32),
    /// Median render + readback (ms).
    pub median_ms: f64,
    /// Fastest frame (ms).
    pub best_ms: f64,
    /// Median with ground truth on: id image and silhouettes read back, boxes measured (ms).
    pub truth_median_ms: f64,
    /// Median ms per image with the depth image read back too.
    pub depth_median_ms: f64,
    /// Median ms to build the depth camera's organized point cloud (x y z rgb) from one depth
    /// image and its colour image.
    pub depth_cloud_median_ms: f64,
    /// Labelled things in the world.
    pub labelled: usize,
}

/// Renders `frames` camera images of the world from the robot's camera while it drives a
/// circle (render + readback + post-processing per frame, after one warm-up), interleaving a
/// camera without and one with ground truth so both see the same machine load.
pub fn camera(config: &RunConfig, frames: usize) -> Result<CameraBench> {
    let (world, robot) = config.load_world_and_robot()?;
    let mut sim = Simulation::new(world, robot, &config.options)?;
    // The colour image alone, then with ground truth, then with a depth image.
    let mut sensor = rover_sim::sensors::CameraSensor::new(&sim)?;
    sensor.disable_depth();
    let mut truth = rover_sim::sensors::CameraSensor::new(&sim)?;
    truth.disable_depth();
    truth.enable_ground_truth(&sim)?;
    let mut depth = rover_sim::sensors::CameraSensor::new(&sim)?;
    depth.enable_depth();
    depth.capture(&sim)?;
    sim.set_cmd_vel(Twist::new(0.3, 0.4))?;
    sensor.capture(&sim)?;
    truth.capture(&sim)?;
    let mut times = Vec::with_capacity(frames);
    let mut truth_times = Vec::with_capacity(frames);
    let mut depth_times = Vec::with_capacity(frames);
    let mut cloud_times = Vec::with_capacity(frames);
    let builder = DepthCloudBuilder::new(depth.info());
    let mut cloud = PointCloud::new(CloudSource::DepthCamera, "bench", CloudLayout::XyzRgb);
    for _ in 0..frames.max(1) {
        for _ in 0..5 {
            sim.step();
        }
        let start = Instant::now();
        sensor.capture(&sim)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        truth.capture(&sim)?;
        truth_times.push(start.elapsed().as_secs_f64() * 1e3);
        let start = Instant::now();
        let frame = depth.capture(&sim)?;
        depth_times.push(start.elapsed().as_secs_f64() * 1e3);
        if let Some(depth_m) = frame.depth_m {
            let start = Instant::now();
            builder.fill(depth_m, frame.rgb, (0.4, 5.0), &mut cloud);
            cloud_times.push(start.elapsed().as_secs_f64() * 1e3);
        }
    }
    let best_ms = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(CameraBench {
        adapter: sensor.renderer().adapter().to_owned(),
        size: (sensor.info().width, sensor.info().height),
        median_ms: median(&mut times),
        best_ms,
        truth_median_ms: median(&mut truth_times),
        depth_median_ms: median(&mut depth_times),
        depth_cloud_median_ms: median(&mut cloud_times),
        labelled: rover_sim::model::EntityIds::new(sim.world()).len(),
    })
}

/// Laser benchmark figures.
#[derive(Debug, Clone)]
pub struct LaserBench {
    /// Rays per scan.
    pub rays: u32,
    /// Scans per sim second.
    pub rate_hz: f64,
    /// Median wall time of one scan (ms).
    pub median_ms: f64,
    /// Fastest scan (ms).
    pub best_ms: f64,
    /// Median wall time of one follower command with the scan's obstacles (us).
    pub follower_us: f64,
    /// Median wall time of the avoidance's full window search over the scan's returns, with
    /// the way ahead blocked (the worst case, us).
    pub window_search_us: f64,
}

/// Laser: time per scan (ray casts against the physics scene) and the follower's command with
/// that scan's obstacles, in the configured world with its robot (default: the playground and
/// the tutorial car with its laser).
pub fn laser(config: &RunConfig, scans: usize) -> Result<LaserBench> {
    let (world, robot) = config.load_world_and_robot()?;
    anyhow::ensure!(
        !robot.lasers.is_empty(),
        "{}: the robot has no <sensor type=\"ray\">; try --robot assets/robots/my_robot_laser.urdf.xacro",
        robot.source.display()
    );
    let mut sim = Simulation::new(world, robot, &config.options)?;
    let mut sensor = rover_sim::sensors::LaserSensor::new(&sim, 0)?;
    let mount = rover_core::LaserMount::from_base_from_laser(
        sim.world_from_base().inverse() * sensor.world_from_sensor(&sim),
    );
    // The camera's geometry does not matter here: no detections are fed.
    let geometry = rover_core::CameraGeometry {
        fx: 381.0,
        fy: 381.0,
        cx: 320.5,
        cy: 240.5,
        width_px: 640.0,
        height_px: 480.0,
        height_m: 0.18,
        forward_m: 0.15,
        left_m: 0.0,
        yaw_rad: 0.0,
        pitch_down_rad: 0.0,
    };
    let mut follower = rover_core::Follower::new(rover_core::FollowerConfig::default(), geometry)
        .with_laser(mount);
    sim.set_cmd_vel(Twist::new(0.3, 0.4))?;
    sensor.scan_now(&sim);
    let mut times = Vec::with_capacity(scans);
    let mut follower_times = Vec::with_capacity(scans);
    let mut window_times = Vec::with_capacity(scans);
    let mut points: Vec<[f64; 2]> = Vec::new();
    let avoid = rover_core::AvoidConfig::default();
    for _ in 0..scans.max(1) {
        for _ in 0..5 {
            if let Some(sample) = sim.step() {
                follower.record_pose(sample.sim_time_s, sample.odometry);
            }
        }
        let start = Instant::now();
        let scan = sensor.scan_now(&sim);
        times.push(start.elapsed().as_secs_f64() * 1e3);
        points.clear();
        points.extend(
            scan.points()
                .map(|[x, y]| [f64::from(x) + mount.x_m, f64::from(y) + mount.y_m]),
        );
        points.push([0.5, 0.0]);
        follower.observe_scan(scan);
        let start = Instant::now();
        let _ = follower.command(sim.sim_time_s(), sim.odometry(), true);
        follower_times.push(start.elapsed().as_secs_f64() * 1e6);
        let start = Instant::now();
        let out = avoid.choose(Twist::new(0.8, 0.0), [4.0, 0.0], &points, 0.8, 1.2, 0.0);
        window_times.push(start.elapsed().as_secs_f64() * 1e6);
        std::hint::black_box(out);
    }
    let best_ms = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(LaserBench {
        rays: sensor.config().samples,
        rate_hz: sensor.config().update_rate_hz,
        median_ms: median(&mut times),
        best_ms,
        follower_us: median(&mut follower_times),
        window_search_us: median(&mut window_times),
    })
}

/// IMU, p3d and GPS benchmark figures.
#[derive(Debug, Clone)]
pub struct SensorsBench {
    /// Each IMU: its name, readings timed, median wall time per reading (us).
    pub imus: Vec<(String, usize, f64)>,
    /// Each p3d: its name, readings timed, median wall time per reading (us).
    pub p3ds: Vec<(String, usize, f64)>,
    /// Each GPS: its name, fixes timed, median wall time per fix (us).
    pub gpss: Vec<(String, usize, f64)>,
    /// Each 3D lidar: its name, scans timed, median wall time per scan (ms), its rate (Hz).
    pub lidars: Vec<(String, usize, f64, f64)>,
}

/// The robot's IMUs, p3d publishers and GPS receivers, each timed per reading (the link's state, the frames,
/// the noise) over `steps` physics steps of the robot driving a circle; the physics step
/// itself is not timed.
pub fn sensors(config: &RunConfig, steps: usize) -> Result<SensorsBench> {
    let (world, robot) = config.load_world_and_robot()?;
    anyhow::ensure!(
        !robot.imus.is_empty()
            || !robot.p3ds.is_empty()
            || !robot.gpss.is_empty()
            || !robot.lidars.is_empty(),
        "{}: the robot has no IMU, p3d, GPS or 3D lidar; try --robot assets/robots/my_robot_laser.urdf.xacro or my_robot_vlp16.urdf.xacro",
        robot.source.display()
    );
    let mut sim = Simulation::new(world, robot, &config.options)?;
    let mut imus: Vec<_> = (0..sim.robot().imus.len())
        .filter_map(|i| rover_sim::sensors::ImuSensor::new(&sim, i))
        .collect();
    let mut p3ds: Vec<_> = (0..sim.robot().p3ds.len())
        .filter_map(|i| rover_sim::sensors::P3dSensor::new(&sim, i))
        .collect();
    let mut gpss: Vec<_> = (0..sim.robot().gpss.len())
        .filter_map(|i| rover_sim::sensors::GpsSensor::new(&sim, i))
        .collect();
    let mut lidars = (0..sim.robot().lidars.len())
        .map(|i| LidarSensor::new(&sim, i))
        .collect::<rover_sim::Result<Vec<_>>>()?;
    let mut lidar_times = vec![Vec::with_capacity(steps); lidars.len()];
    let mut gps_times = vec![Vec::with_capacity(steps); gpss.len()];
    let mut imu_times = vec![Vec::with_capacity(steps); imus.len()];
    let mut p3d_times = vec![Vec::with_capacity(steps); p3ds.len()];
    sim.set_cmd_vel(Twist::new(0.3, 0.4))?;
    for _ in 0..steps.max(1) {
        sim.step();
        for (imu, times) in imus.iter_mut().zip(&mut imu_times) {
            time_reading(times, || imu.update(&sim).is_some());
        }
        for (p3d, times) in p3ds.iter_mut().zip(&mut p3d_times) {
            time_reading(times, || p3d.update(&sim).is_some());
        }
        for (gps, times) in gpss.iter_mut().zip(&mut gps_times) {
            time_reading(times, || gps.update(&sim).is_some());
        }
        for (lidar, times) in lidars.iter_mut().zip(&mut lidar_times) {
            time_reading(times, || lidar.scan_if_due(&sim).is_some());
        }
    }
    let figures = |names: Vec<String>, times: Vec<Vec<f64>>| -> Vec<(String, usize, f64)> {
        names
            .into_iter()
            .zip(times)
            .map(|(name, mut t)| (name, t.len(), median(&mut t)))
            .collect()
    };
    Ok(SensorsBench {
        imus: figures(
            imus.iter().map(|i| i.config().name.clone()).collect(),
            imu_times,
        ),
        p3ds: figures(
            p3ds.iter().map(|p| p.config().name.clone()).collect(),
            p3d_times,
        ),
        gpss: figures(
            gpss.iter().map(|g| g.config().name.clone()).collect(),
            gps_times,
        ),
        lidars: lidars
            .iter()
            .zip(lidar_times)
            .map(|(l, mut t)| {
                let c = &l.config().rays;
                (
                    c.name.clone(),
                    t.len(),
                    median(&mut t) / 1e3,
                    c.update_rate_hz,
                )
            })
            .collect(),
    })
}

/// Times `update` (us) into `times` when it read something.
fn time_reading(times: &mut Vec<f64>, update: impl FnOnce() -> bool) {
    let start = Instant::now();
    let read = update();
    let us = start.elapsed().as_secs_f64() * 1e6;
    if read {
        times.push(us);
    }
}

pub(crate) fn bench_sensors(world: WorldArgs, steps: usize) -> Result<()> {
    let config = world.run_config(None);
    let b = sensors(&config, steps)?;
    for (kind, list) in [("IMU", &b.imus), ("p3d", &b.p3ds), ("GPS", &b.gpss)] {
        for (name, n, us) in list {
            say!(
                "sensors benchmark: {kind} {name}: median {us:.2} us per reading ({n} readings in {steps} physics steps)"
            );
        }
    }
    for (name, n, ms, rate_hz) in &b.lidars {
        say!(
            "sensors benchmark: lidar {name}: median {ms:.2} ms per scan ({n} scans in {steps} physics steps): {:.1}% of one core at {rate_hz} Hz",
            ms * rate_hz / 10.0
        );
    }
    Ok(())
}

pub(crate) fn bench_laser(world: WorldArgs, scans: usize) -> Result<()> {
    let config = world.run_config(None);
    let b = laser(&config, scans)?;
    say!(
        "laser benchmark: {} rays at {} Hz, {scans} scans: median {:.3} ms, best {:.3} ms per scan ({:.2}% of a core at {} Hz); follower command {:.1} us; avoidance window search (worst case, every return) {:.0} us",
        b.rays,
        b.rate_hz,
        b.median_ms,
        b.best_ms,
        b.median_ms * b.rate_hz / 10.0,
        b.rate_hz,
        b.follower_us,
        b.window_search_us
    );
    Ok(())
}

pub(crate) fn bench_camera(world: WorldArgs, frames: usize) -> Result<()> {
    let config = world.run_config(None);
    let b = camera(&config, frames)?;
    say!(
        "camera benchmark: {}x{} on {}, {frames} frames: median {:.2} ms, best {:.2} ms per frame (render + readback)",
        b.size.0,
        b.size.1,
        b.adapter,
        b.median_ms,
        b.best_ms
    );
    say!(
        "with ground truth ({} labelled things: id image, silhouettes, boxes): median {:.2} ms, +{:.2} ms",
        b.labelled,
        b.truth_median_ms,
        b.truth_median_ms - b.median_ms
    );
    say!(
        "with a depth image (the depth buffer read back as metres): median {:.2} ms, +{:.2} ms",
        b.depth_median_ms,
        b.depth_median_ms - b.median_ms
    );
    say!(
        "the depth image as an organized point cloud (x y z rgb, {}x{}): median {:.2} ms per frame",
        b.size.0,
        b.size.1,
        b.depth_cloud_median_ms
    );
    Ok(())
}
