//! The trace CSV: one row per diff-drive control update. With ground truth on
//! (`--ground-truth`) the fixed columns are followed by [`TRACE_TRUTH_COLUMNS`]: how the newest
//! judged detection result matched its image's ground truth. A robot with actuated joints gets
//! three more columns per joint after those: `<joint>.position`, `<joint>.velocity` and
//! `<joint>.effort` (rad or m, rad/s or m/s, N m or N).

use std::io::Write;

use rover_sim::physics::{ControlSample, JointState};

use crate::follower::FollowState;
use crate::pilot::Mode;

/// The fixed columns of the trace CSV (joint columns follow for robots with actuated joints).
pub const TRACE_HEADER: &str = "sim_time_s,x_m,y_m,yaw_rad,odom_x_m,odom_y_m,odom_yaw_rad,cmd_linear_mps,cmd_angular_radps,mode,follow_state";

/// The ground-truth columns (with `--ground-truth`), after the fixed ones: the newest detection
/// result judged against its own image's ground truth at IoU >= 0.5 — that image's frame
/// number, the labelled things to find in it (ignore regions left out), how many the
/// detections found and missed, the detections that matched nothing (false positives), and
/// the mean IoU of the found ones. Empty until the first result.
pub const TRACE_TRUTH_COLUMNS: &str =
    "truth_image,truth_things,truth_found,truth_missed,truth_false,truth_mean_iou";

/// How one detection result matched its image's ground truth (the trace's
/// [`TRACE_TRUTH_COLUMNS`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TruthColumns {
    /// The frame number of the image the detections came from.
    pub image: u64,
    /// Labelled things to find in it (not ignore regions).
    pub things: u32,
    /// Things a detection found (IoU >= 0.5, same class).
    pub found: u32,
    /// Things no detection found.
    pub missed: u32,
    /// Detections that matched nothing and lie on no ignore region.
    pub false_positives: u32,
    /// Mean IoU of the found things (`None` when nothing was found).
    pub mean_iou: Option<f64>,
}

impl TruthColumns {
    /// The columns of one judged frame.
    pub fn of(image: u64, m: &rover_perception::FrameMatch) -> Self {
        let found = m.matches.len();
        Self {
            image,
            things: (found + m.misses.len()) as u32,
            found: found as u32,
            missed: m.misses.len() as u32,
            false_positives: m.false_positives.len() as u32,
            mean_iou: (found > 0)
                .then(|| m.matches.iter().map(|p| p.iou).sum::<f64>() / found as f64),
        }
    }
}

/// Writes trace rows with fixed formatting, so identical runs give identical bytes.
#[derive(Debug)]
pub struct TraceWriter<W: Write> {
    out: W,
    rows: u64,
    truth_columns: bool,
}

impl<W: Write> TraceWriter<W> {
    /// Starts a trace, writing the header.
    pub fn new(out: W) -> std::io::Result<Self> {
        Self::with_joints(out, &[])
    }

    /// Starts a trace with three columns per joint of `joints` after the fixed ones.
    pub fn with_joints(out: W, joints: &[&str]) -> std::io::Result<Self> {
        Self::with_columns(out, false, joints)
    }

    /// Starts a trace with the ground-truth columns ([`TRACE_TRUTH_COLUMNS`]) when
    /// `truth_columns`, then three columns per joint of `joints`.
    pub fn with_columns(mut out: W, truth_columns: bool, joints: &[&str]) -> std::io::Result<Self> {
        write!(out, "{TRACE_HEADER}")?;
        if truth_columns {
            write!(out, ",{TRACE_TRUTH_COLUMNS}")?;
        }
        for j in joints {
            write!(out, ",{j}.position,{j}.velocity,{j}.effort")?;
        }
        writeln!(out)?;
        Ok(Self {
            out,
            rows: 0,
            truth_columns,
        })
    }

    /// Appends one row. `state` is what the follower is doing (in manual mode too: it keeps
    /// watching).
    pub fn row(
        &mut self,
        s: &ControlSample,
        mode: Mode,
        state: FollowState,
    ) -> std::io::Result<()> {
        self.row_with_joints(s, (mode, state), std::iter::empty())
    }

    /// Appends one row with the joints' states, in the header's joint order.
    pub fn row_with_joints(
        &mut self,
        s: &ControlSample,
        (mode, state): (Mode, FollowState),
        joints: impl Iterator<Item = JointState>,
    ) -> std::io::Result<()> {
        self.full_row(s, (mode, state), None, joints)
    }

