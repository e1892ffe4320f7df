//! `rover eval`: runs scenario files (world + robot + success criteria, see
//! docs/FOLLOWER.md) headless, several at once, and judges the follower.
//!
//! Each scenario runs in a child process of this binary (`--worker`): deterministic (lockstep
//! detection on sim time), single-threaded rendering (`LP_NUM_THREADS=1`) so that `--jobs N`
//! scales with cores, and isolated (a crash fails one scenario, not the suite). The parent shows
//! progress, prints a table and writes `eval.json` and `eval.csv`; `--shard I/N` runs a slice
//! of the suite on one machine and `--merge` puts the slices' JSON back together.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use rover_core::{
    Scenario, ScenarioOptions, ScenarioResult, ShardIndex, ShardManifest, check_shard_set,
    collect_scenario_files, robot_name, run_scenario, write_whole,
};
use serde::{Deserialize, Serialize};

use super::args::EvalArgs;
use crate::viewer::{Recorder, RecorderOptions};

/// What `eval.json` holds.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EvalReport {
    /// Runs done (scenario x robot; skipped ones not counted).
    pub scenarios: usize,
    /// Runs whose criteria all held.
    pub passed: usize,
    /// Runs skipped: the robot lacks a sensor the scenario needs.
    #[serde(default)]
    pub skipped: usize,
    /// passed / scenarios.
    pub pass_rate: f64,
    /// One result per scenario, in name order.
    pub results: Vec<ScenarioResult>,
    /// Wall-clock figures (the only part that differs between identical evaluations).
    pub timing: Timing,
    /// A shard's report (`--shard I/N`): what made it, for `--merge` to check the set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardManifest>,
}

/// Wall-clock figures of an evaluation.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Timing {
    /// Scenarios run at once.
    pub jobs: usize,
    /// Wall seconds for the whole evaluation.
    pub wall_s: f64,
    /// Sum of the scenarios' sim seconds divided by `wall_s`.
    pub sim_per_wall: f64,
}

