//! The driver's station: a winit window showing the live camera image with its boxes and a HUD,
//! keyboard and gamepad teleop, and the loop paced to real time. An adapter at the edge: the
//! session it drives is the same one headless runs use.

use std::collections::BTreeSet;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rover_perception::BoundingBoxes;
use rover_sim::{CameraFrame, CameraInfo, ControlSample, Pose, Simulation, Twist};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::font::Canvas;
use crate::gamepad::{Gamepads, PadCommand};
use crate::pilot::Mode;
use crate::script::{Action, Script};
use crate::session::{EventLevel, LoopStats, Observer, Session};
use crate::teleop::{KeyAction, key_action};
use crate::trace::TraceWriter;

/// Window settings.
#[derive(Debug, Clone)]
pub struct WindowOptions {
    /// Sim seconds per wall second.
    pub real_time_factor: f64,
    /// Keep driving after a key is released, as teleop_twist_keyboard does.
    pub latched: bool,
    /// W/A/S/D drive (instead of teleop's w/x/e/c speed keys).
    pub wasd: bool,
    /// Quit after this many sim seconds.
    pub duration_s: Option<f64>,
    /// Start paused.
    pub paused: bool,
    /// Timed inputs, as in headless runs.
    pub script: Script,
    /// Write the window's image (camera, boxes, HUD) as PNG here when quitting.
    pub screenshot: Option<std::path::PathBuf>,
}

/// Height of the HUD strip under the camera image (px).
const HUD_H: usize = 112;

/// Says plainly when there is no display to open a window on.
pub fn check_display() -> Result<()> {
    let has = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
    if cfg!(target_os = "linux") && !has("DISPLAY") && !has("WAYLAND_DISPLAY") {
        anyhow::bail!(
            "no display to open a window on (neither DISPLAY nor WAYLAND_DISPLAY is set). Run \
             `rover --headless` (add `--viewer web` to watch in a browser), or start rover from a \
             desktop session"
        );
    }
    Ok(())
}

/// Forwards to the recorder, keeping the newest warning and the newest image for the window.
struct Tap<'a> {
    inner: &'a mut dyn Observer,
    warning: Option<String>,
    image: Vec<u8>,
    image_size: (usize, usize),
    trace: Option<TraceWriter<std::io::BufWriter<std::fs::File>>>,
    mode: Mode,
}

impl Observer for Tap<'_> {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        self.inner.start(sim, camera, labels);
    }
    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        self.mode = stats.mode;
        if let Some(t) = self.trace.as_mut()
            && let Err(e) = t.row(sample, stats.mode)
        {
            tracing::warn!("trace: {e}");
            self.trace = None;
        }
        self.inner.control(sim, sample, stats);
    }
    fn camera_frame(&mut self, frame: &CameraFrame<'_>, world_from_camera: Pose) {
        self.image.clear();
        self.image.extend_from_slice(frame.rgb);
        self.image_size = (frame.width as usize, frame.height as usize);
        self.inner.camera_frame(frame, world_from_camera);
    }
    fn detections(&mut self, boxes: &BoundingBoxes, labels: &[String]) {
        self.inner.detections(boxes, labels);
    }
    fn event(&mut self, sim_time_s: f64, level: EventLevel, text: &str) {
        if level == EventLevel::Warn {
            self.warning = Some(text.to_owned());
        }
        self.inner.event(sim_time_s, level, text);
    }
}

struct Gpu {
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    texture: wgpu::Texture,
    size: (u32, u32),
}

