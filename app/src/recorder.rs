//! The Rerun recorder: an [`Observer`] that streams a run to a Rerun viewer and/or an .rrd file.
//! It only watches the loop; nothing in the simulation depends on it.
//!
//! Entity paths (docs/RERUN.md):
//! ```text
//! world                                  ViewCoordinates RIGHT_HAND_Z_UP (REP-103), static
//! world/ground, world/objects/<name>     Mesh3D, static
//! world/people/<name>                    Transform3D (per control update when walking) + Mesh3D
//! world/robot                            Transform3D world_from_base, per control update
//! world/robot/<link>                     Transform3D base_from_link (wheels turn) + Mesh3D visuals
//! world/robot/camera                     Transform3D base_from_camera_optical, static
//! world/robot/camera/image               Pinhole (Gazebo's K), Image, AnnotationContext
//! world/robot/camera/image/detections    Boxes2D "person 0.87" with class ids
//! world/odometry                         Points3D (odometry position) + trail LineStrips3D
//! plots/...                              Scalars: cmd/measured velocity, wheel speeds, mode,
//!                                        detector latency/Hz/dropped, real-time factor
//! log                                    TextLog: mode changes, warnings
//! ```
//! Timelines: `sim_time` (seconds of simulated time) and `frame` (camera frame number).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rerun::blueprint::{
    Blueprint, Horizontal, Spatial2DView, Spatial3DView, TextLogView, TimePanel, TimeSeriesView,
    Vertical,
};
use rerun::external::re_uri::ProxyUri;
use rerun::sink::{FileSink, GrpcSink, LogSink};
use rerun::{RecordingStream, RecordingStreamBuilder};
use rover_perception::BoundingBoxes;
use rover_sim::render::meshes::{MeshData, object_mesh, person_parts, shape_mesh};
use rover_sim::{CameraFrame, CameraInfo, ControlSample, Pose, Rgba, Simulation};

use crate::pilot::Mode;
use crate::session::{EventLevel, LoopStats, Observer};

/// The rerun SDK version rover is built with; a viewer must match it.
pub const RERUN_VERSION: &str = "0.36.3";

/// Where the recording goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Viewer {
    /// Start the native viewer (`rerun` on PATH) and stream to it.
    Spawn,
    /// Stream to a running viewer at this gRPC URL (`rerun+http://host:port/proxy`).
    Connect(String),
    /// Serve the web viewer from rover itself and print its URL.
    Web,
    /// Write an .rrd file only.
    Save(PathBuf),
    /// No viewer.
    None,
}

impl Viewer {
    /// Parses `--viewer MODE [ARG]`.
    pub fn parse(words: &[String]) -> Result<Self> {
        let arg = words.get(1).cloned();
        let mode = words.first().map(String::as_str).unwrap_or("none");
        Ok(match (mode, arg) {
            ("spawn", None) => Viewer::Spawn,
            ("web", None) => Viewer::Web,
            ("none", None) => Viewer::None,
            ("connect", url) => {
                Viewer::Connect(url.unwrap_or_else(|| rerun::DEFAULT_CONNECT_URL.to_owned()))
            }
            ("save", Some(path)) => Viewer::Save(PathBuf::from(path)),
            ("save", None) => anyhow::bail!("--viewer save needs a file: --viewer save run.rrd"),
            (m @ ("spawn" | "web" | "none"), Some(extra)) => {
                anyhow::bail!("--viewer {m} takes no argument, found '{extra}'")
            }
            (other, _) => anyhow::bail!(
                "--viewer '{other}' is unknown; expected spawn, connect [URL], web, save FILE.rrd or none"
            ),
        })
    }
}

/// How camera images are logged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageOptions {
    /// Images per sim second (None = every camera frame).
    pub rate_hz: Option<f64>,
    /// Downscale factor (1 = full size, 2 = half width and height, ...).
    pub downscale: u32,
    /// JPEG quality (None = raw RGB).
    pub jpeg_quality: Option<u8>,
}