pub(crate) fn run(args: EvalArgs) -> Result<()> {
    if let Some(out) = &args.worker {
        return worker(&args, out);
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the output folder {}", args.out.display()))?;
    if !args.merge.is_empty() {
        let report = merge(&args.merge)?;
        return finish(&args, report, "eval.json");
    }
    let paths = if args.paths.is_empty() {
        vec![rover_core::bundled_path("scenarios")]
    } else {
        args.paths.clone()
    };
    let files = collect_scenario_files(&paths)?;
    if files.is_empty() {
        bail!(
            "no scenario files (*.toml) in {}",
            paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let mut robot_names: Vec<(String, &Path)> = args
        .robot
        .iter()
        .map(|r| (robot_name(r), r.as_path()))
        .collect();
    robot_names.sort_unstable();
    if let Some(w) = robot_names.windows(2).find(|w| w[0].0 == w[1].0) {
        bail!(
            "two robots are named \"{}\" ({} and {}); rename one: results are keyed by the file name",
            w[0].0,
            w[0].1.display(),
            w[1].1.display()
        );
    }
    // Load them all first: a bad file is reported before anything runs. Every scenario runs
    // for every --robot (or for its own robot).
    let mut models = Vec::with_capacity(args.robot.len());
    for r in &args.robot {
        let model = Scenario::load_robot(r).with_context(|| format!("robot {}", r.display()))?;
        models.push((r.as_path(), model));
    }
    let robots: Vec<Option<(&Path, &rover_sim::model::RobotModel)>> = if models.is_empty() {
        vec![None]
    } else {
        models.iter().map(|(p, m)| Some((*p, m))).collect()
    };
    let mut jobs = Vec::with_capacity(files.len() * robots.len());
    for f in &files {
        for robot in &robots {
            let s = Scenario::load_with_model(f, *robot).with_context(|| match robot {
                Some((r, _)) => format!("scenario {} with robot {}", f.display(), r.display()),
                None => format!("scenario {}", f.display()),
            })?;
            if args.tag.is_empty() || args.tag.iter().any(|t| s.tags.contains(t)) {
                jobs.push(Job {
                    file: f.clone(),
                    robot: robot.map(|(p, _)| p.to_path_buf()),
                    duration_s: s.duration_s,
                    skip: s.unmet_needs().map(|why| ScenarioResult::skipped(&s, why)),
                    name: s.name,
                    robot_name: s.robot_name,
                });
            }
        }
    }
    let mut names: Vec<(&str, &str)> = jobs
        .iter()
        .map(|j| (j.name.as_str(), j.robot_name.as_str()))
        .collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        bail!(
            "two scenarios are named \"{}\"; names must be unique",
            w[0].0
        );
    }
    let manifest = match args.shard {
        Some((index, count)) => {
            let shard = ShardIndex { index, count };
            let manifest = shard_manifest(&args, shard, &files, &jobs)?;
            jobs = jobs
                .into_iter()
                .enumerate()
                .filter(|(i, _)| shard.owns(*i as u64))
                .map(|(_, s)| s)
                .collect();
            Some(manifest)
        }
        None => None,
    };
    if jobs.is_empty() {
        bail!("no scenarios to run (check --tag and --shard)");
    }
    if args.detector.model.is_none() {
        // Fetch the default model once, before the workers race for it.
        rover_perception::ensure_default_model()?;
    }
    let workers = args
        .jobs
        .unwrap_or_else(crate::cli::args::cores)
        .clamp(1, jobs.len());
    let mut report = run_all(&args, &jobs, workers)?;
    report.shard = manifest;
    let name = match args.shard {
        Some((i, n)) => format!("eval-shard-{i}-of-{n}.json"),
        None => "eval.json".to_owned(),
    };
    finish(&args, report, &name)
}

/// The manifest of shard `shard` of the evaluation of `jobs` (all of them) from `files`: the
/// model and every input hashed.
fn shard_manifest(
    args: &EvalArgs,
    shard: ShardIndex,
    files: &[PathBuf],
    jobs: &[Job],
) -> Result<ShardManifest> {
    let model = match &args.detector.model {
        Some(m) => m.clone(),
        None => rover_perception::ensure_default_model()?,
    };
    let mut inputs = files.to_vec();
    inputs.extend(args.robot.iter().cloned());
    let labels = jobs.iter().map(Job::label).collect();
    Ok(ShardManifest::new(
        "eval",
        shard,
        None,
        Some(&model),
        &inputs,
        labels,
    )?)
}

/// One scenario with one robot.
struct Job {
    file: PathBuf,
    name: String,
    /// The robot in place of the scenario's own (`--robot`).
    robot: Option<PathBuf>,
    robot_name: String,
    duration_s: f64,
    /// The result, when the robot lacks a sensor the scenario needs: not run.
    skip: Option<ScenarioResult>,
}

impl Job {
    /// "name" or "name @ robot" when several robots run.
    fn label(&self) -> String {
        match self.robot {
            Some(_) => format!("{} @ {}", self.name, self.robot_name),
            None => self.name.clone(),
        }
    }
}

/// Runs the jobs in child processes, `workers` at a time, longest first.
fn run_all(args: &EvalArgs, jobs: &[Job], workers: usize) -> Result<EvalReport> {
    let exe = std::env::current_exe().context("cannot find rover's own executable")?;
    let total_sim_s: f64 = jobs
        .iter()
        .filter(|s| s.skip.is_none())
        .map(|s| s.duration_s)
        .sum();
    let bar = ProgressBar::new(jobs.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} scenarios  {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(250));
    // Longest first: the last job to finish is a short one.
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by(|&a, &b| {
        jobs[b]
            .duration_s
            .total_cmp(&jobs[a].duration_s)
            .then(a.cmp(&b))
    });
    let queue = Mutex::new(order.into_iter());
    let results: Mutex<Vec<Option<ScenarioResult>>> = Mutex::new(vec![None; jobs.len()]);
    let running: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let scratch = tempfile::tempdir().context("cannot create a temporary folder")?;
    let started = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                loop {
                    let next = queue.lock().ok().and_then(|mut q| q.next());
                    let Some(i) = next else { break };
                    let job = &jobs[i];
                    let name = job.label();
                    if let Ok(mut r) = running.lock() {
                        r.push(name.clone());
                        bar.set_message(r.join(", "));
                    }
                    let json = scratch.path().join(format!("{i}.json"));
                    let result = match &job.skip {
                        Some(skipped) => skipped.clone(),
                        None => run_child(&exe, args, job, &json),
                    };
                    let line =
                        format!("{} {:<40} {:>6.1} s", verdict(&result), name, result.wall_s);
                    if bar.is_hidden() {
                        // Not a terminal (CI, a pipe): plain lines instead of the bar.
                        eprintln!("{line}");
                    } else {
                        bar.println(line);
                    }
                    bar.inc(1);
                    if let Ok(mut r) = running.lock() {
                        r.retain(|n| *n != name);
                        bar.set_message(r.join(", "));
                    }
                    if let Ok(mut all) = results.lock() {
                        all[i] = Some(result);
                    }
                }
            });
        }
    });
    bar.finish_and_clear();
    let wall_s = started.elapsed().as_secs_f64();
    let results: Vec<ScenarioResult> = results
        .into_inner()
        .map_err(|_| anyhow::anyhow!("a worker thread panicked"))?
        .into_iter()
        .flatten()
        .collect();
    Ok(report_of(
        results,
        Timing {
            jobs: workers,
            wall_s,
            sim_per_wall: total_sim_s / wall_s.max(1e-9),
        },
    ))
}

