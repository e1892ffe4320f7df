//! The files a run writes, as observers every runner composes: the trace CSV
//! ([`TraceObserver`]), the camera frames ([`FrameSaver`]), and [`RunFiles`], both opened and
//! finished the same way by headless runs and the window.

use std::fs::File;
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

use rover_perception::BoundingBoxes;
use rover_sim::{
    geometry::Pose,
    model::CameraInfo,
    physics::{ControlSample, Simulation},
    sensors::{CameraFrame, GroundTruthBox},
};

use crate::error::{CoreError, Result};
use crate::judge::LiveJudge;
use crate::observer::{LoopStats, Observer};
use crate::trace::{TraceWriter, TruthColumns};

/// A buffered file that only ever holds whole lines: it writes its buffer up to the last
/// newline, and when a write fails (disk full) it cuts the file back to the end of the last
/// line written in full, so a trace stays readable up to its last complete row.
#[derive(Debug)]
struct RowFile {
    file: File,
    buffer: Vec<u8>,
    /// Bytes of whole lines in the file.
    durable: u64,
    /// Whole lines in the file.
    lines: u64,
}

impl RowFile {
    const CHUNK: usize = 64 << 10;

    /// Wraps a file opened for writing (at its start).
    fn new(file: File) -> Self {
        Self {
            file,
            buffer: Vec::with_capacity(Self::CHUNK * 2),
            durable: 0,
            lines: 0,
        }
    }

    /// Lines written to the file in full so far.
    fn lines_in_file(&self) -> u64 {
        self.lines
    }

    /// Writes the buffer's whole lines; on failure cuts the file back to `durable`.
    fn write_lines(&mut self) -> std::io::Result<()> {
        let Some(last_newline) = self.buffer.iter().rposition(|&b| b == b'\n') else {
            return Ok(());
        };
        let end = last_newline + 1;
        if let Err(e) = self.file.write_all(&self.buffer[..end]) {
            let _ = self.file.set_len(self.durable);
            let _ = self.file.seek(std::io::SeekFrom::Start(self.durable));
            self.buffer.clear();
            return Err(e);
        }
        self.durable += end as u64;
        self.lines += self.buffer[..end].iter().filter(|&&b| b == b'\n').count() as u64;
        self.buffer.drain(..end);
        Ok(())
    }
}

impl Write for RowFile {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.buffer.extend_from_slice(bytes);
        if self.buffer.len() >= Self::CHUNK {
            self.write_lines()?;
        }
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.write_lines()?;
        self.file.flush()
    }
}

/// Writes the trace CSV: one row per control update ([`TRACE_HEADER`](crate::TRACE_HEADER)).
#[derive(Debug)]
pub struct TraceObserver {
    path: PathBuf,
    /// The file until the run starts (the header needs the robot's joints).
    file: Option<RowFile>,
    writer: Option<TraceWriter<RowFile>>,
    /// The actuated joints, in column order.
    joints: Vec<rover_sim::model::JointId>,
    failed: Option<CoreError>,
    rows: u64,
    /// With ground truth on: judges each detection result for the ground-truth columns.
    judge: Option<LiveJudge>,
    /// The newest judged result's columns.
    truth: Option<TruthColumns>,
}

impl TraceObserver {
    /// Creates (truncates) the trace file; the header is written when the run starts.
    pub fn create(path: &Path) -> Result<Self> {
        Self::create_with(path, false)
    }

    /// As [`TraceObserver::create`]; with `ground_truth` (the run measures it) the trace has
    /// the ground-truth columns ([`crate::TRACE_TRUTH_COLUMNS`]).
    pub fn create_with(path: &Path, ground_truth: bool) -> Result<Self> {
        let file = File::create(path).map_err(|e| CoreError::write(path, e))?;
        Ok(Self {
            path: path.to_path_buf(),
            file: Some(RowFile::new(file)),
            writer: None,
            joints: Vec::new(),
            failed: None,
            rows: 0,
            judge: ground_truth.then(LiveJudge::default),
            truth: None,
        })
    }

    /// Rows written so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Flushes the file; returns the number of rows.
    pub fn finish(mut self) -> Result<u64> {
        if let Some(file) = self.file.take() {
            // The run never started: the header alone.
            self.writer =
                Some(TraceWriter::new(file).map_err(|e| CoreError::write(&self.path, e))?);
        }
        if let Some(w) = self.writer.take() {
            let mut file = w.into_inner();
            file.flush().map_err(|e| self.write_failed(e, &file))?;
        }
        Ok(self.rows)
    }

    /// A failed write, saying how many whole rows the file keeps ([`RowFile`] cut it back).
    fn write_failed(&self, e: std::io::Error, file: &RowFile) -> CoreError {
        let kept = file.lines_in_file().saturating_sub(1);
        CoreError::write(
            &self.path,
            std::io::Error::new(
                e.kind(),
                format!("{e}; the file keeps its first {kept} rows, each complete"),
            ),
        )
    }
}