impl Default for ImageOptions {
    fn default() -> Self {
        Self {
            rate_hz: None,
            downscale: 1,
            jpeg_quality: None,
        }
    }
}

/// Recorder settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RecorderOptions {
    /// Viewer mode.
    pub viewer: Viewer,
    /// Also record to this .rrd file.
    pub record: Option<PathBuf>,
    /// Image logging.
    pub images: ImageOptions,
    /// Web viewer (HTTP) port.
    pub web_port: u16,
    /// gRPC port of the web viewer's data server.
    pub grpc_port: u16,
}

impl Default for RecorderOptions {
    fn default() -> Self {
        Self {
            viewer: Viewer::None,
            record: None,
            images: ImageOptions::default(),
            web_port: 9090,
            grpc_port: 9876,
        }
    }
}

/// What `rerun --version` on PATH says, if there is one.
pub fn viewer_on_path() -> Option<String> {
    let out = std::process::Command::new("rerun")
        .arg("--version")
        .stdin(std::process::Stdio::null())
        .output()
        .ok()?;
    out.status.success().then(|| {
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .nth(1)
            .unwrap_or("")
            .to_owned()
    })
}

/// The pip command that installs the matching viewer.
pub fn pip_command() -> String {
    format!("pip install rerun-sdk=={RERUN_VERSION}")
}

/// Picks the default viewer: the native one when a matching `rerun` is on PATH, else the web
/// viewer. Returns the choice and why.
pub fn default_viewer() -> (Viewer, String) {
    match viewer_on_path() {
        Some(v) if v == RERUN_VERSION => {
            (Viewer::Spawn, format!("found the Rerun viewer {v} on PATH"))
        }
        Some(v) => (
            Viewer::Web,
            format!(
                "the Rerun viewer on PATH is {v} but rover speaks {RERUN_VERSION}: `{}` to use the native viewer; serving the web viewer instead",
                pip_command()
            ),
        ),
        None => (
            Viewer::Web,
            format!(
                "no Rerun viewer on PATH (`{}` installs it); serving the web viewer instead",
                pip_command()
            ),
        ),
    }
}

/// The Rerun recorder.
pub struct Recorder {
    rec: RecordingStream,
    images: ImageOptions,
    next_image_s: f64,
    frame: i64,
    trail: Vec<[f32; 3]>,
    trail_logged_s: f64,
    scaled: Vec<u8>,
    jpeg: Vec<u8>,
    link_paths: Vec<String>,
    people_paths: Vec<String>,
    /// Port of a viewer we stream to, probed now and then to notice it has gone.
    watch_port: Option<u16>,
    watch_next: Instant,
    viewer_gone: bool,
    started: Instant,
    /// Where the web viewer is, when serving it.
    pub web_url: Option<String>,
    _web: Option<Box<dyn std::any::Any>>,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("web_url", &self.web_url)
            .finish_non_exhaustive()
    }
}

fn proxy_uri(url: &str) -> Result<ProxyUri> {
    url.parse::<ProxyUri>().map_err(|e| {
        anyhow::anyhow!(
            "'{url}' is not a Rerun gRPC URL ({e}); expected e.g. {}",
            rerun::DEFAULT_CONNECT_URL
        )
    })
}

/// True when something accepts TCP connections on 127.0.0.1:`port`.
fn port_open(host: &str, port: u16) -> bool {
    use std::net::ToSocketAddrs;
    (host, port)
        .to_socket_addrs()
        .ok()
        .and_then(|mut a| a.next())
        .is_some_and(|addr| {
            std::net::TcpStream::connect_timeout(&addr, Duration::from_millis(200)).is_ok()
        })
}