/// "pass", "FAIL" or "skip".
fn verdict(r: &ScenarioResult) -> &'static str {
    if r.skipped.is_some() {
        "skip"
    } else if r.passed {
        "pass"
    } else {
        "FAIL"
    }
}

fn report_of(mut results: Vec<ScenarioResult>, timing: Timing) -> EvalReport {
    results.sort_by(|a, b| a.name.cmp(&b.name).then_with(|| a.robot.cmp(&b.robot)));
    let run = results.iter().filter(|r| r.skipped.is_none()).count();
    let passed = results.iter().filter(|r| r.passed).count();
    EvalReport {
        scenarios: run,
        passed,
        skipped: results.len() - run,
        pass_rate: if run == 0 {
            0.0
        } else {
            passed as f64 / run as f64
        },
        results,
        timing,
        shard: None,
    }
}

/// One scenario in a child process; a child that fails to start, crashes or writes no result
/// becomes a failed result carrying its last words.
fn run_child(exe: &Path, args: &EvalArgs, job: &Job, json: &Path) -> ScenarioResult {
    let (file, name) = (&job.file, job.name.as_str());
    let mut cmd = Command::new(exe);
    cmd.arg("eval")
        .arg("--worker")
        .arg(json)
        .arg("--out")
        .arg(&args.out)
        .args(args.detector.to_args());
    if let Some(robot) = &job.robot {
        cmd.arg("--robot").arg(robot);
    }
    cmd.arg(file)
        .env("LP_NUM_THREADS", "1")
        .env(
            "RUST_LOG",
            std::env::var("ROVER_EVAL_LOG").unwrap_or_else(|_| "warn".into()),
        )
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    if args.rrd {
        cmd.arg("--rrd");
    }
    if args.traces {
        cmd.arg("--traces");
    }
    let file_text = file.display().to_string();
    let output = match cmd.output() {
        Ok(o) => o,
        Err(e) => {
            return ScenarioResult::failed(
                name,
                &job.robot_name,
                &file_text,
                format!("cannot start: {e}"),
            );
        }
    };
    let stderr = String::from_utf8_lossy(&output.stderr);
    match std::fs::read_to_string(json)
        .ok()
        .and_then(|t| serde_json::from_str::<ScenarioResult>(&t).ok())
    {
        Some(r) => r,
        None => {
            let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            ScenarioResult::failed(
                name,
                &job.robot_name,
                &file_text,
                format!(
                    "the run ended without a result ({}): {}",
                    output.status,
                    tail.join(" | ")
                ),
            )
        }
    }
}

