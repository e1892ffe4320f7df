//! The ROS 2 bridge (`rover --ros2`) against a real DDS peer: Eclipse Cyclone DDS (what
//! rmw_cyclonedds_cpp uses), from PyPI `cyclonedds` 11.0.1, with the ROS 2 messages declared
//! under their DDS type names as rmw does (the wheel fetched by set-up). Skipped, counted and
//! listed (a failure in strict mode), where it is not there. Each test runs in its own DDS domain, so tests and other peers do not meet.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, ensure};
use rover_core::parse_trace;

/// The ROS 2 messages the peer uses, as cyclonedds IdlStructs named like rmw names them:
/// examples/ros2/rover_msgs.py's, and (below) the tests' own.
const MESSAGES: &str = r#"
from dataclasses import dataclass
from cyclonedds.idl import IdlStruct
import cyclonedds.idl.types as types
from rover_msgs import (BoundingBox, BoundingBoxes, Header, Odometry, Point, Pose,
                        PoseWithCovariance, Quaternion, Time, Twist, TwistWithCovariance, Vector3)
"#;

/// examples/ros2: `rover_msgs.py`, the ROS 2 messages declared for Cyclone DDS, which the
/// peers import (so the tests check the examples' declarations too).
fn examples_ros2() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/ros2")
}

/// A rover and a Python peer in DDS domain `domain`, logs in `dir`.
struct Graph {
    dir: tempfile::TempDir,
    domain: u16,
    cyclonedds: PathBuf,
    rover: Option<Child>,
}

impl Graph {
    fn new(cyclonedds: PathBuf, domain: u16) -> Result<Self> {
        Ok(Self {
            dir: tempfile::tempdir()?,
            domain,
            cyclonedds,
            rover: None,
        })
    }

    fn trace_path(&self) -> PathBuf {
        self.dir.path().join("trace.csv")
    }

    /// `rover --headless --ros2` for `duration_s` of sim time at real time.
    fn spawn_rover(&mut self, duration_s: f64, extra: &[&str]) -> Result<()> {
        let log = std::fs::File::create(self.dir.path().join("rover.log"))?;
        let child = Command::new(env!("CARGO_BIN_EXE_rover"))
            .args(["--headless", "--ros2", "--rtf", "1", "--duration"])
            .arg(duration_s.to_string())
            .arg("--trace")
            .arg(self.trace_path())
            .args(extra)
            .env("ROS_DOMAIN_ID", self.domain.to_string())
            .env("RUST_LOG", "info")
            .stdin(Stdio::null())
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()
            .context("starting rover")?;
        self.rover = Some(child);
        Ok(())
    }

    /// `rover --ros2` with TIAGo (example-robot-data's, without a hand), its wheels driven and
    /// its controllers file, and `extra` arguments; `false` (the skip recorded) without
    /// example-robot-data.
    fn spawn_tiago(&mut self, duration_s: f64, extra: &[&str]) -> Result<bool> {
        let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
            return Ok(false);
        };
        let controllers =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/controllers/tiago_no_hand.yaml");
        let (urdf, controllers) = (urdf.to_string_lossy(), controllers.to_string_lossy());
        let mut args = vec![
            "--robot",
            urdf.as_ref(),
            "--drive",
            "wheel_left_joint,wheel_right_joint",
            "--controllers",
            controllers.as_ref(),
        ];
        args.extend_from_slice(extra);
        self.spawn_rover(duration_s, &args)?;
        Ok(true)
    }

    /// Runs `script` (after the message definitions) with cyclonedds importable; its output.
    fn python(&self, name: &str, script: &str, timeout: Duration) -> Result<String> {
        let path = self.dir.path().join(name);
        std::fs::write(&path, format!("{MESSAGES}\n{script}"))?;
        self.python_file(name, &path, timeout)
    }

    /// Runs the Python file `path` with cyclonedds importable, stopping it after `timeout`;
    /// its output (logged as `name`).
    fn python_file(&self, name: &str, path: &Path, timeout: Duration) -> Result<String> {
        // Output into a file: a pipe would fill up and stall the peer.
        let log_path = self.dir.path().join(format!("{name}.log"));
        let log = std::fs::File::create(&log_path)?;
        let mut child = Command::new("python3")
            .arg(path)
            .env(
                "PYTHONPATH",
                std::env::join_paths([&self.cyclonedds, &examples_ros2()])?,
            )
            .env("PYTHONUNBUFFERED", "1")
            .env("ROS_DOMAIN_ID", self.domain.to_string())
            .stdin(Stdio::null())
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()?;
        rover_tests::wait_or_kill(&mut child, timeout)?;
        Ok(std::fs::read_to_string(&log_path)?)
    }

    /// Waits for rover to finish; its exit must be clean.
    fn wait_rover(&mut self, timeout: Duration) -> Result<()> {
        self.wait_exit(timeout, false)
    }

    /// Waits for rover to exit, at most `timeout` (then kills it): exit code 0, or 130 too
    /// when `interrupted` (ended by SIGINT, its files finished).
    fn wait_exit(&mut self, timeout: Duration, interrupted: bool) -> Result<()> {
        let Some(mut child) = self.rover.take() else {
            return Ok(());
        };
        let start = Instant::now();
        loop {
            if let Some(status) = child.try_wait()? {
                let log = std::fs::read_to_string(self.dir.path().join("rover.log"))?;
                ensure!(
                    status.success() || (interrupted && status.code() == Some(130)),
                    "rover failed ({status}):\n{log}"
                );
                return Ok(());
            }
            if start.elapsed() > timeout {
                let _ = child.kill();
                anyhow::bail!("rover did not finish in {timeout:?}");
            }
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// Ends rover's run early as Ctrl-C does (its files finished, exit code 130).
    fn stop_rover(&mut self, timeout: Duration) -> Result<()> {
        if let Some(child) = &mut self.rover
            && child.try_wait()?.is_none()
        {
            let status = Command::new("kill")
                .arg("-INT")
                .arg(child.id().to_string())
                .status()?;
            ensure!(status.success(), "kill -INT {} failed", child.id());
        }
        self.wait_exit(timeout, true)
    }
}

impl Drop for Graph {
    fn drop(&mut self) {
        if let Some(mut child) = self.rover.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// Cyclone DDS's Python package, unpacked from PyPI by set-up; `None` (the skip recorded)
/// without it.
fn cyclonedds() -> Option<PathBuf> {
    let dir = rover_tests::pypi("cyclonedds", "11.0.1")?;
    let ok = Command::new("python3")
        .args(["-c", "import cyclonedds.domain"])
        .env("PYTHONPATH", &dir)
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        Some(dir)
    } else {
        rover_tests::skip::skip_or_panic(format!(
            "cyclonedds from {} does not import in python3",
            dir.display()
        ));
        None
    }
}

/// A DDS domain of this test's own (ROS 2 allows 0..=232).
fn domain(salt: u16) -> u16 {
    10 + ((std::process::id() as u16).wrapping_add(salt)) % 200
}

/// A Cyclone DDS participant publishing geometry_msgs/msg/Twist on `rt/cmd_vel` drives the car
/// (>= 0.3 m); one subscribing to `rt/odom` receives nav_msgs/msg/Odometry equal to the trace's
/// odometry (1e-6, the trace's precision) at the same stamps, in frame odom, child
/// base_link (the tutorial car's robotBaseFrame).
#[test]
fn a_cyclone_dds_peer_drives_the_car_and_reads_its_odometry() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(1))?;
    graph.spawn_rover(12.0, &[])?;
    let out = graph.python(
        "drive.py",
        r#"
import math, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.util import duration

dp = DomainParticipant(int(__import__('os').environ['ROS_DOMAIN_ID']))
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(1000))
cmd = DataWriter(dp, Topic(dp, 'rt/cmd_vel', Twist), qos=reliable)
odom = DataReader(dp, Topic(dp, 'rt/odom', Odometry), qos=reliable)
got = []
end = time.time() + 9
while time.time() < end:
    cmd.write(Twist(linear=Vector3(0.5, 0.0, 0.0), angular=Vector3(0.0, 0.0, 0.0)))
    for m in odom.take(N=1000):
        got.append(m)
    time.sleep(0.1)
print('odom', len(got))
for m in got:
    p = m.pose.pose
    q = p.orientation
    # The heading of a base that may tilt (odometrySource world), as tf reads it.
    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
    print('o %d %d %s %s %.9f %.9f %.9f %.9f' % (m.header.stamp.sec, m.header.stamp.nanosec,
          m.header.frame_id, m.child_frame_id, p.position.x, p.position.y, yaw,
          m.twist.twist.linear.x))
"#,
        Duration::from_secs(40),
    )?;
    graph.wait_rover(Duration::from_secs(60))?;
    let trace = std::fs::read_to_string(graph.trace_path())?;
    let rows = parse_trace(&trace)?;
    let last = rows.last().context("an empty trace")?;
    let driven = last.x_m.hypot(last.y_m);
    println!(
        "{}\nrover drove {driven:.3} m",
        out.lines().take(3).collect::<Vec<_>>().join("\n")
    );
    ensure!(driven >= 0.3, "the car drove {driven} m:\n{out}");
    let odom: Vec<Vec<&str>> = out
        .lines()
        .filter_map(|l| l.strip_prefix("o "))
        .map(|l| l.split(' ').collect())
        .collect();
    ensure!(
        odom.len() >= 100,
        "{} odometry messages:\n{out}",
        odom.len()
    );
    let sent: usize = out
        .lines()
        .find_map(|l| l.strip_prefix("odom "))
        .and_then(|n| n.trim().parse().ok())
        .unwrap_or(0);
    let mut compared = 0;
    for f in &odom {
        ensure!(f.len() == 8, "{f:?}");
        ensure!(f[2] == "odom" && f[3] == "base_link", "frames {f:?}");
        let stamp_s = f[0].parse::<f64>()? + f[1].parse::<f64>()? * 1e-9;
        let Some(row) = rows.iter().find(|r| (r.sim_time_s - stamp_s).abs() < 5e-5) else {
            continue;
        };
        let (x, y): (f64, f64) = (f[4].parse()?, f[5].parse()?);
        let yaw: f64 = f[6].parse()?;
        ensure!(
            (x - row.odom_x_m).abs() <= 1e-6
                && (y - row.odom_y_m).abs() <= 1e-6
                && (yaw - row.odom_yaw_rad).abs() <= 1e-6,
            "at {stamp_s} s: odom ({x}, {y}, {yaw}) vs trace ({}, {}, {})",
            row.odom_x_m,
            row.odom_y_m,
            row.odom_yaw_rad
        );
        compared += 1;
    }
    println!(
        "{compared} of {} odometry messages equal the trace",
        odom.len()
    );
    ensure!(
        compared + 5 >= odom.len() && odom.len() + 50 >= sent,
        "{compared} of {} matched a trace row ({sent} sent)",
        odom.len()
    );
    Ok(())
}

