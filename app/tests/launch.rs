//! `rover launch` on the tutorial series' own launch files, against real ROS: Debian's
//! rosmaster (started by rover), roslaunch (the reference for parsing), rospy nodes nobody on
//! the project wrote (the tutorial's listener_yolo.py, teleop_twist_keyboard.py as the
//! tutorial's teleop.py). Each test builds the catkin packages in a temporary folder, with a
//! master port of its own. Where ROS or ../shared is missing they skip (a failure under CI).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail, ensure};
use rover_core::{TraceRow, parse_trace};
use rover_ros1::{Value, ros_call};
use rover_tests::ros::{PYTHON, darknet_msgs, free_port};

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn lock() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner())
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn fixtures() -> PathBuf {
    repo().join("tests/launch_files")
}

fn shared_ros() -> PathBuf {
    repo().join("../shared/ros")
}

/// Why these tests cannot run here, if they cannot.
fn missing() -> Option<String> {
    for tool in ["/usr/bin/rosmaster", "/usr/bin/roslaunch", "/usr/bin/tmux"] {
        if !Path::new(tool).exists() {
            return Some(format!(
                "{tool} not found (apt-get install python3-rosmaster python3-roslaunch tmux; ./test does)"
            ));
        }
    }
    if !shared_ros().join("seed_nodes/listener_yolo.py").exists() {
        return Some(format!("{} not found", shared_ros().display()));
    }
    let ok = Command::new(PYTHON)
        .args(["-c", "import rospy, geometry_msgs.msg, yaml"])
        .status()
        .is_ok_and(|s| s.success());
    (!ok).then(|| format!("{PYTHON} cannot import rospy/geometry_msgs/yaml"))
}

/// A catkin workspace built from the tutorial's files: `mrobot_gazebo` (my_gazebo3.launch,
/// worlds/playground.world, urdf/my_gazebo_robot_All.urdf.xacro = rover's car with its camera,
/// scripts/listener_yolo.py) and `my_robot` (simulation.launch, urdf/robot.urdf,
/// scripts/teleop.py = teleop_twist_keyboard.py), with a master port of its own.
struct Workspace {
    dir: tempfile::TempDir,
    port: u16,
}

impl Workspace {
    fn new() -> Result<Self> {
        let dir = tempfile::tempdir()?;
        let ws = dir.path();
        let car = repo().join("assets/robots/my_robot.urdf");
        let seeds = fixtures().join("seeds");
        let package = |name: &str| -> Result<PathBuf> {
            let p = ws.join("src").join(name);
            for sub in ["launch", "urdf", "scripts", "worlds"] {
                std::fs::create_dir_all(p.join(sub))?;
            }
            std::fs::write(
                p.join("package.xml"),
                format!(
                    "<?xml version=\"1.0\"?>\n<package format=\"2\"><name>{name}</name><version>0.0.1</version><description>the tutorial's package</description><maintainer email=\"user@example.org\">user</maintainer><license>BSD</license></package>\n"
                ),
            )?;
            Ok(p)
        };
        let executable = |from: &Path, to: &Path| -> Result<()> {
            use std::os::unix::fs::PermissionsExt;
            std::fs::copy(from, to)?;
            std::fs::set_permissions(to, std::fs::Permissions::from_mode(0o755))?;
            Ok(())
        };
        let mrobot = package("mrobot_gazebo")?;
        std::fs::copy(
            seeds.join("my_gazebo3.launch"),
            mrobot.join("launch/my_gazebo3.launch"),
        )?;
        std::fs::copy(
            seeds.join("playground.world"),
            mrobot.join("worlds/playground.world"),
        )?;
        std::fs::copy(&car, mrobot.join("urdf/my_gazebo_robot_All.urdf.xacro"))?;
        executable(
            &shared_ros().join("seed_nodes/listener_yolo.py"),
            &mrobot.join("scripts/listener_yolo.py"),
        )?;
        let my_robot = package("my_robot")?;
        std::fs::copy(
            seeds.join("simulation.launch"),
            my_robot.join("launch/simulation.launch"),
        )?;
        std::fs::copy(&car, my_robot.join("urdf/robot.urdf"))?;
        executable(
            &shared_ros().join("teleop_twist_keyboard/teleop_twist_keyboard.py"),
            &my_robot.join("scripts/teleop.py"),
        )?;
        darknet_msgs(&shared_ros(), &ws.join("py"))?;
        // teleop_twist_keyboard.py starts with `#!/usr/bin/env python`: Debian's
        // python-is-python3, in the workspace.
        std::fs::create_dir_all(ws.join("bin"))?;
        std::os::unix::fs::symlink(PYTHON, ws.join("bin/python"))?;
        Ok(Self {
            dir,
            port: free_port()?,
        })
    }

