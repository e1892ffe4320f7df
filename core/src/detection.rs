//! The detector's schedule, as the session runs it: which camera images it takes, where it
//! runs, and when its results come back ([`DetectorMode`]). The session renders the image and
//! hands it over; this decides the rest, so the session's step reads the same for every mode.

use std::time::Instant;

use rover_perception::{
    BoundingBoxes, Detect, Detector, DetectorConfig, DetectorWorker, FaultInjector, Frame,
    FrameStamp, InjectedFault, LockstepDetector, PerceptionError, RgbView, WorkerStats,
};
use rover_sim::sensors::CameraFrame;

use crate::error::{CoreError, Result};

/// How detection runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DetectorMode {
    /// No camera processing: the follower holds still.
    Off,
    /// Synchronously on the loop's thread at this rate on sim time (deterministic).
    Lockstep {
        /// Detections per sim second.
        rate_hz: f64,
    },
    /// At this rate on sim time, on a second thread while the simulation and camera go on;
    /// each result is handed to the follower one detection period (sim time) after its image
    /// was taken, waiting for the thread if it is not done. Deterministic like `Lockstep`
    /// (the same images, the same delivery times whatever the wall clock does), using two
    /// cores.
    Pipelined {
        /// Detections per sim second.
        rate_hz: f64,
    },
    /// On its own thread, always on the newest frame (interactive, real time).
    Worker,
}

/// A detector's result: its boxes, or its failure.
pub(crate) type Detected = std::result::Result<BoundingBoxes, PerceptionError>;

/// The detector as the session runs it ([`DetectorMode`], once loaded).
pub(crate) enum Detection {
    /// No detector.
    Off,
    /// [`DetectorMode::Lockstep`].
    Lockstep(Box<LockstepDetector>),
    /// [`DetectorMode::Pipelined`].
    Pipelined(Box<Pipelined>),
    /// [`DetectorMode::Worker`].
    Worker(DetectorWorker),
}

/// [`DetectorMode::Pipelined`]: a worker thread fed on a sim-time schedule, its results taken
/// at a fixed sim-time delay. At most one image is in flight.
pub(crate) struct Pipelined {
    worker: DetectorWorker,
    period_s: f64,
    /// Sim time from which the next image is detected.
    next_s: f64,
    /// When the image in flight is due back (its stamp + one period).
    deliver_at_s: Option<f64>,
}

impl Detection {
    /// Loads the detector and starts it in `mode` (not [`DetectorMode::Off`]), with its class
    /// names; the inner error when it cannot be loaded (the session runs on without one). A bad
    /// pipelined rate is an error.
    pub fn start(
        mode: DetectorMode,
        config: &DetectorConfig,
        inject_fault: Option<InjectedFault>,
    ) -> Result<std::result::Result<(Self, Vec<String>), PerceptionError>> {
        let detector = match Detector::load(config.clone()) {
            Ok(detector) => detector,
            Err(e) => return Ok(Err(e)),
        };
        let labels = detector.labels().to_vec();
        tracing::info!(
            "detector: {} at {}x{} on {}, {} thread(s)",
            detector.model_path().display(),
            detector.input_size().0,
            detector.input_size().1,
            detector.config().runtime.name(),
            detector.config().threads
        );
        let detector: Box<dyn Detect> = match inject_fault {
            Some(fault) => Box::new(FaultInjector::new(detector, fault)),
            None => Box::new(detector),
        };
        let detection = match mode {
            DetectorMode::Lockstep { rate_hz } => {
                Self::Lockstep(Box::new(LockstepDetector::new(detector, rate_hz)?))
            }
            DetectorMode::Pipelined { rate_hz } => {
                if !(rate_hz.is_finite() && rate_hz > 0.0) {
                    return Err(CoreError::Option(format!(
                        "the detection rate must be a positive number of Hz, found {rate_hz}"
                    )));
                }
                Self::Pipelined(Box::new(Pipelined {
                    worker: DetectorWorker::spawn(detector)?,
                    period_s: 1.0 / rate_hz,
                    next_s: 0.0,
                    deliver_at_s: None,
                }))
            }
            DetectorMode::Worker | DetectorMode::Off => {
                Self::Worker(DetectorWorker::spawn(detector)?)
            }
        };
        Ok(Ok((detection, labels)))
    }

