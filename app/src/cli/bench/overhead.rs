//! What the loop's optional outputs cost a headless run: recording (`rover bench record`) and
//! the ROS bridge (`rover bench ros`).

use std::time::Instant;

use anyhow::Result;
use rover_core::{Perception, RunConfig, run_headless, run_headless_driven, run_headless_observed};

use crate::cli::args::WorldArgs;
use crate::viewer::{ImageOptions, Recorder, RecorderOptions, Viewer};

/// Recording overhead: the same headless run (camera and lockstep detector on) without and
/// with `--record`.
#[derive(Debug, Clone)]
pub struct RecordBench {
    /// Wall seconds without recording (best of the repeats).
    pub plain_s: f64,
    /// Wall seconds with recording to an .rrd file (best of the repeats).
    pub recorded_s: f64,
    /// Size of the recording (bytes).
    pub rrd_bytes: u64,
}

impl RecordBench {
    /// recorded / plain.
    pub fn ratio(&self) -> f64 {
        self.recorded_s / self.plain_s
    }
}

/// Runs `config` `repeats` times each without and with a recorder writing into `dir`.
pub fn record(
    config: &RunConfig,
    images: ImageOptions,
    repeats: u32,
    dir: &std::path::Path,
) -> Result<RecordBench> {
    let config = RunConfig {
        perception: Perception::On,
        ..config.clone()
    };
    let mut plain = f64::INFINITY;
    let mut recorded = f64::INFINITY;
    let mut rrd_bytes = 0;
    for i in 0..repeats.max(1) {
        let started = Instant::now();
        run_headless(&config)?;
        plain = plain.min(started.elapsed().as_secs_f64());
        let path = dir.join(format!("bench-{i}.rrd"));
        let started = Instant::now();
        let options = RecorderOptions {
            viewer: Viewer::Save(path.clone()),
            images,
            ..RecorderOptions::default()
        };
        let mut rec = Recorder::start(&options)?
            .ok_or_else(|| anyhow::anyhow!("the recorder did not start"))?;
        run_headless_observed(&config, &mut rec, true)?;
        if let Err(e) = rec.finish() {
            tracing::warn!("the recording was not written in full: {e}");
        }
        drop(rec);
        recorded = recorded.min(started.elapsed().as_secs_f64());
        rrd_bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        let _ = std::fs::remove_file(&path);
    }
    Ok(RecordBench {
        plain_s: plain,
        recorded_s: recorded,
        rrd_bytes,
    })
}

