//! `rover eval`'s options ([`EvalArgs`]).

use std::path::PathBuf;

use clap::Args;

use super::detector::DetectorArgs;
use super::parsers::parse_shard;

/// `rover eval`'s options.
#[derive(Debug, Args)]
pub(crate) struct EvalArgs {
    /// Scenario files, or folders of them (their *.toml in name order) [default: scenarios/]
    #[arg(value_name = "PATH")]
    pub(crate) paths: Vec<PathBuf>,

    /// Scenarios run at once, each in its own process [default: the number of CPU cores]
    #[arg(long, short = 'j', value_name = "N")]
    pub(crate) jobs: Option<usize>,

    /// Folder for eval.json and eval.csv (and per-scenario .rrd/.csv files)
    #[arg(long, default_value = "eval-out", value_name = "DIR")]
    pub(crate) out: PathBuf,

    /// Also record every scenario to OUT/NAME.rrd, for inspection in Rerun
    #[arg(long)]
    pub(crate) rrd: bool,

    /// Also write every scenario's trace to OUT/NAME.csv
    #[arg(long)]
    pub(crate) traces: bool,

    /// Run only shard I of N: the scenarios (in name order) whose index modulo N is I; the
    /// results go to OUT/eval-shard-I-of-N.json for `--merge` (see docs/FOLLOWER.md)
    #[arg(long, value_name = "I/N", value_parser = parse_shard)]
    pub(crate) shard: Option<(usize, usize)>,

    /// Merge shards' result files into OUT/eval.json and eval.csv instead of running anything
    #[arg(long, value_name = "JSON", num_args = 1.., conflicts_with_all = ["jobs", "rrd", "shard", "paths", "robot"])]
    pub(crate) merge: Vec<PathBuf>,

    /// Run only scenarios with this tag (repeatable), e.g. --tag fast
    #[arg(long, value_name = "TAG")]
    pub(crate) tag: Vec<String>,

    /// Run every scenario with this robot (URDF or xacro) instead of the one it names
    /// (repeatable: every scenario for every robot, and a robots x scenarios table). A scenario
    /// whose `needs` the robot lacks (e.g. a laser for obstacles) is skipped with the reason
    #[arg(long, value_name = "FILE")]
    pub(crate) robot: Vec<PathBuf>,

    #[command(flatten)]
    pub(crate) detector: DetectorArgs,

    /// Internal: run the one scenario given in this process and write its result to this file
    #[arg(long, hide = true, value_name = "RESULT.json")]
    pub(crate) worker: Option<PathBuf>,
}