    /// Appends one row: with the ground-truth columns, `truth` (empty fields while `None`),
    /// then the joints' states in the header's joint order.
    pub fn full_row(
        &mut self,
        s: &ControlSample,
        (mode, state): (Mode, FollowState),
        truth: Option<&TruthColumns>,
        joints: impl Iterator<Item = JointState>,
    ) -> std::io::Result<()> {
        let g = &s.ground_truth;
        let o = &s.odometry;
        write!(
            self.out,
            "{:.4},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{},{}",
            s.sim_time_s,
            g.x_m,
            g.y_m,
            g.yaw_rad,
            o.x_m,
            o.y_m,
            o.yaw_rad,
            s.cmd.linear_mps,
            s.cmd.angular_radps,
            mode.as_str(),
            state.as_str()
        )?;
        if self.truth_columns {
            match truth {
                Some(t) => {
                    write!(
                        self.out,
                        ",{},{},{},{},{},",
                        t.image, t.things, t.found, t.missed, t.false_positives
                    )?;
                    if let Some(iou) = t.mean_iou {
                        write!(self.out, "{iou:.4}")?;
                    }
                }
                None => write!(self.out, ",,,,,,")?,
            }
        }
        for j in joints {
            write!(
                self.out,
                ",{:.6},{:.6},{:.4}",
                j.position, j.velocity, j.effort
            )?;
        }
        writeln!(self.out)?;
        self.rows += 1;
        Ok(())
    }

    /// Rows written so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// The writer, without flushing it.
    pub fn into_inner(self) -> W {
        self.out
    }

    /// Flushes and returns the writer.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

/// One parsed trace row (for tests and tools that read traces back).
#[derive(Debug, Clone, PartialEq)]
pub struct TraceRow {
    /// Sim time (s).
    pub sim_time_s: f64,
    /// Ground-truth x (m).
    pub x_m: f64,
    /// Ground-truth y (m).
    pub y_m: f64,
    /// Ground-truth yaw (rad).
    pub yaw_rad: f64,
    /// Odometry x (m).
    pub odom_x_m: f64,
    /// Odometry y (m).
    pub odom_y_m: f64,
    /// Odometry yaw (rad).
    pub odom_yaw_rad: f64,
    /// Commanded linear.x (m/s).
    pub cmd_linear_mps: f64,
    /// Commanded angular.z (rad/s).
    pub cmd_angular_radps: f64,
    /// `manual` or `follow`.
    pub mode: String,
    /// The follower's state ([`FollowState::as_str`]).
    pub follow_state: String,
    /// With the ground-truth columns, once a result was judged.
    pub truth: Option<TruthColumns>,
    /// The actuated joints' states, in the header's order ([`trace_joints`]).
    pub joints: Vec<JointState>,
}

/// The joints a trace has columns for, in order (from its header).
pub fn trace_joints(text: &str) -> Vec<String> {
    let header = text.lines().next().unwrap_or("");
    let rest = header.strip_prefix(TRACE_HEADER).unwrap_or("");
    rest.strip_prefix(",")
        .and_then(|r| r.strip_prefix(TRACE_TRUTH_COLUMNS))
        .unwrap_or(rest)
        .split(',')
        .filter_map(|c| c.strip_suffix(".position"))
        .map(str::to_owned)
        .collect()
}

/// A trace CSV that is not what [`TraceWriter`] writes.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("trace line {line}: {message}")]
pub struct TraceParseError {
    /// 1-based line.
    pub line: usize,
    /// What was wrong.
    pub message: String,
}

/// Parses a trace CSV produced by [`TraceWriter`].
pub fn parse_trace(text: &str) -> Result<Vec<TraceRow>, TraceParseError> {
    let mut lines = text.lines();
    let header = lines.next().unwrap_or("");
    let truth_prefix = format!("{TRACE_HEADER},{TRACE_TRUTH_COLUMNS}");
    let truth = header == truth_prefix || header.starts_with(&format!("{truth_prefix},"));
    let first_joint = if truth { 17 } else { 11 };
    let joint_columns = header.split(',').count().saturating_sub(first_joint);
    if !header.starts_with(TRACE_HEADER) || !joint_columns.is_multiple_of(3) {
        return Err(TraceParseError {
            line: 1,
            message: format!(
                "unexpected header: {header}; expected {TRACE_HEADER} and three columns per joint"
            ),
        });
    }
    let fields = first_joint + joint_columns;
    let mut rows = Vec::new();
    for (n, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != fields {
            return Err(TraceParseError {
                line: n + 2,
                message: format!("expected {fields} fields, found {}", f.len()),
            });
        }
        let num = |i: usize| -> Result<f64, TraceParseError> {
            f[i].parse().map_err(|e| TraceParseError {
                line: n + 2,
                message: format!("field {}: {e}", i + 1),
            })
        };
        rows.push(TraceRow {
            sim_time_s: num(0)?,
            x_m: num(1)?,
            y_m: num(2)?,
            yaw_rad: num(3)?,
            odom_x_m: num(4)?,
            odom_y_m: num(5)?,
            odom_yaw_rad: num(6)?,
            cmd_linear_mps: num(7)?,
            cmd_angular_radps: num(8)?,
            mode: f[9].to_owned(),
            follow_state: f[10].to_owned(),
            truth: match truth && !f[11].is_empty() {
                false => None,
                true => {
                    let whole = |i: usize| -> Result<u32, TraceParseError> {
                        f[i].parse().map_err(|e| TraceParseError {
                            line: n + 2,
                            message: format!("field {}: {e}", i + 1),
                        })
                    };
                    Some(TruthColumns {
                        image: f[11].parse().map_err(|e| TraceParseError {
                            line: n + 2,
                            message: format!("field 12: {e}"),
                        })?,
                        things: whole(12)?,
                        found: whole(13)?,
                        missed: whole(14)?,
                        false_positives: whole(15)?,
                        mean_iou: match f[16] {
                            "" => None,
                            _ => Some(num(16)?),
                        },
                    })
                }
            },
            joints: (first_joint..fields)
                .step_by(3)
                .map(|i| {
                    Ok(JointState {
                        position: num(i)?,
                        velocity: num(i + 1)?,
                        effort: num(i + 2)?,
                    })
                })
                .collect::<Result<_, TraceParseError>>()?,
        });
    }
    Ok(rows)
}

#[cfg(test)]
#[allow(
    clippy::unwrap_used,
    reason = "tests: a failed unwrap is a failed test"
)]
mod tests {
    use super::*;

