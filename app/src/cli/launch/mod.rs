//! `rover launch`: a catkin package's roslaunch file, run as roslaunch runs it, with rover in
//! Gazebo's and darknet_ros' place.
//!
//! The file is read with roslaunch's rules ([`rover_core::load_launch`]). What rover is, it does
//! itself: gazebo_ros' world and `spawn_model`, `robot_state_publisher`,
//! `joint_state_publisher`, controller spawners and darknet_ros become rover's world, robot,
//! /tf, /joint_states, controllers and detector, said once at start. The other nodes are
//! started as processes against a ROS master (started by rover when none answers), with the
//! launch's parameters set first, and stopped when rover stops.
//!
//! `--dump-params`, `--nodes`, `--args NODE` and `--files` answer as roslaunch's options of the
//! same names do, reading every include.

mod children;
mod master;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use rover_core::{
    Launch, LaunchOptions, LaunchParam as Param, NodeOutput as Output, NodeRole, ParamSource,
    ParamValue, RoverPart, find_launch_file, find_node_executable, load_launch as load, ns_join,
};
use rover_sim::description::ResourcePaths;

use super::args::{LaunchArgs, RunArgs};
use children::{Children, NodeProcess};
use master::Master;

/// Runs `rover launch`.
pub(crate) fn run(args: LaunchArgs) -> Result<()> {
    let mut resources = ResourcePaths::from_env();
    let own = args.run.world.robot_options().resources;
    resources.packages.extend(own.packages);
    resources.model_search.splice(0..0, own.model_search);
    let (file, top_args) = launch_target(&args.launch, &resources)?;
    let querying = args.dump_params || args.nodes || args.node_args.is_some() || args.files;
    let options = LaunchOptions {
        args: top_args,
        resources: resources.clone(),
        rover: !querying,
        run_commands: true,
    };
    let launch = load(&file, &options)?;
    for warning in &launch.warnings {
        tracing::warn!("{warning}");
    }
    if querying {
        return query(&args, &launch, &resources);
    }
    let part = RoverPart::of(&launch)?;
    let log_dir = log_dir();
    let mut run = args.run;
    let mut launch = launch;
    say!("rover launch {}:", file.display());
    apply(&part, &mut launch, &mut run, &log_dir)?;
    let mut master = Master::ensure()?;
    let processes = processes(&launch, &part, &resources, &master.uri);
    master.set_params(&launch)?;
    if processes.iter().any(|p| p.node.output == Output::Log) {
        if let Err(e) = std::fs::create_dir_all(&log_dir) {
            tracing::warn!("cannot create {}: {e}", log_dir.display());
        }
        say!("  logs of output=\"log\" nodes: {}", log_dir.display());
    }
    let stop = super::signals::stop_on_signals()?;
    let mut children = Children::start(processes, std::sync::Arc::clone(&stop), &log_dir);
    let result = super::run::run_until(run, stop);
    children.stop();
    master.stop();
    match children.required_exit() {
        Some(why) => Err(anyhow::anyhow!(why)),
        None => result,
    }
}

/// `PKG FILE` or `PATH`, then `name:=value` args.
fn launch_target(
    words: &[String],
    resources: &ResourcePaths,
) -> Result<(PathBuf, Vec<(String, String)>)> {
    let (args, names): (Vec<&String>, Vec<&String>) = words.iter().partition(|w| w.contains(":="));
    let args = args
        .iter()
        .filter_map(|w| w.split_once(":="))
        .map(|(n, v)| (n.to_owned(), v.to_owned()))
        .collect();
    let file = match names.as_slice() {
        [path] => {
            let path = PathBuf::from(path);
            if !path.is_file() {
                bail!(
                    "{}: no such launch file (give PKG FILE.launch, or the path of a .launch file)",
                    path.display()
                );
            }
            path
        }
        [package, name] => {
            let here = std::env::current_dir().unwrap_or_default().join("launch");
            let dir = resources.find_package(package, &here).with_context(|| {
                format!("package \"{package}\" (add its folder to ROS_PACKAGE_PATH, or pass --package-path {package}=DIR)")
            })?;
            find_launch_file(&dir, name).map_err(anyhow::Error::msg)?
        }
        _ => bail!(
            "expected PKG FILE.launch or PATH.launch, then name:=value args; found {}",
            words.join(" ")
        ),
    };
    Ok((file, args))
}

