//! The ROS 1 bridge against real ROS: Debian's rosmaster, rospy nodes nobody on the project
//! wrote (the tutorial's listener_yolo.py, teleop_twist_keyboard.py from ../shared/ros),
//! rostopic, and rosbag's C++ recorder. Each test starts its own master on a free port. They
//! run one at a time (each runs rover in real time with its camera and detector, and the rate
//! checks need the CPU). Where ROS or ../shared is missing they skip, counted and listed by
//! `./test` (a failure under CI=true or --strict; `./test` installs the ROS packages).

use std::ffi::{OsStr, OsString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail, ensure};
use rover_core::{TraceRow, parse_trace};
use rover_ros1::Value;
use rover_ros1::ros_call;

static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

const PYTHON: &str = "/usr/bin/python3";

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn shared_ros() -> PathBuf {
    repo().join("../shared/ros")
}

/// Why these tests cannot run here, if they cannot.
fn missing_ros() -> Option<String> {
    for tool in ["/usr/bin/rosmaster", "/usr/bin/rostopic", "/usr/bin/rosbag"] {
        if !Path::new(tool).exists() {
            return Some(format!(
                "{tool} not found (apt-get install python3-rosmaster python3-rostopic python3-rosbag ros-core; ./test does)"
            ));
        }
    }
    let ok = Command::new(PYTHON)
        .args(["-c", "import rospy, geometry_msgs.msg, nav_msgs.msg"])
        .status()
        .is_ok_and(|s| s.success());
    (!ok).then(|| format!("{PYTHON} cannot import rospy/geometry_msgs/nav_msgs"))
}

/// This test cannot run here: a failure in strict mode (CI), else a counted skip.
fn skip(reason: &str) -> Result<()> {
    rover_tests::skip(reason)
}

/// A master on a free port, its environment, and the processes started against it (killed
/// when dropped).
struct RosGraph {
    dir: tempfile::TempDir,
    master_uri: String,
    port: u16,
    master: Option<Child>,
    children: Vec<Child>,
    /// Index of rover in `children`.
    rover: Option<usize>,
}

impl RosGraph {
    fn start() -> Result<Self> {
        let dir = tempfile::tempdir()?;
        let port = std::net::TcpListener::bind("127.0.0.1:0")?
            .local_addr()?
            .port();
        let mut graph = Self {
            master_uri: format!("http://127.0.0.1:{port}/"),
            port,
            dir,
            master: None,
            children: Vec::new(),
            rover: None,
        };
        graph.start_master()?;
        Ok(graph)
    }

    fn start_master(&mut self) -> Result<()> {
        let log = std::fs::File::create(self.dir.path().join("master.log"))?;
        let child = self
            .command("/usr/bin/rosmaster")
            .args(["--core", "-p", &self.port.to_string()])
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()
            .context("starting rosmaster")?;
        self.master = Some(child);
        self.wait_for(Duration::from_secs(30), "the master to answer", |g| {
            ros_call(
                &g.master_uri,
                "getPid",
                &[Value::from("/test")],
                Duration::from_secs(1),
            )
            .is_ok()
        })
    }

    fn kill_master(&mut self) {
        if let Some(mut m) = self.master.take() {
            let _ = m.kill();
            let _ = m.wait();
        }
    }

    /// A command with this graph's ROS environment.
    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("ROS_MASTER_URI", &self.master_uri)
            .env("ROS_IP", "127.0.0.1")
            .env("ROS_HOME", self.dir.path())
            .env("ROS_LOG_DIR", self.dir.path().join("log"))
            .env("PYTHONUNBUFFERED", "1")
            // A DDS domain of the graph's own, for rover's --ros2 and its peers.
            .env("ROS_DOMAIN_ID", self.dds_domain().to_string())
            .stdin(Stdio::null());
        c
    }

    /// The graph's DDS domain (ROS 2 allows 0..=232), from its master's port.
    fn dds_domain(&self) -> u16 {
        120 + self.port % 100
    }

    /// Starts a process whose output goes to `<dir>/<name>.log`.
    fn spawn(&mut self, name: &str, mut command: Command) -> Result<()> {
        let log = std::fs::File::create(self.log_path(name))?;
        let child = command
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()
            .with_context(|| format!("starting {name}"))?;
        self.children.push(child);
        Ok(())
    }

    fn log_path(&self, name: &str) -> PathBuf {
        self.dir.path().join(format!("{name}.log"))
    }

    fn log(&self, name: &str) -> String {
        std::fs::read_to_string(self.log_path(name)).unwrap_or_default()
    }

    /// `rover --headless --ros` for `duration_s` of sim time, tracing to `<dir>/trace.csv`.
    fn spawn_rover(&mut self, duration_s: f64, extra: &[&str]) -> Result<()> {
        let mut c = self.command(env!("CARGO_BIN_EXE_rover"));
        c.args(["--headless", "--ros", "--rtf", "1", "--duration"])
            .arg(duration_s.to_string())
            .arg("--trace")
            .arg(self.trace_path())
            .args(extra)
            .env("RUST_LOG", "info");
        self.rover = Some(self.children.len());
        self.spawn("rover", c)?;
        self.wait_for(
            Duration::from_secs(120),
            "rover to register",
            Self::rover_registered,
        )
    }

    /// Whether the master knows the node /rover.
    fn rover_registered(&self) -> bool {
        ros_call(
            &self.master_uri,
            "lookupNode",
            &[Value::from("/test"), Value::from("/rover")],
            Duration::from_secs(1),
        )
        .is_ok()
    }

    fn trace_path(&self) -> PathBuf {
        self.dir.path().join("trace.csv")
    }

    /// Runs a subscriber like [`Self::run`]; also says how long it ran and whether rover was
    /// still running after it, for a failure's message (one that heard nothing may have come
    /// after rover finished).
    fn run_subscriber(&mut self, command: Command, timeout: Duration) -> Result<(String, String)> {
        let start = Instant::now();
        let out = self.run(command, timeout)?;
        let rover = match self.rover.and_then(|i| self.children.get_mut(i)) {
            None => "not started".to_owned(),
            Some(rover) => match rover.try_wait() {
                Ok(None) => "still running".to_owned(),
                Ok(Some(status)) => format!("already exited ({status})"),
                Err(e) => format!("unknown ({e})"),
            },
        };
        let note = format!(
            "it ran {:.1} s; rover then {rover}",
            start.elapsed().as_secs_f64()
        );
        Ok((out, note))
    }

    /// Waits for rover (the first child named rover) to exit; returns its trace.
    fn wait_rover(&mut self, timeout: Duration) -> Result<Vec<TraceRow>> {
        let start = Instant::now();
        let rover = self
            .rover
            .and_then(|i| self.children.get_mut(i))
            .context("no rover process")?;
        loop {
            if let Some(status) = rover.try_wait()? {
                ensure!(status.success(), "rover failed: {}", self.log("rover"));
                break;
            }
            if start.elapsed() > timeout {
                bail!("rover did not finish in {timeout:?}: {}", self.log("rover"));
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(parse_trace(&std::fs::read_to_string(self.trace_path())?)?)
    }

    fn wait_for(
        &self,
        timeout: Duration,
        what: &str,
        mut ready: impl FnMut(&Self) -> bool,
    ) -> Result<()> {
        let start = Instant::now();
        while !ready(self) {
            if start.elapsed() > timeout {
                bail!(
                    "timed out waiting for {what}; rover log:\n{}",
                    self.log("rover")
                );
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        Ok(())
    }

    /// Writes `script` to `<dir>/<name>` and runs it with the graph's python, as [`Self::run`].
    fn run_python(&self, name: &str, script: &str, timeout: Duration) -> Result<String> {
        self.run_python_with(name, script, None, timeout)
    }

    /// As [`Self::run_python`], with `python_path` (generated messages) on its PYTHONPATH.
    fn run_python_with(
        &self,
        name: &str,
        script: &str,
        python_path: Option<&Path>,
        timeout: Duration,
    ) -> Result<String> {
        let path = self.dir.path().join(name);
        std::fs::write(&path, script)?;
        let mut c = self.command(PYTHON);
        c.arg(&path);
        if let Some(py) = python_path {
            c.env("PYTHONPATH", py);
        }
        self.run(c, timeout)
    }

    /// The words after `key ` on the first line of `out` that starts with it; an error with
    /// the output and rover's log when none does.
    fn keyed_line(&self, out: &str, key: &str) -> Result<Vec<String>> {
        let found = out
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key} ")))
            .with_context(|| format!("no {key}:\n{out}\nrover:\n{}", self.log("rover")))?;
        Ok(found.split(' ').map(str::to_owned).collect())
    }

    /// Starts the Python `script` as the child `ros2_peer` (its output in that log), with
    /// `python_path` (see [`both_transports`]).
    fn spawn_ros2_peer(&mut self, python_path: &OsStr, script: &str) -> Result<()> {
        let path = self.dir.path().join("ros2_peer.py");
        std::fs::write(&path, script)?;
        let mut peer = self.command("python3");
        peer.arg(&path).env("PYTHONPATH", python_path);
        self.spawn("ros2_peer", peer)
    }

    /// Starts rover with TIAGo (`urdf`), its wheels driven, and `extra` arguments.
    fn spawn_tiago(&mut self, duration_s: f64, urdf: &Path, extra: &[&str]) -> Result<()> {
        let urdf = urdf.to_string_lossy();
        let mut args = vec![
            "--robot",
            urdf.as_ref(),
            "--drive",
            "wheel_left_joint,wheel_right_joint",
        ];
        args.extend_from_slice(extra);
        self.spawn_rover(duration_s, &args)
    }

    /// Runs a ROS tool to completion (killed after `timeout`); returns its stdout + stderr.
    fn run(&self, mut command: Command, timeout: Duration) -> Result<String> {
        let mut child = command
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()?;
        rover_tests::wait_or_kill(&mut child, timeout)?;
        let mut out = String::new();
        if let Some(mut o) = child.stdout.take() {
            o.read_to_string(&mut out)?;
        }
        if let Some(mut e) = child.stderr.take() {
            e.read_to_string(&mut out)?;
        }
        Ok(out)
    }

    /// rospy can import darknet_ros_msgs: generated from ../shared/ros with genpy.
    fn darknet_msgs(&self) -> Result<PathBuf> {
        rover_tests::ros::darknet_msgs(&shared_ros(), &self.dir.path().join("py"))
    }
}

impl Drop for RosGraph {
    fn drop(&mut self) {
        for c in &mut self.children {
            let _ = c.kill();
            let _ = c.wait();
        }
        self.kill_master();
    }
}

fn lock() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|p| p.into_inner())
}

fn row_at(rows: &[TraceRow], t_s: f64) -> Result<&TraceRow> {
    rows.iter()
        .find(|r| r.sim_time_s >= t_s - 1e-6)
        .with_context(|| format!("no trace row at {t_s} s"))
}