impl Observer for TraceObserver {
    fn start(&mut self, sim: &Simulation, _camera: Option<&CameraInfo>, _labels: &[String]) {
        let Some(file) = self.file.take() else {
            return;
        };
        let robot = sim.robot();
        self.joints = robot.actuated_joints();
        let names: Vec<&str> = self
            .joints
            .iter()
            .map(|j| robot.joint(*j).name.as_str())
            .collect();
        match TraceWriter::with_columns(file, self.judge.is_some(), &names) {
            Ok(w) => self.writer = Some(w),
            Err(e) => self.failed = Some(CoreError::write(&self.path, e)),
        }
    }

    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        if let Some(w) = self.writer.as_mut() {
            let joints = self
                .joints
                .iter()
                .map(|j| sim.joint_state(*j).unwrap_or_default());
            let state = (stats.mode, stats.follow_state);
            match w.full_row(sample, state, self.truth.as_ref(), joints) {
                Ok(()) => self.rows += 1,
                Err(e) => {
                    if let Some(w) = self.writer.take() {
                        self.failed = Some(self.write_failed(e, &w.into_inner()));
                    }
                }
            }
        }
    }
    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        if let Some(judge) = self.judge.as_mut() {
            let frame = judge.judge(boxes, truth);
            self.truth = Some(TruthColumns::of(boxes.image_stamp.frame, frame));
        }
    }
    fn failure(&mut self) -> Option<CoreError> {
        self.failed.take()
    }
}

/// Writes the robot camera's images as PNG (`frame_NNNNNN.png`, by frame number), every Nth.
#[derive(Debug)]
pub struct FrameSaver {
    dir: PathBuf,
    every: u64,
    written: u64,
    failed: Option<CoreError>,
    stopped: bool,
}

impl FrameSaver {
    /// Creates `dir` if needed; `every` = 1 writes every image.
    pub fn new(dir: &Path, every: u64) -> Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| CoreError::write(dir, e))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            every: every.max(1),
            written: 0,
            failed: None,
            stopped: false,
        })
    }

    /// Images written so far.
    pub fn written(&self) -> u64 {
        self.written
    }

    /// The folder images go to.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

impl Observer for FrameSaver {
    fn camera_frame(&mut self, frame: &CameraFrame<'_>, _world_from_camera: Pose) {
        if self.stopped || !frame.seq.is_multiple_of(self.every) {
            return;
        }
        let path = self.dir.join(format!("frame_{:06}.png", frame.seq));
        match image::save_buffer(
            &path,
            frame.rgb,
            frame.width,
            frame.height,
            image::ExtendedColorType::Rgb8,
        ) {
            Ok(()) => self.written += 1,
            Err(e) => {
                self.stopped = true;
                self.failed = Some(CoreError::write(&path, std::io::Error::other(e)));
            }
        }
    }
    fn failure(&mut self) -> Option<CoreError> {
        self.failed.take()
    }
}

/// The files a run writes besides a recording: the trace and the camera frames, as one
/// observer. Headless runs and the window open them the same way.
#[derive(Debug, Default)]
pub struct RunFiles {
    /// `--trace`.
    pub trace: Option<TraceObserver>,
    /// `--save-frames`.
    pub frames: Option<FrameSaver>,
}

/// What [`RunFiles`] wrote.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RunFilesWritten {
    /// Trace rows.
    pub rows: u64,
    /// Camera images.
    pub frames: u64,
}

impl RunFiles {
    /// Creates the trace file (with the ground-truth columns when the run measures
    /// `ground_truth`) and the frames folder, as asked.
    pub fn open(
        trace: Option<&Path>,
        save_frames: Option<&Path>,
        frame_every: u64,
        ground_truth: bool,
    ) -> Result<Self> {
        Ok(Self {
            trace: trace
                .map(|p| TraceObserver::create_with(p, ground_truth))
                .transpose()?,
            frames: save_frames
                .map(|dir| FrameSaver::new(dir, frame_every))
                .transpose()?,
        })
    }

    /// Flushes the trace; says where the frames went.
    pub fn finish(self) -> Result<RunFilesWritten> {
        let rows = self
            .trace
            .map(TraceObserver::finish)
            .transpose()?
            .unwrap_or(0);
        let frames = self.frames.as_ref().map_or(0, FrameSaver::written);
        if let Some(f) = &self.frames {
            tracing::info!(
                "wrote {} camera frames to {}",
                f.written(),
                f.dir().display()
            );
        }
        Ok(RunFilesWritten { rows, frames })
    }
}

impl Observer for RunFiles {
    fn start(&mut self, sim: &Simulation, camera: Option<&CameraInfo>, labels: &[String]) {
        if let Some(t) = self.trace.as_mut() {
            t.start(sim, camera, labels);
        }
    }
    fn control(&mut self, sim: &Simulation, sample: &ControlSample, stats: &LoopStats) {
        if let Some(t) = self.trace.as_mut() {
            t.control(sim, sample, stats);
        }
    }
    fn camera_frame(&mut self, frame: &CameraFrame<'_>, world_from_camera: Pose) {
        if let Some(f) = self.frames.as_mut() {
            f.camera_frame(frame, world_from_camera);
        }
    }
    fn detections_truth(&mut self, boxes: &BoundingBoxes, truth: &[GroundTruthBox]) {
        if let Some(t) = self.trace.as_mut() {
            t.detections_truth(boxes, truth);
        }
    }
    fn failure(&mut self) -> Option<CoreError> {
        self.trace
            .as_mut()
            .and_then(Observer::failure)
            .or_else(|| self.frames.as_mut().and_then(Observer::failure))
    }
}