impl Gpu {
    fn new(window: Arc<Window>, size: (u32, u32)) -> Result<Self> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let inner = window.inner_size();
        let surface = instance
            .create_surface(window)
            .context("cannot draw into the window")?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .context(
            "no GPU or software Vulkan for the window (apt-get install mesa-vulkan-drivers)",
        )?;
        tracing::info!("window: drawing with {}", adapter.get_info().name);
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                label: Some("rover window"),
                ..Default::default()
            }))?;
        let config = surface
            .get_default_config(&adapter, inner.width.max(1), inner.height.max(1))
            .context("the window surface is not supported by this adapter")?;
        surface.configure(&device, &config);
        let texture_format = if config.format.is_srgb() {
            wgpu::TextureFormat::Rgba8UnormSrgb
        } else {
            wgpu::TextureFormat::Rgba8Unorm
        };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("window image"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: texture_format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("window layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("window image"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("window shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("window.wgsl").into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("window pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("window pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(config.format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Ok(Self {
            surface,
            device,
            queue,
            config,
            pipeline,
            bind_group,
            texture,
            size,
        })
    }

    fn resize(&mut self, width: u32, height: u32) {
        if width > 0 && height > 0 {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.device, &self.config);
        }
    }

    fn draw(&mut self, rgba: &[u8]) {
        let (w, h) = self.size;
        self.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w * 4),
                rows_per_image: Some(h),
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.device, &self.config);
                return;
            }
            _ => return,
        };
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("window"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // Keep the image's aspect: letterbox inside the window.
            let (ww, wh) = (self.config.width as f32, self.config.height as f32);
            let scale = (ww / w as f32).min(wh / h as f32);
            let (vw, vh) = (w as f32 * scale, h as f32 * scale);
            pass.set_viewport((ww - vw) / 2.0, (wh - vh) / 2.0, vw, vh, 0.0, 1.0);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        self.queue.submit([encoder.finish()]);
        self.queue.present(frame);
    }
}

/// What a window session did.
#[derive(Debug, Clone, Copy)]
pub struct WindowSummary {
    /// Sim time reached (s).
    pub sim_time_s: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Mode at the end.
    pub mode: Mode,
}

struct App<'a> {
    session: Session,
    tap: Tap<'a>,
    options: WindowOptions,
    window: Option<Arc<Window>>,
    gpu: Option<Gpu>,
    error: Option<anyhow::Error>,
    canvas: Vec<u8>,
    canvas_size: (usize, usize),
    paused: bool,
    step_once: bool,
    /// (wall, sim) when pacing was last anchored.
    anchor: (Instant, f64),
    held: BTreeSet<String>,
    last_move: Option<String>,
    next_script_step: usize,
    next_redraw: Instant,
    pads: Option<Gamepads>,
    started: Instant,
    rtf_window: (Instant, f64),
    rtf: f64,
}

