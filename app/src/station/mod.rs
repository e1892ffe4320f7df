//! The driver's station: a winit window showing the live camera image with its boxes and a HUD,
//! keyboard ([`keys`]) and gamepad ([`gamepad`]) teleop, and the loop paced to real time. An
//! adapter at the edge: the session it drives is the same one headless runs use, fed by the same
//! script player and watched by the same observers.
//!
//! The picture is drawn on the CPU ([`canvas`], [`hud`]) and shown with softbuffer: no second
//! GPU device next to the camera's, and nothing to fail on machines where a Vulkan surface
//! cannot be presented.

mod arm;
pub mod canvas;
pub mod gamepad;
mod hud;
pub mod keys;

use std::num::NonZeroU32;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use rover_core::{
    Action, CoreError, EventLevel, Fanout, InputSource, JointAction, LoopStats, Mode, Observer,
    Script, ScriptPlayer, Session,
};
use rover_sim::{
    geometry::Pose,
    physics::{ControlSample, Simulation, Twist},
    sensors::CameraFrame,
};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use arm::ArmKeys;
use canvas::{Canvas, pack, unpack};
use gamepad::{Gamepads, PadCommand};
use keys::{KeyCommand, KeyOptions, KeyTeleop};

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
    /// Set from outside (SIGINT/SIGTERM) to close the window as if its close button was
    /// pressed: the caller then finishes the trace and recording.
    pub stop: Option<Arc<AtomicBool>>,
}

/// What a window run did.
#[derive(Debug, Clone, Copy)]
pub struct WindowSummary {
    /// Sim time reached (s).
    pub sim_time_s: f64,
    /// Wall time (s).
    pub wall_s: f64,
    /// Mode at the end.
    pub mode: Mode,
    /// Closed by [`WindowOptions::stop`] (a signal) rather than by the user or a duration.
    pub interrupted: bool,
}

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

/// What the station keeps of the session's events for drawing: the newest camera image
/// (packed once per frame, not per redraw) and the newest warning.
#[derive(Debug, Default)]
struct Feed {
    image: Vec<u32>,
    image_size: (usize, usize),
    warning: Option<String>,
    mode: Mode,
    /// With `--ground-truth`: the newest result against its image's ground truth.
    judge: rover_core::LiveJudge,
    truth: Option<String>,
}

impl Observer for Feed {
    fn control(&mut self, _sim: &Simulation, _sample: &ControlSample, stats: &LoopStats) {
        self.mode = stats.mode;
    }
    fn camera_frame(&mut self, frame: &CameraFrame<'_>, _world_from_camera: Pose) {
        self.image.clear();
        self.image
            .extend(frame.rgb.chunks_exact(3).map(|p| pack([p[0], p[1], p[2]])));
        self.image_size = (frame.width as usize, frame.height as usize);
    }
    fn event(&mut self, _sim_time_s: f64, level: EventLevel, text: &str) {
        if level == EventLevel::Warn {
            self.warning = Some(text.to_owned());
        }
    }
    fn detections_truth(
        &mut self,
        boxes: &rover_perception::BoundingBoxes,
        truth: &[rover_sim::sensors::GroundTruthBox],
    ) {
        let matched = self.judge.judge(boxes, truth);
        hud::truth_text(self.truth.get_or_insert_with(String::new), matched, truth);
    }
}

/// Seconds between the window's status lines in the log.
const STATUS_EVERY_S: f64 = 10.0;

type Surface = softbuffer::Surface<Arc<Window>, Arc<Window>>;

struct App<'a, 'o> {
    session: Session,
    feed: Feed,
    observers: &'a mut Fanout<'o>,
    /// Input from outside (the ROS bridge's /cmd_vel), polled like the gamepad.
    external: &'a mut dyn InputSource,
    player: ScriptPlayer,
    keys: KeyTeleop,
    /// The arm keys' picked joint.
    arm: ArmKeys,
    options: WindowOptions,
    window: Option<Arc<Window>>,
    surface: Option<Surface>,
    error: Option<anyhow::Error>,
    canvas: Vec<u32>,
    canvas_size: (usize, usize),
    paused: bool,
    step_once: bool,
    /// (wall, sim) when pacing was last anchored.
    anchor: (Instant, f64),
    next_redraw: Instant,
    pads: Option<Gamepads>,
    started: Instant,
    rtf_window: (Instant, f64),
    rtf: f64,
    /// Closed by a signal.
    interrupted: bool,
    /// Start of the status log's window: wall time, sim time, detections.
    status_window: (Instant, f64, u64),
}

impl App<'_, '_> {
    fn input(&mut self, action: Action) {
        let mut obs = (&mut self.feed, &mut *self.observers);
        self.session.input(action, &mut obs);
    }

    /// Jogs the arm's picked joint one step.
    fn jog(&mut self, direction: i8) {
        if let Some(action) = self.arm.jog(self.session.sim(), direction) {
            self.input(action);
        }
    }

    /// Sends the arm to its "home" pose, when the robot has an arm.
    fn home(&mut self) {
        if !self.arm.is_empty() {
            self.input(Action::Joint(JointAction::Pose("home".into())));
        }
    }