/// `--worker RESULT.json FILE`: runs one scenario in this process and writes its result.
fn worker(args: &EvalArgs, out: &Path) -> Result<()> {
    let [file] = args.paths.as_slice() else {
        bail!("--worker runs exactly one scenario file");
    };
    if args.robot.len() > 1 {
        bail!("--worker runs with at most one --robot");
    }
    let robot = args.robot.first().map(PathBuf::as_path);
    let result = match Scenario::load_with_robot(file, robot) {
        Err(e) => ScenarioResult::failed(
            "?",
            &robot.map_or_else(|| "?".to_owned(), robot_name),
            &file.display().to_string(),
            e.to_string(),
        ),
        Ok(s) => {
            // Files of a run with several robots carry the robot's name.
            let stem = match robot {
                Some(_) => format!("{}@{}", s.name, s.robot_name),
                None => s.name.clone(),
            };
            let options = ScenarioOptions {
                // `--jobs` workers already fill the cores.
                detector: args.detector.config(1)?,
                inject_fault: args.detector.inject_fault,
                trace: args.traces.then(|| args.out.join(format!("{stem}.csv"))),
            };
            let outcome = if args.rrd {
                let rrd = args.out.join(format!("{stem}.rrd"));
                let rec_options = RecorderOptions {
                    record: Some(rrd),
                    ..RecorderOptions::default()
                };
                match Recorder::start(&rec_options)? {
                    Some(mut rec) => {
                        let r = run_scenario(&s, &options, &mut rec);
                        if let Err(e) = rec.finish() {
                            tracing::warn!("the recording was not written in full: {e}");
                        }
                        r
                    }
                    None => run_scenario(&s, &options, &mut rover_core::NoObserver),
                }
            } else {
                run_scenario(&s, &options, &mut rover_core::NoObserver)
            };
            outcome.unwrap_or_else(|e| {
                ScenarioResult::failed(
                    &s.name,
                    &s.robot_name,
                    &file.display().to_string(),
                    e.to_string(),
                )
            })
        }
    };
    let text = serde_json::to_string_pretty(&result)?;
    std::fs::write(out, text).with_context(|| format!("cannot write {}", out.display()))?;
    Ok(())
}

/// Reads shards' reports and puts them together (each scenario once), after checking that
/// they are one complete set of one evaluation (their manifests; the missing shards named).
/// The result does not depend on the order of `files`.
fn merge(files: &[PathBuf]) -> Result<EvalReport> {
    let mut reports = Vec::with_capacity(files.len());
    for f in files {
        let text =
            std::fs::read_to_string(f).with_context(|| format!("cannot read {}", f.display()))?;
        let report: EvalReport = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a rover eval report", f.display()))?;
        let Some(manifest) = report.shard.clone() else {
            bail!(
                "{}: not a shard's report (no shard manifest: made without --shard, or by a rover before 0.1)",
                f.display()
            );
        };
        reports.push((f.clone(), manifest, report));
    }
    let manifests: Vec<(PathBuf, ShardManifest)> = reports
        .iter()
        .map(|(f, m, _)| (f.clone(), m.clone()))
        .collect();
    check_shard_set(&manifests)?;
    let mut results: Vec<ScenarioResult> = Vec::new();
    let mut timing = Timing::default();
    for (f, _, report) in reports {
        for r in report.results {
            if results
                .iter()
                .any(|o| o.name == r.name && o.robot == r.robot)
            {
                bail!(
                    "{}: scenario \"{}\" (robot {}) is in more than one shard",
                    f.display(),
                    r.name,
                    r.robot
                );
            }
            results.push(r);
        }
        timing.jobs += report.timing.jobs;
        timing.wall_s = timing.wall_s.max(report.timing.wall_s);
    }
    let expected = manifests.first().map_or(0, |(_, m)| m.items.len());
    if results.len() != expected {
        bail!(
            "the shards hold {} results for an evaluation of {expected} runs",
            results.len()
        );
    }
    let sim: f64 = results.iter().map(|r| r.metrics.sim_s).sum();
    timing.sim_per_wall = sim / timing.wall_s.max(1e-9);
    Ok(report_of(results, timing))
}

/// Writes JSON and CSV, prints the table; fails (exit 1) when a scenario failed. The files
/// come first: a reader who stops reading the table (`rover eval | head`) loses nothing.
fn finish(args: &EvalArgs, report: EvalReport, json_name: &str) -> Result<()> {
    let json_path = args.out.join(json_name);
    // Whole or not at all: a shard cancelled while writing leaves no report, so a merge names
    // it missing instead of reading half of it.
    write_whole(
        &json_path,
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )
    .with_context(|| format!("cannot write {}", json_path.display()))?;
    let csv_path = json_path.with_extension("csv");
    let mut csv = Vec::new();
    write_csv(&mut csv, &report)?;
    std::fs::write(&csv_path, csv)
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    let skipped = if report.skipped > 0 {
        format!(
            ", {} skipped (a sensor they need is missing)",
            report.skipped
        )
    } else {
        String::new()
    };
    let summary = format!(
        "\n{}/{} scenarios passed ({:.0}%){skipped}; {} jobs, {:.1} s wall, {:.2} sim s per wall s\nresults: {}, {}",
        report.passed,
        report.scenarios,
        100.0 * report.pass_rate,
        report.timing.jobs,
        report.timing.wall_s,
        report.timing.sim_per_wall,
        json_path.display(),
        csv_path.display()
    );
    let mut stdout = std::io::stdout().lock();
    let printed = write_table(&mut stdout, &report).and_then(|()| writeln!(stdout, "{summary}"));
    if let Err(e) = printed
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        return Err(e.into());
    }
    if report.passed < report.scenarios {
        bail!(
            "{} of {} scenarios failed",
            report.scenarios - report.passed,
            report.scenarios
        );
    }
    Ok(())
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".to_owned(), |v| format!("{v:.digits$}"))
}