impl Recorder {
    /// Opens the viewer/file sinks. Returns `Ok(None)` when there is nothing to record to.
    pub fn start(options: &RecorderOptions) -> Result<Option<Self>> {
        if options.viewer == Viewer::None && options.record.is_none() {
            return Ok(None);
        }
        let mut sinks: Vec<Box<dyn LogSink>> = Vec::new();
        let mut files = Vec::new();
        if let Some(path) = &options.record {
            files.push(path.clone());
        }
        let mut watch_port = None;
        let mut web_url = None;
        let mut web: Option<Box<dyn std::any::Any>> = None;
        match &options.viewer {
            Viewer::None => {}
            Viewer::Save(path) => files.push(path.clone()),
            Viewer::Spawn => {
                if let Some(v) = viewer_on_path()
                    && v != RERUN_VERSION
                {
                    tracing::warn!(
                        "the Rerun viewer on PATH is {v}, rover streams {RERUN_VERSION}: run `{}`",
                        pip_command()
                    );
                }
                let spawn = rerun::SpawnOptions {
                    wait_for_bind: true,
                    hide_welcome_screen: true,
                    memory_limit: "50%".into(),
                    ..rerun::SpawnOptions::default()
                };
                let info = rerun::spawn(&spawn).with_context(|| {
                    format!(
                        "cannot start the Rerun viewer (`{}` installs it; or use --viewer web)",
                        pip_command()
                    )
                })?;
                tracing::info!(
                    "Rerun viewer started (pid {}, port {})",
                    info.child_pid
                        .map_or_else(|| "?".to_owned(), |p| p.to_string()),
                    info.port
                );
                let url = format!("rerun+http://127.0.0.1:{}/proxy", info.port);
                sinks.push(Box::new(GrpcSink::new(proxy_uri(&url)?)));
                watch_port = Some(info.port);
            }
            Viewer::Connect(url) => {
                let uri = proxy_uri(url)?;
                let (host, port) =
                    host_port(url).unwrap_or(("127.0.0.1".into(), rerun::DEFAULT_SERVER_PORT));
                if !port_open(&host, port) {
                    anyhow::bail!(
                        "no Rerun viewer answers at {url}: start one with `rerun` (`{}`), or use --viewer web",
                        pip_command()
                    );
                }
                sinks.push(Box::new(GrpcSink::new(uri)));
                watch_port = Some(port);
            }
            Viewer::Web => {
                let grpc = rerun::grpc_server::GrpcServerSink::new(
                    "127.0.0.1",
                    options.grpc_port,
                    rerun::ServerOptions {
                        memory_limit: rerun::MemoryLimit::from_fraction_of_total(0.25),
                        ..rerun::ServerOptions::default()
                    },
                )
                .context("cannot start the Rerun data server for the web viewer")?;
                sinks.push(Box::new(grpc));
                let connect = format!("rerun+http://127.0.0.1:{}/proxy", options.grpc_port);
                let server = rerun::serve_web_viewer(rerun::web_viewer::WebViewerConfig {
                    bind_ip: "127.0.0.1".into(),
                    web_port: options.web_port.into(),
                    connect_to: vec![connect.clone()],
                    open_browser: false,
                    ..Default::default()
                })
                .with_context(|| {
                    format!("cannot serve the web viewer on port {}", options.web_port)
                })?;
                let url = format!(
                    "{}/?url={}",
                    server.server_url(),
                    connect.replace('+', "%2B")
                );
                web = Some(Box::new(server));
                web_url = Some(url);
            }
        }
        for path in &files {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .with_context(|| format!("cannot create {}", dir.display()))?;
            }
            sinks.push(Box::new(
                FileSink::new(path).with_context(|| format!("cannot write {}", path.display()))?,
            ));
        }
        let rec = RecordingStreamBuilder::new("rover")
            .batcher_config(rerun::log::ChunkBatcherConfig::LOW_LATENCY)
            .with_blueprint(blueprint())
            .set_sinks(sinks)
            .context("cannot start the Rerun recording")?;
        rec.set_log_time_enabled(false);
        Ok(Some(Self {
            rec,
            images: options.images,
            next_image_s: 0.0,
            frame: 0,
            trail: Vec::with_capacity(4096),
            trail_logged_s: f64::NEG_INFINITY,
            scaled: Vec::new(),
            jpeg: Vec::new(),
            link_paths: Vec::new(),
            people_paths: Vec::new(),
            watch_port,
            watch_next: Instant::now() + Duration::from_secs(2),
            viewer_gone: false,
            started: Instant::now(),
            web_url,
            _web: web,
        }))
    }

    /// Logs the static scene: world, robot visuals, camera intrinsics, class names.
    fn scene(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        let world = sim.world();
        let robot = sim.robot();
        self.log_static("world", &rerun::ViewCoordinates::RIGHT_HAND_Z_UP());
        let [gx, gy] = world.ground.size_m;
        self.log_static(
            "world/ground",
            &rerun::Boxes3D::from_centers_and_sizes(
                [[0.0f32, 0.0, -0.01]],
                [[gx as f32, gy as f32, 0.02]],
            )
            .with_colors([color(world.ground.color)])
            .with_fill_mode(rerun::FillMode::Solid),
        );
        for object in &world.objects {
            let p = object.position_m;
            let path = format!("world/objects/{}", object.name);
            let pose = Pose::from_parts(
                glam::Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32),
                glam::Quat::from_rotation_z(object.yaw_rad as f32),
            );
            self.log_static(&path, &transform(pose));
            self.log_static(&path, &mesh(&object_mesh(&object.shape), object.color));
        }
        self.people_paths.clear();
        for (i, person) in world.people.iter().enumerate() {
            let path = format!("world/people/{}", person.name);
            let mut positions = Vec::new();
            let mut normals = Vec::new();
            let mut colors = Vec::new();
            let mut triangles = Vec::new();
            for part in person_parts(person) {
                let base = positions.len() as u32;
                for v in &part.mesh.vertices {
                    positions.push((part.pose * glam::Vec3::from_array(v.position)).to_array());
                    normals
                        .push((part.pose.rotation * glam::Vec3::from_array(v.normal)).to_array());
                    colors.push(color(part.color));
                }
                triangles.extend(
                    part.mesh
                        .indices
                        .chunks_exact(3)
                        .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
                );
            }
            self.log_static(
                &format!("{path}/body"),
                &rerun::Mesh3D::new(positions)
                    .with_vertex_normals(normals)
                    .with_vertex_colors(colors)
                    .with_triangle_indices(triangles),
            );
            if person.walk.is_none() {
                self.log_static(&path, &transform(sim.world_from_person(i)));
            }
            self.people_paths.push(path);
        }
        // The robot: one entity per link under world/robot, visuals as meshes.
        self.link_paths.clear();
        for link in &robot.links {
            let path = format!("world/robot/{}", link.name);
            for (v, visual) in link.visuals.iter().enumerate() {
                let vpath = format!("{path}/visual_{v}");
                if let Ok(m) = shape_mesh(&visual.shape) {
                    self.log_static(&vpath, &transform(visual.link_from_shape));
                    self.log_static(&vpath, &mesh(&m, visual.color));
                }
            }
            self.link_paths.push(path);
        }
        if let Some(info) = camera {
            let config = robot.cameras.first();
            let link = config
                .and_then(|c| robot.link_index(&c.link))
                .unwrap_or(robot.root);
            let base_from_link = sim.world_from_base().inverse() * sim.world_from_link(link);
            let base_from_optical =
                base_from_link * Pose::from_rotation(rover_sim::camera::link_from_optical());
            self.log_static("world/robot/camera", &transform(base_from_optical));
            let k = self.images.downscale.max(1) as f32;
            let proj = rerun::components::PinholeProjection::from_focal_length_and_principal_point(
                [info.k[0] as f32 / k, info.k[4] as f32 / k],
                [info.k[2] as f32 / k, info.k[5] as f32 / k],
            );
            let (w, h) = scaled_size(info.width, info.height, self.images.downscale);
            self.log_static(
                "world/robot/camera/image",
                &rerun::Pinhole::new(proj)
                    .with_resolution([w as f32, h as f32])
                    .with_image_plane_distance(0.5f32),
            );
        }
        if !labels.is_empty() {
            self.log_static(
                "world/robot/camera/image",
                &rerun::AnnotationContext::new(
                    labels
                        .iter()
                        .enumerate()
                        .map(|(i, name)| (i as u16, name.as_str(), class_color(i))),
                ),
            );
        }
        self.log_static(
            "plots/velocity/linear",
            &rerun::SeriesLines::new().with_names(["cmd linear.x (m/s)", "measured (m/s)"]),
        );
        self.log_static(
            "plots/velocity/angular",
            &rerun::SeriesLines::new().with_names(["cmd angular.z (rad/s)", "measured (rad/s)"]),
        );
        self.log_static(
            "plots/wheels",
            &rerun::SeriesLines::new().with_names([
                "left target (rad/s)",
                "right target (rad/s)",
                "left measured (rad/s)",
                "right measured (rad/s)",
            ]),
        );
    }

    fn log_static(&self, path: &str, data: &dyn rerun::AsComponents) {
        if let Err(e) = self.rec.log_static(path, data) {
            tracing::warn!("rerun: {path}: {e}");
        }
    }

    fn log(&self, path: &str, data: &dyn rerun::AsComponents) {
        if let Err(e) = self.rec.log(path, data) {
            tracing::warn!("rerun: {path}: {e}");
        }
    }

    fn set_time(&self, sim_time_s: f64) {
        self.rec.set_duration_secs("sim_time", sim_time_s);
        self.rec.set_time_sequence("frame", self.frame);
    }

    /// Notices (once) that a streamed-to viewer has gone; the run goes on.
    fn watch_viewer(&mut self) {
        let Some(port) = self.watch_port else {
            return;
        };
        if self.viewer_gone || Instant::now() < self.watch_next {
            return;
        }
        self.watch_next = Instant::now() + Duration::from_secs(2);
        if !port_open("127.0.0.1", port) {
            self.viewer_gone = true;
            tracing::warn!(
                "the Rerun viewer has gone away; the run goes on (a --record file keeps recording)"
            );
        }
    }

    /// Flushes the recording and closes its files (writes the .rrd footer); a web viewer
    /// server keeps serving until the recorder is dropped.
    pub fn finish(&mut self) {
        if let Err(e) = self.rec.flush_with_timeout(Duration::from_secs(5))
            && !self.viewer_gone
        {
            tracing::warn!("rerun: could not flush everything: {e}");
        }
        self.rec.finalize_deferred_sinks();
        tracing::debug!("recorder ran {:.1} s", self.started.elapsed().as_secs_f64());
    }
}

