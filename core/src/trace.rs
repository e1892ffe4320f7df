//! The trace CSV: one row per diff-drive control update.

use std::io::Write;

use rover_sim::ControlSample;

use crate::follower::FollowState;
use crate::pilot::Mode;

/// Column header of the trace CSV.
pub const TRACE_HEADER: &str = "sim_time_s,x_m,y_m,yaw_rad,odom_x_m,odom_y_m,odom_yaw_rad,cmd_linear_mps,cmd_angular_radps,mode,follow_state";

/// Writes trace rows with fixed formatting, so identical runs give identical bytes.
#[derive(Debug)]
pub struct TraceWriter<W: Write> {
    out: W,
    rows: u64,
}

impl<W: Write> TraceWriter<W> {
    /// Starts a trace, writing the header.
    pub fn new(mut out: W) -> std::io::Result<Self> {
        writeln!(out, "{TRACE_HEADER}")?;
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
        let g = &s.ground_truth;
        let o = &s.odometry;
        writeln!(
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
    if header != TRACE_HEADER {
        return Err(TraceParseError {
            line: 1,
            message: format!("unexpected header: {header}; expected {TRACE_HEADER}"),
        });
    }
    let mut rows = Vec::new();
    for (n, line) in lines.enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 11 {
            return Err(TraceParseError {
                line: n + 2,
                message: format!("expected 11 fields, found {}", f.len()),
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
        });
    }
    Ok(rows)
}