/// The human table: one row per run (scenario x robot), the measured figures and what failed
/// (or why it was skipped); then, with several robots, the robots x scenarios matrix.
pub fn write_table(out: &mut dyn Write, report: &EvalReport) -> std::io::Result<()> {
    let robot_width = report
        .results
        .iter()
        .map(|r| r.robot.len())
        .chain([5])
        .max()
        .unwrap_or(5);
    writeln!(
        out,
        "{:<24} {:<robot_width$} {:<6} {:>6} {:>7} {:>7} {:>7} {:>7} {:>6} {:>5} {:>5} {:>5} {:>6}  failed",
        "scenario",
        "robot",
        "result",
        "acq s",
        "final m",
        "max m",
        "clear m",
        "avoid s",
        "lost s",
        "AP50",
        "P",
        "R",
        "wall s"
    )?;
    for r in &report.results {
        let m = &r.metrics;
        let failed: Vec<String> = r
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| format!("{} ({}; want {})", c.name, c.value, c.limit))
            .chain(r.error.iter().cloned())
            .chain(r.skipped.iter().cloned())
            .collect();
        if r.skipped.is_some() {
            writeln!(
                out,
                "{:<24} {:<robot_width$} {:<6} {:>6} {:>7} {:>7} {:>7} {:>7} {:>6} {:>5} {:>5} {:>5} {:>6}  {}",
                r.name,
                r.robot,
                "skip",
                "",
                "",
                "",
                "",
                "",
                "",
                "",
                "",
                "",
                "",
                failed.join("; ")
            )?;
            continue;
        }
        let (ap50, precision, recall) = detector_summary(m);
        writeln!(
            out,
            "{:<24} {:<robot_width$} {:<6} {:>6} {:>7} {:>7} {:>7.3} {:>7.1} {:>6.1} {:>5} {:>5} {:>5} {:>6.1}  {}",
            r.name,
            r.robot,
            verdict(r),
            opt(m.acquired_at_s, 1),
            opt(m.final_range_m, 2),
            opt(m.max_range_after_acquire_m, 2),
            m.min_clearance_m,
            m.avoiding_s,
            m.longest_lost_s,
            opt(ap50, 2),
            opt(precision, 2),
            opt(recall, 2),
            r.wall_s,
            failed.join("; ")
        )?;
    }
    write_detector_classes(out, report, robot_width)?;
    let mut robots: Vec<&str> = report.results.iter().map(|r| r.robot.as_str()).collect();
    robots.sort_unstable();
    robots.dedup();
    if robots.len() > 1 {
        write_matrix(out, report, &robots)?;
    }
    Ok(())
}

/// The detector against ground truth in one run: AP50 over its classes, and the lowest
/// class precision and recall at IoU 0.5.
fn detector_summary(m: &rover_core::ScenarioMetrics) -> (Option<f64>, Option<f64>, Option<f64>) {
    let Some(d) = &m.detector else {
        return (None, None, None);
    };
    let lowest = |v: fn(&rover_perception::ClassMetrics) -> Option<f64>| {
        d.classes.iter().filter_map(v).min_by(f64::total_cmp)
    };
    (d.ap50, lowest(|c| c.precision), lowest(|c| c.recall))
}

