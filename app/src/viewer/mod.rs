//! The Rerun recorder: an [`Observer`] that streams a run to a Rerun viewer and/or an .rrd file.
//! It only watches the loop; nothing in the simulation depends on it.
//!
//! * [`sinks`] — viewer modes, `--record` files, the web viewer server, the viewer-gone watch;
//! * [`scene`] — the static scene logged once;
//! * this module — per-tick logging (poses, plots, boxes, events);
//! * [`images`] — camera images (rate, downscale, JPEG);
//! * [`blueprint`] — the layout the viewer opens with.
//!
//! Entity paths (docs/RERUN.md):
//! ```text
//! world                                  ViewCoordinates RIGHT_HAND_Z_UP (REP-103), static
//! world/ground, world/objects/<name>     Mesh3D, static
//! world/people/<name>                    Transform3D (per control update when walking) + Mesh3D
//! world/people/<name>/limb<k>            a walking person's legs and arms: Transform3D per update
//! world/robot                            Transform3D world_from_base, per control update
//! world/robot/<link>                     Transform3D base_from_link (wheels turn) + Mesh3D visuals
//! world/robot/camera                     Transform3D base_from_camera_optical, static
//! world/robot/camera/image               Pinhole (Gazebo's K), Image, AnnotationContext
//! world/robot/camera/image/detections    Boxes2D "person 0.87" with class ids
//! world/robot/camera/image/depth         DepthImage (metres) of a <sensor type="depth">
//! world/robot/camera/image/ground_truth  Boxes2D (with --ground-truth): each labelled thing's
//!                                        visible box, "person (truth)" or "MISSED person";
//!                                        ignore regions under .../ground_truth/ignore
//! world/robot/camera/image/false_positives  Boxes2D: detections that found nothing
//! plots/detector/<class>/{precision,recall,iou}  Scalars: running, IoU 0.5 (--ground-truth)
//! world/odometry                         Points3D (odometry position) + trail LineStrips3D
//! world/odometry/follower/{target,goal}  Points3D: the follower's target estimate, the point it
//!                                        drives to (the pursued point once the target is lost)
//! plots/joints/<joint>                   Scalars: an actuated joint's position and target
//! plots/imu/<sensor>/{angular_velocity,linear_acceleration}  Scalars x, y, z: each IMU's
//!                                        readings (rad/s; m/s^2, gravity included)
//! world/p3d/<plugin>                     Points3D: a world-frame p3d's ground-truth position
//! plots/gps/<plugin>/{latitude,longitude,altitude}  Scalars: each GPS fix (deg, deg, m)
//! plots/bumper/<sensor>/contacts         Scalars: how many collisions each bumper touches
//! world/clouds/<sensor>                  Points3D: each 3D lidar's cloud, coloured by height
//! world/clouds/depth                     Points3D: the depth camera's cloud, in its colours
//! plots/...                              Scalars: cmd/measured velocity, wheel speeds, mode,
//!                                        detector latency/Hz/dropped, real-time factor
//! log                                    TextLog: mode changes, warnings
//! ```
//! Timelines: `sim_time` (seconds of simulated time) and `frame` (camera frame number).

mod blueprint;
mod clouds;
mod images;
mod scene;
mod sinks;

use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rerun::{RecordingStream, RecordingStreamBuilder};
use rover_core::{EventLevel, LiveJudge, LoopStats, Mode, Observer};
use rover_perception::BoundingBoxes;
use rover_sim::{
    geometry::Pose,
    model::CameraInfo,
    physics::{ControlSample, Simulation},
    sensors::{
        CameraFrame, ContactsReading, FixReading, GroundTruthBox, ImuReading, LaserScan,
        PointCloud, PoseReading,
    },
};

pub use blueprint::blueprint;
pub use images::ImageOptions;
pub use sinks::{
    RERUN_VERSION, RecorderOptions, Viewer, default_viewer, describe_file, pip_command,
    viewer_on_path,
};

use images::ImageLogger;
use scene::{ScenePaths, transform};
use sinks::ViewerWatch;

/// Detections as Rerun boxes on an image shown at 1/`scale` of its size.
fn detection_boxes<'a>(
    boxes: impl Iterator<Item = &'a rover_perception::BoundingBox> + Clone,
    scale: f32,
) -> rerun::Boxes2D {
    rerun::Boxes2D::from_mins_and_sizes(
        boxes
            .clone()
            .map(|b| [b.xmin as f32 / scale, b.ymin as f32 / scale]),
        boxes.map(|b| [b.width() as f32 / scale, b.height() as f32 / scale]),
    )
}

