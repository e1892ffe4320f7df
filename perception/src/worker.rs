//! The detector on its own thread. It always works on the newest frame: a frame submitted while
//! another waits replaces it (the stale one is dropped and counted), so detections never lag
//! behind a queue.

use std::collections::VecDeque;
use std::sync::mpsc::{self, Receiver, Sender};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;

use crate::detector::Detect;
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
    /// Frames waiting, oldest first: at most one after [`DetectorWorker::submit`], as many as
    /// queued with [`DetectorWorker::submit_queued`].
    pending: VecDeque<Frame>,
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
    /// Moves `detector` (a [`crate::Detector`], or one wrapped in a [`crate::FaultInjector`])
    /// onto a new thread.
    pub fn spawn(mut detector: impl Detect + 'static) -> Result<Self> {
        Self::spawn_with(move |view, stamp| detector.detect(view, stamp))
    }

    /// Runs any detection function on a new thread (a detector, or a stand-in in tests).
    fn spawn_with<F>(mut detect: F) -> Result<Self>
    where
        F: FnMut(RgbView<'_>, FrameStamp) -> Result<BoundingBoxes> + Send + 'static,
    {
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
                            if let Some(frame) = slot.pending.pop_front() {
                                break frame;
                            }
                            slot = thread_shared
                                .1
                                .wait(slot)
                                .unwrap_or_else(PoisonError::into_inner);
                        }
                    };
                    // A panic in the detector (rover, tract or the model) must not end the
                    // thread silently: it becomes an error the session reports, and the
                    // thread stops, since the detector's state is no longer trustworthy.
                    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        RgbView::new(frame.width, frame.height, &frame.pixels)
                            .and_then(|view| detect(view, frame.stamp))
                    }))
                    .unwrap_or_else(|payload| {
                        Err(PerceptionError::Panicked(panic_text(payload.as_ref())))
                    });
                    let panicked = matches!(result, Err(PerceptionError::Panicked(_)));
                    lock(&thread_shared).stats.processed += 1;
                    // Receivers gone means the worker is being dropped: just stop.
                    if result_tx.send(result).is_err() || panicked {
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

    /// Hands a frame to the detector, replacing (dropping) any still waiting.
    pub fn submit(&self, frame: Frame) {
        {
            let mut slot = lock(&self.shared);
            slot.stats.submitted += 1;
            while let Some(stale) = slot.pending.pop_front() {
                slot.stats.dropped += 1;
                let _ = self.recycle.send(stale.pixels);
            }
            slot.pending.push_back(frame);
        }
        self.shared.1.notify_one();
    }

    /// Queues a frame behind any still waiting, dropping none: every queued frame gets its
    /// result, in order (for a caller that takes each result, like pipelined detection, and so
    /// bounds the queue).
    pub fn submit_queued(&self, frame: Frame) {
        {
            let mut slot = lock(&self.shared);
            slot.stats.submitted += 1;
            slot.pending.push_back(frame);
        }
        self.shared.1.notify_one();
    }

    /// The newest result since the last call, if any (older boxes are skipped; an error is
    /// never skipped). A worker thread that has stopped reports [`PerceptionError::WorkerGone`].
    pub fn latest(&self) -> Option<Result<BoundingBoxes>> {
        let mut newest = None;
        loop {
            match self.results.try_recv() {
                Ok(Ok(boxes)) => newest = Some(Ok(boxes)),
                Ok(Err(e)) => return Some(Err(e)),
                Err(mpsc::TryRecvError::Empty) => return newest,
                Err(mpsc::TryRecvError::Disconnected) => {
                    return Some(newest.unwrap_or_else(|| {
                        Err(PerceptionError::WorkerGone(
                            "the detector thread ended unexpectedly".into(),
                        ))
                    }));
                }
            }
        }
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

/// The message of a caught panic.
pub(crate) fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic without a message".to_owned())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(n: u64) -> Frame {
        Frame {
            pixels: vec![0; 4 * 4 * 3],
            width: 4,
            height: 4,
            stamp: FrameStamp {
                sim_time_s: n as f64,
                frame: n,
            },
        }
    }

    fn empty(stamp: FrameStamp) -> BoundingBoxes {
        BoundingBoxes {
            image_stamp: stamp,
            frame_id: "camera".into(),
            bounding_boxes: Vec::new(),
            latency_ms: 0.0,
        }
    }

    #[test]
    fn a_panic_in_the_detector_becomes_an_error_not_silence() -> Result<()> {
        let worker = DetectorWorker::spawn_with(|_view, stamp| {
            if stamp.frame == 2 {
                panic!("index out of bounds in a test detector");
            }
            Ok(empty(stamp))
        })?;
        worker.submit(frame(1));
        assert_eq!(worker.wait()?.image_stamp.frame, 1);
        worker.submit(frame(2));
        let err = worker
            .wait()
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(
            err.contains("crashed") && err.contains("index out of bounds"),
            "{err}"
        );
        // The thread stops: later calls say so instead of waiting forever. (`wait` returns
        // once the thread has exited, whenever that is; `latest` may still see it exiting.)
        worker.submit(frame(3));
        match worker.wait() {
            Err(PerceptionError::WorkerGone(_)) => {}
            other => panic!("expected WorkerGone, got {other:?}"),
        }
        match worker.latest() {
            Some(Err(PerceptionError::WorkerGone(_))) => {}
            other => panic!("expected WorkerGone once the thread is gone, got {other:?}"),
        }
        Ok(())
    }

    #[test]
    fn latest_never_skips_an_error() -> Result<()> {
        let worker = DetectorWorker::spawn_with(|_view, stamp| {
            if stamp.frame == 1 {
                Err(PerceptionError::Inference("bad frame".into()))
            } else {
                Ok(empty(stamp))
            }
        })?;
        worker.submit(frame(1));
        // Wait until both results are queued, then ask once.
        while worker.stats().processed < 1 {
            std::thread::yield_now();
        }
        worker.submit(frame(2));
        while worker.stats().processed < 2 {
            std::thread::yield_now();
        }
        assert!(matches!(
            worker.latest(),
            Some(Err(PerceptionError::Inference(_)))
        ));
        Ok(())
    }
}