/// tf2's (from examples/ros2/rover_msgs.py), sensor_msgs' and darknet_ros's (ROS 2 branch)
/// messages for the peer.
const MORE_MESSAGES: &str = r#"
from rover_msgs import Transform, TransformStamped, TFMessage

@dataclass
class Image(IdlStruct, typename="sensor_msgs::msg::dds_::Image_"):
    header: Header
    height: types.uint32
    width: types.uint32
    encoding: str
    is_bigendian: types.uint8
    step: types.uint32
    data: types.sequence[types.uint8]

@dataclass
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header
    name: types.sequence[str]
    position: types.sequence[types.float64]
    velocity: types.sequence[types.float64]
    effort: types.sequence[types.float64]
"#;

/// `/tf_static` reaches a peer that joins 4 s after rover started (transient local), with the
/// camera's optical frame; the camera's images arrive as rgb8 640x480 in that frame at the
/// camera's 30 Hz of sim time, and `/joint_states` names the wheels: the rates delivered to
/// the peer are printed.
#[test]
fn a_late_cyclone_peer_gets_tf_static_and_the_camera_images() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(2))?;
    graph.spawn_rover(16.0, &[])?;
    std::thread::sleep(Duration::from_secs(4));
    let script = format!(
        "{MORE_MESSAGES}\n{}",
        r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.util import duration

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
static = DataReader(dp, Topic(dp, 'rt/tf_static', TFMessage), qos=latched)
images = DataReader(dp, Topic(dp, 'rt/camera/image_raw', Image), qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(100)))
joints = DataReader(dp, Topic(dp, 'rt/joint_states', JointState), qos=Qos(Policy.History.KeepLast(1000)))
boxes = DataReader(dp, Topic(dp, 'rt/darknet_ros/bounding_boxes', BoundingBoxes), qos=Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100)))
got_static, got_images, got_joints, got_boxes = [], [], [], []
start = time.time()
while time.time() < start + 6:
    got_static += static.take(N=10)
    got_images += images.take(N=100)
    got_joints += joints.take(N=1000)
    got_boxes += boxes.take(N=100)
    time.sleep(0.02)
for m in got_boxes:
    t = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
    ti = m.image_header.stamp.sec + m.image_header.stamp.nanosec * 1e-9
    for b in m.bounding_boxes:
        print('box %s %.3f %d %d %d %d %d %s %.3f %.3f' % (b.class_id.replace(' ', '_'), b.probability,
              b.xmin, b.ymin, b.xmax, b.ymax, b.id, m.image_header.frame_id, ti, t))
wall = time.time() - start
for m in got_static:
    print('static ' + ','.join(t.header.frame_id + '>' + t.child_frame_id for t in m.transforms))
stamps = [i.header.stamp.sec + i.header.stamp.nanosec * 1e-9 for i in got_images]
if got_images:
    i = got_images[-1]
    print('image %d %d %s %d %d %s' % (i.width, i.height, i.encoding, i.step, len(i.data), i.header.frame_id))
    print('images %d over %.2f s sim, %.2f s wall' % (len(stamps), max(stamps) - min(stamps), wall))
if got_joints:
    j = got_joints[-1]
    js = [m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in got_joints]
    print('joints %s %d over %.2f s sim' % (','.join(j.name), len(js), max(js) - min(js)))
