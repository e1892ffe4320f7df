//! Lockstep detection for deterministic headless runs: the detector runs synchronously on the
//! calling thread at a fixed rate on sim time, so the same run always sees the same boxes at the
//! same sim times (the threaded [`crate::DetectorWorker`] depends on wall-clock speed).

use crate::detector::Detect;
use crate::error::{PerceptionError, Result};
use crate::messages::{BoundingBoxes, FrameStamp};
use crate::preprocess::RgbView;
use crate::worker::panic_text;

/// A detector called synchronously at a fixed sim-time rate.
pub struct LockstepDetector {
    detector: Box<dyn Detect>,
    period_s: f64,
    next_s: f64,
}

impl std::fmt::Debug for LockstepDetector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LockstepDetector")
            .field("period_s", &self.period_s)
            .field("next_s", &self.next_s)
            .finish_non_exhaustive()
    }
}

impl LockstepDetector {
    /// Runs `detector` (a [`crate::Detector`], or one wrapped in a [`crate::FaultInjector`]) at
    /// `rate_hz` on sim time (the first frame at or after t = 0 is detected).
    pub fn new(detector: impl Detect + 'static, rate_hz: f64) -> Result<Self> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(PerceptionError::Inference(format!(
                "lockstep detection rate must be a positive number of Hz, found {rate_hz}"
            )));
        }
        Ok(Self {
            detector: Box::new(detector),
            period_s: 1.0 / rate_hz,
            next_s: 0.0,
        })
    }

    /// True when a frame taken at `sim_time_s` should be detected.
    pub fn due(&self, sim_time_s: f64) -> bool {
        sim_time_s + 1e-9 >= self.next_s
    }

    /// Detects `image` if it is due (by its stamp's sim time), advancing the schedule like a
    /// fixed-rate timer (`next += period`, resynchronised if far behind).
    pub fn detect_if_due(
        &mut self,
        image: RgbView<'_>,
        stamp: FrameStamp,
    ) -> Result<Option<BoundingBoxes>> {
        if !self.due(stamp.sim_time_s) {
            return Ok(None);
        }
        self.next_s += self.period_s;
        if self.next_s + 1e-9 < stamp.sim_time_s {
            self.next_s = stamp.sim_time_s + self.period_s;
        }
        // A panic in the detector (rover, tract or the model) becomes an error, as on the
        // worker thread: the run goes on without detections instead of ending.
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.detector.detect(image, stamp)
        }))
        .map_err(|payload| PerceptionError::Panicked(panic_text(payload.as_ref())))?
        .map(Some)
    }
}