#[test]
fn the_tutorials_listener_yolo_drives_the_car_toward_the_person() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let listener = shared_ros().join("seed_nodes/listener_yolo.py");
    if !listener.exists() {
        return skip(&format!("{} not found", listener.display()));
    }
    let mut graph = RosGraph::start()?;
    let py = graph.darknet_msgs()?;
    // The tutorial's node first (it waits for boxes), then rover in the default world.
    let mut node = graph.command(PYTHON);
    node.arg(&listener).env("PYTHONPATH", &py);
    graph.spawn("listener", node)?;
    graph.spawn_rover(12.0, &[])?;
    let rows = graph.wait_rover(Duration::from_secs(120))?;
    let said = graph.log("listener");
    assert!(
        said.lines().any(|l| l.trim() == "person"),
        "listener_yolo.py printed no `person`:\n{said}\nrover:\n{}",
        graph.log("rover")
    );
    assert!(said.contains("go on"), "listener never published:\n{said}");
    // Its 0.1 m/s reached the car (the trace's cmd column) and moved it.
    assert!(
        rows.iter()
            .any(|r| (r.cmd_linear_mps - 0.1).abs() < 1e-9 && r.cmd_angular_radps == 0.0),
        "no 0.1 m/s command in the trace; rover:\n{}",
        graph.log("rover")
    );
    let (start, end) = (row_at(&rows, 0.0)?, row_at(&rows, 10.0)?);
    let moved_m = end.x_m - start.x_m;
    assert!(
        moved_m >= 0.3,
        "the car moved {moved_m:.3} m forward in 10 s of sim time (want >= 0.3 m)"
    );
    Ok(())
}

/// gazebo_msgs for rospy, generated by genpy from tests/ros_msgs into the graph's folder: the
/// PYTHONPATH that imports it.
fn gazebo_msgs_for_rospy(graph: &RosGraph) -> Result<PathBuf> {
    let msgs = repo().join("tests/ros_msgs");
    rover_tests::ros::generate_msgs(
        "gazebo_msgs",
        &msgs.join("gazebo_msgs/msg"),
        &[
            ("geometry_msgs", &msgs.join("geometry_msgs/msg")),
            ("std_msgs", Path::new("/usr/share/std_msgs/msg")),
        ],
        &graph.dir.path().join("gazebo_py"),
    )
}

/// gazebo_ros' `/gazebo/model_states`: a rospy subscriber (gazebo_msgs generated by genpy
/// from tests/ros_msgs, so the MD5 sums must agree) gets every model's name, pose and twist:
/// the robot at its spawn, the table where the world puts it, the ball resting on the table.
#[test]
fn gazebo_model_states_reach_a_rospy_subscriber() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let mut graph = RosGraph::start()?;
    let py = gazebo_msgs_for_rospy(&graph)?;
    let world = repo().join("worlds/arm_car_reach.toml");
    graph.spawn_rover(6.0, &["--world", &world.to_string_lossy(), "--no-detector"])?;
    let script = r#"
import rospy, time
from gazebo_msgs.msg import ModelStates
rospy.init_node('model_states_check')
got = []
sub = rospy.Subscriber('/gazebo/model_states', ModelStates, got.append)
end = time.time() + 20
while time.time() < end and len(got) < 50:
    time.sleep(0.05)
if got:
    m = got[-1]
    print('messages %d' % len(got))
    print('names %s' % ','.join(m.name))
    for n, p, t in zip(m.name, m.pose, m.twist):
        print('model %s %.4f %.4f %.4f %.4f %.4f' % (n, p.position.x, p.position.y, p.position.z, t.linear.x, p.orientation.w))
"#;
    let out = graph.run_python_with(
        "model_states.py",
        script,
        Some(&py),
        Duration::from_secs(40),
    )?;
    graph.wait_rover(Duration::from_secs(120))?;
    println!("{out}");
    let model = |name: &str| -> Result<Vec<f64>> {
        let line = out
            .lines()
            .find_map(|l| l.strip_prefix(&format!("model {name} ")))
            .with_context(|| format!("no model {name}:\n{out}\nrover:\n{}", graph.log("rover")))?;
        Ok(line.split(' ').filter_map(|w| w.parse().ok()).collect())
    };
    ensure!(out.contains("names my_robot,table,ball"), "names: {out}");
    let robot = model("my_robot")?;
    ensure!(
        robot[0].abs() < 0.02 && robot[1].abs() < 0.02,
        "robot at {robot:?}"
    );
    let table = model("table")?;
    ensure!(
        (table[0] - 0.42).abs() < 1e-3 && table[1].abs() < 1e-3 && (table[2] - 0.075).abs() < 1e-3,
        "table at {table:?} (the world puts it at 0.42 0 0.075)"
    );
    let ball = model("ball")?;
    ensure!(
        (ball[0] - 0.40).abs() < 0.03 && (ball[1] - 0.03).abs() < 0.03 && ball[3].abs() < 0.05,
        "ball at {ball:?} (placed at 0.40 0.03, resting)"
    );
    ensure!(
        ball[2] > 0.1 && ball[2] < 0.22,
        "the ball is not on the table: z {}",
        ball[2]
    );
    Ok(())
}

/// The playground car's bumper (`libgazebo_ros_bumper.so`, /bumper_states): a rospy node
/// (gazebo_msgs/ContactsState generated by genpy from tests/ros_msgs) drives the car at
/// 0.3 m/s into a low crate whose face is 1 m ahead; the bumper reports nothing while the car
/// rolls toward it, then the crate by name (`crate::link::collision`) against
/// `my_robot::base_link::base_link_collision`, its contact points at the car's nose in
/// base_link and its force pushing the car back.
#[test]
fn the_bumper_reports_the_crate_the_car_drives_into_to_a_rospy_subscriber() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let mut graph = RosGraph::start()?;
    let py = gazebo_msgs_for_rospy(&graph)?;
    let world = graph.dir.path().join("crate.toml");
    std::fs::write(
        &world,
        "[[box]]\nname = \"crate\"\nsize_m = [0.4, 1.0, 0.12]\nposition_m = [1.35, 0.0]\n",
    )?;
    let robot = repo().join("assets/robots/my_robot_laser.urdf.xacro");
    graph.spawn_rover(
        12.0,
        &[
            "--world",
            &world.to_string_lossy(),
            "--robot",
            &robot.to_string_lossy(),
            "--no-detector",
        ],
    )?;
    let script = r#"
import rospy, time
from gazebo_msgs.msg import ContactsState
from geometry_msgs.msg import Twist
rospy.init_node('bumper_check')
got = []
rospy.Subscriber('/bumper_states', ContactsState, got.append)
pub = rospy.Publisher('/cmd_vel', Twist, queue_size=1)
cmd = Twist()
cmd.linear.x = 0.3
end = time.time() + 25
while time.time() < end and sum(1 for m in got if m.states) < 20:
    pub.publish(cmd)
    time.sleep(0.05)
empty = 0
for m in got:
    if m.states:
        break
    empty += 1
touching = [m for m in got if m.states]
print('counts %d %d %d' % (len(got), empty, len(touching)))
if touching:
    m = touching[-1]
    s = m.states[0]
    print('frame %s' % m.header.frame_id)
    print('names %s %s' % (s.collision1_name, s.collision2_name))
    print('first %.4f %.4f' % (s.contact_positions[0].x, s.total_wrench.force.x))
"#;
    let out = graph.run_python_with("bumper.py", script, Some(&py), Duration::from_secs(60))?;
    graph.wait_rover(Duration::from_secs(120))?;
    println!("{out}");
    let line = |key: &str| graph.keyed_line(&out, key);
    let counts: Vec<u64> = line("counts")?
        .iter()
        .filter_map(|w| w.parse().ok())
        .collect();
    // About 3 s of rolling at 50 Hz before the nose meets the crate.
    ensure!(
        counts.len() == 3 && counts[1] > 50 && counts[2] >= 20,
        "counts {counts:?}"
    );
    ensure!(line("frame")? == ["base_link"], "frame: {out}");
    ensure!(
        line("names")?
            == [
                "my_robot::base_link::base_link_collision",
                "crate::link::collision"
            ],
        "names: {out}"
    );
    let first: Vec<f64> = line("first")?
        .iter()
        .filter_map(|w| w.parse().ok())
        .collect();
    ensure!(
        first.len() == 2 && (first[0] - 0.15).abs() < 0.02 && first[1] <= 0.0,
        "contact at x {:?} in base_link, force x {:?}",
        first.first(),
        first.get(1)
    );
    Ok(())
}

/// The playground car's IMU, laser, p3d and GPS reach rospy subscribers of Debian's
/// sensor_msgs/Imu, LaserScan, NavSatFix and nav_msgs/Odometry: the IMU at its 100 Hz in
/// base_link, gravity up at rest, a unit quaternion; the ground truth in the world frame where
/// the car stands; the fix at the GPS's reference point.
#[test]
fn the_imu_laser_p3d_and_gps_reach_rospy_subscribers() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let mut graph = RosGraph::start()?;
    let world = repo().join("worlds/playground.toml");
    graph.spawn_rover(8.0, &["--world", &world.to_string_lossy(), "--no-detector"])?;
    let script = r#"
import math, rospy, time
from sensor_msgs.msg import Imu, LaserScan
from nav_msgs.msg import Odometry
from sensor_msgs.msg import NavSatFix
from geometry_msgs.msg import Vector3Stamped
rospy.init_node('imu_check')
imu, scans, truth, fixes, velocities = [], [], [], [], []
rospy.Subscriber('/fix', NavSatFix, fixes.append)
rospy.Subscriber('/fix_velocity', Vector3Stamped, velocities.append)
rospy.Subscriber('/imu', Imu, imu.append)
rospy.Subscriber('/scan', LaserScan, scans.append)
rospy.Subscriber('/ground_truth/state', Odometry, truth.append)
end = time.time() + 20
while time.time() < end and (len(imu) < 200 or len(scans) < 10 or len(truth) < 100
                             or len(fixes) < 8):
    time.sleep(0.05)