"#
    );
    let out = graph.python("late.py", &script, Duration::from_secs(30))?;
    graph.wait_rover(Duration::from_secs(60))?;
    println!("{out}");
    let static_line = out
        .lines()
        .find_map(|l| l.strip_prefix("static "))
        .with_context(|| format!("no /tf_static for the late joiner:\n{out}"))?;
    ensure!(
        static_line.contains("camera_link>camera_link_optical"),
        "no optical frame in /tf_static: {static_line}"
    );
    let image: Vec<&str> = out
        .lines()
        .find_map(|l| l.strip_prefix("image "))
        .map(|l| l.split(' ').collect())
        .with_context(|| format!("no image:\n{out}"))?;
    ensure!(
        image
            == [
                "640",
                "480",
                "rgb8",
                "1920",
                "921600",
                "camera_link_optical"
            ],
        "image {image:?}"
    );
    let rate: Vec<f64> = out
        .lines()
        .find_map(|l| l.strip_prefix("images "))
        .map(|l| {
            l.split(' ')
                .filter_map(|w| w.parse().ok())
                .collect::<Vec<f64>>()
        })
        .unwrap_or_default();
    ensure!(rate.len() == 3, "{out}");
    let hz = (rate[0] - 1.0) / rate[1];
    println!(
        "images delivered at {hz:.1} Hz of sim time ({:.1} per wall second)",
        rate[0] / rate[2]
    );
    ensure!(hz > 25.0, "images at {hz} Hz");
    ensure!(
        out.lines()
            .any(|l| l.starts_with("joints ") && l.contains("left_wheel_joint")),
        "{out}"
    );
    // darknet_ros's boxes: the person, inside the 640x480 image, from an image no newer than
    // the message.
    let boxes: Vec<Vec<&str>> = out
        .lines()
        .filter_map(|l| l.strip_prefix("box "))
        .map(|l| l.split(' ').collect())
        .collect();
    let people = boxes.iter().filter(|b| b[0] == "person").count();
    println!("{} boxes, {people} of them person", boxes.len());
    ensure!(people >= 5, "{out}");
    for b in &boxes {
        let p: f64 = b[1].parse()?;
        let v: Vec<i64> = b[2..6]
            .iter()
            .map(|s| s.parse())
            .collect::<Result<_, _>>()?;
        let (image_s, sent_s): (f64, f64) = (b[8].parse()?, b[9].parse()?);
        ensure!(
            p > 0.0
                && p <= 1.0
                && 0 <= v[0]
                && v[0] < v[2]
                && v[2] <= 640
                && 0 <= v[1]
                && v[1] < v[3]
                && v[3] <= 480,
            "a box {b:?}"
        );
        ensure!(
            b[7] == "camera_link_optical" && image_s <= sent_s,
            "a box {b:?}"
        );
    }
    Ok(())
}

/// A peer publishing garbage on `rt/cmd_vel` (a string under Twist's type name): rover warns
/// once and goes on; a real Twist afterwards still drives the car.
#[test]
fn garbage_on_cmd_vel_is_ignored_with_one_warning() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(3))?;
    graph.spawn_rover(10.0, &[])?;
    let out = graph.python(
        "garbage.py",
        r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter

@dataclass
class Bad(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    data: str

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
bad = DataWriter(dp, Topic(dp, 'rt/cmd_vel', Bad))
for i in range(20):
    bad.write(Bad(data='not a twist %d' % i))
    time.sleep(0.1)
del bad
good = DataWriter(dp, Topic(dp, 'rt/cmd_vel', Twist))
for i in range(40):
    good.write(Twist(linear=Vector3(0.5, 0.0, 0.0), angular=Vector3(0.0, 0.0, 0.0)))
    time.sleep(0.1)
print('done')
"#,
        Duration::from_secs(30),
    )?;
    graph.wait_rover(Duration::from_secs(60))?;
    let log = std::fs::read_to_string(graph.dir.path().join("rover.log"))?;
    let rows = parse_trace(&std::fs::read_to_string(graph.trace_path())?)?;
    let driven = rows.last().map_or(0.0, |r| r.x_m.hypot(r.y_m));
    let warnings = log.matches("could not be read").count();
    println!("{out}rover drove {driven:.3} m; {warnings} warning(s)");
    ensure!(out.contains("done"), "{out}");
    ensure!(
        driven >= 0.3,
        "the car drove {driven} m after the garbage:\n{log}"
    );
    ensure!(warnings <= 1, "{warnings} warnings:\n{log}");
    Ok(())
}

/// The tutorial's listener_yolo node ported to ROS 2's wire (examples/ros2/listener_yolo.py,
/// Cyclone DDS) drives rover toward the person: it prints `person` from
/// `rt/darknet_ros/bounding_boxes` and its 0.1 m/s on `rt/cmd_vel` moves the car >= 0.3 m.
#[test]
fn the_listener_yolo_port_drives_the_car_toward_the_person() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(4))?;
    graph.spawn_rover(12.0, &[])?;
    let listener = examples_ros2().join("listener_yolo.py");
    let said = graph.python_file("listener", &listener, Duration::from_secs(14))?;
    graph.wait_rover(Duration::from_secs(60))?;
    let rows = parse_trace(&std::fs::read_to_string(graph.trace_path())?)?;
    let people = said.lines().filter(|l| l.trim() == "person").count();
    let went = said.lines().filter(|l| l.trim() == "go on").count();
    ensure!(people > 0 && went > 0, "the listener said:\n{said}");
    ensure!(
        rows.iter()
            .any(|r| (r.cmd_linear_mps - 0.1).abs() < 1e-9 && r.cmd_angular_radps == 0.0),
        "no 0.1 m/s command in the trace"
    );
    let at = |t: f64| {
        rows.iter()
            .find(|r| r.sim_time_s >= t)
            .context("the trace ends early")
    };
    let moved_m = at(10.0)?.x_m - at(0.0)?.x_m;
    println!(
        "the listener saw `person` {people} times and said `go on` {went} times; the car moved {moved_m:.3} m in 10 s"
    );
    ensure!(
        moved_m >= 0.3,
        "the car moved {moved_m:.3} m (want >= 0.3 m)"
    );
    Ok(())
}