    /// Whether there is no detector (none asked for, none loaded, or it failed).
    pub fn is_off(&self) -> bool {
        matches!(self, Self::Off)
    }

    /// The worker's newest result, whenever it is ready, with its counters.
    pub fn latest(&self) -> Option<(Detected, WorkerStats)> {
        match self {
            Self::Worker(worker) => worker.latest().map(|r| (r, worker.stats())),
            _ => None,
        }
    }

    /// Whether a pipelined result is due at `now_s` (then it is owed: taken this step).
    pub fn take_owed(&mut self, now_s: f64) -> bool {
        match self {
            Self::Pipelined(p) if p.deliver_at_s.is_some_and(|t| now_s + 1e-9 >= t) => {
                p.deliver_at_s = None;
                true
            }
            _ => false,
        }
    }

    /// Waits for the owed pipelined result.
    pub fn wait_owed(&self) -> Option<Detected> {
        match self {
            Self::Pipelined(p) => Some(p.worker.wait()),
            _ => None,
        }
    }

    /// Whether the detector would take a camera image due at `now_s` (an image nobody else
    /// looks at is not rendered otherwise).
    pub fn wants_image(&self, now_s: f64) -> bool {
        match self {
            Self::Off => false,
            Self::Lockstep(d) => d.due(now_s),
            Self::Pipelined(p) => now_s + 1e-9 >= p.next_s,
            Self::Worker(_) => true,
        }
    }

    /// Hands `frame` (stamped `stamp`) to the detector when it takes it: a lockstep result at
    /// once; a pipelined image queued, and the result in flight (`owed`, or still out when the
    /// camera is slower than the detection rate) waited for and returned, `owed` cleared; a
    /// worker's image submitted (its first one starts `worker_started`).
    pub fn submit(
        &mut self,
        frame: &CameraFrame<'_>,
        stamp: FrameStamp,
        owed: &mut bool,
        worker_started: &mut Option<Instant>,
    ) -> Option<Detected> {
        match self {
            Self::Off => None,
            Self::Lockstep(detector) => {
                RgbView::new(frame.width as usize, frame.height as usize, frame.rgb)
                    .and_then(|view| detector.detect_if_due(view, stamp))
                    .transpose()
            }
            Self::Pipelined(p) => {
                if frame.sim_time_s + 1e-9 < p.next_s {
                    return None;
                }
                p.next_s += p.period_s;
                if p.next_s + 1e-9 < frame.sim_time_s {
                    p.next_s = frame.sim_time_s + p.period_s;
                }
                // Queued behind the one in flight; that one (due now, or still out when the
                // camera is slower than the detection rate) is taken right after, on sim time
                // like everything else: never two results outstanding.
                let still_out = p.deliver_at_s.take().is_some();
                let earlier = std::mem::take(owed) || still_out;
                p.worker
                    .submit_queued(worker_frame(&p.worker, frame, stamp));
                p.deliver_at_s = Some(frame.sim_time_s + p.period_s);
                earlier.then(|| p.worker.wait())
            }
            Self::Worker(worker) => {
                let detector_frame = worker_frame(worker, frame, stamp);
                worker_started.get_or_insert_with(Instant::now);
                worker.submit(detector_frame);
                None
            }
        }
    }
}

/// A camera image copied into one of `worker`'s recycled buffers, as the detector takes it.
fn worker_frame(worker: &DetectorWorker, frame: &CameraFrame<'_>, stamp: FrameStamp) -> Frame {
    let mut pixels = worker.buffer();
    pixels.clear();
    pixels.extend_from_slice(frame.rgb);
    Frame {
        pixels,
        width: frame.width as usize,
        height: frame.height as usize,
        stamp,
    }
}