    fn path(&self, relative: &str) -> PathBuf {
        self.dir.path().join(relative)
    }

    fn master_uri(&self) -> String {
        format!("http://127.0.0.1:{}/", self.port)
    }

    /// The environment a user of the series has: packages on ROS_PACKAGE_PATH (and
    /// teleop_twist_keyboard, which the tutorial's teleop.py loads the manifest of),
    /// darknet_ros_msgs importable, Debian's python first on PATH.
    fn env(&self, command: &mut Command, extra_packages: &[&Path]) {
        let mut packages = vec![self.path("src"), shared_ros().join("teleop_twist_keyboard")];
        packages.extend(extra_packages.iter().map(|p| p.to_path_buf()));
        let package_path = std::env::join_paths(&packages).unwrap_or_default();
        let path = format!(
            "{}:/usr/bin:{}",
            self.path("bin").display(),
            std::env::var("PATH").unwrap_or_default()
        );
        command
            .current_dir(self.dir.path())
            .env("ROS_PACKAGE_PATH", package_path)
            .env("ROS_MASTER_URI", self.master_uri())
            .env("ROS_IP", "127.0.0.1")
            .env("ROS_HOME", self.path("ros_home"))
            .env("ROS_LOG_DIR", self.path("ros_log"))
            .env("PYTHONPATH", self.path("py"))
            .env("PATH", path)
            .env("ROVER_BIN", env!("CARGO_BIN_EXE_rover"))
            .env_remove("ROS_NAMESPACE");
    }

    fn rover(&self, args: &[&str]) -> Command {
        let mut c = Command::new(env!("CARGO_BIN_EXE_rover"));
        c.arg("launch").args(args).stdin(Stdio::null());
        self.env(&mut c, &[]);
        c
    }

    /// Whether a master answers on this workspace's port.
    fn master_answers(&self) -> bool {
        ros_call(
            &self.master_uri(),
            "getPid",
            &[Value::from("/test")],
            Duration::from_millis(500),
        )
        .is_ok()
    }

    /// Nothing of the launch is left: the master rover started does not answer, and no
    /// process names the workspace or the master's port.
    fn ensure_clean(&self) -> Result<()> {
        ensure!(
            !self.master_answers(),
            "the master rover started still answers"
        );
        let left = self.leftovers();
        ensure!(left.is_empty(), "processes left behind: {left:?}");
        Ok(())
    }

    /// Processes still running whose command line names this workspace or its master port.
    fn leftovers(&self) -> Vec<String> {
        let needles = [
            self.dir.path().to_string_lossy().into_owned(),
            format!("-p {}", self.port),
        ];
        let mut found = Vec::new();
        let Ok(entries) = std::fs::read_dir("/proc") else {
            return found;
        };
        for entry in entries.flatten() {
            let Ok(cmdline) = std::fs::read(entry.path().join("cmdline")) else {
                continue;
            };
            let text = String::from_utf8_lossy(&cmdline).replace('\0', " ");
            let stat = std::fs::read_to_string(entry.path().join("stat")).unwrap_or_default();
            let zombie = stat
                .rsplit(')')
                .next()
                .is_some_and(|s| s.trim_start().starts_with('Z'));
            if !zombie && needles.iter().any(|n| text.contains(n.as_str())) {
                found.push(format!("{}: {text}", entry.file_name().to_string_lossy()));
            }
        }
        found
    }
}

/// This test's workspace, one test at a time; `None` (the skip recorded) where ROS or
/// ../shared is missing.
fn setup() -> Result<Option<(std::sync::MutexGuard<'static, ()>, Workspace)>> {
    let one = lock();
    if let Some(why) = missing() {
        rover_tests::skip(&why)?;
        return Ok(None);
    }
    Ok(Some((one, Workspace::new()?)))
}

/// A thread reading `pipe` to its end (so a chatty child never blocks on a full pipe).
fn drain<R: std::io::Read + Send + 'static>(pipe: Option<R>) -> std::thread::JoinHandle<Vec<u8>> {
    std::thread::spawn(move || {
        let mut buf = Vec::new();
        if let Some(mut p) = pipe {
            let _ = p.read_to_end(&mut buf);
        }
        buf
    })
}

