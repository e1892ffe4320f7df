//! `rover` and `rover --headless`: a run in the window (the driver's station) or headless.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::Result;
use rover_core::{
    DetectorMode, Fanout, InputSource, RunConfig, RunFiles, Session, SessionOptions, run_headless,
    run_headless_driven, run_headless_observed,
};

use super::args::RunArgs;
use super::transports::Transports;
use crate::station::{self, WindowOptions};
use crate::viewer::{self, Recorder};

pub(crate) fn run(args: RunArgs) -> Result<()> {
    let stop = super::signals::stop_on_signals()?;
    run_until(args, stop)
}

/// A run that ends early when `stop` is set (the flag [`super::signals::stop_on_signals`]
/// gives).
pub(crate) fn run_until(args: RunArgs, stop: Arc<AtomicBool>) -> Result<()> {
    if !args.headless {
        return run_window(args, stop);
    }
    let config = RunConfig {
        stop: Some(Arc::clone(&stop)),
        script: args.script,
        duration_s: args.duration,
        trace: args.trace.clone(),
        progress_every: Some(Duration::from_secs(5)),
        save_frames: args.save_frames,
        frame_every: args.frame_every,
        perception: args.follow.perception(),
        detect_hz: Some(args.follow.detect_hz),
        serial_detection: args.follow.serial_detect,
        // Pipelined or serial detection waits for the detector at each result, so it gets the
        // core the loop thread leaves free.
        detector: args.detector.config(super::args::spare_detect_threads())?,
        inject_fault: args.detector.inject_fault,
        follower: args.follow.follower()?,
        arm: args.arm.arm(args.detector.threshold)?,
        ground_truth: args.follow.ground_truth,
        // ROS peers expect real time: --ros and --ros2 pace headless runs unless --rtf says
        // otherwise.
        real_time_factor: args.window.rtf.or(args.ros.any().then_some(1.0)),
        // ... and the detector keeps up on its own thread (newest frame), as in the window.
        detector_thread: args.ros.any(),
        ..args.world.run_config(args.cmd_timeout)
    };
    let recorder_options = args.viewer.options(false)?;
    if recorder_options.record.is_some()
        && recorder_options.footer
        && config.duration_s.is_some_and(|d| d > LONG_RECORDING_S)
    {
        tracing::info!(
            "a long recording: rerun keeps an index entry per chunk in memory until it writes the .rrd footer (~150 MB per sim hour of the walking world); --record-no-footer keeps memory flat"
        );
    }
    let mut recorder = Recorder::start(&recorder_options)?;
    if let Some(url) = recorder.as_ref().and_then(|r| r.web_url.as_ref()) {
        say!("Rerun web viewer: {url}");
    }
    let summary = if args.ros.bridges() {
        run_with_ros(&config, &args.ros, recorder.as_mut())
    } else {
        match recorder.as_mut() {
            Some(rec) => run_headless_observed(&config, rec, true),
            None => run_headless(&config),
        }
        .map_err(anyhow::Error::from)
    };
    let mut record_failed = None;
    if let Some(rec) = recorder.as_mut() {
        record_failed = rec.finish().err();
        if let Some(path) = &recorder_options.record {
            say!("recording: {}", viewer::describe_file(path));
        }
        if let (Some(url), Ok(_)) = (&rec.web_url, &summary) {
            say!("run finished; still serving the web viewer at {url} (Ctrl-C to quit)");
            while !stop.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(100));
            }
        }
    }
    let summary = summary?;
    say!(
        "rover: world \"{}\", robot \"{}\": {:.2} s sim time in {} physics steps, {:.3} s wall ({:.2}x real time)",
        summary.world,
        summary.robot,
        summary.sim_time_s,
        summary.steps,
        summary.wall_s,
        summary.real_time_factor()
    );
    if let Some(last) = summary.last {
        let g = last.ground_truth;
        let o = last.odometry;
        say!(
            "final pose: x {:.3} m, y {:.3} m, yaw {:.1} deg (odometry: x {:.3} m, y {:.3} m, yaw {:.1} deg); mode {}",
            g.x_m,
            g.y_m,
            g.yaw_rad.to_degrees(),
            o.x_m,
            o.y_m,
            o.yaw_rad.to_degrees(),
            summary.mode.as_str()
        );
    }
    if let Some(path) = &args.trace {
        say!("trace: {} ({} rows)", path.display(), summary.rows);
    }
    end_of_run(
        record_failed,
        recorder_options.record.as_deref(),
        summary.interrupted,
        summary.sim_time_s,
    )
}