print('counts %d %d %d' % (len(imu), len(scans), len(truth)))
if truth:
    m = truth[-1]
    stamps = [x.header.stamp.to_sec() for x in truth[-50:]]
    gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
    print('truth %s %s %.4f %.4f %.5f' % (m.header.frame_id, m.child_frame_id,
          m.pose.pose.position.x, m.pose.pose.position.y, gaps[len(gaps) // 2]))
if imu:
    m = imu[-1]
    q = m.orientation
    print('imu %s %.4f %.4f' % (m.header.frame_id, m.linear_acceleration.z,
                                 math.sqrt(q.x*q.x + q.y*q.y + q.z*q.z + q.w*q.w)))
    stamps = [x.header.stamp.to_sec() for x in imu[-100:]]
    gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
    print('period %.5f' % gaps[len(gaps) // 2])
if scans:
    print('scan %s %d' % (scans[-1].header.frame_id, len(scans[-1].ranges)))
if fixes:
    f = fixes[-1]
    print('fix %s %.9f %.9f %d %d' % (f.header.frame_id, f.latitude, f.longitude,
                                     f.status.service, f.position_covariance_type))
if velocities:
    v = velocities[-1]
    print('velocity %s %d %.4f' % (v.header.frame_id, len(velocities),
                                   abs(v.vector.x) + abs(v.vector.y) + abs(v.vector.z)))
"#;
    let out = graph.run_python("imu.py", script, Duration::from_secs(40))?;
    graph.wait_rover(Duration::from_secs(120))?;
    println!("{out}");
    let line = |key: &str| graph.keyed_line(&out, key);
    let imu = line("imu")?;
    ensure!(imu[0] == "base_link", "IMU frame {imu:?}");
    let az: f64 = imu[1].parse()?;
    ensure!((az - 9.81).abs() < 0.3, "IMU at rest reads z {az} m/s^2");
    let norm: f64 = imu[2].parse()?;
    ensure!((norm - 1.0).abs() < 1e-3, "IMU quaternion norm {norm}");
    let period: f64 = line("period")?[0].parse()?;
    ensure!(
        (period - 0.01).abs() < 1e-4,
        "IMU stamps {period} s apart (median), 100 Hz expected"
    );
    ensure!(line("scan")? == ["base_scan", "360"], "scan: {out}");
    // hector's velocity beside each fix, in the same frame; the car stands still.
    let velocity = line("velocity")?;
    ensure!(velocity[0] == "base_link", "velocity frame {velocity:?}");
    let (n, speed): (u32, f64) = (velocity[1].parse()?, velocity[2].parse()?);
    ensure!(n >= 8 && speed < 0.01, "velocity {velocity:?}");
    // The playground spawns the car at the origin, where it stays (no one drives it).
    let truth = line("truth")?;
    ensure!(truth[..2] == ["world", "base_link"], "p3d frames {truth:?}");
    let (x, y, gap): (f64, f64, f64) = (truth[2].parse()?, truth[3].parse()?, truth[4].parse()?);
    ensure!(x.abs() < 0.01 && y.abs() < 0.01, "p3d at {x} {y}");
    ensure!(
        (gap - 0.02).abs() < 1e-4,
        "p3d every {gap} s, 50 Hz expected"
    );
    Ok(())
}

/// TurtleBot3 burger's own URDF (ROBOTIS' xacro, its libgazebo_ros_imu.so model plugin):
/// rospy receives /imu in imu_link at every physics step, gravity up while it stands.
#[test]
fn turtlebot3s_imu_reaches_a_rospy_subscriber() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let Some(dir) = rover_tests::shared("corpus/turtlebot3_description") else {
        return Ok(());
    };
    let robot = dir.join("urdf/turtlebot3_burger.urdf.xacro");
    let mut graph = RosGraph::start()?;
    graph.spawn_rover(6.0, &["--robot", &robot.to_string_lossy(), "--no-detector"])?;
    let script = r#"
import rospy, time
from sensor_msgs.msg import Imu
rospy.init_node('turtlebot3_imu_check')
imu = []
rospy.Subscriber('/imu', Imu, imu.append)
end = time.time() + 20
while time.time() < end and len(imu) < 400:
    time.sleep(0.05)
if imu:
    m = imu[-1]
    stamps = [x.header.stamp.to_sec() for x in imu[-100:]]
    gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
    az = sorted(x.linear_acceleration.z for x in imu[-200:])
    print('imu %s %d %.5f %.4f' % (m.header.frame_id, len(imu), gaps[len(gaps) // 2],
                                   az[len(az) // 2]))
"#;
    let mut c = graph.command(PYTHON);
    let path = graph.dir.path().join("turtlebot3_imu.py");
    std::fs::write(&path, script)?;
    c.arg(&path);
    let out = graph.run(c, Duration::from_secs(40))?;
    graph.wait_rover(Duration::from_secs(120))?;
    println!("{out}");
    let line: Vec<&str> = out
        .lines()
        .find_map(|l| l.strip_prefix("imu "))
        .with_context(|| format!("no /imu:\n{out}\nrover:\n{}", graph.log("rover")))?
        .split(' ')
        .collect();
    ensure!(line[0] == "imu_link", "frame {line:?}");
    let gap: f64 = line[2].parse()?;
    ensure!(
        (gap - 0.005).abs() < 1e-4,
        "/imu every {gap} s; updateRate 0 is every 200 Hz physics step"
    );
    let az: f64 = line[3].parse()?;
    // Every step's change of velocity: the burger still settles on its ball casters in its
    // first seconds (median 9.828 measured); 0.05 bounds that, a missing gravity would be 9.8.
    ensure!((az - 9.81).abs() < 0.05, "median z {az} m/s^2 standing");
    Ok(())
}

#[test]
fn teleop_twist_keyboard_in_tmux_drives_and_stops_the_car() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let teleop_dir = shared_ros().join("teleop_twist_keyboard");
    if !teleop_dir.join("teleop_twist_keyboard.py").exists() {
        return skip(&format!("{} not found", teleop_dir.display()));
    }
    if Command::new("tmux").arg("-V").output().is_err() {
        return skip("tmux not found (apt-get install tmux)");
    }
    let mut graph = RosGraph::start()?;
    graph.spawn_rover(14.0, &["--no-detector"])?;
    let script = teleop_dir.join("teleop_twist_keyboard.py");
    let shell = format!(
        "PYTHONUNBUFFERED=1 ROS_MASTER_URI={} ROS_IP=127.0.0.1 ROS_HOME={} ROS_PACKAGE_PATH={} {PYTHON} {} > {} 2>&1",
        graph.master_uri,
        graph.dir.path().display(),
        teleop_dir.display(),
        script.display(),
        graph.log_path("teleop").display()
    );
    let tmux = rover_tests::ros::Tmux::start(graph.dir.path(), &shell)?;
    // teleop waits for rover's /cmd_vel subscription, then reads keys.
    graph.wait_for(Duration::from_secs(30), "teleop's key help", |g| {
        g.log("teleop").contains("CTRL-C to quit")
    })?;
    // A held key repeats (teleop stops after its 0.5 s key_timeout without one).
    tmux.press("i", 15)?;
    tmux.press("k", 1)?;
    let rows = graph.wait_rover(Duration::from_secs(120))?;
    drop(tmux);
    let driving: Vec<&TraceRow> = rows.iter().filter(|r| r.cmd_linear_mps == 0.5).collect();
    let (Some(first), Some(last)) = (driving.first(), driving.last()) else {
        bail!(
            "`i` never drove the car; teleop:\n{}\nrover:\n{}",
            graph.log("teleop"),
            graph.log("rover")
        );
    };
    assert!(
        last.x_m - first.x_m > 0.3,
        "drove {:.3} m while `i` was held",
        last.x_m - first.x_m
    );
    let end = rows.last().context("empty trace")?;
    assert_eq!(end.cmd_linear_mps, 0.0, "`k` stopped the command");
    let settled: Vec<&TraceRow> = rows
        .iter()
        .filter(|r| r.sim_time_s > last.sim_time_s + 1.0)
        .collect();
    ensure!(!settled.is_empty(), "the run ended right after `k`");
    let spread = settled
        .iter()
        .map(|r| r.x_m)
        .fold(f64::NEG_INFINITY, f64::max)
        - settled.iter().map(|r| r.x_m).fold(f64::INFINITY, f64::min);
    assert!(
        spread < 0.01,
        "the car kept moving after `k` ({spread:.3} m)"
    );
    Ok(())
}

/// The first `name: value` number in `rostopic echo`'s output.
fn echoed(text: &str, name: &str) -> Result<f64> {
    text.lines()
        .find_map(|l| l.trim().strip_prefix(&format!("{name}: ")))
        .with_context(|| format!("no {name} in\n{text}"))?
        .trim()
        .parse()
        .with_context(|| format!("{name} is not a number"))
}

/// The first box `rostopic echo` printed is person-sized and inside the 640x480 image.
fn check_person_box(text: &str) -> Result<()> {
    let [xmin, ymin, xmax, ymax] = ["xmin", "ymin", "xmax", "ymax"].map(|f| echoed(text, f));
    let (xmin, ymin, xmax, ymax) = (xmin?, ymin?, xmax?, ymax?);
    for v in [xmin, ymin, xmax, ymax] {
        ensure!(v.fract() == 0.0, "pixel bounds are integers: {v}");
    }
    ensure!(
        0.0 <= xmin && xmin < xmax && xmax <= 640.0 && 0.0 <= ymin && ymin < ymax && ymax <= 480.0,
        "box ({xmin}, {ymin})-({xmax}, {ymax}) in a 640x480 image"
    );
    ensure!(
        xmax - xmin >= 10.0 && ymax - ymin >= 30.0,
        "a person-sized box: ({xmin}, {ymin})-({xmax}, {ymax})"
    );
    Ok(())
}

/// `rostopic hz` prints `average rate: X`; the last one.
fn average_rate(text: &str) -> Option<f64> {
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("average rate:"))
        .filter_map(|v| v.trim().parse().ok())
        .next_back()
}

#[test]
fn rostopic_and_rosbag_see_gazebos_and_darknets_topics() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    if !shared_ros().join("darknet_ros_msgs/msg").exists() {
        return skip("../shared/ros/darknet_ros_msgs not found");
    }
    let mut graph = RosGraph::start()?;
    let py = graph.darknet_msgs()?;
    graph.spawn_rover(45.0, &[])?;

    // /odom as a rospy node sees it, for comparison with the trace.
    let odom = graph.run_python(
        "odom.py",
        "import math, threading, rospy\nfrom nav_msgs.msg import Odometry\nrospy.init_node('odom_check')\ngot = []\ndone = threading.Event()\ndef keep(m):\n    if len(got) < 200:\n        got.append(m)\n    else:\n        done.set()\nrospy.Subscriber('/odom', Odometry, keep, queue_size=500)\ndone.wait(60)\nfor m in got[:200]:\n    q = m.pose.pose.orientation\n    print('%d.%09d %.12f %.12f %.12f %s %s' % (m.header.stamp.secs, m.header.stamp.nsecs, m.pose.pose.position.x, m.pose.pose.position.y, 2 * math.atan2(q.z, q.w), m.header.frame_id, m.child_frame_id))\n",
        Duration::from_secs(60),
    )?;

    let mut c = graph.command("/usr/bin/rostopic");
    c.args(["echo", "-n", "1", "/darknet_ros/bounding_boxes"])
        .env("PYTHONPATH", &py);
    let (boxes, after_echo) = graph.run_subscriber(c, Duration::from_secs(30))?;

    let mut c = graph.command("/usr/bin/rostopic");
    c.args(["hz", "/camera/image_raw"]);
    let image_hz = graph.run(c, Duration::from_secs(8))?;
    let mut c = graph.command("/usr/bin/rostopic");
    c.args(["hz", "/odom"]);
    let odom_hz = graph.run(c, Duration::from_secs(8))?;

    let bag = graph.dir.path().join("run.bag");
    let mut c = graph.command("/usr/bin/rosbag");
    c.args(["record", "--duration=5", "-O"]).arg(&bag).args([
        "/odom",
        "/tf",
        "/tf_static",
        "/clock",
        "/joint_states",
        "/camera/image_raw",
        "/camera/camera_info",
        "/darknet_ros/bounding_boxes",
        "/darknet_ros/found_object",
    ]);
    let record = graph.run(c, Duration::from_secs(30))?;
    let mut c = graph.command("/usr/bin/rosbag");
    c.arg("info").arg(&bag);
    let info = graph.run(c, Duration::from_secs(30))?;
    let rows = graph.wait_rover(Duration::from_secs(120))?;
    let rover_log = graph.log("rover");

    // rostopic echo: darknet_ros's message, a person with pixel bounds inside the image.
    assert!(
        boxes.contains("Class: \"person\""),
        "no person in\n{boxes}\nrostopic echo: {after_echo}\nrover:\n{rover_log}"
    );
    check_person_box(&boxes)?;

    // rostopic hz: the camera's 30 Hz within 20%, the plugin's 100 Hz within 10%.
    let image_rate =
        average_rate(&image_hz).with_context(|| format!("rostopic hz said\n{image_hz}"))?;
    assert!(
        (24.0..=36.0).contains(&image_rate),
        "image at {image_rate:.1} Hz, camera rate 30 Hz"
    );
    let odom_rate =
        average_rate(&odom_hz).with_context(|| format!("rostopic hz said\n{odom_hz}"))?;
    assert!(
        (90.0..=110.0).contains(&odom_rate),
        "/odom at {odom_rate:.1} Hz, updateRate 100 Hz"
    );

    eprintln!("rostopic hz: image {image_rate:.2} Hz, /odom {odom_rate:.2} Hz");
    // rosbag record + info: every topic, with counts.
    for topic in [
        "/odom",
        "/tf ",
        "/clock",
        "/camera/image_raw",
        "/darknet_ros/found_object",
    ] {
        let line = info.lines().find(|l| l.contains(topic)).with_context(|| {
            format!("{topic} missing in rosbag info:\n{info}\nrecord said:\n{record}")
        })?;
        assert!(line.contains(" msgs"), "no count for {topic}: {line}");
    }
    assert!(info.contains("nav_msgs/Odometry"), "{info}");
    assert!(info.contains("darknet_ros_msgs/ObjectCount"), "{info}");

    // /odom equals the trace's odometry columns at matching stamps.
    let mut compared = 0;
    for line in odom.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let [t, x, y, yaw, frame, child] = f[..] else {
            bail!("odom recorder said: {line}\n{odom}");
        };
        assert_eq!((frame, child), ("odom", "base_link"));
        let (t, x, y, yaw): (f64, f64, f64, f64) =
            (t.parse()?, x.parse()?, y.parse()?, yaw.parse()?);
        let row = rows
            .iter()
            .find(|r| (r.sim_time_s - t).abs() < 5e-5)
            .with_context(|| format!("no trace row at {t} s"))?;
        let dyaw = (row.odom_yaw_rad - yaw + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        assert!(
            (row.odom_x_m - x).abs() <= 1e-6
                && (row.odom_y_m - y).abs() <= 1e-6
                && dyaw.abs() <= 1e-6,
            "at {t} s /odom ({x}, {y}, {yaw}) vs trace ({}, {}, {})",
            row.odom_x_m,
            row.odom_y_m,
            row.odom_yaw_rad
        );
        compared += 1;
    }
    assert_eq!(compared, 200, "odom recorder said\n{odom}");
    Ok(())
}

/// `--ground-truth --ros`: the ground truth of each detected image goes out shaped like
/// darknet_ros's boxes on /rover/ground_truth/bounding_boxes (rostopic reads it with
/// darknet_ros_msgs): the person in view, `probability` 1, COCO's number as `id`, the visible
/// box inside the image.
#[test]
fn the_ground_truth_topic_carries_the_person_in_view() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    if !shared_ros().join("darknet_ros_msgs/msg").exists() {
        return skip("../shared/ros/darknet_ros_msgs not found");
    }
    let mut graph = RosGraph::start()?;
    let py = graph.darknet_msgs()?;
    graph.spawn_rover(30.0, &["--ground-truth"])?;
    let mut c = graph.command("/usr/bin/rostopic");
    c.args(["echo", "-n", "3", "/rover/ground_truth/bounding_boxes"])
        .env("PYTHONPATH", &py);
    let (truth, after_echo) = graph.run_subscriber(c, Duration::from_secs(30))?;
    graph.wait_rover(Duration::from_secs(120))?;
    let rover_log = graph.log("rover");
    assert!(
        truth.contains("Class: \"person\""),
        "no person in\n{truth}\nrostopic echo: {after_echo}\nrover:\n{rover_log}"
    );
    assert_eq!(echoed(&truth, "probability")?, 1.0);
    assert_eq!(echoed(&truth, "id")?, 0.0, "person is COCO's class 0");
    check_person_box(&truth)?;
    assert!(truth.contains("frame_id: \"ground_truth\""), "{truth}");
    Ok(())
}

#[test]
fn rover_survives_a_roscore_restart_and_publishes_again() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let mut graph = RosGraph::start()?;
    graph.spawn_rover(30.0, &["--no-detector"])?;
    let echo_odom = |g: &RosGraph| -> Result<String> {
        let mut c = g.command("/usr/bin/rostopic");
        c.args(["echo", "-n", "1", "/odom/header/stamp"]);
        g.run(c, Duration::from_secs(20))
    };
    let before = echo_odom(&graph)?;
    assert!(
        before.contains("secs:"),
        "no /odom before the restart: {before}"
    );
    graph.kill_master();
    std::thread::sleep(Duration::from_secs(2));
    graph.start_master()?;
    // rover notices (it watches the master) and registers again.
    graph.wait_for(
        Duration::from_secs(20),
        "rover to register again",
        RosGraph::rover_registered,
    )?;
    let after = echo_odom(&graph)?;
    assert!(
        after.contains("secs:"),
        "no /odom after the restart: {after}"
    );
    // The parameter a restarted master lost is set again.
    let description = ros_call(
        &graph.master_uri,
        "getParam",
        &[Value::from("/test"), Value::from("/robot_description")],
        Duration::from_secs(2),
    )?;
    assert!(
        description.as_str().is_some_and(|d| d.contains("<robot")),
        "/robot_description after the restart: {description:?}"
    );
    graph.wait_rover(Duration::from_secs(120))?;
    let log = graph.log("rover");
    assert_eq!(log.matches("went away").count(), 1, "one warning:\n{log}");
    assert!(log.contains("registered again"), "{log}");
    Ok(())
}

/// TIAGo (example-robot-data 6.0.0) with a controllers file: `/joint_states` lists its 12
/// moving joints every control update, `rostopic pub` of a Float64 moves the torso (and an
/// over-limit command stops at its limit), and a two-point JointTrajectory sent with rostopic
/// is followed within the controller's tolerances.
#[test]
fn rostopic_drives_tiagos_torso_and_arm_through_its_controllers() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let ok = Command::new(PYTHON)
        .args(["-c", "import trajectory_msgs.msg, std_msgs.msg"])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        return skip("python3-trajectory-msgs is not installed (./test installs it)");
    }
    let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
        return Ok(());
    };
    let controllers = repo().join("assets/controllers/tiago_no_hand.yaml");
    let mut graph = RosGraph::start()?;
    let controllers = controllers.to_string_lossy();
    graph.spawn_tiago(
        26.0,
        &urdf,
        &["--controllers", controllers.as_ref(), "--no-detector"],
    )?;

    // /joint_states as a rospy node sees it: names and stamps of 20 messages.
    let states = graph.run_python(
        "joint_states.py",
        "import threading, rospy\nfrom sensor_msgs.msg import JointState\nrospy.init_node('joint_states_check')\ngot = []\ndone = threading.Event()\ndef keep(m):\n    got.append(m)\n    if len(got) >= 20:\n        done.set()\nrospy.Subscriber('/joint_states', JointState, keep, queue_size=100)\ndone.wait(30)\nfor m in got[:20]:\n    print('%.6f %d %d %d %s' % (m.header.stamp.to_sec(), len(m.name), len(m.position), len(m.effort), ','.join(m.name)))\n",
        Duration::from_secs(40),
    )?;
    let lines: Vec<Vec<&str>> = states
        .lines()
        .map(|l| l.split(' ').collect::<Vec<_>>())
        .filter(|f| f.len() == 5)
        .collect();
    ensure!(
        lines.len() == 20,
        "expected 20 /joint_states messages:\n{states}"
    );
    for f in &lines {
        ensure!(
            f[1] == "12" && f[2] == "12" && f[3] == "12",
            "a /joint_states message without all 12 joints: {f:?}"
        );
    }
    for name in [
        "torso_lift_joint",
        "head_2_joint",
        "arm_7_joint",
        "wheel_left_joint",
    ] {
        ensure!(
            lines[0][4].contains(name),
            "{name} missing: {}",
            lines[0][4]
        );
    }
    let stamps: Vec<f64> = lines.iter().filter_map(|f| f[0].parse().ok()).collect();
    // The drive's control update (100 Hz) carries it: no gap longer than three of them.
    let worst_gap = stamps.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    ensure!(
        worst_gap <= 0.03 + 1e-6,
        "a /joint_states gap of {worst_gap:.3} s:\n{states}"
    );

    // The controllers' state topics, as the master lists them (Debian has no control_msgs
    // for rostopic echo).
    for (topic, kind) in [
        (
            "/torso_controller/state",
            "control_msgs/JointControllerState",
        ),
        (
            "/arm_controller/state",
            "control_msgs/JointTrajectoryControllerState",
        ),
    ] {
        let mut c = graph.command("/usr/bin/rostopic");
        c.args(["info", topic]);
        let info = graph.run(c, Duration::from_secs(20))?;
        ensure!(
            info.contains(&format!("Type: {kind}")) && info.contains("/rover"),
            "{topic}: {info}"
        );
    }

    let publish = |topic: &str, kind: &str, value: &str| -> Result<String> {
        let mut c = graph.command("/usr/bin/rostopic");
        c.args(["pub", "-1", topic, kind, value]);
        graph.run(c, Duration::from_secs(20))
    };
    let torso = "/torso_controller/command";
    publish(torso, "std_msgs/Float64", "data: 0.2")?;
    std::thread::sleep(Duration::from_secs(3));
    publish(torso, "std_msgs/Float64", "data: 0.6")?;
    let arm: Vec<String> = (1..=7).map(|i| format!("arm_{i}_joint")).collect();
    let first = [0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0];
    let second = [0.2, -1.34, -0.2, 1.94, -1.57, 1.37, 0.0];
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let trajectory = format!(
        "{{joint_names: [{}], points: [{{positions: [{}], time_from_start: {{secs: 2, nsecs: 0}}}}, {{positions: [{}], time_from_start: {{secs: 4, nsecs: 0}}}}]}}",
        arm.join(", "),
        list(&first),
        list(&second)
    );
    let sent = publish(
        "/arm_controller/command",
        "trajectory_msgs/JointTrajectory",
        &trajectory,
    )?;
    let rows = graph.wait_rover(Duration::from_secs(120))?;
    let log = graph.log("rover");
    let names = rover_core::trace_joints(&std::fs::read_to_string(graph.trace_path())?);
    let column = |joint: &str| -> Result<Vec<(f64, f64)>> {
        let k = names
            .iter()
            .position(|n| n == joint)
            .with_context(|| format!("no {joint} column in {names:?}"))?;
        Ok(rows
            .iter()
            .map(|r| (r.sim_time_s, r.joints[k].position))
            .collect())
    };
    let torso_q = column("torso_lift_joint")?;
    ensure!(
        torso_q.iter().any(|(_, q)| (q - 0.2).abs() < 0.005),
        "the torso never reached 0.2 m; rover:\n{log}"
    );
    let highest = torso_q.iter().map(|(_, q)| *q).fold(f64::MIN, f64::max);
    let last = torso_q.last().map_or(0.0, |(_, q)| *q);
    ensure!(
        (last - 0.35).abs() < 0.005 && highest < 0.355,
        "0.6 m should stop at the 0.35 m limit: ended at {last:.4}, highest {highest:.4}"
    );
    ensure!(
        log.contains("controller arm_controller: trajectory reached its goal")
            && !log.contains("VIOLATED"),
        "the trajectory was not followed within its tolerances (rostopic: {sent}); rover:\n{log}"
    );
    for (joint, goal) in arm.iter().zip(second) {
        let q = column(joint)?.last().map_or(f64::NAN, |(_, q)| *q);
        ensure!(
            (q - goal).abs() < 0.02,
            "{joint} ended at {q:.4}, goal {goal}"
        );
    }
    Ok(())
}

