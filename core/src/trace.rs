//! The trace CSV: one row per diff-drive control update. A robot with actuated joints gets
//! three more columns per joint after the fixed ones: `<joint>.position`, `<joint>.velocity`
//! and `<joint>.effort` (rad or m, rad/s or m/s, N m or N).

use std::io::Write;

use rover_sim::{ControlSample, JointState};

use crate::follower::FollowState;
use crate::pilot::Mode;

/// The fixed columns of the trace CSV (joint columns follow for robots with actuated joints).
pub const TRACE_HEADER: &str = "sim_time_s,x_m,y_m,yaw_rad,odom_x_m,odom_y_m,odom_yaw_rad,cmd_linear_mps,cmd_angular_radps,mode,follow_state";

/// Writes trace rows with fixed formatting, so identical runs give identical bytes.
#[derive(Debug)]
pub struct TraceWriter<W: Write> {
    out: W,
    rows: u64,
}

impl<W: Write> TraceWriter<W> {
    /// Starts a trace, writing the header.
    pub fn new(out: W) -> std::io::Result<Self> {
        Self::with_joints(out, &[])
    }

    /// Starts a trace with three columns per joint of `joints` after the fixed ones.
    pub fn with_joints(mut out: W, joints: &[&str]) -> std::io::Result<Self> {
        write!(out, "{TRACE_HEADER}")?;
        for j in joints {
            write!(out, ",{j}.position,{j}.velocity,{j}.effort")?;
        }
        writeln!(out)?;
        Ok(Self { out, rows: 0 })
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
    /// The actuated joints' states, in the header's order ([`trace_joints`]).
    pub joints: Vec<JointState>,
}

/// The joints a trace has columns for, in order (from its header).
pub fn trace_joints(text: &str) -> Vec<String> {
    let header = text.lines().next().unwrap_or("");
    header
        .strip_prefix(TRACE_HEADER)
        .unwrap_or("")
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
    let joint_columns = header.split(',').count().saturating_sub(11);
    if !header.starts_with(TRACE_HEADER) || !joint_columns.is_multiple_of(3) {
        return Err(TraceParseError {
            line: 1,
            message: format!(
                "unexpected header: {header}; expected {TRACE_HEADER} and three columns per joint"
            ),
        });
    }
    let fields = 11 + joint_columns;
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
            joints: (11..fields)
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