    /// One physics step (with the script's due inputs); an observer that fails (a trace it
    /// cannot write) is said once in the log and the HUD, and the run goes on.
    fn step(&mut self) -> Result<Option<ControlSample>> {
        let mut obs = (&mut self.feed, &mut *self.observers);
        let sample = self.player.step(&mut self.session, &mut obs)?;
        if let Some(failure) = self.observers.failure() {
            self.observer_failed(&failure);
        }
        Ok(sample)
    }

    fn observer_failed(&mut self, failure: &CoreError) {
        let text = format!("{failure}; the run goes on without it");
        tracing::warn!("{text}");
        self.feed.warning = Some(text);
    }

    fn key(&mut self, name: &str, pressed: bool) {
        match self.keys.key(name, pressed, self.session.pilot().mode()) {
            Some(KeyCommand::Input(action)) => self.input(action),
            Some(KeyCommand::TogglePause) => {
                self.paused = !self.paused;
                self.anchor = (Instant::now(), self.session.sim().sim_time_s());
            }
            Some(KeyCommand::StepOnce) if self.paused => self.step_once = true,
            Some(KeyCommand::SelectJoint(i)) => self.arm.select(i),
            Some(KeyCommand::SelectToolAxis) if self.session.has_tool() => {
                self.arm.select_tool_axis();
            }
            Some(KeyCommand::Jog(direction)) => self.jog(direction),
            Some(KeyCommand::Home) => self.home(),
            Some(KeyCommand::StepOnce | KeyCommand::SelectToolAxis) | None => {}
        }
    }

    fn advance(&mut self) -> Result<bool> {
        let now = Instant::now();
        if let Some(pads) = self.pads.as_mut() {
            let teleop = self.session.pilot().teleop();
            match pads.poll(teleop.speed_mps, teleop.turn_radps) {
                Some(PadCommand::Drive(cmd)) => self.input(Action::CmdVel(cmd)),
                Some(PadCommand::ToggleFollow) => self.input(Action::ToggleFollow),
                Some(PadCommand::Stop) if self.session.pilot().mode() == Mode::Manual => {
                    self.input(Action::CmdVel(Twist::ZERO));
                }
                Some(PadCommand::NextJoint(step)) => self.arm.select_next(step),
                Some(PadCommand::Jog(direction)) => self.jog(direction),
                Some(PadCommand::Home) => self.home(),
                Some(PadCommand::Stop) | None => {}
            }
        }
        while let Some(action) = self.external.poll() {
            self.input(action);
        }
        let target = if self.paused {
            if std::mem::take(&mut self.step_once) {
                // One control update.
                while self.step()?.is_none() {}
            }
            self.session.sim().sim_time_s()
        } else {
            let (wall, sim) = self.anchor;
            sim + now.duration_since(wall).as_secs_f64() * self.options.real_time_factor
        };
        let target = self.options.duration_s.map_or(target, |d| target.min(d));
        let budget = now + Duration::from_millis(30);
        while self.session.sim().sim_time_s() + self.session.sim().dt_s() / 2.0 <= target {
            self.step()?;
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
        // A status line in the log every 10 s (what the HUD shows, for logs and soak runs).
        let (w0, s0, d0) = self.status_window;
        let dt = now.duration_since(w0).as_secs_f64();
        if dt >= STATUS_EVERY_S {
            let sim_s = self.session.sim().sim_time_s();
            let detections = self.session.detections();
            let stats = self.session.stats();
            tracing::info!(
                "status: sim {sim_s:.1} s, {:.2}x real time, detector {:.1} Hz, latency {:.0} ms, frames dropped {}",
                (sim_s - s0) / dt,
                (detections - d0) as f64 / dt,
                stats.detector_latency_ms,
                stats.frames_dropped
            );
            self.status_window = (now, sim_s, detections);
        }
        Ok(self
            .options
            .duration_s
            .is_some_and(|d| self.session.sim().sim_time_s() >= d - 1e-9))
    }

    fn compose(&mut self) {
        let (width, height) = self.canvas_size;
        let mut canvas = Canvas {
            pixels: &mut self.canvas,
            width,
            height,
        };
        hud::compose(
            &mut canvas,
            &hud::HudState {
                image: &self.feed.image,
                image_size: self.feed.image_size,
                warning: self.feed.warning.as_deref(),
                session: &self.session,
                paused: self.paused,
                real_time_factor: self.rtf,
                arm: arm::task_line(&self.session.stats().arm)
                    .or_else(|| self.arm.status(self.session.sim())),
                truth: self.feed.truth.as_deref(),
            },
        );
    }

    /// Shows the canvas, scaled to the window (nearest pixel, aspect kept).
    fn present(&mut self) -> Result<()> {
        let (Some(window), Some(surface)) = (&self.window, self.surface.as_mut()) else {
            return Ok(());
        };
        let size = window.inner_size();
        let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) else {
            return Ok(());
        };
        surface
            .resize(w, h)
            .map_err(|e| anyhow::anyhow!("cannot size the window's buffer: {e}"))?;
        let mut buffer = surface
            .buffer_mut()
            .map_err(|e| anyhow::anyhow!("cannot draw into the window: {e}"))?;
        let (cw, ch) = self.canvas_size;
        scale_into(
            &self.canvas,
            cw,
            ch,
            &mut buffer,
            w.get() as usize,
            h.get() as usize,
        );
        buffer
            .present()
            .map_err(|e| anyhow::anyhow!("cannot show the window's image: {e}"))?;
        Ok(())
    }
}