/// The VLP-16 car (assets/robots/my_robot_vlp16.urdf.xacro) in the playground: a rospy node
/// reads `/velodyne_points` with Debian's sensor_msgs.point_cloud2 — velodyne_pointcloud's
/// fields (x y z intensity float32 at 0 4 8 16, ring uint16 at 20, 32 bytes a point), an
/// unorganized dense cloud in the frame `velodyne`, all 16 rings, every point within the
/// plugin's 0.9-100 m, at 10 Hz of sim time.
#[test]
fn a_vlp16s_cloud_reaches_a_rospy_subscriber() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let mut graph = RosGraph::start()?;
    let world = repo().join("worlds/playground.toml");
    let robot = repo().join("assets/robots/my_robot_vlp16.urdf.xacro");
    graph.spawn_rover(
        6.0,
        &[
            "--world",
            &world.to_string_lossy(),
            "--robot",
            &robot.to_string_lossy(),
            "--no-detector",
        ],
    )?;
    let out = graph.run_python(
        "cloud.py",
        r#"
import math, rospy, time
from sensor_msgs.msg import PointCloud2
import sensor_msgs.point_cloud2 as pc2
rospy.init_node('cloud_check')
clouds = []
rospy.Subscriber('/velodyne_points', PointCloud2, clouds.append)
end = time.time() + 30
while time.time() < end and len(clouds) < 6:
    time.sleep(0.05)
m = clouds[-1]
print('fields ' + ' '.join('%s:%d:%d' % (f.name, f.offset, f.datatype) for f in m.fields))
print('shape %d %d %d %d %d %s' % (m.height, m.width, m.point_step, m.row_step, int(m.is_dense), m.header.frame_id))
pts = list(pc2.read_points(m, field_names=('x', 'y', 'z', 'ring')))
r = [math.sqrt(x*x + y*y + z*z) for x, y, z, _ in pts]
print('points %d %d %.3f %.3f' % (len(pts), len(set(p[3] for p in pts)), min(r), max(r)))
stamps = [c.header.stamp.to_sec() for c in clouds]
gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
print('period %.4f' % gaps[len(gaps) // 2])
"#,
        Duration::from_secs(60),
    )?;
    graph.wait_rover(Duration::from_secs(120))?;
    println!("{out}");
    let line = |key: &str| graph.keyed_line(&out, key);
    ensure!(
        line("fields")? == ["x:0:7", "y:4:7", "z:8:7", "intensity:16:7", "ring:20:4"],
        "fields: {out}"
    );
    let shape = line("shape")?;
    ensure!(
        shape[0] == "1" && shape[2] == "32" && shape[4] == "1",
        "shape {shape:?}"
    );
    ensure!(shape[5] == "velodyne", "frame {}", shape[5]);
    let width: u64 = shape[1].parse()?;
    ensure!(shape[3] == (32 * width).to_string(), "row_step {shape:?}");
    let points = line("points")?;
    let (n, rings, lo, hi): (u64, u64, f64, f64) = (
        points[0].parse()?,
        points[1].parse()?,
        points[2].parse()?,
        points[3].parse()?,
    );
    ensure!(n == width && n > 5000, "{n} points, width {width}");
    ensure!(rings == 16, "{rings} rings");
    ensure!(lo > 0.9 && hi < 100.0, "ranges {lo}..{hi} m");
    let period: f64 = line("period")?[0].parse()?;
    ensure!(
        (period - 0.1).abs() < 1e-3,
        "clouds {period} s apart, 10 Hz expected"
    );
    Ok(())
}

/// TIAGo's xtion is a depth camera (`<sensor type="depth">`, gazebo_ros_openni_kinect): a rospy
/// node receives `/xtion/depth_registered/image_raw` as 32FC1 (4-byte rows, little-endian,
/// metres within the sensor's 0.3-8 m clip range or NaN) with a camera_info of the same size
/// on `/xtion/depth_registered/camera_info`, in the colour image's optical frame.
#[test]
fn tiagos_xtion_publishes_a_32fc1_depth_image_with_its_camera_info() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
        return Ok(());
    };
    let mut graph = RosGraph::start()?;
    graph.spawn_tiago(20.0, &urdf, &[])?;
    let out = graph.run_python(
        "depth.py",
        "import math, struct, rospy\nfrom sensor_msgs.msg import Image, CameraInfo\nrospy.init_node('depth_check')\nimg = rospy.wait_for_message('/xtion/depth_registered/image_raw', Image, timeout=40)\ninfo = rospy.wait_for_message('/xtion/depth_registered/camera_info', CameraInfo, timeout=20)\nvals = struct.unpack('<%df' % (len(img.data) // 4), img.data)\nfinite = [v for v in vals if not math.isnan(v)]\nprint('image %s %d %d %d %d %d %s' % (img.encoding, img.width, img.height, img.step, len(img.data), img.is_bigendian, img.header.frame_id))\nprint('info %d %d %.3f %s' % (info.width, info.height, info.K[0], info.header.frame_id))\nprint('values %d %.4f %.4f' % (len(finite), min(finite) if finite else -1, max(finite) if finite else -1))\nfrom sensor_msgs.msg import PointCloud2\ncloud = rospy.wait_for_message('/xtion/depth_registered/points', PointCloud2, timeout=20)\nprint('cloud %d %d %d %d %s %s' % (cloud.width, cloud.height, cloud.point_step, int(cloud.is_dense), cloud.header.frame_id, ','.join('%s:%d' % (f.name, f.offset) for f in cloud.fields)))\nzs = [struct.unpack_from('<f', cloud.data, 32 * i + 8)[0] for i in range(0, cloud.width * cloud.height, 7)]\nzs = [z for z in zs if not math.isnan(z)]\nprint('cloudz %d %.4f %.4f' % (len(zs), min(zs) if zs else -1, max(zs) if zs else -1))\n",
        Duration::from_secs(60),
    )?;
    println!("{out}");
    let line = |key: &str| -> Vec<String> {
        out.lines()
            .find(|l| l.starts_with(key))
            .map(|l| l.split(' ').map(str::to_owned).collect())
            .unwrap_or_default()
    };
    let image = line("image ");
    ensure!(image.len() == 8, "no depth image:\n{out}");
    ensure!(image[1] == "32FC1", "encoding {}", image[1]);
    let (w, h): (usize, usize) = (image[2].parse()?, image[3].parse()?);
    ensure!((w, h) == (640, 480), "{w}x{h}");
    ensure!(image[4] == (4 * w).to_string(), "step {}", image[4]);
    ensure!(image[5] == (4 * w * h).to_string(), "{} bytes", image[5]);
    ensure!(image[6] == "0", "big-endian");
    let info = line("info ");
    ensure!(info.len() == 5, "no depth camera_info:\n{out}");
    ensure!(
        info[1] == image[2] && info[2] == image[3],
        "camera_info {info:?} vs image {image:?}"
    );
    ensure!(info[4] == image[7], "frames: {} vs {}", info[4], image[7]);
    // The plugin's frameName, a link of TIAGo's URDF (it used to come out with a second
    // `_optical` on the end).
    ensure!(info[4] == "xtion_rgb_optical_frame", "frame {}", info[4]);
    let values = line("values ");
    ensure!(values.len() == 4, "{out}");
    let (finite, lo, hi): (usize, f64, f64) =
        (values[1].parse()?, values[2].parse()?, values[3].parse()?);
    ensure!(finite > 1000, "{finite} pixels in range:\n{out}");
    ensure!(
        lo >= 0.3 - 1e-3 && hi <= 8.0 + 1e-3,
        "depth {lo}..{hi} m outside the clip range"
    );
    // The organized cloud on `pointCloudTopicName`: a point per pixel in the same frame, x y z
    // rgb, NaN outside the plugin's 0.5-8 m cutoffs.
    let cloud = line("cloud ");
    ensure!(cloud.len() == 7, "no cloud:\n{out}");
    ensure!(cloud[1..5] == ["640", "480", "32", "0"], "cloud {cloud:?}");
    ensure!(cloud[5] == info[4], "cloud frame {}", cloud[5]);
    ensure!(cloud[6] == "x:0,y:4,z:8,rgb:16", "fields {}", cloud[6]);
    let z = line("cloudz ");
    let (n, zlo, zhi): (usize, f64, f64) = (z[1].parse()?, z[2].parse()?, z[3].parse()?);
    ensure!(n > 100, "{n} cloud points in range");
    ensure!(
        zlo > 0.5 && zhi < 8.0,
        "cloud z {zlo}..{zhi} m outside the cutoffs"
    );
    graph.wait_rover(Duration::from_secs(120))?;
    Ok(())
}