impl Observer for Recorder {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        self.scene(sim, camera, labels);
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        self.watch_viewer();
        self.set_time(sample.sim_time_s);
        self.log("world/robot", &transform(sim.world_from_base()));
        let base_from_world = sim.world_from_base().inverse();
        for i in 0..self.link_paths.len().min(sim.robot().links.len()) {
            if i == sim.robot().root {
                continue;
            }
            let pose = base_from_world * sim.world_from_link(i);
            let path = std::mem::take(&mut self.link_paths[i]);
            self.log(&path, &transform(pose));
            self.link_paths[i] = path;
        }
        for i in 0..self.people_paths.len() {
            if sim.world().people[i].walk.is_some() {
                let path = std::mem::take(&mut self.people_paths[i]);
                self.log(&path, &transform(sim.world_from_person(i)));
                self.people_paths[i] = path;
            }
        }
        let o = sample.odometry;
        let here = [o.x_m as f32, o.y_m as f32, 0.02];
        self.log(
            "world/odometry",
            &rerun::Points3D::new([here]).with_radii([0.04f32]),
        );
        if self.trail.last() != Some(&here) {
            if self.trail.len() == self.trail.capacity() {
                // Keep the trail bounded: drop every other point of the older half.
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
        if sample.sim_time_s - self.trail_logged_s >= 0.5 {
            self.trail_logged_s = sample.sim_time_s;
            self.log(
                "world/odometry/trail",
                &rerun::LineStrips3D::new([self.trail.as_slice()]).with_radii([0.01f32]),
            );
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
        if frame.sim_time_s + 1e-9 < self.next_image_s {
            return;
        }
        if let Some(hz) = self.images.rate_hz.filter(|hz| *hz > 0.0) {
            self.next_image_s = frame.sim_time_s + 1.0 / hz - 1e-6;
        }
        self.set_time(frame.sim_time_s);
        let factor = self.images.downscale.max(1);
        let (w, h) = scaled_size(frame.width, frame.height, factor);
        let pixels: &[u8] = if factor == 1 {
            frame.rgb
        } else {
            downscale_into(
                frame.rgb,
                frame.width,
                frame.height,
                factor,
                &mut self.scaled,
            );
            &self.scaled
        };
        match self.images.jpeg_quality {
            None => self.log(
                "world/robot/camera/image",
                &rerun::Image::from_rgb24(pixels.to_vec(), [w, h]),
            ),
            Some(q) => {
                self.jpeg.clear();
                let mut encoder =
                    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut self.jpeg, q);
                match encoder.encode(pixels, w, h, image::ExtendedColorType::Rgb8) {
                    Ok(()) => {
                        let bytes = self.jpeg.clone();
                        self.log(
                            "world/robot/camera/image",
                            &rerun::EncodedImage::new(bytes)
                                .with_media_type(rerun::MediaType::JPEG),
                        );
                    }
                    Err(e) => tracing::warn!("rerun: JPEG encoding failed: {e}"),
                }
            }
        }
    }

    fn detections(&mut self, boxes: &BoundingBoxes, _labels: &[String]) {
        let stamp = boxes.image_stamp;
        self.rec.set_duration_secs("sim_time", stamp.sim_time_s);
        self.rec.set_time_sequence("frame", stamp.frame as i64);
        let k = self.images.downscale.max(1) as f32;
        let b = &boxes.bounding_boxes;
        let data = rerun::Boxes2D::from_mins_and_sizes(
            b.iter().map(|b| [b.xmin as f32 / k, b.ymin as f32 / k]),
            b.iter()
                .map(|b| [b.width() as f32 / k, b.height() as f32 / k]),
        )
        .with_labels(
            b.iter()
                .map(|b| format!("{} {:.2}", b.class, b.probability)),
        )
        .with_class_ids(b.iter().map(|b| u16::try_from(b.id).unwrap_or(u16::MAX)));
        self.log("world/robot/camera/image/detections", &data);
        self.set_time(stamp.sim_time_s);
    }

    fn event(&mut self, sim_time_s: f64, level: EventLevel, text: &str) {
        self.rec.set_duration_secs("sim_time", sim_time_s);
        let level = match level {
            EventLevel::Info => rerun::TextLogLevel::INFO,
            EventLevel::Warn => rerun::TextLogLevel::WARN,
        };
        self.log("log", &rerun::TextLog::new(text).with_level(level));
    }
}

fn host_port(url: &str) -> Option<(String, u16)> {
    let rest = url.split("://").nth(1)?;
    let authority = rest.split('/').next()?;
    let (host, port) = authority.rsplit_once(':')?;
    Some((host.to_owned(), port.parse().ok()?))
}

fn transform(pose: Pose) -> rerun::Transform3D {
    rerun::Transform3D::from_translation_rotation(
        pose.translation.to_array(),
        rerun::Quaternion::from_xyzw(pose.rotation.to_array()),
    )
}

fn color(c: Rgba) -> [u8; 4] {
    c.0.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

fn mesh(m: &MeshData, c: Rgba) -> rerun::Mesh3D {
    rerun::Mesh3D::new(m.vertices.iter().map(|v| v.position))
        .with_vertex_normals(m.vertices.iter().map(|v| v.normal))
        .with_triangle_indices(m.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]))
        .with_albedo_factor(color(c))
}

