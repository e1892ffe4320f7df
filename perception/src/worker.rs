//! The detector on its own thread. It always works on the newest frame: a frame submitted while
//! another waits replaces it (the stale one is dropped and counted), so detections never lag
//! behind a queue.

use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;

use crate::detector::Detector;
use crate::error::{PerceptionError, Result};
use crate::messages::{BoundingBoxes, FrameStamp};
use crate::preprocess::RgbView;

/// An RGB8 camera frame handed to the worker.
#[derive(Debug, Clone, Default)]
pub struct Frame {
    /// `width * height * 3` bytes.
    pub pixels: Vec<u8>,
    /// Width (px).
    pub width: usize,
    /// Height (px).
    pub height: usize,
    /// Which image this is.
    pub stamp: FrameStamp,
}

/// Counters of a worker's life.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WorkerStats {
    /// Frames submitted.
    pub submitted: u64,
    /// Frames detected.
    pub processed: u64,
    /// Frames replaced by a newer one before the detector got to them.
    pub dropped: u64,
}

#[derive(Default)]
struct Slot {
    pending: Option<Frame>,
    shutdown: bool,
    stats: WorkerStats,
}

type Shared = Arc<(Mutex<Slot>, Condvar)>;

/// A detector running on a background thread.
pub struct DetectorWorker {
    shared: Shared,
    results: Receiver<Result<BoundingBoxes>>,
    recycled: Receiver<Vec<u8>>,
    recycle: Sender<Vec<u8>>,
    handle: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for DetectorWorker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DetectorWorker")
            .field("stats", &self.stats())
            .finish()
    }
}

fn lock(shared: &Shared) -> std::sync::MutexGuard<'_, Slot> {
    shared.0.lock().unwrap_or_else(PoisonError::into_inner)
}

impl DetectorWorker {
    /// Moves `detector` onto a new thread.
    pub fn spawn(mut detector: Detector) -> Result<Self> {
        let shared: Shared = Arc::default();
        let (result_tx, results) = mpsc::channel();
        let (recycle, recycled) = mpsc::channel::<Vec<u8>>();
        let thread_shared = Arc::clone(&shared);
        let thread_recycle = recycle.clone();
        let handle = std::thread::Builder::new()
            .name("rover-detector".to_owned())
            .spawn(move || {
                loop {
                    let frame = {
                        let mut slot = lock(&thread_shared);
                        loop {
                            if slot.shutdown {
                                return;
                            }
                            if let Some(frame) = slot.pending.take() {
                                break frame;
                            }
                            slot = thread_shared
                                .1
                                .wait(slot)
                                .unwrap_or_else(PoisonError::into_inner);
                        }
                    };
                    let result = RgbView::new(frame.width, frame.height, &frame.pixels)
                        .and_then(|view| detector.detect(view, frame.stamp));
                    lock(&thread_shared).stats.processed += 1;
                    // Receivers gone means the worker is being dropped: just stop.
                    if result_tx.send(result).is_err() {
                        return;
                    }
                    let _ = thread_recycle.send(frame.pixels);
                }
            })
            .map_err(|e| {
                PerceptionError::WorkerGone(format!("cannot start the detector thread: {e}"))
            })?;
        Ok(Self {
            shared,
            results,
            recycled,
            recycle,
            handle: Some(handle),
        })
    }

    /// A pixel buffer to fill for the next frame: a recycled one when available.
    pub fn buffer(&self) -> Vec<u8> {
        self.recycled.try_recv().unwrap_or_default()
    }

    /// Hands a frame to the detector, replacing (dropping) one still waiting.
    pub fn submit(&self, frame: Frame) {
        let stale = {
            let mut slot = lock(&self.shared);
            slot.stats.submitted += 1;
            let stale = slot.pending.replace(frame);
            if stale.is_some() {
                slot.stats.dropped += 1;
            }
            stale
        };
        self.shared.1.notify_one();
        if let Some(stale) = stale {
            let _ = self.recycle.send(stale.pixels);
        }
    }

    /// The newest result since the last call, if any (older ones are skipped).
    pub fn latest(&self) -> Option<Result<BoundingBoxes>> {
        self.results.try_iter().last()
    }

    /// Waits for the next result (for tools and tests).
    pub fn wait(&self) -> Result<BoundingBoxes> {
        self.results
            .recv()
            .map_err(|e| PerceptionError::WorkerGone(e.to_string()))?
    }

    /// Counters so far.
    pub fn stats(&self) -> WorkerStats {
        lock(&self.shared).stats
    }
}

impl Drop for DetectorWorker {
    fn drop(&mut self) {
        lock(&self.shared).shutdown = true;
        self.shared.1.notify_all();
        if let Some(handle) = self.handle.take() {
            let _ = handle.join();
        }
    }
}