/// ros2_control's and rover's own messages for the controller test.
const CONTROL_MESSAGES: &str = r#"
@dataclass
class String_(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str

@dataclass
class MultiArrayDimension(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayDimension_"):
    label: str
    size: types.uint32
    stride: types.uint32

@dataclass
class MultiArrayLayout(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayLayout_"):
    dim: types.sequence[MultiArrayDimension]
    data_offset: types.uint32

@dataclass
class Float64MultiArray(IdlStruct, typename="std_msgs::msg::dds_::Float64MultiArray_"):
    layout: MultiArrayLayout
    data: types.sequence[types.float64]

@dataclass
class Duration(IdlStruct, typename="builtin_interfaces::msg::dds_::Duration_"):
    sec: types.int32
    nanosec: types.uint32

@dataclass
class JointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectoryPoint_"):
    positions: types.sequence[types.float64]
    velocities: types.sequence[types.float64]
    accelerations: types.sequence[types.float64]
    effort: types.sequence[types.float64]
    time_from_start: Duration

@dataclass
class JointTrajectory(IdlStruct, typename="trajectory_msgs::msg::dds_::JointTrajectory_"):
    header: Header
    joint_names: types.sequence[str]
    points: types.sequence[JointTrajectoryPoint]
"#;

/// TIAGo (example-robot-data 6.0.0) with its controllers over ROS 2, as ros2_control names
/// the topics: a late Cyclone peer gets `/robot_description` (transient local, the URDF);
/// a Float64MultiArray on `/torso_controller/commands` moves the torso to 0.2 m; a two-point
/// JointTrajectory on `/arm_controller/joint_trajectory` is followed to its goal within the
/// controller's tolerances; `look` on `/rover/arm/task` comes back on `/rover/arm/state`.
#[test]
fn a_cyclone_peer_drives_tiagos_controllers_and_arm_task() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(5))?;
    if !graph.spawn_tiago(
        16.0,
        &[
            "--ee-link",
            "arm_tool_link",
            "--arm-base",
            "torso_lift_link",
        ],
    )? {
        return Ok(());
    }
    std::thread::sleep(Duration::from_secs(2));
    let script = format!(
        "{CONTROL_MESSAGES}\n{}",
        r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.util import duration

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10))
latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
description = DataReader(dp, Topic(dp, 'rt/robot_description', String_), qos=latched)
state = DataReader(dp, Topic(dp, 'rt/rover/arm/state', String_), qos=latched)
torso = DataWriter(dp, Topic(dp, 'rt/torso_controller/commands', Float64MultiArray), qos=reliable)
arm = DataWriter(dp, Topic(dp, 'rt/arm_controller/joint_trajectory', JointTrajectory), qos=reliable)
task = DataWriter(dp, Topic(dp, 'rt/rover/arm/task', String_), qos=reliable)
urdf = None
end = time.time() + 10
while urdf is None and time.time() < end:
    for m in description.take(N=1):
        urdf = getattr(m, 'data', None)
    time.sleep(0.05)
print('description %d %s' % (len(urdf or ''), (urdf or '').find('<robot') >= 0))
time.sleep(1.0)  # the writers have matched rover's readers
torso.write(Float64MultiArray(layout=MultiArrayLayout(dim=[], data_offset=0), data=[0.2]))
names = ['arm_%d_joint' % i for i in range(1, 8)]
point = lambda q, t: JointTrajectoryPoint(positions=q, velocities=[], accelerations=[], effort=[], time_from_start=Duration(t, 0))
arm.write(JointTrajectory(header=Header(stamp=Time(0, 0), frame_id=''), joint_names=names,
          points=[point([0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0], 2), point([0.2, -1.34, -0.2, 1.94, -1.57, 1.37, 0.0], 4)]))
task.write(String_(data='look'))
seen = []
end = time.time() + 3
while time.time() < end:
    seen += [m.data for m in state.take(N=10) if hasattr(m, 'data')]
    time.sleep(0.05)
print('states ' + ','.join(s.replace(' ', '_') for s in seen))
"#
    );
    let out = graph.python("control.py", &script, Duration::from_secs(30))?;
    graph.wait_rover(Duration::from_secs(90))?;
    println!("{out}");
    let log = std::fs::read_to_string(graph.dir.path().join("rover.log"))?;
    let description = out
        .lines()
        .find_map(|l| l.strip_prefix("description "))
        .unwrap_or_default();
    ensure!(
        description.ends_with(" True") && !description.starts_with("0 "),
        "no URDF on /robot_description: {out}"
    );
    ensure!(
        out.lines()
            .any(|l| l.starts_with("states ") && l.contains("look")),
        "the arm's state never said look:\n{out}\nrover:\n{log}"
    );
    let trace = std::fs::read_to_string(graph.trace_path())?;
    let rows = parse_trace(&trace)?;
    let names = rover_core::trace_joints(&trace);
    let last_q = |joint: &str| -> Result<Vec<f64>> {
        let k = names
            .iter()
            .position(|n| n == joint)
            .with_context(|| format!("no {joint} column"))?;
        Ok(rows.iter().map(|r| r.joints[k].position).collect())
    };
    let torso = last_q("torso_lift_joint")?;
    ensure!(
        torso.iter().any(|q| (q - 0.2).abs() < 0.005),
        "the torso never reached 0.2 m; rover:\n{log}"
    );
    ensure!(
        log.contains("controller arm_controller: trajectory reached its goal")
            && !log.contains("VIOLATED"),
        "the trajectory was not followed within its tolerances; rover:\n{log}"
    );
    let goal = [0.2, -1.34, -0.2, 1.94, -1.57, 1.37, 0.0];
    for (i, g) in goal.iter().enumerate() {
        let joint = format!("arm_{}_joint", i + 1);
        let q = last_q(&joint)?.last().copied().unwrap_or(f64::NAN);
        ensure!((q - g).abs() < 0.02, "{joint} ended at {q:.4}, goal {g}");
    }
    println!("torso at 0.2 m, the arm at its trajectory's goal, state `look`");
    Ok(())
}

/// Prints what `ros_discovery_info` says of rover's participant (`node NS NAME READERS
/// WRITERS`, then a `match` line: whether its Gids are the GUIDs of rover's DDS readers and
/// writers as DDS discovery reports them), read by a peer that joins late, with Gids of
/// `GID_BYTES` bytes.
const DISCOVERY_PEER: &str = r#"
import os, sys, time, uuid
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.sub import DataReader
from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication, BuiltinTopicDcpsSubscription
from cyclonedds.qos import Qos, Policy
from cyclonedds.util import duration

N = GID_BYTES

@dataclass
class Gid(IdlStruct, typename="rmw_dds_common::msg::dds_::Gid_"):
    data: types.array[types.uint8, N]

@dataclass
class NodeEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::NodeEntitiesInfo_"):
    node_namespace: types.bounded_str[256]
    node_name: types.bounded_str[256]
    reader_gid_seq: types.sequence[Gid]
    writer_gid_seq: types.sequence[Gid]

@dataclass
class ParticipantEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"):
    gid: Gid
    node_entities_info_seq: types.sequence[NodeEntitiesInfo]

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
info = DataReader(dp, Topic(dp, 'ros_discovery_info', ParticipantEntitiesInfo), qos=latched)
pubs = BuiltinDataReader(dp, BuiltinTopicDcpsPublication)
subs = BuiltinDataReader(dp, BuiltinTopicDcpsSubscription)
got, writers, readers = [], {}, {}
end = time.time() + 5
while time.time() < end:
    got += info.take(N=10)
    for e in pubs.take(N=1000):
        writers[e.key.bytes] = (e.participant_key.bytes, e.topic_name)
    for e in subs.take(N=1000):
        readers[e.key.bytes] = (e.participant_key.bytes, e.topic_name)
    time.sleep(0.05)
print('messages %d' % len(got))
for m in got:
    participant = bytes(m.gid.data[:16])
    # rover's endpoints as DDS discovery saw them, ros_discovery_info's own writer excepted.
    dds_w = {k for k, (p, t) in writers.items() if p == participant and t != 'ros_discovery_info'}
    dds_r = {k for k, (p, t) in readers.items() if p == participant}
    # A Gid is a 16-byte GUID, zero-padded to 24 bytes before Iron. (At 16 bytes there is no
    # padding: a wrong size shows as the fields after the Gids decoding to nonsense.)
    if N > 16:
        print('padding %s' % all(b == 0 for b in m.gid.data[16:]))
    for n in m.node_entities_info_seq:
        w = {bytes(g.data[:16]) for g in n.writer_gid_seq}
        r = {bytes(g.data[:16]) for g in n.reader_gid_seq}
        print('node %s %s %d %d' % (n.node_namespace, n.node_name, len(n.reader_gid_seq), len(n.writer_gid_seq)))
        print('match %s %s %d %d' % (w == dds_w, r == dds_r, len(dds_r), len(dds_w)))
        print('topics %s' % ' '.join(sorted(t for k, (p, t) in writers.items() if k in w)))
"#;

