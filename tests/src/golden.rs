//! Golden traces compared within stated tolerances, for machines other than the one they were
//! recorded on (the detector's and renderer's floating point differ across CPUs, so a follow
//! run there is not the same bytes; on the recording machine the comparison is byte for byte).
//!
//! Per row, in order, the two traces must have:
//! * the same `sim_time_s`, `mode` and `follow_state` (the follower did the same thing);
//! * the robot's pose (ground truth `x_m, y_m, yaw_rad` and odometry `odom_*`) within
//!   [`Tolerance::position_m`] / [`Tolerance::yaw_rad`] of the recorded one: how far the runs
//!   may drift apart;
//! * the *change* of that difference from the row before within [`Tolerance::step_m`] /
//!   [`Tolerance::step_rad`]: two runs of the same physics drift apart smoothly (a control row
//!   is 10 ms), so a single row that jumps away from its neighbours is a broken trace even when
//!   it stays within the drift bound;
//! * the same number of rows.

use std::collections::HashMap;

/// How far a trace may be from its golden one (see the module's doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Largest distance between the two positions (ground truth and odometry), m.
    pub position_m: f64,
    /// Largest difference between the two headings, rad.
    pub yaw_rad: f64,
    /// Largest change of the position difference from one row to the next, m.
    pub step_m: f64,
    /// Largest change of the heading difference from one row to the next, rad.
    pub step_rad: f64,
}

impl Tolerance {
    /// The follow goldens' tolerances off the recording machine: the drift measured between
    /// machines (docs/TESTING.md) with room, and row-to-row changes far below a centimetre.
    pub const FOLLOW: Tolerance = Tolerance {
        position_m: 0.05,
        yaw_rad: 0.05,
        step_m: 0.002,
        step_rad: 0.005,
    };
}

/// What a tolerance comparison found: the largest differences, for the test's output.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Drift {
    /// Rows compared.
    pub rows: usize,
    /// Largest position difference, m.
    pub position_m: f64,
    /// Largest heading difference, rad.
    pub yaw_rad: f64,
    /// Largest row-to-row change of the position difference, m.
    pub step_m: f64,
    /// Largest row-to-row change of the heading difference, rad.
    pub step_rad: f64,
}

/// One row's columns by name.
struct Row<'a> {
    line: usize,
    cells: Vec<&'a str>,
}

fn rows(text: &str) -> Result<(HashMap<&str, usize>, Vec<Row<'_>>), String> {
    let mut lines = text.lines().enumerate();
    let (_, header) = lines.next().ok_or("empty trace")?;
    let columns: HashMap<&str, usize> =
        header.split(',').enumerate().map(|(i, c)| (c, i)).collect();
    let rows = lines
        .map(|(i, l)| Row {
            line: i + 1,
            cells: l.split(',').collect(),
        })
        .collect();
    Ok((columns, rows))
}

fn number(row: &Row<'_>, columns: &HashMap<&str, usize>, name: &str) -> Result<f64, String> {
    let cell = columns
        .get(name)
        .and_then(|&i| row.cells.get(i))
        .ok_or_else(|| format!("line {}: no column {name}", row.line))?;
    cell.parse()
        .map_err(|e| format!("line {}: {name} = {cell:?}: {e}", row.line))
}

fn text<'a>(row: &Row<'a>, columns: &HashMap<&str, usize>, name: &str) -> Result<&'a str, String> {
    columns
        .get(name)
        .and_then(|&i| row.cells.get(i).copied())
        .ok_or_else(|| format!("line {}: no column {name}", row.line))
}