/// How often a walking person's skinned body is re-posed and logged for a live viewer (s of sim
/// time): 10 Hz, smooth enough to watch, a fraction of the control rate's data.
const BODY_LOG_PERIOD_S: f64 = 0.1;
/// ... and for a recording no live viewer watches: once a second. A MakeHuman body is about
/// 10k vertices with their normals, 245 kB a pose: at 10 Hz it was 95 % of a recording (9.3 GB
/// per sim hour of the walking world); the person's place and heading are still logged at
/// every control update.
const FILE_BODY_LOG_PERIOD_S: f64 = 1.0;

/// The Rerun recorder.
pub struct Recorder {
    rec: RecordingStream,
    images: ImageLogger,
    frame: i64,
    trail: Vec<[f32; 3]>,
    trail_logged_s: f64,
    /// When the moving skinned bodies were last re-posed and logged (sim s).
    bodies_logged_s: f64,
    /// How often they are (s of sim time): [`BODY_LOG_PERIOD_S`] with a live viewer, else
    /// [`FILE_BODY_LOG_PERIOD_S`].
    body_period_s: f64,
    paths: ScenePaths,
    /// Reused buffer for SDF model link poses.
    model_poses: Vec<Pose>,
    /// Entity path of the laser's scan and the sensor's pose in its link.
    laser: Option<(String, Pose)>,
    /// Scan points in the link frame (reused).
    scan_points: Vec<[f32; 3]>,
    /// Each IMU's plot paths: angular velocity, linear acceleration.
    imu_paths: Vec<[String; 2]>,
    /// Each p3d's entity path (`None`: measured against a link, not drawn in the world).
    p3d_paths: Vec<Option<String>>,
    /// Each GPS's plot paths: latitude, longitude, altitude.
    gps_paths: Vec<[String; 3]>,
    /// The point clouds' paths and points.
    clouds: clouds::Clouds,
    /// Each bumper's plot path (how many collisions it touches).
    bumper_paths: Vec<String>,
    watch: Option<ViewerWatch>,
    viewer_gone: bool,
    started: Instant,
    /// Where the web viewer is, when serving it.
    pub web_url: Option<String>,
    _web: Option<Box<dyn std::any::Any>>,
    /// The detector's class names (ground truth boxes take their class ids from them).
    labels: Vec<String>,
    /// Detections against ground truth, running (with `--ground-truth`).
    judge: LiveJudge,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("web_url", &self.web_url)
            .finish_non_exhaustive()
    }
}

/// Batching for recordings no live viewer watches (see [`Recorder::start`]).
const FILE_BATCHING: rerun::log::ChunkBatcherConfig = rerun::log::ChunkBatcherConfig {
    flush_tick: Duration::from_secs(2),
    flush_num_bytes: 16 << 20,
    ..rerun::log::ChunkBatcherConfig::DEFAULT
};

impl Recorder {
    /// Opens the viewer/file sinks. Returns `Ok(None)` when there is nothing to record to.
    pub fn start(options: &RecorderOptions) -> Result<Option<Self>> {
        let Some(sinks) = sinks::open(options)? else {
            return Ok(None);
        };
        // A live viewer wants data at once; a file alone gets larger, fewer chunks: rerun
        // keeps an index entry per chunk in memory until it writes the .rrd footer, so chunk
        // count is what a long recording's memory grows with.
        let live = sinks.watch.is_some() || sinks.web_url.is_some();
        let rec = RecordingStreamBuilder::new("rover")
            .batcher_config(if live {
                rerun::log::ChunkBatcherConfig::LOW_LATENCY
            } else {
                FILE_BATCHING
            })
            .with_blueprint(blueprint())
            .set_sinks(sinks.sinks)
            .context("cannot start the Rerun recording")?;
        rec.set_log_time_enabled(false);
        Ok(Some(Self {
            rec,
            images: ImageLogger::new(options.images),
            frame: 0,
            trail: Vec::with_capacity(4096),
            trail_logged_s: f64::NEG_INFINITY,
            bodies_logged_s: f64::NEG_INFINITY,
            body_period_s: if live {
                BODY_LOG_PERIOD_S
            } else {
                FILE_BODY_LOG_PERIOD_S
            },
            model_poses: Vec::new(),
            laser: None,
            scan_points: Vec::new(),
            imu_paths: Vec::new(),
            p3d_paths: Vec::new(),
            gps_paths: Vec::new(),
            clouds: clouds::Clouds::default(),
            bumper_paths: Vec::new(),
            paths: ScenePaths::default(),
            watch: sinks.watch,
            viewer_gone: false,
            started: Instant::now(),
            labels: Vec::new(),
            judge: LiveJudge::default(),
            web_url: sinks.web_url,
            _web: sinks.web_server,
        }))
    }