pub(crate) fn bench_record(
    world: WorldArgs,
    duration: f64,
    repeats: u32,
    jpeg: Option<u8>,
) -> Result<()> {
    let config = RunConfig {
        duration_s: Some(duration),
        ..world.run_config(None)
    };
    let dir = std::env::temp_dir().join(format!("rover-bench-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    say!(
        "recording overhead: {duration} sim s headless, camera + lockstep detector on, best of {repeats}"
    );
    let b = record(
        &config,
        ImageOptions {
            jpeg_quality: jpeg,
            ..ImageOptions::default()
        },
        repeats,
        &dir,
    );
    let _ = std::fs::remove_dir_all(&dir);
    let b = b?;
    say!("without --record: {:.2} s wall", b.plain_s);
    say!(
        "with --record:    {:.2} s wall ({:.1} MB .rrd)",
        b.recorded_s,
        b.rrd_bytes as f64 / 1e6
    );
    say!("ratio: {:.2}x (goal <= 1.3x)", b.ratio());
    Ok(())
}

/// What the ROS bridge costs the loop.
#[derive(Debug, Clone, Copy)]
pub struct RosBench {
    /// Wall seconds without the bridge (best of the repeats).
    pub plain_s: f64,
    /// Wall seconds with the bridge and its subscribers (best of the repeats).
    pub bridged_s: f64,
    /// Messages the subscribers received in the fastest bridged run, per topic (image, /odom,
    /// /tf).
    pub received: [u64; 3],
    /// Wall seconds the bridge itself spent on the loop thread in that run.
    pub bridge_loop_s: f64,
}

/// The same headless run (camera + lockstep detector, unpaced) without and with the ROS
/// bridge, while an in-process node subscribes to the camera image, /odom and /tf (raw bytes,
/// like `rostopic hz`).
pub fn ros(config: &RunConfig, repeats: u32) -> Result<RosBench> {
    use rover_ros1::{Node, NodeOptions};
    let master = NodeOptions::from_env("rover_bench")?;
    rover_ros1::ros_call(
        &master.master_uri,
        "getPid",
        &[rover_ros1::Value::from("/rover_bench")],
        std::time::Duration::from_secs(2),
    )
    .map_err(|e| {
        anyhow::anyhow!(
            "no ROS master at {} ({e}): start roscore (or `rosmaster --core`) first",
            master.master_uri
        )
    })?;
    let config = RunConfig {
        perception: Perception::On,
        real_time_factor: None,
        ..config.clone()
    };
    let (world, robot) = config.load_world_and_robot()?;
    let plan = crate::ros::RosPlan::for_robot(&robot);
    let image_topic = plan
        .image_topic
        .clone()
        .ok_or_else(|| anyhow::anyhow!("the robot has no camera"))?;
    let listener = Node::start(master)?;
    let mut subs = vec![
        listener.subscribe_raw(&image_topic, "sensor_msgs/Image", 4)?,
        listener.subscribe_raw(&plan.odom_topic, "nav_msgs/Odometry", 1000)?,
        listener.subscribe_raw("/tf", "tf2_msgs/TFMessage", 1000)?,
    ];
    let options = crate::ros::RosOptions {
        name: "rover".into(),
        sim_time: false,
        ground_truth: false,
    };
    let mut plain = f64::INFINITY;
    let mut bridged = f64::INFINITY;
    let mut received = [0; 3];
    let mut bridge_loop_s = 0.0;
    for _ in 0..repeats.max(1) {
        let started = Instant::now();
        run_headless(&config)?;
        plain = plain.min(started.elapsed().as_secs_f64());

        let (mut bridge, mut cmd_vel) = crate::ros::RosBridge::start(&options, &robot)?;
        // The subscribers connect before the clock starts.
        let wait = Instant::now();
        while !listener.is_registered() && wait.elapsed().as_secs_f64() < 10.0 {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        std::thread::sleep(std::time::Duration::from_secs(2));
        for s in &subs {
            while s.try_recv().is_some() {}
        }
        let counting = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
        let flag = counting.clone();
        let owned = std::mem::take(&mut subs);
        let counter = std::thread::spawn(move || {
            let mut n = [0u64; 3];
            while flag.load(std::sync::atomic::Ordering::Relaxed) {
                let mut any = false;
                for (i, s) in owned.iter().enumerate() {
                    while s.try_recv().is_some() {
                        n[i] += 1;
                        any = true;
                    }
                }
                if !any {
                    std::thread::sleep(std::time::Duration::from_millis(2));
                }
            }
            (n, owned)
        });
        let started = Instant::now();
        let run = run_headless_driven(
            &config,
            world.clone(),
            robot.clone(),
            &mut bridge,
            true,
            &mut cmd_vel,
        );
        let wall = started.elapsed().as_secs_f64();
        bridge.finish();
        std::thread::sleep(std::time::Duration::from_millis(500));
        counting.store(false, std::sync::atomic::Ordering::Relaxed);
        let (n, owned) = counter
            .join()
            .map_err(|_| anyhow::anyhow!("the counting thread panicked"))?;
        subs = owned;
        run?;
        if wall < bridged {
            bridged = wall;
            received = n;
            bridge_loop_s = bridge.loop_time().as_secs_f64();
        }
    }
    Ok(RosBench {
        plain_s: plain,
        bridged_s: bridged,
        received,
        bridge_loop_s,
    })
}

pub(crate) fn bench_ros(world: WorldArgs, duration: f64, repeats: u32) -> Result<()> {
    let config = RunConfig {
        duration_s: Some(duration),
        ..world.run_config(None)
    };
    say!(
        "ROS bridge cost: {duration} sim s headless, camera + lockstep detector on, unpaced, best of {repeats}"
    );
    let b = ros(&config, repeats)?;
    say!("without --ros: {:.2} s wall", b.plain_s);
    say!(
        "with --ros and 3 subscribers: {:.2} s wall (received {} images, {} odom, {} tf)",
        b.bridged_s,
        b.received[0],
        b.received[1],
        b.received[2]
    );
    say!(
        "ratio: {:.3}x; {:+.2} ms per sim second",
        b.bridged_s / b.plain_s,
        (b.bridged_s - b.plain_s) * 1e3 / duration
    );
    say!(
        "the bridge on the loop thread: {:.2} ms per sim second ({:.3}% of real time)",
        b.bridge_loop_s * 1e3 / duration,
        b.bridge_loop_s * 100.0 / duration
    );
    Ok(())
}
