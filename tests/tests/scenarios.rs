//! The scenario suite's fast subset (scenarios tagged "fast"), in-process: real physics, real
//! renderer, real default detector in lockstep, the follower with its laser. The whole suite
//! runs with `rover eval scenarios/` (see docs/FOLLOWER.md).

use anyhow::Result;
use rover_core::{NoObserver, parse_trace};
use rover_core::{Scenario, ScenarioOptions, collect_scenario_files, run_scenario};
use rover_tests::repo;

fn fast_scenarios() -> Result<Vec<Scenario>> {
    let files = collect_scenario_files(&[repo("scenarios")])?;
    let mut all = Vec::new();
    for f in files {
        all.push(Scenario::load(&f)?);
    }
    assert!(all.len() >= 15, "the suite has {} scenarios", all.len());
    Ok(all
        .into_iter()
        .filter(|s| s.tags.iter().any(|t| t == "fast"))
        .collect())
}

fn run_named(name: &str) -> Result<()> {
    let scenarios = fast_scenarios()?;
    let s = scenarios
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| anyhow::anyhow!("no fast scenario {name}"))?;
    let dir = tempfile::tempdir()?;
    let trace = dir.path().join("trace.csv");
    let result = run_scenario(
        s,
        &ScenarioOptions {
            trace: Some(trace.clone()),
            ..ScenarioOptions::default()
        },
        &mut NoObserver,
    )?;
    for c in &result.checks {
        println!(
            "{name}: {} {} (want {}) {}",
            c.name,
            c.value,
            c.limit,
            if c.passed { "ok" } else { "FAILED" }
        );
    }
    assert!(result.passed, "{name} failed: {:#?}", result.checks);
    // The trace says what the follower was doing on every row.
    let rows = parse_trace(&std::fs::read_to_string(trace)?)?;
    assert!(rows.iter().any(|r| r.follow_state != "waiting"));
    Ok(())
}

#[test]
fn the_suite_has_a_fast_subset() -> Result<()> {
    let fast = fast_scenarios()?;
    assert!(fast.len() >= 3, "{} fast scenarios", fast.len());
    Ok(())
}

#[test]
fn fast_static_ahead_4m() -> Result<()> {
    run_named("static_ahead_4m")
}

#[test]
fn fast_crossing() -> Result<()> {
    run_named("crossing")
}

#[test]
fn fast_crate_between() -> Result<()> {
    run_named("crate_between")
}

/// The must-show of the follower issue: in the default world, once at the standoff the car stays
/// there, |angular cmd| < 0.05 rad/s and no SEARCHING for the last 10 s (the scenario's
/// `calm_last_s`), read back here from the trace's `follow_state` column too.
#[test]
fn fast_default_world() -> Result<()> {
    run_named("default_world")
}

#[test]
fn fast_nobody() -> Result<()> {
    run_named("nobody")
}