    fn log(&self, path: &str, data: &dyn rerun::AsComponents) {
        if let Err(e) = self.rec.log(path, data) {
            tracing::warn!("rerun: {path}: {e}");
        }
    }

    /// Re-poses and logs the walking people's skinned bodies, every `body_period_s`.
    fn log_bodies(&mut self, sim: &Simulation, sim_time_s: f64) {
        if sim_time_s - self.bodies_logged_s < self.body_period_s {
            return;
        }
        self.bodies_logged_s = sim_time_s;
        for (i, path, body) in &mut self.paths.bodies {
            let person = &sim.world().people[*i];
            body.pose(sim.person_gait_phase_rad(*i), person.stride_m());
            let mesh = rerun::Mesh3D::update_fields()
                .with_vertex_positions(body.positions().iter().map(|p| p.to_array()))
                .with_vertex_normals(body.normals().iter().map(|n| n.to_array()));
            if let Err(e) = self.rec.log(path.as_str(), &mesh) {
                tracing::warn!("rerun: {path}: {e}");
            }
        }
    }

    fn set_time(&self, sim_time_s: f64) {
        self.rec.set_duration_secs("sim_time", sim_time_s);
        self.rec.set_time_sequence("frame", self.frame);
    }

    /// Notices (once) that a streamed-to viewer has gone; the run goes on. The probing runs
    /// on the watch's own thread: here it is one atomic load.
    fn watch_viewer(&mut self) {
        if !self.viewer_gone && self.watch.as_ref().is_some_and(ViewerWatch::gone) {
            self.viewer_gone = true;
            tracing::warn!(
                "the Rerun viewer has gone away; the run goes on (a --record file keeps recording)"
            );
        }
    }

    /// Flushes the recording and closes its files (writes the .rrd footer); a web viewer
    /// server keeps serving until the recorder is dropped. `Err` says why not everything was
    /// written (a full disk, a viewer that stopped reading).
    pub fn finish(&mut self) -> std::result::Result<(), String> {
        let flushed = self.rec.flush_with_timeout(Duration::from_secs(5));
        self.rec.finalize_deferred_sinks();
        tracing::debug!("recorder ran {:.1} s", self.started.elapsed().as_secs_f64());
        match flushed {
            Err(e) if !self.viewer_gone => Err(e.to_string()),
            _ => Ok(()),
        }
    }

    /// Appends the odometry position to the trail, keeping it bounded.
    fn extend_trail(&mut self, here: [f32; 3]) {
        if self.trail.last() == Some(&here) {
            return;
        }
        if self.trail.len() == self.trail.capacity() {
            // Drop every other point of the older half.
            let half = self.trail.len() / 2;
            let mut k = 0;
            for j in 0..self.trail.len() {
                if j >= half || j % 2 == 0 {
                    self.trail[k] = self.trail[j];
                    k += 1;
                }
            }
            self.trail.truncate(k);
        }
        self.trail.push(here);
    }
}