/// The arm's reach over ROS: a rospy node asks `/rover/arm/task` for `reach`; TIAGo, seeing a
/// red ball on a stand 0.75 m ahead through its xtion, reports `reach arrived` on the latched
/// `/rover/arm/state`, and `/rover/arm/goal` is a PointStamped in base_footprint 10 cm short
/// of the ball, at its height.
#[test]
fn a_rospy_node_switches_tiagos_reach_on_and_reads_its_state_and_goal() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
        return Ok(());
    };
    let mut graph = RosGraph::start()?;
    let world = graph.dir.path().join("ball.toml");
    std::fs::write(
        &world,
        "[[cylinder]]\nname = \"stand\"\nradius_m = 0.04\nlength_m = 0.7\nposition_m = [0.75, -0.25, 0.35]\ncolor = \"#8a8a8a\"\n\
         [[sphere]]\nname = \"ball\"\nradius_m = 0.06\nposition_m = [0.75, -0.25, 0.76]\ncolor = \"#d02020\"\nmass_kg = 0.1\n",
    )?;
    let script = graph.dir.path().join("start.toml");
    std::fs::write(
        &script,
        "steps = [\n  { at = 0.0, joint = \"arm_1_joint\", position = 0.2 },\n  { at = 0.0, joint = \"arm_2_joint\", position = -1.34 },\n  { at = 0.0, joint = \"arm_3_joint\", position = -0.2 },\n  { at = 0.0, joint = \"arm_4_joint\", position = 1.94 },\n  { at = 0.0, joint = \"arm_5_joint\", position = -1.57 },\n  { at = 0.0, joint = \"arm_6_joint\", position = 1.37 },\n  { at = 0.0, joint = \"head_2_joint\", position = -0.6 },\n]\n",
    )?;
    let (world, script) = (world.to_string_lossy(), script.to_string_lossy());
    graph.spawn_tiago(
        45.0,
        &urdf,
        &[
            "--world",
            world.as_ref(),
            "--script",
            script.as_ref(),
            "--ee-link",
            "arm_tool_link",
            "--arm-base",
            "torso_lift_link",
        ],
    )?;
    let out = graph.run_python(
        "reach.py",
        "import rospy\nfrom std_msgs.msg import String\nfrom geometry_msgs.msg import PointStamped\nrospy.init_node('reach_check')\nstates = []\nrospy.Subscriber('/rover/arm/state', String, lambda m: states.append(m.data))\ntask = rospy.Publisher('/rover/arm/task', String, queue_size=1, latch=True)\nrospy.sleep(3.0)\ntask.publish(String('reach'))\nend = rospy.Time.now() + rospy.Duration(30)\nwhile 'reach arrived' not in states and rospy.Time.now() < end:\n    rospy.sleep(0.1)\nprint('states ' + ','.join(s.replace(' ', '_') for s in states))\ng = rospy.wait_for_message('/rover/arm/goal', PointStamped, timeout=10)\nprint('goal %s %.4f %.4f %.4f' % (g.header.frame_id, g.point.x, g.point.y, g.point.z))\n",
        Duration::from_secs(60),
    )?;
    println!("{out}");
    let states = out
        .lines()
        .find_map(|l| l.strip_prefix("states "))
        .unwrap_or_default();
    ensure!(
        states.split(',').any(|s| s == "reach_arrived"),
        "no `reach arrived` on /rover/arm/state:\n{out}"
    );
    let (frame, [x, y, z]) = stamped_point(&out, "goal")?;
    ensure!(frame == "base_footprint", "goal frame {frame}");
    // The ball's near surface is about 0.69 m ahead; 10 cm short of it, at its height.
    ensure!(
        (0.5..0.68).contains(&x) && (-0.3..-0.1).contains(&y) && (0.7..0.85).contains(&z),
        "goal ({x}, {y}, {z}) is not 10 cm short of the ball"
    );
    graph.wait_rover(Duration::from_secs(120))?;
    Ok(())
}