impl App<'_> {
    fn key(&mut self, name: &str, pressed: bool) {
        let obs: &mut dyn Observer = &mut self.tap;
        let is_move = |name: &str| matches!(key_action(name), Some(KeyAction::Move { .. }));
        let name = match (self.options.wasd, name) {
            (_, "ArrowUp") | (true, "w") => "i",
            (_, "ArrowDown") | (true, "s") => ",",
            (_, "ArrowLeft") | (true, "a") => "j",
            (_, "ArrowRight") | (true, "d") => "l",
            (true, "x" | "e" | "c") => return,
            (_, other) => other,
        };
        if !pressed {
            // Hold-to-drive: releasing the key that drives stops, unless latched like the
            // terminal teleop.
            self.held.remove(name);
            if !self.options.latched && is_move(name) && self.last_move.as_deref() == Some(name) {
                match self.held.iter().find(|k| is_move(k)).cloned() {
                    Some(other) => {
                        if let Some(action) = key_action(&other) {
                            self.session.input(Action::Key(action), obs);
                        }
                        self.last_move = Some(other);
                    }
                    None => {
                        self.last_move = None;
                        if self.session.pilot().mode() == Mode::Manual {
                            self.session.input(Action::Key(KeyAction::Stop), obs);
                        }
                    }
                }
            }
            return;
        }
        match name {
            "f" => self.session.input(Action::ToggleFollow, obs),
            "p" => {
                self.paused = !self.paused;
                self.anchor = (Instant::now(), self.session.sim().sim_time_s());
            }
            "n" if self.paused => self.step_once = true,
            other => {
                if let Some(action) = key_action(other) {
                    if is_move(other) {
                        self.held.insert(other.to_owned());
                        self.last_move = Some(other.to_owned());
                    }
                    self.session.input(Action::Key(action), obs);
                }
            }
        }
    }

    fn advance(&mut self) -> Result<bool> {
        let now = Instant::now();
        if let Some(pads) = self.pads.as_mut() {
            let teleop = self.session.pilot().teleop();
            match pads.poll(teleop.speed_mps, teleop.turn_radps) {
                Some(PadCommand::Drive(cmd)) => self.session.manual_cmd(cmd, &mut self.tap),
                Some(PadCommand::ToggleFollow) => {
                    self.session.input(Action::ToggleFollow, &mut self.tap);
                }
                Some(PadCommand::Stop) if self.session.pilot().mode() == Mode::Manual => {
                    self.session.manual_cmd(Twist::ZERO, &mut self.tap);
                }
                Some(PadCommand::Stop) | None => {}
            }
        }
        let target = if self.paused {
            if std::mem::take(&mut self.step_once) {
                // One control update.
                loop {
                    self.script_steps();
                    if self.session.step(&mut self.tap)?.is_some() {
                        break;
                    }
                }
            }
            self.session.sim().sim_time_s()
        } else {
            let (wall, sim) = self.anchor;
            sim + now.duration_since(wall).as_secs_f64() * self.options.real_time_factor
        };
        let target = self.options.duration_s.map_or(target, |d| target.min(d));
        let budget = now + Duration::from_millis(30);
        while self.session.sim().sim_time_s() + self.session.sim().dt_s() / 2.0 <= target {
            self.script_steps();
            self.session.step(&mut self.tap)?;
            if Instant::now() > budget {
                // Slower than real time: re-anchor rather than try to catch up forever.
                self.anchor = (Instant::now(), self.session.sim().sim_time_s());
                break;
            }
        }
        let (w0, s0) = self.rtf_window;
        let dt = now.duration_since(w0).as_secs_f64();
        if dt >= 1.0 {
            self.rtf = (self.session.sim().sim_time_s() - s0) / dt;
            self.rtf_window = (now, self.session.sim().sim_time_s());
        }
        Ok(self
            .options
            .duration_s
            .is_some_and(|d| self.session.sim().sim_time_s() >= d - 1e-9))
    }

    fn script_steps(&mut self) {
        let now = self.session.sim().sim_time_s();
        let dt = self.session.sim().dt_s();
        while let Some(step) = self.options.script.steps.get(self.next_script_step) {
            if step.at_s > now + dt / 2.0 {
                break;
            }
            self.session.input(step.action, &mut self.tap);
            self.next_script_step += 1;
        }
    }

    /// Composes camera image, boxes and HUD into the RGBA canvas.
    fn compose(&mut self) {
        let (w, h) = self.canvas_size;
        let img_h = h - HUD_H;
        let mut canvas = Canvas {
            pixels: &mut self.canvas,
            width: w,
            height: h,
        };
        canvas.fill(0, 0, w as i64, h as i64, [24, 26, 30]);
        let (iw, ih) = self.tap.image_size;
        if iw == w && ih == img_h && self.tap.image.len() == iw * ih * 3 {
            for (dst, src) in canvas.pixels[..w * img_h * 4]
                .chunks_exact_mut(4)
                .zip(self.tap.image.chunks_exact(3))
            {
                dst.copy_from_slice(&[src[0], src[1], src[2], 255]);
            }
        } else {
            canvas.text(20, 20, "waiting for the camera...", 2, [200, 200, 200]);
        }
        if let Some(boxes) = self.session.last_boxes() {
            for b in &boxes.bounding_boxes {
                let color = if b.class == self.session.follower().config().target_class {
                    [255, 70, 70]
                } else {
                    [80, 200, 255]
                };
                canvas.rect(b.xmin, b.ymin, b.xmax, b.ymax, 2, color);
                let label = format!("{} {:.2}", b.class, b.probability);
                let lw = label.len() as i64 * 12 + 4;
                let ly = (b.ymin - 18).max(0);
                canvas.fill(b.xmin, ly, lw, 18, color);
                canvas.text(b.xmin + 2, ly + 2, &label, 2, [0, 0, 0]);
            }
        }
        // HUD.
        let stats = self.session.stats();
        let teleop = self.session.pilot().teleop();
        let cmd = self.session.sim().drive().command();
        let y0 = img_h as i64 + 6;
        let (mode_text, mode_color) = match stats.mode {
            Mode::Manual => ("MANUAL".to_owned(), [120, 220, 120]),
            Mode::Follow => (
                format!("FOLLOW ({})", stats.follow_state.as_str()),
                [255, 170, 60],
            ),
        };
        let x = canvas.text(8, y0, &mode_text, 3, mode_color);
        let right = if self.paused {
            "PAUSED".to_owned()
        } else {
            format!("t {:.1} s", self.session.sim().sim_time_s())
        };
        let rx = w as i64 - 8 - right.len() as i64 * 12;
        if rx > x + 12 {
            canvas.text(rx, y0 + 4, &right, 2, [255, 230, 80]);
        }
        // Lines of at most 52 characters (12 px each at scale 2 in 640 px).
        let line2 = format!(
            "cmd {:+.2} m/s {:+.2} rad/s  max {:.2} m/s {:.2} rad/s",
            cmd.linear_mps, cmd.angular_radps, teleop.speed_mps, teleop.turn_radps
        );
        canvas.text(8, y0 + 28, &line2, 2, [230, 230, 230]);
        let line3 = if stats.detector_ok {
            format!(
                "yolo {:.1} Hz {:.0} ms  dropped {}  sim {:.2}x",
                stats.detector_hz, stats.detector_latency_ms, stats.frames_dropped, self.rtf
            )
        } else {
            format!("detector OFF  sim {:.2}x real time", self.rtf)
        };
        canvas.text(8, y0 + 48, &line3, 2, [230, 230, 230]);
        match &self.tap.warning {
            Some(warning) => {
                let text: String = warning.chars().take(104).collect();
                let (a, b) =
                    text.split_at(text.char_indices().nth(52).map_or(text.len(), |(i, _)| i));
                canvas.text(8, y0 + 72, &format!("! {a}"), 2, [255, 120, 90]);
                canvas.text(8, y0 + 90, b, 2, [255, 120, 90]);
            }
            None => {
                canvas.text(
                    8,
                    y0 + 72,
                    "i,jluom. drive k stop q/z speed f follow p pause",
                    2,
                    [160, 170, 180],
                );
                canvas.text(
                    8,
                    y0 + 90,
                    "pad: hold LB + sticks, A follow    esc quit",
                    2,
                    [160, 170, 180],
                );
            }
        }
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let (w, h) = self.canvas_size;
        let attributes = Window::default_attributes()
            .with_title("rover — driver's station")
            .with_inner_size(winit::dpi::LogicalSize::new(w as f64, h as f64));
        let window = match event_loop.create_window(attributes) {
            Ok(w) => Arc::new(w),
            Err(e) => {
                self.error = Some(anyhow::anyhow!("cannot open the window: {e}"));
                event_loop.exit();
                return;
            }
        };
        match Gpu::new(window.clone(), (w as u32, h as u32)) {
            Ok(gpu) => self.gpu = Some(gpu),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
                return;
            }
        }
        self.window = Some(window);
        self.anchor = (Instant::now(), self.session.sim().sim_time_s());
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(gpu) = self.gpu.as_mut() {
                    gpu.resize(size.width, size.height);
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if event.repeat {
                    return;
                }
                let pressed = event.state == ElementState::Pressed;
                let name = match &event.logical_key {
                    Key::Named(NamedKey::Escape) => {
                        if pressed {
                            event_loop.exit();
                        }
                        return;
                    }
                    Key::Named(NamedKey::Space) => "space".to_owned(),
                    Key::Named(NamedKey::ArrowUp) => "ArrowUp".to_owned(),
                    Key::Named(NamedKey::ArrowDown) => "ArrowDown".to_owned(),
                    Key::Named(NamedKey::ArrowLeft) => "ArrowLeft".to_owned(),
                    Key::Named(NamedKey::ArrowRight) => "ArrowRight".to_owned(),
                    Key::Character(c) => c.to_lowercase(),
                    _ => return,
                };
                // Shifted teleop keys (< for , and > for .) arrive as other characters.
                let name = match name.as_str() {
                    "<" => ",".to_owned(),
                    ">" => ".".to_owned(),
                    _ => name,
                };
                self.key(&name, pressed);
            }
            WindowEvent::RedrawRequested => {
                self.compose();
                if let Some(gpu) = self.gpu.as_mut() {
                    gpu.draw(&self.canvas);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        match self.advance() {
            Ok(true) => {
                event_loop.exit();
                return;
            }
            Ok(false) => {}
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
                return;
            }
        }
        let now = Instant::now();
        if now >= self.next_redraw {
            self.next_redraw = now + Duration::from_millis(33);
            if let Some(w) = &self.window {
                w.request_redraw();
            }
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(now + Duration::from_millis(2)));
    }
}