impl Observer for Recorder {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        self.labels = labels.to_vec();
        self.paths = scene::log_scene(&self.rec, sim, camera, labels, self.images.options());
        self.laser = sim.robot().lasers.first().and_then(|l| {
            let link = sim.robot().link_id(&l.link)?;
            let path = self.paths.links.get(link.index())?;
            Some((format!("{path}/scan"), l.link_from_sensor))
        });
        self.imu_paths = sim
            .robot()
            .imus
            .iter()
            .map(|i| {
                ["angular_velocity", "linear_acceleration"]
                    .map(|what| format!("plots/imu/{}/{what}", i.name))
            })
            .collect();
        self.p3d_paths = sim
            .robot()
            .p3ds
            .iter()
            .map(|p| {
                p.reference_link
                    .is_none()
                    .then(|| format!("world/p3d/{}", p.name))
            })
            .collect();
        self.gps_paths = sim
            .robot()
            .gpss
            .iter()
            .map(|g| {
                ["latitude", "longitude", "altitude"]
                    .map(|what| format!("plots/gps/{}/{what}", g.name))
            })
            .collect();
        self.clouds.start(sim);
        self.bumper_paths = (sim.robot().bumpers.iter())
            .map(|b| format!("plots/bumper/{}/contacts", b.name))
            .collect();
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        self.watch_viewer();
        self.set_time(sample.sim_time_s);
        self.log("world/robot", &transform(sim.world_from_base()));
        let base_from_world = sim.world_from_base().inverse();
        for ((id, _), path) in sim.robot().link_ids().zip(&self.paths.links) {
            if id != sim.robot().root {
                self.log(path, &transform(base_from_world * sim.world_from_link(id)));
            }
        }
        if !self.paths.moving_model_links.is_empty() {
            sim.model_link_poses_into(&mut self.model_poses);
            for (i, path) in &self.paths.moving_model_links {
                if let Some(pose) = self.model_poses.get(*i) {
                    self.log(path, &transform(*pose));
                }
            }
        }
        for (i, path) in self.paths.people.iter().enumerate() {
            if sim.world().people[i].moves() {
                self.log(path, &transform(sim.world_from_person(i)));
            }
        }
        self.log_bodies(sim, sample.sim_time_s);
        for (i, path, swing, standing) in &self.paths.limbs {
            let phase_rad = sim.person_gait_phase_rad(*i);
            self.log(path, &transform(swing.pose_at(*standing, phase_rad)));
        }
        let o = sample.odometry;
        let here = [o.x_m as f32, o.y_m as f32, 0.02];
        self.log(
            "world/odometry",
            &rerun::Points3D::new([here]).with_radii([0.04f32]),
        );
        self.extend_trail(here);
        if sample.sim_time_s - self.trail_logged_s >= 0.5 {
            self.trail_logged_s = sample.sim_time_s;
            self.log(
                "world/odometry/trail",
                &rerun::LineStrips3D::new([self.trail.as_slice()]).with_radii([0.01f32]),
            );
        }
        for (id, path) in &self.paths.joints {
            if let (Some(state), Some(target)) = (sim.joint_state(*id), sim.joint_setpoint(*id)) {
                self.log(path, &rerun::Scalars::new([state.position, target]));
            }
        }
        let gt = sample.ground_truth;
        self.log(
            "plots/velocity/linear",
            &rerun::Scalars::new([sample.cmd.linear_mps, gt.linear_mps]),
        );
        self.log(
            "plots/velocity/angular",
            &rerun::Scalars::new([sample.cmd.angular_radps, gt.angular_radps]),
        );
        let t = sample.wheel_targets_radps;
        let m = sample.wheel_measured_radps;
        self.log(
            "plots/wheels",
            &rerun::Scalars::new([t[0], t[1], m[0], m[1]]),
        );
        self.log(
            "plots/mode",
            &rerun::Scalars::single(if stats.mode == Mode::Follow { 1.0 } else { 0.0 }),
        );
        if stats.mode == Mode::Follow {
            self.log(
                "plots/follower/state",
                &rerun::Scalars::single(stats.follow_state.index() as f64),
            );
            // The target estimate and the point driven to (the pursued point once lost), in
            // the odometry frame like the odometry itself; none logged = cleared.
            let point = |p: Option<[f64; 2]>| p.map(|[x, y]| [x as f32, y as f32, 0.05]);
            self.log(
                "world/odometry/follower/target",
                &rerun::Points3D::new(point(stats.follow_target_m))
                    .with_radii([0.08f32])
                    .with_colors([rerun::Color::from_rgb(255, 170, 60)]),
            );
            self.log(
                "world/odometry/follower/goal",
                &rerun::Points3D::new(point(stats.follow_goal_m))
                    .with_radii([0.06f32])
                    .with_colors([rerun::Color::from_rgb(90, 200, 255)])
                    .with_labels([stats.follow_state.as_str()]),
            );
        }
        self.log_arm(&stats.arm);
        if stats.detector_ok {
            self.log(
                "plots/detector/latency_ms",
                &rerun::Scalars::single(stats.detector_latency_ms),
            );
            self.log(
                "plots/detector/hz",
                &rerun::Scalars::single(stats.detector_hz),
            );
            self.log(
                "plots/detector/dropped",
                &rerun::Scalars::single(stats.frames_dropped as f64),
            );
        }
        let wall = self.started.elapsed().as_secs_f64();
        if wall > 0.5 {
            self.log(
                "plots/real_time_factor",
                &rerun::Scalars::single(sample.sim_time_s / wall),
            );
        }
    }

    fn camera_frame(&mut self, frame: &CameraFrame<'_>, _world_from_camera: Pose) {
        self.frame = frame.seq as i64;
        if self.images.due(frame.sim_time_s) {
            self.set_time(frame.sim_time_s);
            self.images.log(&self.rec, frame);
        }
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        let stamp = boxes.image_stamp;
        self.rec.set_duration_secs("sim_time", stamp.sim_time_s);
        self.rec.set_time_sequence("frame", stamp.frame as i64);
        let k = self.images.options().scale();
        let b = &boxes.bounding_boxes;
        let data = detection_boxes(b.iter(), k)
            .with_labels(
                b.iter()
                    .map(|b| format!("{} {:.2}", b.class, b.probability)),
            )
            .with_class_ids(b.iter().map(|b| u16::try_from(b.id).unwrap_or(u16::MAX)));
        self.log("world/robot/camera/image/detections", &data);
        self.set_time(stamp.sim_time_s);
    }

    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        let stamp = boxes.image_stamp;
        self.rec.set_duration_secs("sim_time", stamp.sim_time_s);
        self.rec.set_time_sequence("frame", stamp.frame as i64);
        let k = self.images.options().scale();
        let matched = self.judge.judge(boxes, truth).clone();
        let class_id = |class: &str| {
            self.labels
                .iter()
                .position(|l| l == class)
                .and_then(|i| u16::try_from(i).ok())
                .unwrap_or(u16::MAX)
        };
        let scaled = |b: rover_sim::sensors::PixelBox| {
            (
                [b.xmin as f32 / k, b.ymin as f32 / k],
                [b.width() as f32 / k, b.height() as f32 / k],
            )
        };
        let (shown, ignored): (Vec<(usize, &GroundTruthBox)>, Vec<_>) = truth
            .iter()
            .enumerate()
            .filter(|(_, t)| t.visible.is_some())
            .partition(|(_, t)| !t.ignore);
        let gt = rerun::Boxes2D::from_mins_and_sizes(
            shown
                .iter()
                .filter_map(|(_, t)| t.visible.map(|b| scaled(b).0)),
            shown
                .iter()
                .filter_map(|(_, t)| t.visible.map(|b| scaled(b).1)),
        )
        .with_labels(shown.iter().map(|(i, t)| {
            if matched.misses.contains(i) {
                format!("MISSED {}", t.class)
            } else {
                format!("{} (truth)", t.class)
            }
        }))
        .with_class_ids(shown.iter().map(|(_, t)| class_id(&t.class)))
        .with_radii([0.5f32]);
        self.log("world/robot/camera/image/ground_truth", &gt);
        let ignore = rerun::Boxes2D::from_mins_and_sizes(
            ignored
                .iter()
                .filter_map(|(_, t)| t.visible.map(|b| scaled(b).0)),
            ignored
                .iter()
                .filter_map(|(_, t)| t.visible.map(|b| scaled(b).1)),
        )
        .with_labels(ignored.iter().map(|(_, t)| format!("ignore: {}", t.class)))
        .with_colors([rerun::Color::from_rgb(128, 128, 128)]);
        self.log("world/robot/camera/image/ground_truth/ignore", &ignore);
        let b = &boxes.bounding_boxes;
        let fp: Vec<_> = matched
            .false_positives
            .iter()
            .filter_map(|&i| b.get(i))
            .collect();
        let false_positives = detection_boxes(fp.iter().copied(), k)
            .with_labels(
                fp.iter()
                    .map(|b| format!("FALSE {} {:.2}", b.class, b.probability)),
            )
            .with_colors([rerun::Color::from_rgb(255, 0, 255)]);
        self.log("world/robot/camera/image/false_positives", &false_positives);
        for (class, tally) in self.judge.tallies() {
            for (what, value) in [
                ("precision", tally.precision()),
                ("recall", tally.recall()),
                ("iou", tally.mean_iou()),
            ] {
                if let Some(v) = value {
                    self.log(
                        &format!("plots/detector/{class}/{what}"),
                        &rerun::Scalars::single(v),
                    );
                }
            }
        }
        self.set_time(stamp.sim_time_s);
    }

    fn laser_scan(&mut self, scan: &LaserScan, _world_from_laser: Pose) {
        let Some(link_from_sensor) = self.laser.as_ref().map(|l| l.1) else {
            return;
        };
        self.scan_points.clear();
        for [x, y] in scan.points() {
            let p = link_from_sensor.transform_point(glam::Vec3::new(x, y, 0.0));
            self.scan_points.push([p.x, p.y, p.z]);
        }
        self.rec.set_duration_secs("sim_time", scan.stamp_s);
        let points = rerun::Points3D::new(self.scan_points.iter().copied())
            .with_radii([0.015f32])
            .with_colors([rerun::Color::from_rgb(230, 40, 40)]);
        if let Some((path, _)) = &self.laser {
            self.log(path, &points);
        }
    }

    fn imu(&mut self, reading: &ImuReading) {
        let Some([angular, linear]) = self.imu_paths.get(reading.sensor) else {
            return;
        };
        self.rec.set_duration_secs("sim_time", reading.stamp_s);
        let angular_velocity = rerun::Scalars::new(reading.angular_velocity_radps);
        let linear_acceleration = rerun::Scalars::new(reading.linear_acceleration_mps2);
        self.log(angular, &angular_velocity);
        self.log(linear, &linear_acceleration);
    }

    fn p3d(&mut self, reading: &PoseReading) {
        let Some(Some(path)) = self.p3d_paths.get(reading.sensor) else {
            return;
        };
        self.rec.set_duration_secs("sim_time", reading.stamp_s);
        let [x, y, z] = reading.position_m.map(|v| v as f32);
        let point = rerun::Points3D::new([[x, y, z]])
            .with_radii([0.03f32])
            .with_colors([rerun::Color::from_rgb(40, 200, 90)]);
        self.log(path, &point);
    }

    fn gps(&mut self, fix: &FixReading) {
        let Some(paths) = self.gps_paths.get(fix.sensor) else {
            return;
        };
        self.rec.set_duration_secs("sim_time", fix.stamp_s);
        for (path, value) in paths
            .iter()
            .zip([fix.latitude_deg, fix.longitude_deg, fix.altitude_m])
        {
            self.log(path, &rerun::Scalars::single(value));
        }
    }

    fn contacts(&mut self, reading: &ContactsReading) {
        let Some(path) = self.bumper_paths.get(reading.sensor) else {
            return;
        };
        self.rec.set_duration_secs("sim_time", reading.stamp_s);
        let touching = rerun::Scalars::single(reading.contacts.len() as f64);
        self.log(path, &touching);
    }

    fn point_cloud(&mut self, cloud: &PointCloud, world_from_sensor: Pose) {
        self.rec.set_duration_secs("sim_time", cloud.stamp_s);
        if let Some((path, points)) = self.clouds.points(cloud, world_from_sensor)
            && let Err(e) = self.rec.log(path, &points)
        {
            tracing::warn!("rerun: {path}: {e}");
        }
    }

    fn event(&mut self, sim_time_s: f64, level: EventLevel, text: &str) {
        // Both timelines, also for an event before the first control update.
        self.set_time(sim_time_s);
        let level = match level {
            EventLevel::Info => rerun::TextLogLevel::INFO,
            EventLevel::Warn => rerun::TextLogLevel::WARN,
        };
        self.log("log", &rerun::TextLog::new(text).with_level(level));
    }
}