/// The PointStamped a rospy check printed as `NAME FRAME X Y Z`: its frame and point.
fn stamped_point(out: &str, name: &str) -> Result<(String, [f64; 3])> {
    let fields: Vec<&str> = out
        .lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(' '))
        .map(|l| l.split(' ').collect())
        .unwrap_or_default();
    ensure!(fields.len() == 4, "no {name} point in:\n{out}");
    Ok((
        fields[0].to_owned(),
        [fields[1].parse()?, fields[2].parse()?, fields[3].parse()?],
    ))
}

/// Pick over ROS: a rospy node publishes `pick` on `/rover/arm/task` in worlds/arm_car_pick.toml
/// and reads the latched `/rover/arm/state` go through the pick's states in order (`pick
/// approaching` ... `pick done`), and `/rover/arm/object` (a PointStamped in base_link) is on
/// the ball the mast's camera sees, on the table in front of the car.
#[test]
fn a_rospy_node_has_the_arm_car_pick_the_ball_and_reads_its_states() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let mut graph = RosGraph::start()?;
    let world = repo().join("worlds/arm_car_pick.toml");
    graph.spawn_rover(45.0, &["--world", &world.to_string_lossy()])?;
    let out = graph.run_python(
        "pick.py",
        "import rospy\nfrom std_msgs.msg import String\nfrom geometry_msgs.msg import PointStamped\nrospy.init_node('pick_check')\nstates = []\nrospy.Subscriber('/rover/arm/state', String, lambda m: states.append(m.data))\ntask = rospy.Publisher('/rover/arm/task', String, queue_size=1, latch=True)\nrospy.sleep(2.0)\ntask.publish(String('pick'))\nend = rospy.Time.now() + rospy.Duration(35)\nwhile not ({'pick done', 'pick failed'} & set(states)) and rospy.Time.now() < end:\n    rospy.sleep(0.1)\nprint('states ' + ','.join(s.replace(' ', '_') for s in states))\no = rospy.wait_for_message('/rover/arm/object', PointStamped, timeout=10)\nprint('object %s %.4f %.4f %.4f' % (o.header.frame_id, o.point.x, o.point.y, o.point.z))\n",
        Duration::from_secs(70),
    )?;
    println!("{out}");
    let states: Vec<&str> = out
        .lines()
        .find_map(|l| l.strip_prefix("states "))
        .map(|l| l.split(',').collect())
        .unwrap_or_default();
    let order = [
        "pick_approaching",
        "pick_grasping",
        "pick_lifting",
        "pick_carrying",
        "pick_releasing",
        "pick_retreating",
        "pick_done",
    ];
    let seen: Vec<&str> = states
        .iter()
        .copied()
        .filter(|s| order.contains(s))
        .collect();
    ensure!(
        seen == order,
        "/rover/arm/state went {states:?}, not through {order:?}:\n{out}"
    );
    let (frame, [x, y, z]) = stamped_point(&out, "object")?;
    ensure!(frame == "base_link", "object frame {frame}");
    // The ball's centre: (0.27, 0.08) on the table, 0.05 m above base_link.
    ensure!(
        (x - 0.27).abs() < 0.03 && (y - 0.08).abs() < 0.03 && (z - 0.05).abs() < 0.03,
        "object ({x}, {y}, {z}) is not the ball"
    );
    graph.wait_rover(Duration::from_secs(120))?;
    Ok(())
}

/// A ROS master for a run with both bridges: the tests' lock, the graph, and the PYTHONPATH of
/// a Cyclone DDS peer (cyclonedds and examples/ros2's `rover_msgs`). `None` with the skip
/// recorded (a failure in strict mode) when ROS or the cyclonedds wheel is missing.
fn both_transports() -> Result<Option<(std::sync::MutexGuard<'static, ()>, RosGraph, OsString)>> {
    let one = lock();
    if let Some(why) = missing_ros() {
        skip(&why)?;
        return Ok(None);
    }
    let Some(cyclonedds) = rover_tests::pypi("cyclonedds", "11.0.1") else {
        return Ok(None);
    };
    let graph = RosGraph::start()?;
    let python_path = std::env::join_paths([cyclonedds, repo().join("examples/ros2")])?;
    Ok(Some((one, graph, python_path)))
}

/// `--ros` and `--ros2` in one run: a Cyclone DDS peer drives the car on `rt/cmd_vel` while a
/// rospy node reads `/odom` through the ROS 1 master, and the DDS peer reads `rt/odom` too;
/// both see the same odometry.
#[test]
fn the_ros1_and_ros2_bridges_run_at_once() -> Result<()> {
    let Some((_one, mut graph, python_path)) = both_transports()? else {
        return Ok(());
    };
    graph.spawn_rover(12.0, &["--ros2", "--no-detector"])?;
    graph.spawn_ros2_peer(
        &python_path,
        r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.topic import Topic
from cyclonedds.util import duration
from rover_msgs import Odometry, Twist, Vector3

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
cmd = DataWriter(dp, Topic(dp, 'rt/cmd_vel', Twist), qos=qos)
odom = DataReader(dp, Topic(dp, 'rt/odom', Odometry), qos=qos)
got = []
end = time.time() + 8
while time.time() < end:
    cmd.write(Twist(linear=Vector3(0.3, 0.0, 0.0), angular=Vector3(0.0, 0.0, 0.0)))
    got += odom.take(N=1000)
    time.sleep(0.1)
for m in got:
    print('o %d %d %.9f' % (m.header.stamp.sec, m.header.stamp.nanosec, m.pose.pose.position.x))
"#,
    )?;
    let ros1 = graph.run_python(
        "ros1_odom.py",
        r#"
import rospy
from nav_msgs.msg import Odometry
got = []
rospy.init_node('odom_reader')
rospy.Subscriber('/odom', Odometry, lambda m: got.append(m))
rospy.sleep(6.0)
for m in got:
    print('o %d %d %.9f' % (m.header.stamp.secs, m.header.stamp.nsecs, m.pose.pose.position.x))
"#,
        Duration::from_secs(30),
    )?;
    let rows = graph.wait_rover(Duration::from_secs(120))?;
    let ros2 = graph.log("ros2_peer");
    let parse = |text: &str| -> Vec<(i64, i64, f64)> {
        text.lines()
            .filter_map(|l| l.strip_prefix("o "))
            .filter_map(|l| {
                let f: Vec<&str> = l.split(' ').collect();
                Some((
                    f.first()?.parse().ok()?,
                    f.get(1)?.parse().ok()?,
                    f.get(2)?.parse().ok()?,
                ))
            })
            .collect()
    };
    let (from_ros1, from_ros2) = (parse(&ros1), parse(&ros2));
    let common: Vec<_> = from_ros1
        .iter()
        .filter_map(|a| {
            from_ros2
                .iter()
                .find(|b| (b.0, b.1) == (a.0, a.1))
                .map(|b| (a, b))
        })
        .collect();
    let driven_m = rows.last().context("an empty trace")?.x_m;
    println!(
        "ROS 1 /odom: {} messages, ROS 2 rt/odom: {}; {} stamps in common; the ROS 2 peer drove the car {driven_m:.2} m",
        from_ros1.len(),
        from_ros2.len(),
        common.len()
    );
    ensure!(
        from_ros1.len() >= 100 && from_ros2.len() >= 100,
        "rospy:\n{ros1}\nCyclone:\n{ros2}"
    );
    ensure!(driven_m >= 0.3, "the car drove {driven_m} m");
    ensure!(common.len() >= 100, "{} common stamps", common.len());
    ensure!(
        common.iter().all(|(a, b)| (a.2 - b.2).abs() < 1e-9),
        "ROS 1 and ROS 2 odometry differ"
    );
    ensure!(
        from_ros1.iter().any(|a| a.2 > 0.3),
        "rospy never saw the car move"
    );
    Ok(())
}