/// A headless run with the ROS 1 and/or ROS 2 bridge (and the recorder, when there is one).
fn run_with_ros(
    config: &RunConfig,
    ros: &super::args::RosArgs,
    recorder: Option<&mut Recorder>,
) -> Result<rover_core::RunSummary> {
    let (world, robot) = config.load_world_and_robot()?;
    let mut transports = Transports::start(ros, &robot, config.ground_truth)?;
    let result = {
        let mut fan = Fanout::default();
        let mut inputs = transports.attach(&mut fan);
        fan.push_some(recorder);
        run_headless_driven(config, world, robot, &mut fan, true, &mut inputs)
    };
    let finished = transports.finish();
    let summary = result?;
    finished?;
    Ok(summary)
}

/// Sim seconds from which a recording with a footer gets the memory hint.
const LONG_RECORDING_S: f64 = 1800.0;

/// How a run ends once its files are written: a recording that could not be written in full
/// (the file sink stopped: disk full, file removed) is an error; a run ended by a signal says
/// so and exits with 130 ([`super::signals::Interrupted`]).
fn end_of_run(
    record_failed: Option<String>,
    record: Option<&std::path::Path>,
    interrupted: bool,
    sim_time_s: f64,
) -> Result<()> {
    match (record_failed, record) {
        (Some(e), Some(path)) => anyhow::bail!(
            "the recording {} was not written in full ({e}; rerun's warning above says why, \
             e.g. no space left on device): it holds the run up to that point without the \
             .rrd footer — the viewer opens it, `rerun rrd verify --check-footers false` checks it",
            path.display()
        ),
        (Some(e), None) => tracing::warn!("rerun: could not flush everything: {e}"),
        _ => {}
    }
    if interrupted {
        say!(
            "interrupted by a signal at {sim_time_s:.2} s sim time: the trace and recording end there, complete"
        );
        return Err(super::signals::Interrupted.into());
    }
    Ok(())
}

fn run_window(args: RunArgs, stop: Arc<AtomicBool>) -> Result<()> {
    station::check_display()?;
    let rtf = args.window.rtf.unwrap_or(1.0);
    anyhow::ensure!(
        rtf.is_finite() && rtf > 0.0,
        "--rtf must be a positive factor, found {rtf}"
    );
    let config = RunConfig {
        script: args.script.clone(),
        ..args.world.run_config(args.cmd_timeout)
    };
    let (world, robot) = config.load_world_and_robot()?;
    let script = config.load_script()?;
    let recorder_options = args.viewer.options(true)?;
    let mut recorder = match Recorder::start(&recorder_options) {
        Ok(r) => r,
        Err(e) => {
            tracing::warn!("{e:#}; going on without a viewer");
            None
        }
    };
    if let Some(url) = recorder.as_ref().and_then(|r| r.web_url.clone()) {
        say!("Rerun web viewer: {url}");
    }
    let mut files = RunFiles::open(
        args.trace.as_deref(),
        args.save_frames.as_deref(),
        args.frame_every,
        args.follow.ground_truth,
    )?;
    let options = SessionOptions {
        sim: config.options.clone(),
        camera: true,
        // The window shows every image.
        every_frame: true,
        detector: if args.follow.no_detector {
            DetectorMode::Off
        } else {
            DetectorMode::Worker
        },
        // Measured under Xvfb on 2 vCPU: two threads raise the detector from 12 to 14-15 Hz
        // and the loop stays at 1.00x real time.
        detector_config: args.detector.config(super::args::spare_detect_threads())?,
        inject_fault: args.detector.inject_fault,
        follower: args.follow.follower()?,
        arm: args.arm.arm(args.detector.threshold)?,
        ground_truth: args.follow.ground_truth,
    };
    let mut transports = Transports::start(&args.ros, &robot, args.follow.ground_truth)?;
    let summary = {
        let mut fan = Fanout::default();
        fan.push(&mut files);
        fan.push_some(recorder.as_mut());
        let mut all = transports.attach(&mut fan);
        let inputs: &mut dyn InputSource = &mut all;
        let session = Session::new(world, robot, &options, &mut fan)?;
        station::run(
            session,
            &mut fan,
            inputs,
            WindowOptions {
                real_time_factor: rtf,
                latched: args.window.latched,
                wasd: args.window.wasd,
                duration_s: args.duration,
                paused: args.window.paused,
                script,
                screenshot: args.window.screenshot.clone(),
                stop: Some(stop),
            },
        )?
    };
    let record_failed = recorder.as_mut().and_then(|r| r.finish().err());
    transports.finish()?;
    say!(
        "rover: {:.1} s sim time in {:.1} s wall; mode {}",
        summary.sim_time_s,
        summary.wall_s,
        summary.mode.as_str()
    );
    let written = files.finish()?;
    if let Some(path) = &args.trace {
        say!("trace: {} ({} rows)", path.display(), written.rows);
    }
    if let Some(path) = &recorder_options.record {
        say!("recording: {}", viewer::describe_file(path));
    }
    end_of_run(
        record_failed,
        recorder_options.record.as_deref(),
        summary.interrupted,
        summary.sim_time_s,
    )
}