/// `--dump-params`, `--nodes`, `--args NODE`, `--files`.
fn query(args: &LaunchArgs, launch: &Launch, resources: &ResourcePaths) -> Result<()> {
    if args.files {
        for f in &launch.files {
            say!("{}", f.display());
        }
    }
    if args.dump_params {
        print!("{}", launch.dump_params());
    }
    if args.nodes {
        for node in &launch.nodes {
            say!("{}", node.full_name());
        }
    }
    if let Some(wanted) = &args.node_args {
        let wanted = ns_join("/", wanted);
        let node = launch
            .nodes
            .iter()
            .find(|n| n.full_name() == wanted)
            .with_context(|| {
                format!(
                    "no node named {wanted}; the nodes are: {}",
                    launch
                        .nodes
                        .iter()
                        .map(|n| n.full_name())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?;
        let dir = resources.find_package(&node.pkg, &node.at.file).ok();
        let exe = find_node_executable(&node.pkg, dir.as_deref(), &node.node_type)
            .map_err(|e| anyhow::anyhow!("{}: {e}", node.at))?;
        let mut words: Vec<String> = node
            .environment(&master::master_uri())
            .into_iter()
            .filter(|(k, v)| std::env::var(k).ok().as_deref() != Some(v.as_str()))
            .map(|(k, v)| format!("{k}=\"{v}\""))
            .collect();
        words.extend(node.command_line(&exe).map_err(anyhow::Error::msg)?);
        say!("{}", words.join(" "));
    }
    Ok(())
}

/// Where `output="log"` nodes write: `ROS_LOG_DIR`, else `ROS_HOME/log`, else `~/.ros/log`,
/// in a folder of this launch (created when something is written there).
fn log_dir() -> PathBuf {
    let base = std::env::var_os("ROS_LOG_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| master::ros_home().join("log"));
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    base.join(format!("rover-launch-{secs}-{}", std::process::id()))
}

/// Turns what rover does itself into run options (the user's own options win), saying what
/// each replaced part of the launch was.
fn apply(part: &RoverPart, launch: &mut Launch, run: &mut RunArgs, log_dir: &Path) -> Result<()> {
    run.ros.ros = true;
    if run.duration.is_none() && run.script.is_none() {
        // As roslaunch: until Ctrl-C (or the window closes).
        run.duration = Some(rover_core::UNTIL_STOPPED_S);
        say!("  runs until Ctrl-C (--duration SECS to stop sooner)");
    }
    apply_world(part, launch, run)?;
    apply_robot(part, launch, run, log_dir)?;
    match &part.detector {
        Some(d) => {
            run.follow.detect = true;
            run.follow.no_detector = false;
            if let Some(t) = d.threshold
                && run.detector.threshold == rover_perception::DEFAULT_THRESHOLD
            {
                run.detector.threshold = t;
            }
            say!(
                "  {}: darknet_ros -> rover's YOLO detector (/darknet_ros/bounding_boxes, found_object, detection_image; threshold {})",
                d.at,
                run.detector.threshold
            );
        }
        None => run.follow.no_detector = !run.follow.detect,
    }
    if !part.controllers.is_empty() {
        let names: Vec<&str> = part.controllers.iter().map(|(n, _)| n.as_str()).collect();
        match (part.controllers_file(), &run.world.controllers) {
            (_, Some(_)) => {}
            (Some(file), None) => run.world.controllers = Some(file.clone()),
            (None, None) => tracing::warn!(
                "controllers {} are spawned but rover found no YAML file loaded for them (<rosparam file=...>); pass --controllers FILE",
                names.join(", ")
            ),
        }
    }
    for (node, role) in launch.nodes.iter().zip(&part.roles) {
        if let Some(what) = role.replaced_by() {
            say!(
                "  {}: node {} ({}/{}) -> {what}",
                node.at,
                node.full_name(),
                node.pkg,
                node.node_type
            );
        }
    }
    Ok(())
}

fn apply_world(part: &RoverPart, launch: &mut Launch, run: &mut RunArgs) -> Result<()> {
    let Some(world) = &part.world else {
        if run.world.world.is_none() {
            run.world.world = Some(rover_core::bundled_path("worlds/empty.toml"));
        }
        say!("  no Gazebo world in the launch: rover's empty world");
        return Ok(());
    };
    if run.world.world.is_none() {
        let name = world.world_name.as_deref().unwrap_or("worlds/empty.world");
        let path = Path::new(name);
        run.world.world = Some(if path.is_file() {
            path.to_path_buf()
        } else if name.starts_with("worlds/") {
            if name != "worlds/empty.world" {
                tracing::warn!(
                    "{}: {name} is one of Gazebo's own worlds, which rover does not have; rover's empty world instead",
                    world.at
                );
            }
            rover_core::bundled_path("worlds/empty.toml")
        } else {
            bail!("{}: world_name {name}: no such file", world.at);
        });
    }
    if !world.gui {
        run.headless = true;
    }
    run.window.paused |= world.paused;
    run.ros.ros_sim_time = world.use_sim_time;
    launch.params.insert(
        "/use_sim_time".to_owned(),
        Param {
            value: ParamValue::Bool(world.use_sim_time),
            source: ParamSource::Value,
            at: world.at.clone(),
        },
    );
    say!(
        "  {}: gazebo_ros empty_world.launch -> rover's world {}{}",
        world.at,
        run.world
            .world
            .as_deref()
            .map(|p| p.display().to_string())
            .unwrap_or_default(),
        if run.headless {
            ", headless"
        } else {
            ", in rover's window"
        }
    );
    Ok(())
}

fn apply_robot(part: &RoverPart, launch: &Launch, run: &mut RunArgs, log_dir: &Path) -> Result<()> {
    let Some(spawn) = &part.spawn else {
        say!("  no spawn_model in the launch: rover's default car");
        return Ok(());
    };
    if run.world.spawn.is_none() {
        run.world.spawn = Some([spawn.xyz_m[0], spawn.xyz_m[1], spawn.yaw_rad.to_degrees()]);
    }
    if run.world.robot.is_some() {
        return Ok(());
    }
    if let Some(file) = &spawn.file {
        run.world.robot = Some(file.clone());
        return Ok(());
    }
    let name = spawn.param.as_deref().unwrap_or("robot_description");
    let key = ns_join("/", name);
    let param = launch.params.get(&key).with_context(|| {
        format!(
            "{}: spawn_model -param {name}: the launch sets no parameter {key}",
            spawn.at
        )
    })?;
    match (&param.source, &param.value) {
        (ParamSource::Xacro { file, args }, _) => {
            run.world.robot = Some(file.clone());
            run.world.xacro_args = args.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
        }
        (ParamSource::TextFile(file), _) => run.world.robot = Some(file.clone()),
        (_, ParamValue::Str(text)) => {
            let path = log_dir.join(format!(
                "{}.urdf",
                if spawn.model.is_empty() {
                    "robot"
                } else {
                    &spawn.model
                }
            ));
            std::fs::create_dir_all(log_dir)
                .and_then(|()| std::fs::write(&path, text))
                .with_context(|| format!("writing {}", path.display()))?;
            run.world.robot = Some(path);
        }
        _ => bail!(
            "{}: spawn_model -param {name}: {key} is not a URDF string",
            spawn.at
        ),
    }
    Ok(())
}

/// The nodes rover starts, with their command lines; a node whose executable is missing is
/// one warning, and left out.
fn processes(
    launch: &Launch,
    part: &RoverPart,
    resources: &ResourcePaths,
    master_uri: &str,
) -> Vec<NodeProcess> {
    let ros_home = master::ros_home();
    let mut out = Vec::new();
    for (node, role) in launch.nodes.iter().zip(&part.roles) {
        if *role != NodeRole::Process {
            continue;
        }
        let dir = resources.find_package(&node.pkg, &node.at.file).ok();
        let command = find_node_executable(&node.pkg, dir.as_deref(), &node.node_type)
            .and_then(|exe| Ok((node.command_line(&exe)?, exe)));
        let (command, exe) = match command {
            Ok(c) => c,
            Err(e) => {
                tracing::warn!("{}: node {} is not started: {e}", node.at, node.full_name());
                continue;
            }
        };
        let cwd = if node.cwd.as_deref() == Some("node") {
            exe.parent()
                .map(Path::to_path_buf)
                .unwrap_or_else(|| ros_home.clone())
        } else {
            ros_home.clone()
        };
        say!(
            "  {}: node {} ({}/{}) -> started: {}",
            node.at,
            node.full_name(),
            node.pkg,
            node.node_type,
            command.join(" ")
        );
        out.push(NodeProcess {
            node: node.clone(),
            command,
            env: node.environment(master_uri),
            cwd,
        });
    }
    out
}