/// gazebo_ros_diff_drive with `odometrySource` world publishes the model's full world pose on
/// /odom and /tf's odom -> base: the arm car's base_link stands 8 cm up (the tutorial car's:
/// wheel axles 3 cm below it, wheels of radius 5 cm; the caster reaches as low), and both
/// transports say so (rospy through the master, a Cyclone DDS peer on `rt/odom` and `rt/tf`), level,
/// /tf equal to /odom.
#[test]
fn both_transports_carry_the_bases_height_and_tilt_on_odom_and_tf() -> Result<()> {
    let Some((_one, mut graph, python_path)) = both_transports()? else {
        return Ok(());
    };
    let arm_car = repo().join("assets/robots/my_robot_arm.urdf.xacro");
    let arm_car = arm_car.to_string_lossy();
    graph.spawn_rover(10.0, &["--ros2", "--no-detector", "--robot", &arm_car])?;
    graph.spawn_ros2_peer(
        &python_path,
        r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.topic import Topic
from cyclonedds.util import duration
from rover_msgs import Odometry, TFMessage

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
odom = DataReader(dp, Topic(dp, 'rt/odom', Odometry), qos=qos)
tf = DataReader(dp, Topic(dp, 'rt/tf', TFMessage), qos=qos)
end = time.time() + 6
while time.time() < end:
    for m in odom.take(N=1000):
        p = m.pose.pose
        print('o %d %d %.9f %.9f %.9f %.9f %.9f' % (m.header.stamp.sec, m.header.stamp.nanosec,
              p.position.z, p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w))
    for m in tf.take(N=1000):
        for t in m.transforms:
            if t.header.frame_id == 'odom' and t.child_frame_id == 'base_link':
                r, q = t.transform.translation, t.transform.rotation
                print('t %d %d %.9f %.9f %.9f %.9f %.9f' % (t.header.stamp.sec,
                      t.header.stamp.nanosec, r.z, q.x, q.y, q.z, q.w))
    time.sleep(0.1)
"#,
    )?;
    let ros1 = graph.run_python(
        "ros1_odom.py",
        r#"
import rospy
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage
lines = []
def on_odom(m):
    p = m.pose.pose
    lines.append('o %d %d %.9f %.9f %.9f %.9f %.9f' % (m.header.stamp.secs, m.header.stamp.nsecs,
                 p.position.z, p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w))
def on_tf(m):
    for t in m.transforms:
        if t.header.frame_id == 'odom' and t.child_frame_id == 'base_link':
            r, q = t.transform.translation, t.transform.rotation
            lines.append('t %d %d %.9f %.9f %.9f %.9f %.9f' % (t.header.stamp.secs,
                         t.header.stamp.nsecs, r.z, q.x, q.y, q.z, q.w))
rospy.init_node('odom_reader')
rospy.Subscriber('/odom', Odometry, on_odom)
rospy.Subscriber('/tf', TFMessage, on_tf)
rospy.sleep(5.0)
print('\n'.join(lines))
"#,
        Duration::from_secs(30),
    )?;
    graph.wait_rover(Duration::from_secs(120))?;
    let ros2 = graph.log("ros2_peer");
    // (kind, stamp in ns, z, quaternion)
    type Pose3 = (char, i64, f64, [f64; 4]);
    let parse = |text: &str| -> Vec<Pose3> {
        text.lines()
            .filter_map(|l| {
                let f: Vec<&str> = l.split(' ').collect();
                let kind = match *f.first()? {
                    "o" => 'o',
                    "t" => 't',
                    _ => return None,
                };
                // Every number is printed with 9 decimals: a shorter one is a line the
                // captured output cut off.
                let n = |i: usize| {
                    f.get(i)
                        .filter(|v| v.rsplit_once('.').is_some_and(|(_, d)| d.len() == 9))
                        .and_then(|v| v.parse::<f64>().ok())
                };
                let stamp = f.get(1)?.parse::<i64>().ok()? * 1_000_000_000
                    + f.get(2)?.parse::<i64>().ok()?;
                Some((kind, stamp, n(3)?, [n(4)?, n(5)?, n(6)?, n(7)?]))
            })
            .collect()
    };
    for (transport, text) in [("ROS 1", ros1.as_str()), ("ROS 2", ros2.as_str())] {
        let poses = parse(text);
        let odom: Vec<&Pose3> = poses.iter().filter(|p| p.0 == 'o').collect();
        let tf: Vec<&Pose3> = poses.iter().filter(|p| p.0 == 't').collect();
        let z_range = odom.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
            (lo.min(p.2), hi.max(p.2))
        });
        let tilt = odom
            .iter()
            .map(|p| p.3[0].hypot(p.3[1]))
            .fold(0.0, f64::max);
        println!(
            "{transport}: {} /odom, {} /tf odom -> base_link; z {:.4}..{:.4} m, tilt quaternion \
             x, y up to {tilt:.5}",
            odom.len(),
            tf.len(),
            z_range.0,
            z_range.1
        );
        ensure!(
            odom.len() >= 50 && tf.len() >= 50,
            "{transport}: {} /odom, {} /tf:\n{text}",
            odom.len(),
            tf.len()
        );
        ensure!(
            z_range.0 > 0.075 && z_range.1 < 0.085,
            "{transport}: the base's height on /odom is {:.4}..{:.4} m, not 0.08 m",
            z_range.0,
            z_range.1
        );
        ensure!(tilt < 0.01, "{transport}: the standing car tilts ({tilt})");
        let mut matched = 0;
        for t in &tf {
            if let Some(o) = odom.iter().find(|o| o.1 == t.1) {
                ensure!(
                    (o.2 - t.2).abs() < 1e-9
                        && o.3.iter().zip(&t.3).all(|(a, b)| (a - b).abs() < 1e-9),
                    "{transport}: /tf {t:?} differs from /odom {o:?}"
                );
                matched += 1;
            }
        }
        ensure!(matched >= 50, "{transport}: {matched} /tf stamps on /odom");
    }
    Ok(())
}

/// The worked example of a topic family (docs/ARCHITECTURE.md): `/rover/status` reaches a
/// rospy node through a ROS 1 master and a Cyclone DDS peer as `rt/rover/status` in the same
/// run, once a second of sim time, the same lines on both, and they say where the odometry
/// is.
#[test]
fn rover_status_reaches_rostopic_and_a_cyclone_peer() -> Result<()> {
    let Some((_one, mut graph, python_path)) = both_transports()? else {
        return Ok(());
    };
    graph.spawn_rover(12.0, &["--ros2", "--no-detector"])?;
    graph.spawn_ros2_peer(
        &python_path,
        r#"
import os, time
from dataclasses import dataclass
from cyclonedds.domain import DomainParticipant
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.topic import Topic
from cyclonedds.util import duration
from cyclonedds.idl import IdlStruct
from cyclonedds.pub import DataWriter
from rover_msgs import Twist, Vector3

@dataclass
class String_(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100))
status = DataReader(dp, Topic(dp, 'rt/rover/status', String_), qos=qos)
cmd = DataWriter(dp, Topic(dp, 'rt/cmd_vel', Twist), qos=qos)
got = []
end = time.time() + 9
while time.time() < end:
    cmd.write(Twist(linear=Vector3(0.3, 0.0, 0.0), angular=Vector3(0.0, 0.0, 0.0)))
    got += status.take(N=100)
    time.sleep(0.1)
for m in got:
    print('s ' + m.data)
"#,
    )?;
    let ros1 = graph.run_python(
        "ros1_status.py",
        r#"
import rospy
from std_msgs.msg import String
got = []
rospy.init_node('status_reader')
rospy.Subscriber('/rover/status', String, lambda m: got.append(m.data))
rospy.sleep(8.0)
for m in got:
    print('s ' + m)
"#,
        Duration::from_secs(30),
    )?;
    let rows = graph.wait_rover(Duration::from_secs(120))?;
    let ros2 = graph.log("ros2_peer");
    let lines = |text: &str| -> Vec<String> {
        text.lines()
            .filter_map(|l| l.strip_prefix("s "))
            .map(str::to_owned)
            .collect()
    };
    let (from_ros1, from_ros2) = (lines(&ros1), lines(&ros2));
    println!(
        "/rover/status: {} lines on ROS 1, {} on ROS 2; first {:?}",
        from_ros1.len(),
        from_ros2.len(),
        from_ros1.first()
    );
    // Once a second: 8 s of listening hears 6 to 9 of them.
    for (name, got) in [("ROS 1", &from_ros1), ("ROS 2", &from_ros2)] {
        ensure!(
            (5..=10).contains(&got.len()),
            "{name}: {} status lines:\nrospy:\n{ros1}\nCyclone:\n{ros2}",
            got.len()
        );
        ensure!(
            got.iter()
                .all(|l| l.starts_with("sim ") && l.contains(" odom ") && l.ends_with("arm off")),
            "{name}: {got:?}"
        );
    }
    ensure!(
        rows.last().is_some_and(|r| r.odom_x_m > 0.3),
        "the Cyclone peer did not drive the car"
    );
    let common = from_ros1.iter().filter(|l| from_ros2.contains(l)).count();
    ensure!(
        common >= 4,
        "{common} lines in common: {from_ros1:?} vs {from_ros2:?}"
    );
    // Each line's sim time and odometry are the trace's at that time.
    for line in &from_ros1 {
        let f: Vec<&str> = line.split(' ').collect();
        let (t, x): (f64, f64) = (f[1].parse()?, f[4].parse()?);
        let row = rows
            .iter()
            .min_by(|a, b| {
                (a.sim_time_s - t)
                    .abs()
                    .total_cmp(&(b.sim_time_s - t).abs())
            })
            .context("an empty trace")?;
        ensure!(
            (row.sim_time_s - t).abs() < 0.06 && (row.odom_x_m - x).abs() < 0.03,
            "{line} vs the trace at {:.2} s: odometry x {:.3}",
            row.sim_time_s,
            row.odom_x_m
        );
    }
    Ok(())
}