/// The detector per run and class (COCO's rules against the renderer's ground truth).
fn write_detector_classes(
    out: &mut dyn Write,
    report: &EvalReport,
    robot_width: usize,
) -> std::io::Result<()> {
    let rows: Vec<_> = report
        .results
        .iter()
        .filter_map(|r| r.metrics.detector.as_ref().map(|d| (r, d)))
        .flat_map(|(r, d)| d.classes.iter().map(move |c| (r, c)))
        .collect();
    if rows.is_empty() {
        return Ok(());
    }
    writeln!(out)?;
    writeln!(
        out,
        "the detector against the renderer's ground truth (IoU 0.5; AP with COCO's rules):\n  {:<24} {:<robot_width$} {:<14} {:>5} {:>8} {:>5} {:>5} {:>5} {:>5} {:>5} {:>5}",
        "scenario", "robot", "class", "AP50", "AP50:95", "P", "R", "IoU", "gt", "TP", "FP"
    )?;
    for (r, c) in rows {
        writeln!(
            out,
            "  {:<24} {:<robot_width$} {:<14} {:>5} {:>8} {:>5} {:>5} {:>5} {:>5} {:>5} {:>5}",
            r.name,
            r.robot,
            c.class,
            opt(c.ap50, 2),
            opt(c.ap50_95, 3),
            opt(c.precision, 2),
            opt(c.recall, 2),
            opt(c.mean_iou, 2),
            c.ground_truth,
            c.true_positives,
            c.false_positives
        )?;
    }
    Ok(())
}

/// Scenarios down, robots across: pass, FAIL or skip in each cell, and each robot's total.
fn write_matrix(out: &mut dyn Write, report: &EvalReport, robots: &[&str]) -> std::io::Result<()> {
    let widths: Vec<usize> = robots.iter().map(|r| r.len().max(6)).collect();
    write!(out, "\n{:<24}", "scenario")?;
    for (robot, w) in robots.iter().zip(&widths) {
        write!(out, " {robot:>w$}")?;
    }
    writeln!(out)?;
    let mut names: Vec<&str> = report.results.iter().map(|r| r.name.as_str()).collect();
    names.dedup();
    for name in &names {
        write!(out, "{name:<24}")?;
        for (robot, w) in robots.iter().zip(&widths) {
            let cell = report
                .results
                .iter()
                .find(|r| r.name == *name && r.robot == *robot)
                .map_or("-", verdict);
            write!(out, " {cell:>w$}")?;
        }
        writeln!(out)?;
    }
    write!(out, "{:<24}", "passed")?;
    for (robot, w) in robots.iter().zip(&widths) {
        let mine = report.results.iter().filter(|r| r.robot == *robot);
        let run = mine.clone().filter(|r| r.skipped.is_none()).count();
        let passed = mine.filter(|r| r.passed).count();
        let cell = format!("{passed}/{run}");
        write!(out, " {cell:>w$}")?;
    }
    writeln!(out)
}

/// One CSV row per run (scenario x robot).
fn write_csv(out: &mut dyn Write, report: &EvalReport) -> std::io::Result<()> {
    writeln!(
        out,
        "scenario,robot,result,acquired_at_s,final_range_m,max_range_after_acquire_m,min_clearance_m,min_person_range_m,drove_while_searching_s,travel_m,final_facing_deg,transitions,final_state,avoiding_s,longest_lost_s,ap50,ap50_95,min_precision,min_recall,wall_s,failed"
    )?;
    for r in &report.results {
        let m = &r.metrics;
        let failed: Vec<&str> = r
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.name.as_str())
            .chain(r.error.as_deref().map(|_| "error"))
            .collect();
        writeln!(
            out,
            "{},{},{},{},{},{},{:.4},{},{:.2},{:.3},{},{},{},{:.2},{:.2},{},{},{},{},{:.2},{}",
            r.name,
            r.robot,
            verdict(r),
            opt(m.acquired_at_s, 3),
            opt(m.final_range_m, 4),
            opt(m.max_range_after_acquire_m, 4),
            m.min_clearance_m,
            opt(m.min_person_range_m, 4),
            m.drove_while_searching_s,
            m.travel_m,
            opt(m.final_facing_deg, 2),
            m.transitions,
            m.final_state,
            m.avoiding_s,
            m.longest_lost_s,
            opt(detector_summary(m).0, 4),
            opt(m.detector.as_ref().and_then(|d| d.ap50_95), 4),
            opt(detector_summary(m).1, 4),
            opt(detector_summary(m).2, 4),
            r.wall_s,
            failed.join(" ")
        )?;
    }
    Ok(())
}