/// `ros2 node list` finds rover: a Cyclone DDS peer that joins 4 s late reads
/// `ros_discovery_info` (transient local) and finds one node, `/rover`, whose reader and
/// writer Gids are exactly rover's DDS readers and writers as DDS discovery reports them (one
/// per topic: cmd_vel, the arm's task in; clock, odom, tf, the camera's ... out; a request
/// reader and a reply writer per parameter service), for both Gid sizes: 24 bytes with `--ros-distro humble`, 16 by default.
#[test]
fn a_late_peer_finds_node_rover_in_ros_discovery_info_for_both_gid_sizes() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    for (salt, gid_bytes, extra) in [(7, 24, &["--ros-distro", "humble"][..]), (8, 16, &[])] {
        let mut graph = Graph::new(cyclonedds.clone(), domain(salt))?;
        graph.spawn_rover(14.0, extra)?;
        std::thread::sleep(Duration::from_secs(4));
        let script = DISCOVERY_PEER.replace("GID_BYTES", &gid_bytes.to_string());
        let out = graph.python("discovery.py", &script, Duration::from_secs(30))?;
        graph.wait_rover(Duration::from_secs(60))?;
        let lines: Vec<&str> = out.lines().collect();
        ensure!(
            lines
                .iter()
                .any(|l| l.starts_with("messages ") && *l != "messages 0"),
            "{gid_bytes}-byte Gids: no ros_discovery_info reached the late peer:\n{out}"
        );
        let nodes: Vec<&&str> = lines.iter().filter(|l| l.starts_with("node ")).collect();
        ensure!(
            nodes.len() == 1 && nodes[0].starts_with("node / rover "),
            "{gid_bytes}-byte Gids: expected one node /rover:\n{out}"
        );
        let counts: Vec<usize> = nodes[0]
            .split(' ')
            .skip(3)
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        // The car: cmd_vel and the arm's task in, and the requests of the 6 parameter services;
        // out at least clock, odom, tf, tf_static, joint_states, robot_description, image and
        // camera_info, darknet_ros's three, and the 6 services' replies.
        ensure!(
            counts.len() == 2 && counts[0] == 8 && counts[1] >= 17,
            "{gid_bytes}-byte Gids: readers, writers {counts:?}:\n{out}"
        );
        ensure!(
            lines.contains(&format!("match True True {} {}", counts[0], counts[1]).as_str())
                && (gid_bytes == 16 || lines.contains(&"padding True")),
            "{gid_bytes}-byte Gids: the Gids are not rover's DDS endpoints:\n{out}"
        );
        let topics = lines
            .iter()
            .find(|l| l.starts_with("topics "))
            .context("no topics line")?;
        for t in [
            "rt/odom",
            "rt/clock",
            "rt/tf",
            "rt/darknet_ros/bounding_boxes",
        ] {
            ensure!(
                topics.split(' ').any(|w| w == t),
                "{gid_bytes}-byte Gids: {t} is not among the node's writers: {topics}"
            );
        }
    }
    Ok(())
}

/// The parameter services' messages, with rmw_cyclonedds_cpp's request header (`guid`, `seq`)
/// in front of each request's and reply's fields, as it puts it on the wire.
const PARAMETER_MESSAGES: &str = r#"
@dataclass
class ParameterValue(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterValue_"):
    type: types.uint8
    bool_value: bool
    integer_value: types.int64
    double_value: types.float64
    string_value: str
    byte_array_value: types.sequence[types.uint8]
    bool_array_value: types.sequence[bool]
    integer_array_value: types.sequence[types.int64]
    double_array_value: types.sequence[types.float64]
    string_array_value: types.sequence[str]

@dataclass
class Parameter(IdlStruct, typename="rcl_interfaces::msg::dds_::Parameter_"):
    name: str
    value: ParameterValue

@dataclass
class SetParametersResult(IdlStruct, typename="rcl_interfaces::msg::dds_::SetParametersResult_"):
    successful: bool
    reason: str

@dataclass
class GetParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Request_"):
    guid: types.uint64
    seq: types.int64
    names: types.sequence[str]

@dataclass
class GetParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Response_"):
    guid: types.uint64
    seq: types.int64
    values: types.sequence[ParameterValue]

@dataclass
class ListParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::ListParameters_Request_"):
    guid: types.uint64
    seq: types.int64
    prefixes: types.sequence[str]
    depth: types.uint64

@dataclass
class ListParametersResult(IdlStruct, typename="rcl_interfaces::msg::dds_::ListParametersResult_"):
    names: types.sequence[str]
    prefixes: types.sequence[str]

@dataclass
class ListParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::ListParameters_Response_"):
    guid: types.uint64
    seq: types.int64
    result: ListParametersResult

@dataclass
class SetParameters_Request_(IdlStruct, typename="rcl_interfaces::srv::dds_::SetParameters_Request_"):
    guid: types.uint64
    seq: types.int64
    parameters: types.sequence[Parameter]

@dataclass
class SetParameters_Response_(IdlStruct, typename="rcl_interfaces::srv::dds_::SetParameters_Response_"):
    guid: types.uint64
    seq: types.int64
    results: types.sequence[SetParametersResult]
"#;

/// `ros2 param get /rover use_sim_time` as a Cyclone DDS client does it: a request on
/// `rq/rover/get_parametersRequest` comes back on `rr/rover/get_parametersReply` with the
/// client's header, `use_sim_time` a bool that is true, `robot_description` the URDF (as
/// `/robot_description` carries it), an unknown name not set; `list_parameters` names both;
/// `set_parameters` is refused with a reason. Five truncated requests from another client are
/// one warning naming the mapping, and the requests after them are answered.
#[test]
fn a_cyclone_client_reads_use_sim_time_through_the_parameter_service() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(9))?;
    graph.spawn_rover(12.0, &[])?;
    let script = format!(
        "{PARAMETER_MESSAGES}\n{}",
        r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.util import duration

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(10))
def client(name, req, resp):
    w = DataWriter(dp, Topic(dp, 'rq/rover/%sRequest' % name, req), qos=qos)
    r = DataReader(dp, Topic(dp, 'rr/rover/%sReply' % name, resp), qos=qos)
    return w, r
@dataclass
class String_(IdlStruct, typename="std_msgs::msg::dds_::String_"):
    data: str
latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
description = DataReader(dp, Topic(dp, 'rt/robot_description', String_), qos=latched)
get = client('get_parameters', GetParameters_Request_, GetParameters_Response_)
lst = client('list_parameters', ListParameters_Request_, ListParameters_Response_)
st = client('set_parameters', SetParameters_Request_, SetParameters_Response_)
# A truncated request (the header's first 8 bytes only) from another client, five times: one
# warning, no reply, and the requests after it are answered.
@dataclass
class Truncated(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Request_"):
    guid: types.uint64
other = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
bad = DataWriter(other, Topic(other, 'rq/rover/get_parametersRequest', Truncated), qos=qos)
time.sleep(3)
for i in range(5):
    bad.write(Truncated(guid=i))
time.sleep(0.5)
get[0].write(GetParameters_Request_(guid=0x1234, seq=7, names=['use_sim_time', 'robot_description', 'nope']))
lst[0].write(ListParameters_Request_(guid=0x1234, seq=8, prefixes=[], depth=0))
value = ParameterValue(type=1, bool_value=False, integer_value=0, double_value=0.0, string_value='', byte_array_value=[], bool_array_value=[], integer_array_value=[], double_array_value=[], string_array_value=[])
st[0].write(SetParameters_Request_(guid=0x1234, seq=9, parameters=[Parameter(name='use_sim_time', value=value)]))
end = time.time() + 5
got = {}
urdf = []
while time.time() < end and (len(got) < 3 or not urdf):
    urdf += description.take(N=1)
    for name, (_, r) in (('get', get), ('list', lst), ('set', st)):
        for m in r.take(N=10):
            got[name] = m
    time.sleep(0.05)
g = got.get('get')
if g:
    print('get header %x %d' % (g.guid, g.seq))
    for v in g.values:
        same = bool(urdf) and v.string_value == urdf[0].data
        print('value %d %s %s' % (v.type, v.bool_value, 'urdf' if same else len(v.string_value)))
l = got.get('list')
if l:
    print('list %d %s' % (l.seq, ' '.join(sorted(l.result.names))))
s = got.get('set')
if s:
    for x in s.results:
        print('set %d %s %s' % (s.seq, x.successful, x.reason))
"#
    );
    let out = graph.python("parameters.py", &script, Duration::from_secs(30))?;
    graph.wait_rover(Duration::from_secs(60))?;
    let lines: Vec<&str> = out.lines().collect();
    let expect = [
        "get header 1234 7",
        "value 1 True 0",
        "value 4 False urdf",
        "value 0 False 0",
        "list 8 robot_description use_sim_time",
    ];
    for e in &expect {
        ensure!(lines.contains(e), "expected \"{e}\":\n{out}");
    }
    ensure!(
        lines
            .iter()
            .any(|l| l.starts_with("set 9 False use_sim_time is read-only")),
        "set_parameters was not refused:\n{out}"
    );
    let log = std::fs::read_to_string(graph.dir.path().join("rover.log"))?;
    let warnings: Vec<&str> = log
        .lines()
        .filter(|l| l.contains("did not decode"))
        .collect();
    ensure!(
        warnings.len() == 1 && warnings[0].contains("Cyclone DDS's mapping"),
        "five truncated requests from one client must be one warning naming the mapping: \
         {warnings:?}\n{log}"
    );
    Ok(())
}