/// MoveIt's way in: rospy's actionlib `SimpleActionClient` (control_msgs generated by genpy
/// from the `.msg` files in tests/ros_msgs, so the MD5 sums must agree) drives TIAGo's arm
/// through `/arm_controller/follow_joint_trajectory` as joint_trajectory_controller serves it:
/// a two-point goal gets feedback and SUCCEEDED; a goal naming a joint the controller lacks is
/// REJECTED with INVALID_JOINTS; one with a NaN position with INVALID_GOAL; a cancelled goal is
/// PREEMPTED and the arm stays where it was.
#[test]
fn an_actionlib_client_follows_joint_trajectories_on_tiagos_arm() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let ok = Command::new(PYTHON)
        .args([
            "-c",
            "import actionlib, actionlib_msgs.msg, trajectory_msgs.msg",
        ])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        return skip("python3-actionlib is not installed (./test installs it)");
    }
    let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
        return Ok(());
    };
    let mut graph = RosGraph::start()?;
    let py = control_msgs(&graph)?;
    let controllers = repo().join("assets/controllers/tiago_no_hand.yaml");
    let controllers = controllers.to_string_lossy();
    graph.spawn_tiago(
        50.0,
        &urdf,
        &["--controllers", controllers.as_ref(), "--no-detector"],
    )?;
    let script = r#"
import math, time, rospy, actionlib
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal
from trajectory_msgs.msg import JointTrajectoryPoint
from sensor_msgs.msg import JointState
rospy.init_node('fjt_check')
names = ['arm_%d_joint' % i for i in range(1, 8)]
latest = {}
def keep(m):
    latest.update(zip(m.name, m.position))
rospy.Subscriber('/joint_states', JointState, keep)
client = actionlib.SimpleActionClient('/arm_controller/follow_joint_trajectory', FollowJointTrajectoryAction)
print('server %s' % client.wait_for_server(rospy.Duration(30)))
def goal(points, joints=names):
    g = FollowJointTrajectoryGoal()
    g.trajectory.joint_names = joints
    for t, q in points:
        p = JointTrajectoryPoint()
        p.positions = q
        p.time_from_start = rospy.Duration(t)
        g.trajectory.points.append(p)
    return g
first = [0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0]
second = [0.2, -1.34, -0.2, 1.94, -1.57, 1.37, 0.0]
feedback = []
client.send_goal(goal([(2.0, first), (4.0, second)]), feedback_cb=feedback.append)
client.wait_for_result(rospy.Duration(20))
r = client.get_result()
q = [latest.get(n, float('nan')) for n in names]
print('A state %d code %d feedback %d err %.4f' % (client.get_state(), r.error_code if r else 99, len(feedback), max(abs(a - b) for a, b in zip(q, second))))
if feedback:
    f = feedback[len(feedback) // 2]
    print('A feedback joints %s desired %d actual %d' % (','.join(f.joint_names), len(f.desired.positions), len(f.actual.positions)))
for label, g in [('B', goal([(1.0, first)], names[:6] + ['wrist_roll'])), ('C', goal([(1.0, [float('nan')] + first[1:])]))]:
    client.send_goal(g)
    client.wait_for_result(rospy.Duration(10))
    r = client.get_result()
    print('%s state %d code %d text %s' % (label, client.get_state(), r.error_code if r else 99, client.get_goal_status_text()))
client.send_goal(goal([(8.0, first)]))
time.sleep(2.0)
client.cancel_goal()
client.wait_for_result(rospy.Duration(10))
time.sleep(0.5)
at_cancel = [latest.get(n, float('nan')) for n in names]
time.sleep(2.5)
later = [latest.get(n, float('nan')) for n in names]
print('D state %d moved_after %.4f from_goal %.4f' % (client.get_state(), max(abs(a - b) for a, b in zip(at_cancel, later)), max(abs(a - b) for a, b in zip(later, first))))
"#;
    let (out, log) = run_action_client(&graph, "fjt.py", script, &py)?;
    let line = |label: &str| goal_line(&out, &log, label);
    // actionlib_msgs/GoalStatus: PREEMPTED 2, SUCCEEDED 3, REJECTED 5.
    let a = line("A")?;
    ensure!(
        a[0] == 3.0 && a[1] == 0.0 && a[2] >= 20.0 && a[3] < 0.02,
        "goal A: state {}, code {}, {} feedback messages, {:.4} rad from the goal",
        a[0],
        a[1],
        a[2],
        a[3]
    );
    ensure!(
        out.contains("A feedback joints arm_1_joint,") && out.contains("desired 7 actual 7"),
        "feedback: {out}"
    );
    let b = line("B")?;
    ensure!(b[0] == 5.0 && b[1] == -2.0, "goal B (unknown joint): {b:?}");
    ensure!(
        out.contains("arm_controller: joint \"wrist_roll\" is not one of its joints"),
        "{out}"
    );
    let c = line("C")?;
    ensure!(c[0] == 5.0 && c[1] == -1.0, "goal C (NaN): {c:?}");
    let d = line("D")?;
    ensure!(
        d[0] == 2.0 && d[1] < 0.01 && d[2] > 0.05,
        "goal D (cancelled): state {}, moved {:.4} rad after the cancel, {:.4} rad from its goal",
        d[0],
        d[1],
        d[2]
    );
    Ok(())
}

/// MoveIt's gripper: rospy's `SimpleActionClient` on `/gripper_controller/gripper_cmd`
/// (control_msgs/GripperCommandAction, generated by genpy from tests/ros_msgs) drives the test
/// grasper (tests/grasper) with a ball between its fingers: closing a little reaches the goal
/// (SUCCEEDED, reached_goal); closing fully stalls on the ball (ABORTED, stalled, pushing with
/// the goal's max_effort, as ROS 1's gripper_action_controller reports it); a NaN position is
/// REJECTED; reopening reaches the goal.
#[test]
fn an_actionlib_gripper_command_closes_on_the_ball() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let ok = Command::new(PYTHON)
        .args(["-c", "import actionlib, actionlib_msgs.msg"])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        return skip("python3-actionlib is not installed (./test installs it)");
    }
    let mut graph = RosGraph::start()?;
    let py = control_msgs(&graph)?;
    let world = repo().join("tests/grasper/grasper.toml");
    graph.spawn_rover(
        60.0,
        &["--world", &world.to_string_lossy(), "--no-detector"],
    )?;
    let script = r#"
import rospy, actionlib
from control_msgs.msg import GripperCommandAction, GripperCommandGoal
rospy.init_node('gripper_check')
client = actionlib.SimpleActionClient('/gripper_controller/gripper_cmd', GripperCommandAction)
print('server %s' % client.wait_for_server(rospy.Duration(30)))
def send(label, position, effort):
    g = GripperCommandGoal()
    g.command.position = position
    g.command.max_effort = effort
    feedback = []
    client.send_goal(g, feedback_cb=feedback.append)
    client.wait_for_result(rospy.Duration(15))
    r = client.get_result()
    if r is None:
        print('%s state %d no result' % (label, client.get_state()))
        return
    print('%s state %d position %.4f effort %.3f stalled %d reached %d feedback %d' % (label, client.get_state(), r.position, r.effort, r.stalled, r.reached_goal, len(feedback)))
send('A', 0.01, 0.0)
send('B', 0.05, 5.0)
send('C', float('nan'), 1.0)
send('D', 0.0, 0.0)
"#;
    let (out, log) = run_action_client(&graph, "gripper.py", script, &py)?;
    let line = |label: &str| goal_line(&out, &log, label);
    // [state, position, effort, stalled, reached, feedback]; GoalStatus: SUCCEEDED 3,
    // ABORTED 4, REJECTED 5.
    let a = line("A")?;
    ensure!(
        a[0] == 3.0 && (a[1] - 0.01).abs() <= 0.002 && a[3] == 0.0 && a[4] == 1.0,
        "goal A (close 1 cm on nothing): {a:?}"
    );
    let b = line("B")?;
    ensure!(
        b[0] == 4.0 && b[1] > 0.029 && b[1] < 0.038 && b[3] == 1.0 && b[4] == 0.0,
        "goal B (close on the ball): {b:?}"
    );
    ensure!(
        b[2] > 2.5 && b[2] <= 5.0 + 1e-3 && b[5] >= 5.0,
        "goal B's effort (max 5 N) and feedback: {b:?}"
    );
    let c = line("C")?;
    ensure!(c[0] == 5.0, "goal C (NaN): {c:?}");
    let d = line("D")?;
    ensure!(
        d[0] == 3.0 && d[1].abs() <= 0.002 && d[4] == 1.0,
        "goal D (reopen): {d:?}"
    );
    Ok(())
}

/// control_msgs for rospy, generated by genpy from the `.msg` files in tests/ros_msgs (so the
/// MD5 sums must agree with rover's); the folder to put on PYTHONPATH.
fn control_msgs(graph: &RosGraph) -> Result<PathBuf> {
    let msgs = repo().join("tests/ros_msgs");
    rover_tests::ros::generate_msgs(
        "control_msgs",
        &msgs.join("control_msgs/msg"),
        &[
            ("trajectory_msgs", &msgs.join("trajectory_msgs/msg")),
            ("actionlib_msgs", Path::new("/usr/share/actionlib_msgs/msg")),
            ("std_msgs", Path::new("/usr/share/std_msgs/msg")),
        ],
        &graph.dir.path().join("control_py"),
    )
}

/// Runs the actionlib client `script` (as `name`, with `py` on PYTHONPATH) against the graph;
/// its output and rover's log. The client must have found the server (`server True`).
fn run_action_client(
    graph: &RosGraph,
    name: &str,
    script: &str,
    py: &Path,
) -> Result<(String, String)> {
    let out = graph.run_python_with(name, script, Some(py), Duration::from_secs(90))?;
    println!("{out}");
    let log = graph.log("rover");
    ensure!(
        out.contains("server True"),
        "no action server:\n{out}\n{log}"
    );
    Ok((out, log))
}

/// The numbers on the client's `LABEL state ...` line for goal `label`.
fn goal_line(out: &str, log: &str, label: &str) -> Result<Vec<f64>> {
    let l = out
        .lines()
        .find(|l| l.starts_with(&format!("{label} state")))
        .with_context(|| format!("no result for goal {label}:\n{out}\nrover:\n{log}"))?;
    Ok(l.split(' ').filter_map(|w| w.parse().ok()).collect())
}