/// Runs `command` to its end (killed after `timeout`).
fn run(mut command: Command, timeout: Duration) -> Result<Output> {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("starting the command")?;
    let stdout = drain(child.stdout.take());
    let stderr = drain(child.stderr.take());
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break s;
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            bail!("timed out after {timeout:?}");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    Ok(Output {
        status,
        stdout: stdout.join().unwrap_or_default(),
        stderr: stderr.join().unwrap_or_default(),
    })
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Metres the car moved along x between the trace's first and last rows.
fn moved_m(rows: &[TraceRow]) -> Result<f64> {
    let (first, last) = (rows.first(), rows.last());
    match (first, last) {
        (Some(a), Some(b)) => Ok(b.x_m - a.x_m),
        _ => bail!("empty trace"),
    }
}

/// Part 4 of the series: `roslaunch mrobot_gazebo my_gazebo3.launch`, unchanged, run by rover:
/// it starts the master, the world, the robot, the detector and the tutorial's listener node;
/// the node sees the person and drives the car toward it; everything is gone afterwards.
#[test]
fn the_series_my_gazebo3_launch_drives_the_car_toward_the_person() -> Result<()> {
    let Some((_one, ws)) = setup()? else {
        return Ok(());
    };
    let trace = ws.path("trace.csv");
    let trace_arg = trace.to_string_lossy();
    let out = run(
        ws.rover(&[
            "mrobot_gazebo",
            "my_gazebo3.launch",
            "--headless",
            "--duration",
            "20",
            "--trace",
            &trace_arg,
        ]),
        Duration::from_secs(240),
    )?;
    let said = text(&out);
    ensure!(out.status.success(), "rover launch failed:\n{said}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    for line in ["[listener_yolo] person", "[listener_yolo] go on"] {
        ensure!(
            stdout.lines().any(|l| l == line),
            "no \"{line}\" line in rover's output:\n{said}"
        );
    }
    for part in [
        "started a ROS master at",
        "gazebo_ros empty_world.launch -> rover's world",
        "playground.world",
        "darknet_ros -> rover's YOLO detector",
        "node /urdf_spawner (gazebo_ros/spawn_model) -> rover spawns the robot",
        "node /robot_state_publisher (robot_state_publisher/robot_state_publisher) -> rover publishes /tf",
        "node /joint_state_publisher (joint_state_publisher/joint_state_publisher) -> rover publishes /joint_states",
        "node /listener_yolo (mrobot_gazebo/listener_yolo.py) -> started",
    ] {
        ensure!(said.contains(part), "rover never said \"{part}\":\n{said}");
    }
    let rows = parse_trace(&std::fs::read_to_string(&trace)?)?;
    let moved = moved_m(&rows)?;
    println!("the car moved {moved:.3} m toward the person in 20 s of sim time");
    ensure!(
        moved >= 0.5,
        "the car moved {moved:.3} m (want >= 0.5 m):\n{said}"
    );
    ws.ensure_clean()
}

/// The first tutorial's `simulation.launch`: its teleop.py (teleop_twist_keyboard) reads the
/// terminal rover runs in (tmux here), and its keys drive the car.
#[test]
fn the_series_simulation_launch_drives_with_the_teleop_keys() -> Result<()> {
    let Some((_one, ws)) = setup()? else {
        return Ok(());
    };
    let trace = ws.path("trace.csv");
    let log = ws.path("rover.log");
    let rc = ws.path("rover.rc");
    // The shell tmux runs: rover launch with the workspace's environment.
    let probe = ws.rover(&[]);
    let mut shell = String::new();
    for (k, v) in probe.get_envs() {
        if let Some(v) = v {
            shell.push_str(&format!(
                "{}='{}' ",
                k.to_string_lossy(),
                v.to_string_lossy()
            ));
        }
    }
    shell = format!(
        "cd '{}' && env {shell}'{}' launch my_robot simulation.launch --headless --duration 30 --trace '{}' > '{}' 2>&1; echo $? > '{}'",
        ws.dir.path().display(),
        env!("CARGO_BIN_EXE_rover"),
        trace.display(),
        log.display(),
        rc.display()
    );
    let tmux = rover_tests::ros::Tmux::start(ws.dir.path(), &shell)?;
    let start = Instant::now();
    let said = || std::fs::read_to_string(&log).unwrap_or_default();
    while !said().contains("CTRL-C to quit") {
        ensure!(
            start.elapsed() < Duration::from_secs(90),
            "teleop never printed its help:\n{}",
            said()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    // A held key repeats (teleop stops after its key timeout without one).
    tmux.press("i", 15)?;
    // `press` leaves a key-repeat gap before `k` (teleop_twist_keyboard's race: Tmux::press).
    tmux.press("k", 1)?;
    while !rc.exists() {
        ensure!(
            start.elapsed() < Duration::from_secs(200),
            "rover launch did not end:\n{}",
            said()
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    drop(tmux);
    let said = std::fs::read_to_string(&log)?;
    let code = std::fs::read_to_string(&rc)?;
    ensure!(code.trim() == "0", "rover launch exited {code}:\n{said}");
    ensure!(
        said.contains("node /teleop (my_robot/teleop.py) -> started")
            && said.contains("rover's world")
            && said.contains("empty.toml"),
        "rover did not say what it did with simulation.launch:\n{said}"
    );
    let rows = parse_trace(&std::fs::read_to_string(&trace)?)?;
    let driving: Vec<&TraceRow> = rows.iter().filter(|r| r.cmd_linear_mps == 0.5).collect();
    let (Some(first), Some(last)) = (driving.first(), driving.last()) else {
        bail!("`i` never drove the car:\n{said}");
    };
    let moved = last.x_m - first.x_m;
    println!("`i` held for 3 s drove the car {moved:.3} m");
    ensure!(moved > 0.3, "drove {moved:.3} m while `i` was held");
    let end = rows.last().context("empty trace")?;
    ensure!(end.cmd_linear_mps == 0.0, "`k` did not stop the command");
    ws.ensure_clean()
}

/// Compares two outputs as the compare script's MODE says (yaml: the same parameters, each of
/// the same type: Python's `3 == 3.0 == True` would let an int pass for a double; lines: the
/// same node names; args: the same environment and command), anonymous names equalled. Empty
/// output on either side is a difference, never a match.
const COMPARE: &str = r#"
import re, sys, yaml
mode, a, b = sys.argv[1], open(sys.argv[2]).read(), open(sys.argv[3]).read()
anon = lambda s: re.sub(r'([A-Za-z0-9]+)_[A-Za-z0-9_]+?_\d+_\d+', r'\1_ANON', s)
a, b = anon(a), anon(b)
def typed(v):
    if isinstance(v, dict):
        return ('dict', sorted((k, typed(x)) for k, x in v.items()))
    if isinstance(v, list):
        return ('list', [typed(x) for x in v])
    return (type(v).__name__, v)
if not a.strip() or not b.strip():
    print('empty output: roslaunch %d bytes, rover %d bytes' % (len(a), len(b)))
    sys.exit(1)
if mode == 'yaml':
    a, b = yaml.safe_load(a) or {}, yaml.safe_load(b) or {}
    missing = ('<missing>', None)
    ta = {k: typed(v) for k, v in a.items()}
    tb = {k: typed(v) for k, v in b.items()}
    diff = [k for k in sorted(set(a) | set(b)) if ta.get(k, missing) != tb.get(k, missing)]
    for k in diff:
        print('param %s: roslaunch %r, rover %r' % (k, ta.get(k, missing), tb.get(k, missing)))
    print('%d params' % len(a))
    diff = diff or not a
elif mode == 'lines':
    a, b = a.split(), b.split()
    diff = a != b
    print('nodes: roslaunch %s, rover %s' % (a, b))
else:
    def split(s):
        words = s.split()
        env = set(w for w in words if re.match(r'^[A-Z_][A-Z0-9_]*=', w))
        return env, [w for w in words if w not in env]
    diff = split(a) != split(b)
    print('args: roslaunch %s\n      rover     %s' % (a.strip(), b.strip()))
sys.exit(1 if diff else 0)
"#;

/// The parsing, checked against the real roslaunch (Debian's python3-roslaunch): on the two
/// seed files and on three launch files that use every construct rover reads, the same
/// parameters (`--dump-params`), node names (`--nodes`) and command lines (`--args NODE`).
/// roslaunch reads stand-ins of gazebo_ros, darknet_ros and xacro (tests/launch_files/stubs);
/// rover reads them too when asked these questions.
#[test]
fn parsing_matches_roslaunch_on_the_seeds_and_every_construct() -> Result<()> {
    let Some((_one, ws)) = setup()? else {
        return Ok(());
    };
    let stubs = fixtures().join("stubs");
    let check = fixtures().join("launch_check");
    let compare = ws.path("compare.py");
    std::fs::write(&compare, COMPARE)?;
    let cases: [(&str, &str, &[&str]); 5] = [
        ("mrobot_gazebo", "my_gazebo3.launch", &["/listener_yolo"]),
        ("my_robot", "simulation.launch", &["/teleop"]),
        ("launch_check", "args_and_includes.launch", &[]),
        ("launch_check", "groups_and_params.launch", &[]),
        (
            "launch_check",
            "nodes_and_remaps.launch",
            &["/talker", "/team/listener", "/robot2/talker2"],
        ),
    ];
    let mut failures = Vec::new();
    let mut checked = 0;
    for (pkg, file, nodes) in cases {
        // `--nodes` of a file without nodes would compare two empty answers: asked only of
        // the files that start nodes.
        let mut queries: Vec<Vec<String>> = vec![vec!["--dump-params".into()]];
        if !nodes.is_empty() {
            queries.push(vec!["--nodes".into()]);
        }
        for node in nodes {
            queries.push(vec!["--args".into(), (*node).into()]);
        }
        for query in queries {
            let mut outputs = Vec::new();
            for tool in ["roslaunch", "rover"] {
                let mut c = if tool == "roslaunch" {
                    Command::new("/usr/bin/roslaunch")
                } else {
                    let mut c = Command::new(env!("CARGO_BIN_EXE_rover"));
                    c.arg("launch");
                    c
                };
                c.args(&query)
                    .args([pkg, file])
                    .env("ROVER_LAUNCH_SET", "set");
                ws.env(&mut c, &[&stubs, &check]);
                let out = run(c, Duration::from_secs(60))?;
                ensure!(
                    out.status.success(),
                    "{tool} {query:?} {pkg} {file} failed:\n{}",
                    text(&out)
                );
                let path = ws.path(&format!("{tool}.out"));
                std::fs::write(&path, &out.stdout)?;
                outputs.push(path);
            }
            let mode = match query[0].as_str() {
                "--dump-params" => "yaml",
                "--nodes" => "lines",
                _ => "args",
            };
            if (file, mode) == ("groups_and_params.launch", "yaml") {
                std::fs::copy(&outputs[0], ws.path("roslaunch-params.yaml"))?;
            }
            let mut c = Command::new(PYTHON);
            c.arg(&compare).arg(mode).args(&outputs);
            let out = run(c, Duration::from_secs(30))?;
            println!("{pkg} {file} {query:?}: {}", text(&out).trim());
            checked += 1;
            if !out.status.success() {
                failures.push(format!("{pkg} {file} {query:?}:\n{}", text(&out)));
            }
        }
    }
    ensure!(
        failures.is_empty(),
        "rover launch differs from roslaunch:\n{}",
        failures.join("\n")
    );
    println!("{checked} queries answered as roslaunch answers them");
    assert_compare_catches_a_mistyped_param(&ws, &compare, &stubs, &check)
}

/// The comparison is strict enough to fail: a copy of groups_and_params.launch with
/// `int_as_double` declared `type="int"` (roslaunch reads the original as the double 3.0; rover
/// reads the copy as the int 3, equal under Python's `==`) differs from roslaunch's parameters,
/// naming that parameter; so does an empty output.
fn assert_compare_catches_a_mistyped_param(
    ws: &Workspace,
    compare: &Path,
    stubs: &Path,
    check: &Path,
) -> Result<()> {
    let original = std::fs::read_to_string(check.join("launch/groups_and_params.launch"))?;
    let declared = r#"<param name="int_as_double" type="double" value="3"/>"#;
    ensure!(
        original.contains(declared),
        "the fixture no longer declares {declared}"
    );
    let mistyped = ws.path("mistyped.launch");
    std::fs::write(
        &mistyped,
        original.replace(
            declared,
            r#"<param name="int_as_double" type="int" value="3"/>"#,
        ),
    )?;
    let mut c = Command::new(env!("CARGO_BIN_EXE_rover"));
    c.args(["launch", "--dump-params"]).arg(&mistyped);
    c.env("ROVER_LAUNCH_SET", "set");
    ws.env(&mut c, &[stubs, check]);
    let out = run(c, Duration::from_secs(60))?;
    ensure!(
        out.status.success(),
        "rover launch --dump-params mistyped.launch:\n{}",
        text(&out)
    );
    let rover = ws.path("rover-mistyped.yaml");
    std::fs::write(&rover, &out.stdout)?;
    let empty = ws.path("empty.yaml");
    std::fs::write(&empty, "")?;
    let roslaunch = ws.path("roslaunch-params.yaml");
    for (against, expected) in [
        (
            &rover,
            "param /int_as_double: roslaunch ('float', 3.0), rover ('int', 3)",
        ),
        (&empty, "empty output"),
    ] {
        let mut c = Command::new(PYTHON);
        c.arg(compare).arg("yaml").arg(&roslaunch).arg(against);
        let out = run(c, Duration::from_secs(30))?;
        let said = text(&out);
        println!("against {}: {}", against.display(), said.trim());
        ensure!(
            !out.status.success() && said.contains(expected),
            "the comparison passed {} against roslaunch's parameters:\n{said}",
            against.display()
        );
    }
    Ok(())
}

/// Ctrl-C (SIGINT) during a launch: rover stops the nodes it started and the master, ends its
/// run as at its last step (trace rows complete, the MCAP recording with its footer) and exits
/// 130; no process is left.
#[test]
fn ctrl_c_stops_every_node_and_the_master_and_loses_nothing() -> Result<()> {
    let Some((_one, ws)) = setup()? else {
        return Ok(());
    };
    let trace = ws.path("trace.csv");
    let mcap = ws.path("run.mcap");
    let log = ws.path("rover.log");
    let file = std::fs::File::create(&log)?;
    let mut child = ws
        .rover(&[
            "mrobot_gazebo",
            "my_gazebo3.launch",
            "--headless",
            "--duration",
            "120",
            "--trace",
            &trace.to_string_lossy(),
            "--record-mcap",
            &mcap.to_string_lossy(),
        ])
        .stdout(file.try_clone()?)
        .stderr(file)
        .spawn()?;
    let start = Instant::now();
    let said = || std::fs::read_to_string(&log).unwrap_or_default();
    // Ten of the listener's commands, then Ctrl-C while it drives.
    while said().matches("[listener_yolo] go on").count() < 10 {
        if start.elapsed() > Duration::from_secs(120) || child.try_wait()?.is_some() {
            let _ = child.kill();
            bail!("the listener never drove:\n{}", said());
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    ensure!(!ws.leftovers().is_empty(), "no node process was running");
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()?;
    ensure!(status.success(), "kill -INT failed");
    let stopped = Instant::now();
    let code = loop {
        if let Some(s) = child.try_wait()? {
            break s.code();
        }
        if stopped.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            bail!("rover launch did not stop after SIGINT:\n{}", said());
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    println!(
        "stopped {:.1} s after SIGINT",
        stopped.elapsed().as_secs_f64()
    );
    ensure!(
        code == Some(130),
        "exit code {code:?} (want 130):\n{}",
        said()
    );
    ws.ensure_clean()?;
    // The trace holds the run up to the stop: the listener's 0.1 m/s, which rover took before
    // Ctrl-C, is in it (how much sim time ten commands take depends on the detector's pace, so
    // the end's time is only bounded by the run's length).
    let rows = parse_trace(&std::fs::read_to_string(&trace)?)?;
    let last = rows.last().context("empty trace")?;
    ensure!(
        last.sim_time_s > 0.0 && last.sim_time_s < 120.0,
        "the trace ends at {} s",
        last.sim_time_s
    );
    ensure!(
        rows.iter().any(|r| (r.cmd_linear_mps - 0.1).abs() < 1e-9),
        "the listener's 0.1 m/s is not in the trace (it ends at {} s)",
        last.sim_time_s
    );
    let bytes = std::fs::read(&mcap)?;
    ensure!(
        bytes.len() > 1000 && bytes.ends_with(b"\x89MCAP0\r\n"),
        "the MCAP recording is not complete ({} bytes, no closing magic)",
        bytes.len()
    );
    Ok(())
}

/// Bad input says where: a missing package, an undefined arg (file:line), a cyclic include;
/// a node whose executable is missing is one warning, and the rest of the launch runs. A node
/// that dies is reported and, with `respawn="true"`, started again; a `required="true"` one
/// that exits stops the launch with an error.
#[test]
fn bad_launch_files_are_located_errors_and_a_missing_node_one_warning() -> Result<()> {
    let Some((_one, ws)) = setup()? else {
        return Ok(());
    };
    let dir = ws.path("bad");
    std::fs::create_dir_all(&dir)?;
    let write = |name: &str, body: &str| -> Result<String> {
        let p = dir.join(name);
        std::fs::write(&p, body)?;
        Ok(p.to_string_lossy().into_owned())
    };
    let undefined = write(
        "undefined.launch",
        "<launch>\n  <param name=\"a\" value=\"1\"/>\n  <param name=\"b\" value=\"$(arg nope)\"/>\n</launch>\n",
    )?;
    let cycle = write(
        "cycle.launch",
        "<launch>\n  <include file=\"$(dirname)/cycle2.launch\"/>\n</launch>\n",
    )?;
    write(
        "cycle2.launch",
        "<launch>\n\n  <include file=\"$(dirname)/cycle.launch\"/>\n</launch>\n",
    )?;
    let missing_node = write(
        "missing_node.launch",
        "<launch>\n  <node pkg=\"mrobot_gazebo\" type=\"no_such_node.py\" name=\"ghost\"/>\n  <node pkg=\"mrobot_gazebo\" type=\"quitter.sh\" name=\"quitter\" output=\"screen\" respawn=\"true\" respawn_delay=\"0.5\"/>\n</launch>\n",
    )?;
    let required = write(
        "required.launch",
        "<launch>\n  <node pkg=\"mrobot_gazebo\" type=\"quitter.sh\" name=\"quitter\" required=\"true\"/>\n</launch>\n",
    )?;
    let quitter = ws.path("src/mrobot_gazebo/scripts/quitter.sh");
    std::fs::write(&quitter, "#!/bin/sh\necho bye\nsleep 0.2\nexit 3\n")?;
    std::fs::set_permissions(
        &quitter,
        <std::fs::Permissions as std::os::unix::fs::PermissionsExt>::from_mode(0o755),
    )?;
    let cases: [(Vec<&str>, &str); 3] = [
        (
            vec!["no_such_package", "x.launch"],
            "package \"no_such_package\"",
        ),
        (
            vec![undefined.as_str(), "--dump-params"],
            "undefined.launch:3: arg \"nope\" is not defined",
        ),
        (vec![cycle.as_str()], "cycle2.launch:3: cyclic include"),
    ];
    for (args, expected) in cases {
        let out = run(ws.rover(&args), Duration::from_secs(60))?;
        let said = text(&out);
        ensure!(
            out.status.code() == Some(1) && said.contains(expected) && !said.contains("panicked"),
            "rover launch {args:?}: expected exit 1 and \"{expected}\":\n{said}"
        );
    }
    let out = run(
        ws.rover(&[missing_node.as_str(), "--headless", "--duration", "3"]),
        Duration::from_secs(120),
    )?;
    let said = text(&out);
    ensure!(out.status.success(), "the launch did not run:\n{said}");
    let warnings = said
        .matches("node /ghost is not started: cannot find node type \"no_such_node.py\"")
        .count();
    ensure!(
        warnings == 1,
        "{warnings} warnings for the missing node:\n{said}"
    );
    ensure!(
        said.contains("missing_node.launch:2"),
        "the warning does not say where:\n{said}"
    );
    // The quitter: reported each time it dies, and started again.
    let byes = said.lines().filter(|l| *l == "[quitter] bye").count();
    ensure!(
        byes >= 2
            && said.contains("[quitter] respawning")
            && said.contains("[quitter] process has died")
            && said.contains("exit status: 3"),
        "the respawned node: {byes} runs:\n{said}"
    );
    // A required node that exits ends the launch long before its 60 s, with an error.
    let out = run(
        ws.rover(&[required.as_str(), "--headless", "--duration", "60"]),
        Duration::from_secs(120),
    )?;
    let said = text(&out);
    ensure!(
        out.status.code() == Some(1)
            && said.contains("required node /quitter exited")
            && said.contains("required.launch:2"),
        "a required node's exit did not stop the launch with an error:\n{said}"
    );
    let rows = said
        .lines()
        .find_map(|l| l.strip_prefix("rover: world "))
        .is_some();
    ensure!(rows, "the run did not end as a run ends:\n{said}");
    ws.ensure_clean()
}