/// control_msgs/action/FollowJointTrajectory's services and topics as rcl maps them, with
/// rmw_cyclonedds_cpp's request header; the feedback in Humble's and Jazzy's layout.
const ACTION_MESSAGES: &str = r#"
from rover_msgs import Transform

@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: types.array[types.uint8, 16]

@dataclass
class GoalInfo(IdlStruct, typename="action_msgs::msg::dds_::GoalInfo_"):
    goal_id: UUID
    stamp: Time

@dataclass
class GoalStatus(IdlStruct, typename="action_msgs::msg::dds_::GoalStatus_"):
    goal_info: GoalInfo
    status: types.int8

@dataclass
class GoalStatusArray(IdlStruct, typename="action_msgs::msg::dds_::GoalStatusArray_"):
    status_list: types.sequence[GoalStatus]

@dataclass
class JointTolerance(IdlStruct, typename="control_msgs::msg::dds_::JointTolerance_"):
    name: str
    position: types.float64
    velocity: types.float64
    acceleration: types.float64

@dataclass
class JointComponentTolerance(IdlStruct, typename="control_msgs::msg::dds_::JointComponentTolerance_"):
    joint_name: str
    component: types.uint16
    position: types.float64
    velocity: types.float64
    acceleration: types.float64

@dataclass
class MultiDOFJointTrajectoryPoint(IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectoryPoint_"):
    transforms: types.sequence[Transform]
    velocities: types.sequence[Twist]
    accelerations: types.sequence[Twist]
    time_from_start: Duration

@dataclass
class MultiDOFJointTrajectory(IdlStruct, typename="trajectory_msgs::msg::dds_::MultiDOFJointTrajectory_"):
    header: Header
    joint_names: types.sequence[str]
    points: types.sequence[MultiDOFJointTrajectoryPoint]

@dataclass
class FJT_Goal(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Goal_"):
    trajectory: JointTrajectory
    multi_dof_trajectory: MultiDOFJointTrajectory
    path_tolerance: types.sequence[JointTolerance]
    component_path_tolerance: types.sequence[JointComponentTolerance]
    goal_tolerance: types.sequence[JointTolerance]
    component_goal_tolerance: types.sequence[JointComponentTolerance]
    goal_time_tolerance: Duration

@dataclass
class FJT_Result(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Result_"):
    error_code: types.int32
    error_string: str

@dataclass
class FJT_Feedback(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_Feedback_"):
    header: Header
    joint_names: types.sequence[str]
    desired: JointTrajectoryPoint
    actual: JointTrajectoryPoint
    error: JointTrajectoryPoint
    multi_dof_joint_names: types.sequence[str]
    multi_dof_desired: MultiDOFJointTrajectoryPoint
    multi_dof_actual: MultiDOFJointTrajectoryPoint
    multi_dof_error: MultiDOFJointTrajectoryPoint

@dataclass
class FJT_FeedbackMessage(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_FeedbackMessage_"):
    goal_id: UUID
    feedback: FJT_Feedback

@dataclass
class FJT_SendGoal_Request(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Request_"):
    guid: types.uint64
    seq: types.int64
    goal_id: UUID
    goal: FJT_Goal

@dataclass
class FJT_SendGoal_Response(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_SendGoal_Response_"):
    guid: types.uint64
    seq: types.int64
    accepted: bool
    stamp: Time

@dataclass
class FJT_GetResult_Request(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_GetResult_Request_"):
    guid: types.uint64
    seq: types.int64
    goal_id: UUID

@dataclass
class FJT_GetResult_Response(IdlStruct, typename="control_msgs::action::dds_::FollowJointTrajectory_GetResult_Response_"):
    guid: types.uint64
    seq: types.int64
    status: types.int8
    result: FJT_Result

@dataclass
class CancelGoal_Request(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Request_"):
    guid: types.uint64
    seq: types.int64
    goal_info: GoalInfo

@dataclass
class CancelGoal_Response(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Response_"):
    guid: types.uint64
    seq: types.int64
    return_code: types.int8
    goals_canceling: types.sequence[GoalInfo]
"#;

/// MoveIt's way in on ROS 2: a Cyclone DDS action client sends TIAGo's arm a two-point goal on
/// `/arm_controller/follow_joint_trajectory`: accepted, feedback while it runs (desired,
/// actual, error for the 7 arm joints), the status list says EXECUTING then SUCCEEDED, and
/// get_result answers SUCCEEDED with error code 0; the arm is at the goal. A second goal,
/// cancelled halfway, is CANCELED and the arm stops where it was: it moves no more than
/// 0.01 rad afterwards, far from that goal. A third goal is CANCELED by a command on
/// `~/joint_trajectory`, as joint_trajectory_controller preempts it.
#[test]
fn an_action_client_moves_tiagos_arm_and_a_cancel_stops_it() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(10))?;
    // Long enough for a slow machine: the test stops rover once the client is done.
    if !graph.spawn_tiago(300.0, &["--ros-distro", "jazzy"])? {
        return Ok(());
    }
    std::thread::sleep(Duration::from_secs(2));
    let script = format!(
        "{CONTROL_MESSAGES}\n{ACTION_MESSAGES}\n{ACTION_CLIENT}\n{}",
        r#"
a = '/arm_controller/follow_joint_trajectory/_action/'
send = service('send_goal', FJT_SendGoal_Request, FJT_SendGoal_Response)
cancel = service('cancel_goal', CancelGoal_Request, CancelGoal_Response)
result = service('get_result', FJT_GetResult_Request, FJT_GetResult_Response)
feedback = DataReader(dp, Topic(dp, 'rt' + a + 'feedback', FJT_FeedbackMessage), qos=reliable)
status = DataReader(dp, Topic(dp, 'rt' + a + 'status', GoalStatusArray), qos=latched)
topic = DataWriter(dp, Topic(dp, 'rt/arm_controller/joint_trajectory', JointTrajectory), qos=reliable)
odom = DataReader(dp, Topic(dp, 'rt/odom', Odometry), qos=reliable)
sim_s = [0.0]
def sim_now():
    for o in odom.take(N=100):
        sim_s[0] = max(sim_s[0], o.header.stamp.sec + o.header.stamp.nanosec * 1e-9)
    return sim_s[0]
# Rover's readers found (a slow machine may take seconds), not a fixed wait.
writers = [send[0], cancel[0], result[0], topic]
until = time.time() + 60
while time.time() < until and not all(w.get_matched_subscriptions() for w in writers):
    time.sleep(0.1)
print('matched %s' % [len(w.get_matched_subscriptions()) for w in writers])
time.sleep(1)

names = ['arm_%d_joint' % i for i in range(1, 8)]
point = lambda q, t: JointTrajectoryPoint(positions=q, velocities=[], accelerations=[], effort=[], time_from_start=Duration(t, 0))
def goal(points):
    return FJT_Goal(
        trajectory=JointTrajectory(header=Header(stamp=Time(0, 0), frame_id=''), joint_names=names, points=points),
        multi_dof_trajectory=MultiDOFJointTrajectory(header=Header(stamp=Time(0, 0), frame_id=''), joint_names=[], points=[]),
        path_tolerance=[], component_path_tolerance=[], goal_tolerance=[], component_goal_tolerance=[],
        goal_time_tolerance=Duration(0, 0))
ida, idb = UUID(uuid=[1] * 16), UUID(uuid=[2] * 16)
seen = []
def pump(until, stop=None):
    got = {'send': [], 'cancel': [], 'result': [], 'feedback': []}
    while time.time() < until:
        got['send'] += send[1].take(N=10)
        got['cancel'] += cancel[1].take(N=10)
        got['result'] += result[1].take(N=10)
        got['feedback'] += feedback.take(N=100)
        for s in status.take(N=10):
            seen.append(tuple((bytes(g.goal_info.goal_id.uuid)[0], g.status) for g in s.status_list))
        if stop and stop(got):
            break
        time.sleep(0.02)
    return got

send[0].write(FJT_SendGoal_Request(guid=1, seq=1, goal_id=ida, goal=goal(
    [point([0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0], 2), point([0.2, -1.34, -0.2, 1.94, -1.57, 1.37, 0.0], 4)])))
got = pump(time.time() + 2, lambda g: g['send'])
print('accepted a %s' % [r.accepted for r in got['send']])
result[0].write(FJT_GetResult_Request(guid=1, seq=2, goal_id=ida))
# The 4 s goal's result comes when it is reached: up to 40 s of wall time for a slow machine
# (rover runs at whatever pace it can; a 9 s wait let goal B preempt A on a loaded one).
got = pump(time.time() + 40, lambda g: g['result'])
fa = [f for f in got['feedback'] if bytes(f.goal_id.uuid)[0] == 1]
print('feedback a %d %d' % (len(fa), min([len(f.feedback.actual.positions) for f in fa] or [0])))
if fa:
    f = fa[len(fa) // 2].feedback
    print('feedback names %s' % ','.join(f.joint_names))
    print('feedback error %.6f' % max(abs(d - x - e) for d, x, e in zip(f.desired.positions, f.actual.positions, f.error.positions)))
for r in got['result']:
    print('result a %d %d %s' % (r.status, r.result.error_code, r.result.error_string.replace(' ', '_')))

send[0].write(FJT_SendGoal_Request(guid=1, seq=3, goal_id=idb, goal=goal([point([1.2, -0.5, -0.2, 1.0, -1.0, 0.5, 0.0], 6)])))
got = pump(time.time() + 2.0)
fb = [f for f in got['feedback'] if bytes(f.goal_id.uuid)[0] == 2]
print('accepted b %s' % [r.accepted for r in got['send']])
cancel[0].write(CancelGoal_Request(guid=1, seq=4, goal_info=GoalInfo(goal_id=idb, stamp=Time(0, 0))))
got = pump(time.time() + 2, lambda g: g['cancel'])
fb += [f for f in got['feedback'] if bytes(f.goal_id.uuid)[0] == 2]
for r in got['cancel']:
    print('cancel b %d %d' % (r.return_code, len(r.goals_canceling)))
if fb:
    s = fb[-1].feedback.header.stamp
    print('cancelled at %.3f' % (s.sec + s.nanosec * 1e-9))
result[0].write(FJT_GetResult_Request(guid=1, seq=5, goal_id=idb))
got = pump(time.time() + 3, lambda g: g['result'])
for r in got['result']:
    print('result b %d %d' % (r.status, r.result.error_code))
# A command on ~/joint_trajectory preempts goal C, as joint_trajectory_controller does.
idc = UUID(uuid=[3] * 16)
# The arm holds still after the cancel, for the trace's check: 2 s of rover's clock, with
# margin (a loaded machine runs rover slower than real time).
if fb:
    pump(time.time() + 120, lambda g: sim_now() > s.sec + s.nanosec * 1e-9 + 2.5)
else:
    pump(time.time() + 4.0)
send[0].write(FJT_SendGoal_Request(guid=1, seq=6, goal_id=idc, goal=goal([point([0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0], 4)])))
pump(time.time() + 1.0)
topic.write(JointTrajectory(header=Header(stamp=Time(0, 0), frame_id=''), joint_names=names, points=[point([0.2, -1.0, -0.2, 1.5, -1.0, 0.5, 0.0], 2)]))
result[0].write(FJT_GetResult_Request(guid=1, seq=7, goal_id=idc))
got = pump(time.time() + 3, lambda g: g['result'])
for r in got['result']:
    print('result c %d %s' % (r.status, r.result.error_string.replace(' ', '_')))
pump(time.time() + 1)
print('statuses %s' % ' '.join('/'.join('%d:%d' % x for x in s) for s in seen))
"#
    );
    let out = graph.python("action.py", &script, Duration::from_secs(160))?;
    graph.stop_rover(Duration::from_secs(60))?;
    println!("{out}");
    let log = std::fs::read_to_string(graph.dir.path().join("rover.log"))?;
    let has = |line: &str| out.lines().any(|l| l == line);
    for line in [
        "accepted a [True]",
        "result a 4 0 goal_reached",
        "accepted b [True]",
        "cancel b 0 1",
        "result b 5 0",
        "result c 5 preempted_by_a_command_on_~/joint_trajectory",
        "feedback names arm_1_joint,arm_2_joint,arm_3_joint,arm_4_joint,arm_5_joint,arm_6_joint,arm_7_joint",
    ] {
        ensure!(has(line), "expected \"{line}\":\n{out}\nrover:\n{log}");
    }
    let count = |prefix: &str| -> Option<Vec<f64>> {
        let rest = out.lines().find_map(|l| l.strip_prefix(prefix))?;
        rest.split(' ').map(|w| w.parse().ok()).collect()
    };
    let feedback = count("feedback a ").context("no feedback line")?;
    // 20 Hz over the goal's 4 s: about 80.
    ensure!(
        feedback[0] >= 40.0 && feedback[1] == 7.0,
        "feedback {feedback:?}:\n{out}"
    );
    let error = count("feedback error ").context("no feedback error")?;
    ensure!(error[0] < 1e-9, "error != desired - actual: {error:?}");
    let statuses = out
        .lines()
        .find_map(|l| l.strip_prefix("statuses "))
        .unwrap_or_default();
    ensure!(
        statuses.contains("1:2") && statuses.contains("1:4") && statuses.contains("2:5"),
        "the status list never said A EXECUTING, A SUCCEEDED, B CANCELED: {statuses}"
    );
    // The arm stops where it was when B was cancelled.
    let cancelled_s = count("cancelled at ").context("no feedback for B")?[0];
    let trace = std::fs::read_to_string(graph.trace_path())?;
    let rows = parse_trace(&trace)?;
    let names = rover_core::trace_joints(&trace);
    let k = names
        .iter()
        .position(|n| n == "arm_1_joint")
        .context("no arm_1_joint column")?;
    let at = |t: f64| {
        rows.iter()
            .find(|r| r.sim_time_s >= t)
            .map(|r| r.joints[k].position)
    };
    let last_s = rows.last().map_or(0.0, |r| r.sim_time_s);
    let early = || format!("the trace ends at {last_s:.2} s, before {cancelled_s:.2} s + 2 s");
    let (then, later, end) = (
        at(cancelled_s + 0.5).with_context(early)?,
        at(cancelled_s + 1.5).with_context(early)?,
        at(cancelled_s + 2.0).with_context(early)?,
    );
    println!(
        "arm_1_joint: {then:.4} rad 0.5 s after the cancel, {later:.4} 1.5 s after, {end:.4} 2 s after (B's goal 1.2, A's 0.2)"
    );
    ensure!(
        (later - then).abs() < 0.01 && (end - then).abs() < 0.01,
        "the arm kept moving after the cancel: {then} -> {later} -> {end}"
    );
    ensure!(
        then > 0.25 && (end - 1.2).abs() > 0.2,
        "the arm did not move toward B before the cancel, or reached B: {then}, {end}"
    );
    Ok(())
}

/// A Cyclone DDS action client's set-up: the participant, reliable and latched QoS, and
/// `service(name, request, response)`, the writer and reader of action `a`'s service `name`
/// (the script sets `a`, the action's `/<name>/_action/` prefix).
const ACTION_CLIENT: &str = r#"
import os, time
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.qos import Qos, Policy
from cyclonedds.util import duration

dp = DomainParticipant(int(os.environ['ROS_DOMAIN_ID']))
reliable = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.History.KeepLast(100))
latched = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.TransientLocal, Policy.History.KeepLast(1))
def service(name, req, resp):
    return (DataWriter(dp, Topic(dp, 'rq' + a + name + 'Request', req), qos=reliable),
            DataReader(dp, Topic(dp, 'rr' + a + name + 'Reply', resp), qos=reliable))
"#;

/// GripperCommand's messages for a Cyclone DDS peer (with [`ACTION_MESSAGES`]).
const GRIPPER_MESSAGES: &str = r#"
@dataclass
class GripperCommand(IdlStruct, typename="control_msgs::msg::dds_::GripperCommand_"):
    position: types.float64
    max_effort: types.float64

@dataclass
class GC_Goal(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_Goal_"):
    command: GripperCommand

@dataclass
class GC_Result(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_Result_"):
    position: types.float64
    effort: types.float64
    stalled: bool
    reached_goal: bool

@dataclass
class GC_FeedbackMessage(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_FeedbackMessage_"):
    goal_id: UUID
    feedback: GC_Result

@dataclass
class GC_SendGoal_Request(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_SendGoal_Request_"):
    guid: types.uint64
    seq: types.int64
    goal_id: UUID
    goal: GC_Goal

@dataclass
class GC_SendGoal_Response(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_SendGoal_Response_"):
    guid: types.uint64
    seq: types.int64
    accepted: bool
    stamp: Time

@dataclass
class GC_GetResult_Request(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_GetResult_Request_"):
    guid: types.uint64
    seq: types.int64
    goal_id: UUID

@dataclass
class GC_GetResult_Response(IdlStruct, typename="control_msgs::action::dds_::GripperCommand_GetResult_Response_"):
    guid: types.uint64
    seq: types.int64
    status: types.int8
    result: GC_Result
"#;

/// MoveIt's gripper on ROS 2: a Cyclone DDS action client on `/gripper_controller/gripper_cmd`
/// (control_msgs/action/GripperCommand, as ros2_control's gripper_action_controller serves it)
/// closes the test grasper (tests/grasper) on the ball between its fingers: accepted, feedback
/// while the fingers move, and get_result says ABORTED with `stalled` (the ball stops them
/// short of the goal, pushing with the goal's max_effort); a goal with a NaN position is not
/// accepted; reopening SUCCEEDS with `reached_goal`.
#[test]
fn a_cyclone_action_client_closes_the_gripper_on_the_ball() -> Result<()> {
    let Some(cyclonedds) = cyclonedds() else {
        return Ok(());
    };
    let mut graph = Graph::new(cyclonedds, domain(11))?;
    let world = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/grasper/grasper.toml");
    graph.spawn_rover(
        40.0,
        &["--world", &world.to_string_lossy(), "--no-detector"],
    )?;
    std::thread::sleep(Duration::from_secs(2));
    let script = format!(
        "{CONTROL_MESSAGES}\n{ACTION_MESSAGES}\n{GRIPPER_MESSAGES}\n{ACTION_CLIENT}\n{}",
        r#"
a = '/gripper_controller/gripper_cmd/_action/'
send = service('send_goal', GC_SendGoal_Request, GC_SendGoal_Response)
result = service('get_result', GC_GetResult_Request, GC_GetResult_Response)
feedback = DataReader(dp, Topic(dp, 'rt' + a + 'feedback', GC_FeedbackMessage), qos=reliable)
time.sleep(3)
seq = [0]
def goal(label, k, position, effort, wait):
    seq[0] += 1
    gid = UUID(uuid=[k] * 16)
    send[0].write(GC_SendGoal_Request(guid=7, seq=seq[0], goal_id=gid, goal=GC_Goal(command=GripperCommand(position=position, max_effort=effort))))
    end = time.time() + 3
    accepted = []
    while time.time() < end and not accepted:
        accepted += send[1].take(N=10)
        time.sleep(0.02)
    print('%s accepted %s' % (label, [r.accepted for r in accepted]))
    if not accepted or not accepted[0].accepted:
        return
    seq[0] += 1
    result[0].write(GC_GetResult_Request(guid=7, seq=seq[0], goal_id=gid))
    end = time.time() + wait
    got, fb = [], []
    while time.time() < end and not got:
        got += result[1].take(N=10)
        fb += [f for f in feedback.take(N=100) if bytes(f.goal_id.uuid)[0] == k]
        time.sleep(0.02)
    for r in got:
        x = r.result
        print('%s result %d %.4f %.3f %d %d feedback %d' % (label, r.status, x.position, x.effort, x.stalled, x.reached_goal, len(fb)))
goal('close', 1, 0.05, 5.0, 10)
goal('nan', 2, float('nan'), 1.0, 1)
goal('open', 3, 0.0, 0.0, 10)
"#
    );
    let out = graph.python("gripper.py", &script, Duration::from_secs(60))?;
    println!("{out}");
    let log = std::fs::read_to_string(graph.dir.path().join("rover.log"))?;
    let numbers = |prefix: &str| -> Result<Vec<f64>> {
        let rest = out
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .with_context(|| format!("no \"{prefix}\" line:\n{out}\nrover:\n{log}"))?;
        Ok(rest.split(' ').filter_map(|w| w.parse().ok()).collect())
    };
    ensure!(
        out.contains("close accepted [True]") && out.contains("nan accepted [False]"),
        "accepting goals:\n{out}\nrover:\n{log}"
    );
    // [status, position, effort, stalled, reached_goal, feedback]; action_msgs: SUCCEEDED 4,
    // ABORTED 6.
    let close = numbers("close result ")?;
    ensure!(
        close[0] == 6.0
            && close[1] > 0.029
            && close[1] < 0.038
            && close[3] == 1.0
            && close[4] == 0.0,
        "closing on the ball: {close:?}"
    );
    ensure!(
        close[2] > 2.5 && close[2] <= 5.0 + 1e-3 && close[5] >= 5.0,
        "closing on the ball: effort (max 5 N) and feedback: {close:?}"
    );
    let open = numbers("open result ")?;
    ensure!(
        open[0] == 4.0 && open[1].abs() <= 0.002 && open[4] == 1.0,
        "reopening: {open:?}"
    );
    Ok(())
}
