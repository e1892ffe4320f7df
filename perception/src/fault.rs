//! Detector faults injected on purpose (`--inject-fault`), for tests of what a failing detector
//! does to a run.
//!
//! The fault lives in a wrapper, not in the detector: [`Detector::detect`] never checks for
//! one. Whoever runs a detector for a session (rover-core's `Session`) wraps the loaded
//! [`Detector`] in a [`FaultInjector`] only when a fault is asked for, and hands either to the
//! worker thread or the lockstep detector through the [`Detect`] trait. So the fault fails
//! exactly where a real one would: a panic on the worker's thread becomes
//! [`crate::PerceptionError::Panicked`], one on the loop's thread (lockstep) is caught there.

use crate::detector::{Detect, Detector};
use crate::error::{PerceptionError, Result};
use crate::messages::{BoundingBoxes, FrameStamp};
use crate::preprocess::RgbView;

/// A detector fault injected on purpose: after `after_detections` good detections, every
/// further call panics or returns an error, as a bug in tract or a model it cannot run would.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InjectedFault {
    /// Good detections before the fault.
    pub after_detections: u64,
    /// What happens then.
    pub kind: FaultKind,
}

/// How an [`InjectedFault`] fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultKind {
    /// The detection panics.
    Panic,
    /// The detection returns an error.
    Error,
}

/// A [`Detector`] that fails as its [`InjectedFault`] says.
#[derive(Debug)]
pub struct FaultInjector {
    detector: Detector,
    fault: InjectedFault,
    /// Detections run so far.
    detections: u64,
}

impl FaultInjector {
    /// Wraps `detector`: it detects `fault.after_detections` times, then fails every call.
    pub fn new(detector: Detector, fault: InjectedFault) -> Self {
        Self {
            detector,
            fault,
            detections: 0,
        }
    }
}

impl Detect for FaultInjector {
    fn detect(&mut self, image: RgbView<'_>, stamp: FrameStamp) -> Result<BoundingBoxes> {
        if self.detections >= self.fault.after_detections {
            let what = format!(
                "injected fault after {} detections (--inject-fault)",
                self.fault.after_detections
            );
            match self.fault.kind {
                FaultKind::Panic => panic!("{what}"),
                FaultKind::Error => {
                    return Err(PerceptionError::model(self.detector.model_path(), what));
                }
            }
        }
        self.detections += 1;
        self.detector.detect(image, stamp)
    }
}