/// The angle `a - b` wrapped into (-pi, pi].
fn angle_between(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

/// Compares trace `got` with the golden `want` within `tol`. `Ok` with the largest differences
/// found, or every row that broke a tolerance (at most 20 listed, then a count).
pub fn compare(got: &str, want: &str, tol: &Tolerance) -> Result<Drift, Vec<String>> {
    let (gc, got_rows) = rows(got).map_err(|e| vec![format!("this run's trace: {e}")])?;
    let (wc, want_rows) = rows(want).map_err(|e| vec![format!("the golden trace: {e}")])?;
    let mut problems = Vec::new();
    if got_rows.len() != want_rows.len() {
        problems.push(format!(
            "{} rows, the golden trace has {}",
            got_rows.len(),
            want_rows.len()
        ));
    }
    let mut drift = Drift::default();
    // The previous row's (x, y) differences of ground truth and odometry, and heading ones.
    let mut before: Option<[f64; 6]> = None;
    for (g, w) in got_rows.iter().zip(&want_rows) {
        let row = (|| -> Result<Vec<String>, String> {
            let mut wrong = Vec::new();
            let t = number(g, &gc, "sim_time_s")?;
            if t != number(w, &wc, "sim_time_s")? {
                wrong.push(format!(
                    "sim_time_s {t}, golden {}",
                    number(w, &wc, "sim_time_s")?
                ));
            }
            for column in ["mode", "follow_state"] {
                let (a, b) = (text(g, &gc, column)?, text(w, &wc, column)?);
                if a != b {
                    wrong.push(format!("{column} {a}, golden {b}"));
                }
            }
            let mut d = [0.0; 6];
            for (k, column) in ["x_m", "y_m", "odom_x_m", "odom_y_m"].iter().enumerate() {
                d[k] = number(g, &gc, column)? - number(w, &wc, column)?;
            }
            d[4] = angle_between(number(g, &gc, "yaw_rad")?, number(w, &wc, "yaw_rad")?);
            d[5] = angle_between(
                number(g, &gc, "odom_yaw_rad")?,
                number(w, &wc, "odom_yaw_rad")?,
            );
            for (what, dx, dy, yaw, k) in
                [("pose", d[0], d[1], d[4], 0), ("odom", d[2], d[3], d[5], 2)]
            {
                let off = dx.hypot(dy);
                drift.position_m = drift.position_m.max(off);
                drift.yaw_rad = drift.yaw_rad.max(yaw.abs());
                if off > tol.position_m {
                    wrong.push(format!(
                        "{what} {off:.4} m from the golden one (tolerance {} m)",
                        tol.position_m
                    ));
                }
                if yaw.abs() > tol.yaw_rad {
                    wrong.push(format!(
                        "{what} heading {yaw:.4} rad from the golden one (tolerance {} rad)",
                        tol.yaw_rad
                    ));
                }
                if let Some(p) = before {
                    let step = (dx - p[k]).hypot(dy - p[k + 1]);
                    let step_yaw = angle_between(yaw, p[4 + k / 2]).abs();
                    drift.step_m = drift.step_m.max(step);
                    drift.step_rad = drift.step_rad.max(step_yaw);
                    if step > tol.step_m {
                        wrong.push(format!("{what}'s difference from the golden one jumped {step:.4} m from the row before (tolerance {} m)", tol.step_m));
                    }
                    if step_yaw > tol.step_rad {
                        wrong.push(format!("{what}'s heading difference jumped {step_yaw:.4} rad from the row before (tolerance {} rad)", tol.step_rad));
                    }
                }
            }
            before = Some(d);
            Ok(wrong)
        })();
        drift.rows += 1;
        match row {
            Ok(wrong) => {
                problems.extend(wrong.into_iter().map(|p| format!("line {}: {p}", g.line)))
            }
            Err(e) => problems.push(e),
        }
    }
    if problems.is_empty() {
        Ok(drift)
    } else {
        let n = problems.len();
        if n > 20 {
            problems.truncate(20);
            problems.push(format!("... {} more", n - 20));
        }
        Err(problems)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRACE: &str = "sim_time_s,x_m,y_m,yaw_rad,odom_x_m,odom_y_m,odom_yaw_rad,cmd_linear_mps,cmd_angular_radps,mode,follow_state
0.0000,0.000000,0.000000,3.140000,0.000000,0.000000,0.000000,0.0,0.0,follow,waiting
0.0100,0.001000,0.000000,-3.140000,0.001000,0.000000,0.000000,0.1,0.0,follow,tracking
0.0200,0.002000,0.000000,-3.139000,0.002000,0.000000,0.000000,0.1,0.0,follow,tracking
";

    #[test]
    fn a_trace_matches_itself_across_the_heading_wrap() {
        let d = compare(TRACE, TRACE, &Tolerance::FOLLOW);
        assert_eq!(d.map(|d| d.rows), Ok(3));
    }

    #[test]
    fn a_changed_state_a_missing_row_and_a_bad_number_are_each_reported() {
        let state = TRACE.replacen("follow,tracking", "follow,searching", 1);
        let e = compare(&state, TRACE, &Tolerance::FOLLOW).err();
        assert_eq!(
            e,
            Some(vec![
                "line 3: follow_state searching, golden tracking".to_owned()
            ])
        );
        let short: String = TRACE.lines().take(3).map(|l| format!("{l}\n")).collect();
        let e = compare(&short, TRACE, &Tolerance::FOLLOW).err();
        assert_eq!(e, Some(vec!["2 rows, the golden trace has 3".to_owned()]));
        let bad = TRACE.replacen("0.002000,0.000000,-3.139000", "0.002000,nan?,-3.139000", 1);
        let e = compare(&bad, TRACE, &Tolerance::FOLLOW)
            .err()
            .unwrap_or_default();
        assert!(
            e.first()
                .is_some_and(|l| l.starts_with("line 4: y_m = \"nan?\"")),
            "{e:?}"
        );
    }
}