/// The class's colour, the same as `rover detect --out` draws.
fn class_color(i: usize) -> rerun::Rgba32 {
    let image::Rgb([r, g, b]) = crate::detect::class_color(i16::try_from(i).unwrap_or(i16::MAX));
    rerun::Rgba32::from_rgb(r, g, b)
}

fn scaled_size(w: u32, h: u32, factor: u32) -> (u32, u32) {
    let f = factor.max(1);
    (w / f, h / f)
}

/// Box-filter downscale of RGB8 by an integer factor into `out` (reused).
fn downscale_into(rgb: &[u8], w: u32, h: u32, factor: u32, out: &mut Vec<u8>) {
    let f = factor.max(1) as usize;
    let (w, h) = (w as usize, h as usize);
    let (ow, oh) = (w / f, h / f);
    out.clear();
    out.resize(ow * oh * 3, 0);
    for y in 0..oh {
        for x in 0..ow {
            let mut sum = [0u32; 3];
            for dy in 0..f {
                let row = (y * f + dy) * w;
                for dx in 0..f {
                    let i = (row + x * f + dx) * 3;
                    if let Some(px) = rgb.get(i..i + 3) {
                        for (s, v) in sum.iter_mut().zip(px) {
                            *s += u32::from(*v);
                        }
                    }
                }
            }
            let o = (y * ow + x) * 3;
            for (dst, s) in out[o..o + 3].iter_mut().zip(sum) {
                *dst = (s / (f * f) as u32) as u8;
            }
        }
    }
}