    fn sample(t: f64) -> ControlSample {
        ControlSample {
            sim_time_s: t,
            ground_truth: Default::default(),
            odometry: Default::default(),
            odometry_z_roll_pitch: [0.0; 3],
            cmd: Default::default(),
            wheel_targets_radps: [0.0; 2],
            wheel_measured_radps: [0.0; 2],
        }
    }

    #[test]
    fn truth_columns_sit_between_the_fixed_and_the_joint_columns_and_read_back() {
        let mut w = TraceWriter::with_columns(Vec::new(), true, &["arm"]).unwrap();
        let state = (Mode::Follow, FollowState::Tracking);
        let joint = JointState {
            position: 0.5,
            velocity: 0.0,
            effort: 1.0,
        };
        w.full_row(&sample(0.01), state, None, std::iter::once(joint))
            .unwrap();
        let judged = TruthColumns {
            image: 7,
            things: 2,
            found: 1,
            missed: 1,
            false_positives: 3,
            mean_iou: Some(0.8125),
        };
        w.full_row(&sample(0.02), state, Some(&judged), std::iter::once(joint))
            .unwrap();
        let nothing_found = TruthColumns {
            found: 0,
            missed: 2,
            mean_iou: None,
            ..judged
        };
        w.full_row(
            &sample(0.03),
            state,
            Some(&nothing_found),
            std::iter::once(joint),
        )
        .unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            format!("{TRACE_HEADER},{TRACE_TRUTH_COLUMNS},arm.position,arm.velocity,arm.effort")
        );
        assert!(lines[1].ends_with(",follow,tracking,,,,,,,0.500000,0.000000,1.0000"));
        assert!(lines[2].contains(",tracking,7,2,1,1,3,0.8125,0.5"));
        assert!(lines[3].contains(",tracking,7,2,0,2,3,,0.5"));
        let rows = parse_trace(&text).unwrap();
        assert_eq!(trace_joints(&text), vec!["arm"]);
        assert_eq!(
            rows.iter().map(|r| r.truth).collect::<Vec<_>>(),
            vec![None, Some(judged), Some(nothing_found)]
        );
        assert!(rows.iter().all(|r| r.joints == vec![joint]));
        // Without the columns, traces read as before.
        let mut w = TraceWriter::new(Vec::new()).unwrap();
        w.row(&sample(0.01), Mode::Manual, FollowState::Waiting)
            .unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let rows = parse_trace(&text).unwrap();
        assert_eq!((rows[0].truth, rows[0].joints.len()), (None, 0));
    }
}