/// Runs the window until Esc, window close, or `duration_s`. `trace` gets one row per control
/// update, like headless runs.
pub fn run(
    session: Session,
    observer: &mut dyn Observer,
    options: WindowOptions,
    trace: Option<TraceWriter<std::io::BufWriter<std::fs::File>>>,
) -> Result<WindowSummary> {
    check_display()?;
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow::anyhow!(
            "cannot connect to the display ({e}); run `rover --headless` (add `--viewer web` to watch in a browser)"
        )
    })?;
    let (w, h) = session
        .camera_info()
        .map_or((640, 480), |i| (i.width as usize, i.height as usize));
    let canvas_size = (w, h + HUD_H);
    let pads = match Gamepads::new() {
        Ok(p) => Some(p),
        Err(e) => {
            tracing::warn!("no gamepad support ({e}); keyboard only");
            None
        }
    };
    let paused = options.paused;
    let mut app = App {
        session,
        tap: Tap {
            inner: observer,
            warning: None,
            image: Vec::with_capacity(w * h * 3),
            image_size: (0, 0),
            trace,
            mode: Mode::Manual,
        },
        options,
        window: None,
        gpu: None,
        error: None,
        canvas: vec![0; canvas_size.0 * canvas_size.1 * 4],
        canvas_size,
        paused,
        step_once: false,
        anchor: (Instant::now(), 0.0),
        held: BTreeSet::new(),
        last_move: None,
        next_script_step: 0,
        next_redraw: Instant::now(),
        pads,
        started: Instant::now(),
        rtf_window: (Instant::now(), 0.0),
        rtf: 0.0,
    };
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.error {
        return Err(e);
    }
    if let Some(t) = app.tap.trace.take() {
        t.finish()?;
    }
    if let Some(path) = app.options.screenshot.clone() {
        app.compose();
        let (w, h) = app.canvas_size;
        image::save_buffer(
            &path,
            &app.canvas,
            w as u32,
            h as u32,
            image::ExtendedColorType::Rgba8,
        )
        .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(WindowSummary {
        sim_time_s: app.session.sim().sim_time_s(),
        wall_s: app.started.elapsed().as_secs_f64(),
        mode: app.tap.mode,
    })
}
