//! The `rover` command line: clap arguments ([`args`]), runs in the window or headless
//! ([`run`]), `rover bench` ([`bench`]), `rover detect` ([`detect`]), `rover eval` ([`eval`]) and
//! `rover dataset` (`dataset`). `anyhow` errors, `tracing`
//! logs; the binary's `main` only calls [`main`].

/// `println!` that takes a reader who stopped reading (`rover ... | head`) in its stride: the
/// line is dropped and the command goes on to finish its files, where `println!` would panic.
/// Other write errors on stdout are dropped too: stdout is for people, and nothing rover
/// keeps depends on it.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod args;
pub mod bench;
pub mod bench_ik;
mod dataset;
pub mod detect;
pub mod eval;
mod launch;
mod run;
mod signals;
mod transports;

use std::process::ExitCode;

use clap::Parser;

use args::{BenchKind, Cli, Command};
use detect::DetectOptions;
use signals::Interrupted;

/// `rover xacro FILE [name:=value ...]`: the expanded URDF on stdout.
fn xacro(args: args::XacroArgs) -> anyhow::Result<()> {
    let mut resources = rover_sim::description::ResourcePaths::from_env();
    resources.packages.extend(args.package_paths);
    let xacro_args = args
        .args
        .iter()
        .filter_map(|a| a.split_once(":="))
        .map(|(k, v)| (k.to_owned(), v.to_owned()))
        .collect();
    let expanded = rover_sim::description::expand_xacro(&args.file, &xacro_args, &resources)?;
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    out.write_all(expanded.text.as_bytes())?;
    out.flush()?;
    Ok(())
}

/// The log on stderr (`RUST_LOG`, else rover's lines at info and its libraries' quieter), and
/// the same lines on `/rosout` while a `--ros2` bridge listens.
fn init_logging() {
    use tracing_subscriber::layer::SubscriberExt as _;
    use tracing_subscriber::util::SubscriberInitExt as _;
    tracing_subscriber::registry()
        .with(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| {
                tracing_subscriber::EnvFilter::new(
                    "info,tract_onnx=error,tract_hir=error,tract_core=error,rustdds=warn",
                )
            }),
        )
        .with(
            tracing_subscriber::fmt::layer()
                .with_writer(std::io::stderr)
                .with_target(false),
        )
        .with(crate::ros2::rosout_layer())
        .init();
}

/// Parses the command line, runs it and turns errors into `rover: error: ...` and exit code 1.
pub fn main() -> ExitCode {
    init_logging();
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Bench {
            kind:
                Some(BenchKind::Detect {
                    detector,
                    image,
                    runs,
                    profile,
                }),
            ..
        }) => detector
            .tool_config(args::spare_detect_threads())
            .and_then(|config| bench::bench_detect(config, image, runs, profile)),
        Some(Command::Bench {
            kind: Some(BenchKind::People(people)),
            ..
        }) => bench::bench_people(people),
        Some(Command::Bench {
            kind: Some(BenchKind::Camera { world, frames }),
            ..
        }) => bench::bench_camera(world, frames),
        Some(Command::Bench {
            kind: Some(BenchKind::Laser { world, scans }),
            ..
        }) => bench::bench_laser(world, scans),
        Some(Command::Bench {
            kind: Some(BenchKind::Sensors { world, steps }),
            ..
        }) => bench::bench_sensors(world, steps),
        Some(Command::Bench {
            kind:
                Some(BenchKind::Ros {
                    world,
                    duration,
                    repeats,
                }),
            ..
        }) => bench::bench_ros(world, duration, repeats),
        Some(Command::Bench {
            kind:
                Some(BenchKind::Record {
                    world,
                    duration,
                    repeats,
                    image_jpeg,
                }),
            ..
        }) => bench::bench_record(world, duration, repeats, image_jpeg),
        Some(Command::Bench {
            kind: None,
            world,
            physics,
        })
        | Some(Command::Bench {
            kind: Some(BenchKind::Physics { world, physics }),
            ..
        }) => bench::bench_cmd(world, physics),
        Some(Command::Detect {
            images,
            detector,
            json,
            out,
        }) => detector
            .tool_config(args::spare_detect_threads())
            .and_then(|config| {
                detect::run(&DetectOptions {
                    images,
                    detector: config,
                    json,
                    out,
                })
            }),
        Some(Command::Eval(args)) => eval::run(args),
        Some(Command::Launch(args)) => launch::run(args),
        Some(Command::Xacro(args)) => xacro(args),
        Some(Command::Dataset(args)) => dataset::run(args),
        Some(Command::Bench {
            kind:
                Some(BenchKind::Dataset {
                    world,
                    images,
                    image_format,
                    jobs,
                }),
            ..
        }) => dataset::bench(world, images, image_format, jobs),
        Some(Command::Bench {
            kind:
                Some(BenchKind::Ik {
                    world,
                    base,
                    ee_link,
                    targets,
                    pose,
                }),
            ..
        }) => bench_ik::bench(world, base.as_deref(), &ee_link, targets, pose),
        None => run::run(cli.run),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.downcast_ref::<Interrupted>().is_some() => ExitCode::from(130),
        Err(e) => {
            eprintln!("rover: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