/// Nearest-pixel scaling of `src` (`sw` x `sh`) into `dst` (`dw` x `dh`), centred with the
/// aspect kept; the margins are the HUD's background.
fn scale_into(src: &[u32], sw: usize, sh: usize, dst: &mut [u32], dw: usize, dh: usize) {
    if sw == dw && sh == dh {
        dst.copy_from_slice(src);
        return;
    }
    dst.fill(pack(hud::BACKGROUND));
    let scale = (dw as f64 / sw as f64).min(dh as f64 / sh as f64);
    let (ow, oh) = ((sw as f64 * scale) as usize, (sh as f64 * scale) as usize);
    let (x0, y0) = ((dw - ow) / 2, (dh - oh) / 2);
    for y in 0..oh {
        let sy = (y * sh / oh.max(1)).min(sh - 1);
        let row = &src[sy * sw..(sy + 1) * sw];
        let out = &mut dst[(y0 + y) * dw + x0..(y0 + y) * dw + x0 + ow];
        for (x, px) in out.iter_mut().enumerate() {
            *px = row[(x * sw / ow.max(1)).min(sw - 1)];
        }
    }
}

impl ApplicationHandler for App<'_, '_> {
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
        let surface = softbuffer::Context::new(window.clone())
            .and_then(|context| Surface::new(&context, window.clone()));
        match surface {
            Ok(surface) => self.surface = Some(surface),
            Err(e) => {
                self.error = Some(anyhow::anyhow!("cannot draw into the window: {e}"));
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
                self.key(&name, pressed);
            }
            WindowEvent::RedrawRequested => {
                self.compose();
                if let Err(e) = self.present() {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self
            .options
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            self.interrupted = true;
            event_loop.exit();
            return;
        }
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

/// Runs the window until Esc, window close, or `duration_s`; `observers` (trace, frames,
/// recorder) watch the session as in headless runs.
pub fn run(
    session: Session,
    observers: &mut Fanout<'_>,
    external: &mut dyn InputSource,
    options: WindowOptions,
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
    let canvas_size = hud::canvas_size((w, h));
    let pads = match Gamepads::new() {
        Ok(p) => Some(p),
        Err(e) => {
            tracing::warn!("no gamepad support ({e}); keyboard only");
            None
        }
    };
    let arm = ArmKeys::new(session.sim());
    let mut app = App {
        arm,
        session,
        feed: Feed {
            image: Vec::with_capacity(w * h),
            ..Feed::default()
        },
        observers,
        external,
        player: ScriptPlayer::new(options.script.clone()),
        keys: KeyTeleop::new(KeyOptions {
            latched: options.latched,
            wasd: options.wasd,
        }),
        paused: options.paused,
        options,
        window: None,
        surface: None,
        error: None,
        canvas: vec![0; canvas_size.0 * canvas_size.1],
        canvas_size,
        step_once: false,
        anchor: (Instant::now(), 0.0),
        next_redraw: Instant::now(),
        pads,
        started: Instant::now(),
        rtf_window: (Instant::now(), 0.0),
        rtf: 0.0,
        status_window: (Instant::now(), 0.0, 0),
        interrupted: false,
    };
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.error {
        return Err(e);
    }
    if let Some(path) = app.options.screenshot.clone() {
        app.compose();
        let (w, h) = app.canvas_size;
        let rgb: Vec<u8> = app.canvas.iter().flat_map(|px| unpack(*px)).collect();
        image::save_buffer(
            &path,
            &rgb,
            w as u32,
            h as u32,
            image::ExtendedColorType::Rgb8,
        )
        .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(WindowSummary {
        sim_time_s: app.session.sim().sim_time_s(),
        wall_s: app.started.elapsed().as_secs_f64(),
        mode: app.feed.mode,
        interrupted: app.interrupted,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_keeps_the_aspect_and_centres() {
        let src: Vec<u32> = (0..4).collect(); // 2 x 2
        let mut dst = vec![7u32; 6 * 4];
        scale_into(&src, 2, 2, &mut dst, 6, 4);
        // 4 x 4 picture in the middle of 6 x 4, one column of margin each side.
        assert_eq!(
            &dst[0..6],
            &[pack(hud::BACKGROUND), 0, 0, 1, 1, pack(hud::BACKGROUND)]
        );
        assert_eq!(
            &dst[18..24],
            &[pack(hud::BACKGROUND), 2, 2, 3, 3, pack(hud::BACKGROUND)]
        );
        let mut same = vec![0u32; 4];
        scale_into(&src, 2, 2, &mut same, 2, 2);
        assert_eq!(same, src);
    }
}