/// The layout the viewer opens with: 3D view, camera view with boxes, plots, log.
pub fn blueprint() -> Blueprint {
    Blueprint::new(Horizontal::new([
        Vertical::new([
            Spatial3DView::new("World").with_origin("world").into(),
            TextLogView::new("Log").with_origin("log").into(),
        ])
        .with_row_shares([4.0f32, 1.0])
        .into(),
        Vertical::new([
            Spatial2DView::new("Camera")
                .with_origin("world/robot/camera/image")
                .into(),
            TimeSeriesView::new("Linear velocity")
                .with_origin("plots/velocity/linear")
                .into(),
            TimeSeriesView::new("Angular velocity")
                .with_origin("plots/velocity/angular")
                .into(),
            TimeSeriesView::new("Detector")
                .with_origin("plots/detector")
                .into(),
        ])
        .with_row_shares([3.0f32, 1.0, 1.0, 1.0])
        .into(),
    ]))
    .with_time_panel(TimePanel::new().with_timeline("sim_time"))
}

/// The recording's path and size, for the summary `rover` prints after a run.
pub fn describe_file(path: &Path) -> String {
    match std::fs::metadata(path) {
        Ok(m) => format!("{} ({:.1} MB)", path.display(), m.len() as f64 / 1e6),
        Err(_) => path.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viewer_modes_parse_with_their_arguments() -> Result<()> {
        let p = |w: &[&str]| Viewer::parse(&w.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(p(&["spawn"])?, Viewer::Spawn);
        assert_eq!(p(&["web"])?, Viewer::Web);
        assert_eq!(
            p(&["connect"])?,
            Viewer::Connect(rerun::DEFAULT_CONNECT_URL.to_owned())
        );
        assert_eq!(p(&["save", "a.rrd"])?, Viewer::Save(PathBuf::from("a.rrd")));
        assert!(p(&["save"]).is_err());
        assert!(p(&["spawn", "x"]).is_err());
        let e = p(&["native"])
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            e.contains("spawn, connect [URL], web, save FILE.rrd or none"),
            "{e}"
        );
        Ok(())
    }

    #[test]
    fn downscale_averages_blocks() {
        // 4x2 image, two 2x2 blocks: black/white checker -> grey, all 100 -> 100.
        let rgb: Vec<u8> = [0u8, 255, 100, 100, 255, 0, 100, 100]
            .iter()
            .flat_map(|v| [*v, *v, *v])
            .collect();
        let mut out = Vec::new();
        downscale_into(&rgb, 4, 2, 2, &mut out);
        assert_eq!(out, vec![127, 127, 127, 100, 100, 100]);
    }

    #[test]
    fn grpc_urls_give_host_and_port() {
        assert_eq!(
            host_port("rerun+http://127.0.0.1:9876/proxy"),
            Some(("127.0.0.1".to_owned(), 9876))
        );
        assert!(proxy_uri("http://localhost:9876").is_err());
    }
}