impl Recorder {
    /// The arm's look or reach while one runs: the object point, the pre-grasp goal (labelled
    /// with the reach's state) and the tool in the world frame; the reach's state and the
    /// tool's distance to its goal as plots.
    fn log_arm(&self, arm: &rover_core::ArmStatus) {
        if arm.mode != rover_core::ArmMode::Reach {
            return;
        }
        let point = |p: Option<[f64; 3]>| p.map(|[x, y, z]| [x as f32, y as f32, z as f32]);
        self.log(
            "world/arm/object",
            &rerun::Points3D::new(point(arm.object_world_m))
                .with_radii([0.02f32])
                .with_colors([rerun::Color::from_rgb(255, 70, 70)]),
        );
        self.log(
            "world/arm/goal",
            &rerun::Points3D::new(point(arm.goal_world_m))
                .with_radii([0.015f32])
                .with_colors([rerun::Color::from_rgb(90, 200, 255)])
                .with_labels([arm.reach.as_str()]),
        );
        self.log(
            "world/arm/tool",
            &rerun::Points3D::new(point(arm.tool_world_m))
                .with_radii([0.01f32])
                .with_colors([rerun::Color::from_rgb(255, 230, 80)]),
        );
        self.log(
            "plots/arm/reach_state",
            &rerun::Scalars::single(arm.reach.index() as f64),
        );
        if let Some(d) = arm.tool_to_goal_m() {
            self.log("plots/arm/tool_to_goal_m", &rerun::Scalars::single(d));
        }
    }
}
