//! Modern Gazebo's TurtleBot3s over ROS (issue 62): ROBOTIS' Jazzy burger and waffle_pi (SDF
//! models with gz-sim systems, ../shared/corpus/turtlebot3_gz) in turtlebot3_world.world, their
//! topics named by their own ros_gz_bridge files (cmd_vel as geometry_msgs/TwistStamped), each
//! driven a metre by a rospy node on a real ROS 1 master and by an rclpy node on Fast DDS;
//! /scan, /imu, /odom, /joint_states and /tf checked at their declared rates, the waffle_pi's
//! camera images received.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::Duration;

use anyhow::{Context, Result, ensure};

#[path = "ros/graph.rs"]
mod graph;
use graph::*;

/// The corpus's turtlebot3_gazebo package, or `None` (skip recorded).
fn tb3_gz() -> Option<PathBuf> {
    rover_tests::shared("corpus/turtlebot3_gz/turtlebot3_gazebo")
}

/// One of ROBOTIS' Jazzy TurtleBot3s, as its launch files start it.
struct Tb3 {
    /// `turtlebot3_burger` or `turtlebot3_waffle_pi`.
    model: &'static str,
    /// rover's arguments: the model spawned at (-2, -0.5), the bridge's YAML, the package's
    /// models on the resource path.
    args: Vec<String>,
    /// The topics its bridge file leaves out (the waffle_pi's image: ROBOTIS bridges it with
    /// ros_gz_image's image_bridge).
    unbridged: &'static str,
    /// Its LDS's declared `<update_rate>` as a period (s).
    scan_period_s: f64,
    /// Kept until the test ends (the waffle_pi's copy).
    _tmp: tempfile::TempDir,
}

/// The burger and the waffle_pi, or `None` (skip recorded) without ../shared.
fn turtlebots() -> Result<Option<Vec<Tb3>>> {
    let Some(tb3) = tb3_gz() else {
        return Ok(None);
    };
    let tmp = tempfile::tempdir()?;
    let Some((waffle_pi, _)) = rover_tests::turtlebot3_gz_waffle_pi(tmp.path())? else {
        return Ok(None);
    };
    let p = |rel: &str| tb3.join(rel).to_string_lossy().into_owned();
    let args = |robot: String, bridge: &str| {
        vec![
            "--robot".into(),
            robot,
            "--bridge-config".into(),
            p(bridge),
            "--world".into(),
            p("worlds/turtlebot3_world.world"),
            "--model-path".into(),
            p("models"),
            "--spawn=-2,-0.5".into(),
            "--no-detector".into(),
        ]
    };
    Ok(Some(vec![
        Tb3 {
            model: "turtlebot3_burger",
            args: args(
                p("models/turtlebot3_burger/model.sdf"),
                "params/turtlebot3_burger_bridge.yaml",
            ),
            unbridged: "",
            scan_period_s: 0.2,
            _tmp: tempfile::tempdir()?,
        },
        Tb3 {
            model: "turtlebot3_waffle_pi",
            args: args(
                waffle_pi.to_string_lossy().into_owned(),
                "params/turtlebot3_waffle_pi_bridge.yaml",
            ),
            unbridged: "camera/image_raw",
            scan_period_s: 0.1,
            _tmp: tmp,
        },
    ]))
}

/// Whether rover's log lists exactly `unbridged` as not in the bridge map.
fn check_unbridged(log: &str, unbridged: &str) -> Result<()> {
    let listed = log
        .lines()
        .find_map(|l| l.split("published under their gz names: ").nth(1))
        .unwrap_or("")
        .trim();
    ensure!(
        listed == unbridged,
        "not in the bridge map: '{listed}'; expected '{unbridged}'\n{log}"
    );
    Ok(())
}

/// The rospy node: it drives with TwistStamped until /odom says a metre, stops, and reports
/// what each topic carried (median stamp gaps, the scan's shape, the distance).
const ROSPY_DRIVER: &str = r#"
import rospy, time
from geometry_msgs.msg import TwistStamped
from tf2_msgs.msg import TFMessage
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Image, Imu, JointState, LaserScan
rospy.init_node('tb3_gz_driver')
got = {'scan': [], 'imu': [], 'odom': [], 'joint_states': [], 'tf': [], 'image': []}
def keep(name):
    return lambda m: got[name].append(m)
rospy.Subscriber('/scan', LaserScan, keep('scan'))
rospy.Subscriber('/imu', Imu, keep('imu'))
rospy.Subscriber('/odom', Odometry, keep('odom'))
rospy.Subscriber('/joint_states', JointState, keep('joint_states'))
rospy.Subscriber('/tf', TFMessage, keep('tf'))
rospy.Subscriber('/camera/image_raw', Image, keep('image'))
pub = rospy.Publisher('/cmd_vel', TwistStamped, queue_size=1)
end = time.time() + 30
while time.time() < end and (not got['odom'] or pub.get_num_connections() == 0):
    time.sleep(0.05)
start = got['odom'][-1].pose.pose.position.x if got['odom'] else float('nan')
cmd = TwistStamped()
cmd.header.frame_id = 'base_footprint'
cmd.twist.linear.x = 0.2
end = time.time() + 15
while time.time() < end and got['odom'][-1].pose.pose.position.x - start < 1.0:
    cmd.header.stamp = rospy.Time.now()
    pub.publish(cmd)
    time.sleep(0.02)
cmd.twist.linear.x = 0.0
for _ in range(20):
    pub.publish(cmd)
    time.sleep(0.05)
time.sleep(1.0)
odom = got['odom'][-1]
print('odom %s %s %.4f' % (odom.header.frame_id, odom.child_frame_id,
                          odom.pose.pose.position.x - start))
def median_gap(stamps):
    stamps = stamps[-200:]
    gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
    return gaps[len(gaps) // 2] if gaps else float('nan')
for name in ['scan', 'imu', 'odom', 'joint_states']:
    print('gap %s %.5f %d' % (name, median_gap([m.header.stamp.to_sec() for m in got[name]]),
                              len(got[name])))
tf_odom = [t.header.stamp.to_sec() for m in got['tf'] for t in m.transforms[:1]
           if t.header.frame_id == 'odom']
print('gap tf %.5f %d' % (median_gap(tf_odom), len(got['tf'])))
s = got['scan'][-1]
print('scan %s %d %.3f %.3f' % (s.header.frame_id, len(s.ranges), s.range_min, s.range_max))
print('imu %s' % got['imu'][-1].header.frame_id)
print('tf %s' % ' '.join(sorted(set('%s>%s' % (t.header.frame_id, t.child_frame_id)
                                    for m in got['tf'] for t in m.transforms))))
j = got['joint_states'][-1]
print('joints %s' % ' '.join(j.name))
i = got['image'][-1] if got['image'] else None
print('image %d %d %d' % (i.width if i else 0, i.height if i else 0, len(got['image'])))
"#;

/// Checks the driver's report: a metre by odometry and by the truth, every topic at its
/// declared rate.
fn check_report(
    tb3: &Tb3,
    out: &str,
    keyed: impl Fn(&str) -> Result<Vec<String>>,
    truth_m: f64,
) -> Result<()> {
    println!("{}:\n{out}", tb3.model);
    let odom = keyed("odom")?;
    ensure!(
        odom[..2] == ["odom", "base_footprint"],
        "odom frames {odom:?}"
    );
    let by_odom: f64 = odom[2].parse()?;
    ensure!(
        (1.0..1.08).contains(&by_odom),
        "odometry moved {by_odom} m; expected a metre (and the stop's few cm)"
    );
    ensure!(
        (truth_m - by_odom).abs() < 0.03,
        "the truth moved {truth_m} m, odometry {by_odom} m"
    );
    // Declared: the LDS at 5 Hz (the waffle_pi's at 10 Hz), the IMU at 200 Hz, the DiffDrive's odometry and tf at gz-sim's
    // 50 Hz default (the file's <odom_publisher_frequency> is not a gz-sim parameter), the
    // JointStatePublisher every step of the world's 1 kHz physics.
    for (topic, period_s) in [
        ("scan", tb3.scan_period_s),
        ("imu", 0.005),
        ("odom", 0.02),
        ("joint_states", 0.001),
        ("tf", 0.02),
    ] {
        let gap = keyed(&format!("gap {topic}"))?;
        let got: f64 = gap[0].parse()?;
        ensure!(
            (got - period_s).abs() < period_s * 0.02 + 1e-6,
            "/{topic} every {got} s (median of stamps); declared {period_s} s"
        );
    }
    let scan = keyed("scan")?;
    ensure!(
        scan[..2] == ["base_scan", "360"] && scan[2] == "0.120" && scan[3] == "3.500",
        "scan {scan:?}"
    );
    ensure!(
        keyed("imu")? == [format!("{}::imu_link::tb3_imu", tb3.model)],
        "imu frame"
    );
    // The waffle_pi's camera: 640 x 480 images (the burger has none).
    let image = keyed("image")?;
    if tb3.model == "turtlebot3_waffle_pi" {
        ensure!(
            image[..2] == ["640", "480"] && image[2] != "0",
            "camera images {image:?}"
        );
    } else {
        ensure!(image[2] == "0", "the burger has no camera: {image:?}");
    }
    let tf = keyed("tf")?;
    // The DiffDrive's odom -> base_footprint, and the wheels as robot_state_publisher would
    // put them from /joint_states.
    ensure!(
        tf == [
            "base_link>wheel_left_link",
            "base_link>wheel_right_link",
            "odom>base_footprint"
        ],
        "tf {tf:?}"
    );
    ensure!(
        keyed("joints")? == ["wheel_left_joint", "wheel_right_joint"],
        "joint names"
    );
    Ok(())
}

/// How far the trace's ground truth moved from its first row to its last (m).
fn truth_distance(rows: &[rover_core::TraceRow]) -> Result<f64> {
    let (a, b) = (
        rows.first().context("empty trace")?,
        rows.last().context("empty trace")?,
    );
    Ok((b.x_m - a.x_m).hypot(b.y_m - a.y_m))
}

#[test]
fn a_rospy_node_drives_the_gz_turtlebots_a_metre_with_twist_stamped() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let Some(turtlebots) = turtlebots()? else {
        return Ok(());
    };
    for tb3 in &turtlebots {
        let mut graph = RosGraph::start()?;
        let args: Vec<&str> = tb3.args.iter().map(String::as_str).collect();
        graph.spawn_rover(25.0, &args)?;
        let out = graph.run_python("driver.py", ROSPY_DRIVER, Duration::from_secs(90))?;
        let rows = graph.wait_rover(Duration::from_secs(180))?;
        check_unbridged(&graph.log("rover"), tb3.unbridged)?;
        check_report(
            tb3,
            &out,
            |k| graph.keyed_line(&out, k),
            truth_distance(&rows)?,
        )?;
    }
    Ok(())
}

/// The same driver as an rclpy node (Jazzy, Fast DDS), against `rover --ros2`.
#[test]
fn an_rclpy_node_drives_the_gz_turtlebots_a_metre_with_twist_stamped() -> Result<()> {
    let _one = lock();
    let Some(turtlebots) = turtlebots()? else {
        return Ok(());
    };
    let Some(rclpy) = rover_tests::rclpy::rclpy("jazzy") else {
        return Ok(());
    };
    for (k, tb3) in turtlebots.iter().enumerate() {
        rclpy_drive(&rclpy, tb3, k as u32)?;
    }
    Ok(())
}

/// `rover --headless --ros2` (Jazzy's Gids, real time) in DDS domain `domain` for
/// `duration_s`, with `args`; its output in `log`.
fn ros2_rover(
    log: &std::path::Path,
    domain: u16,
    duration_s: f64,
    args: &[impl AsRef<std::ffi::OsStr>],
) -> Result<std::process::Child> {
    let log = std::fs::File::create(log)?;
    Command::new(env!("CARGO_BIN_EXE_rover"))
        .args([
            "--headless",
            "--ros2",
            "--rtf",
            "1",
            "--ros-distro",
            "jazzy",
        ])
        .arg("--duration")
        .arg(duration_s.to_string())
        .args(args)
        .env("ROS_DOMAIN_ID", domain.to_string())
        .env("RUST_LOG", "info")
        .stdin(Stdio::null())
        .stdout(log.try_clone()?)
        .stderr(log)
        .spawn()
        .context("starting rover")
}

/// One TurtleBot3 driven by [`RCLPY_DRIVER`] in a DDS domain of its own.
fn rclpy_drive(rclpy: &rover_tests::rclpy::Rclpy, tb3: &Tb3, salt: u32) -> Result<()> {
    let dir = tempfile::tempdir()?;
    let domain = ((std::process::id() + 7 * salt) % 150) as u16 + 40;
    let trace = dir.path().join("trace.csv");
    let mut args = vec!["--trace".to_owned(), trace.to_string_lossy().into_owned()];
    args.extend(tb3.args.iter().cloned());
    let mut rover = ros2_rover(&dir.path().join("rover.log"), domain, 30.0, &args)?;
    let script = dir.path().join("driver.py");
    std::fs::write(&script, RCLPY_DRIVER)?;
    let out_path = dir.path().join("driver.log");
    let out_file = std::fs::File::create(&out_path)?;
    let mut peer = rclpy
        .python(domain)
        .arg(&script)
        .stdin(Stdio::null())
        .stdout(out_file.try_clone()?)
        .stderr(out_file)
        .spawn()
        .context("starting rclpy")?;
    rover_tests::wait_or_kill(&mut peer, Duration::from_secs(120))?;
    rover_tests::wait_or_kill(&mut rover, Duration::from_secs(180))?;
    let rover_log = std::fs::read_to_string(dir.path().join("rover.log")).unwrap_or_default();
    let status = rover.try_wait()?.context("rover did not exit")?;
    ensure!(status.success(), "rover failed ({status}):\n{rover_log}");
    let out = std::fs::read_to_string(&out_path)?;
    let rows = rover_core::parse_trace(&std::fs::read_to_string(&trace)?)?;
    let keyed = |key: &str| -> Result<Vec<String>> {
        let found = out
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key} ")))
            .with_context(|| format!("no {key}:\n{out}\nrover:\n{rover_log}"))?;
        Ok(found.split(' ').map(str::to_owned).collect())
    };
    ensure!(keyed("rmw")? == ["rmw_fastrtps_cpp"], "the peer's RMW");
    check_unbridged(&rover_log, tb3.unbridged)?;
    check_report(tb3, &out, keyed, truth_distance(&rows)?)
}

/// [`ROSPY_DRIVER`] as an rclpy node.
const RCLPY_DRIVER: &str = r#"
import time
import rclpy
from rclpy.qos import qos_profile_sensor_data
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState, LaserScan
from tf2_msgs.msg import TFMessage
from sensor_msgs.msg import Image
rclpy.init()
node = rclpy.create_node('tb3_gz_driver')
got = {'scan': [], 'imu': [], 'odom': [], 'joint_states': [], 'tf': [], 'image': []}
def keep(name):
    return lambda m: got[name].append(m)
node.create_subscription(LaserScan, '/scan', keep('scan'), qos_profile_sensor_data)
node.create_subscription(Imu, '/imu', keep('imu'), qos_profile_sensor_data)
node.create_subscription(Odometry, '/odom', keep('odom'), 10)
node.create_subscription(JointState, '/joint_states', keep('joint_states'), 1000)
node.create_subscription(TFMessage, '/tf', keep('tf'), 100)
node.create_subscription(Image, '/camera/image_raw', keep('image'), qos_profile_sensor_data)
pub = node.create_publisher(TwistStamped, '/cmd_vel', 10)
def spin(seconds):
    end = time.time() + seconds
    while time.time() < end:
        rclpy.spin_once(node, timeout_sec=0.01)
end = time.time() + 40
while time.time() < end and (not got['odom'] or pub.get_subscription_count() == 0):
    spin(0.05)
start = got['odom'][-1].pose.pose.position.x if got['odom'] else float('nan')
cmd = TwistStamped()
cmd.header.frame_id = 'base_footprint'
cmd.twist.linear.x = 0.2
end = time.time() + 15
while time.time() < end and got['odom'][-1].pose.pose.position.x - start < 1.0:
    cmd.header.stamp = node.get_clock().now().to_msg()
    pub.publish(cmd)
    spin(0.02)
cmd.twist.linear.x = 0.0
for _ in range(20):
    pub.publish(cmd)
    spin(0.05)
spin(1.0)
def stamp(h):
    return h.stamp.sec + h.stamp.nanosec * 1e-9
odom = got['odom'][-1]
print('odom %s %s %.4f' % (odom.header.frame_id, odom.child_frame_id,
                          odom.pose.pose.position.x - start))
def median_gap(stamps):
    stamps = stamps[-200:]
    gaps = sorted(b - a for a, b in zip(stamps, stamps[1:]))
    return gaps[len(gaps) // 2] if gaps else float('nan')
for name in ['scan', 'imu', 'odom', 'joint_states']:
    print('gap %s %.5f %d' % (name, median_gap([stamp(m.header) for m in got[name]]),
                              len(got[name])))
tf_odom = [stamp(t.header) for m in got['tf'] for t in m.transforms[:1]
           if t.header.frame_id == 'odom']
print('gap tf %.5f %d' % (median_gap(tf_odom), len(got['tf'])))
s = got['scan'][-1]
print('scan %s %d %.3f %.3f' % (s.header.frame_id, len(s.ranges), s.range_min, s.range_max))
print('imu %s' % got['imu'][-1].header.frame_id)
print('tf %s' % ' '.join(sorted(set('%s>%s' % (t.header.frame_id, t.child_frame_id)
                                    for m in got['tf'] for t in m.transforms))))
j = got['joint_states'][-1]
print('joints %s' % ' '.join(j.name))
i = got['image'][-1] if got['image'] else None
print('image %d %d %d' % (i.width if i else 0, i.height if i else 0, len(got['image'])))
from rclpy.utilities import get_rmw_implementation_identifier
print('rmw %s' % get_rmw_implementation_identifier())
"#;

/// A one-joint arm with gz-sim's JointPositionController and its bridge map (written in the
/// test's folder): the command topic and the joint states under their ROS names.
fn gz_arm(dir: &std::path::Path) -> Result<Vec<String>> {
    let model = dir.join("bot.sdf");
    let text = std::fs::read_to_string(rover_tests::repo("tests/tests/gz_arm.sdf"))?;
    std::fs::write(&model, text)?;
    let map = dir.join("bot_bridge.yaml");
    std::fs::write(
        &map,
        "- ros_topic_name: arm_cmd\n  gz_topic_name: /model/bot/joint/arm_joint/0/cmd_pos\n  ros_type_name: std_msgs/msg/Float64\n  gz_type_name: gz.msgs.Double\n  direction: ROS_TO_GZ\n- ros_topic_name: joint_states\n  gz_topic_name: /world/default/model/bot/joint_state\n  ros_type_name: sensor_msgs/msg/JointState\n  gz_type_name: gz.msgs.Model\n  direction: GZ_TO_ROS\n",
    )?;
    Ok(vec![
        "--robot".into(),
        model.to_string_lossy().into_owned(),
        "--bridge-config".into(),
        map.to_string_lossy().into_owned(),
        "--no-detector".into(),
    ])
}

/// Sends 0.8 rad on /arm_cmd for 3 s, then reports arm_joint's position on /joint_states.
const ROSPY_ARM: &str = r#"
import rospy, time
from std_msgs.msg import Float64
from sensor_msgs.msg import JointState
rospy.init_node('gz_arm')
states = []
rospy.Subscriber('/joint_states', JointState, states.append)
pub = rospy.Publisher('/arm_cmd', Float64, queue_size=1)
end = time.time() + 30
while time.time() < end and (not states or pub.get_num_connections() == 0):
    time.sleep(0.05)
for _ in range(60):
    pub.publish(Float64(0.8))
    time.sleep(0.05)
s = states[-1]
print('arm %.4f' % s.position[list(s.name).index('arm_joint')])
"#;

/// [`ROSPY_ARM`] as an rclpy node.
const RCLPY_ARM: &str = r#"
import time
import rclpy
from std_msgs.msg import Float64
from sensor_msgs.msg import JointState
rclpy.init()
node = rclpy.create_node('gz_arm')
states = []
node.create_subscription(JointState, '/joint_states', states.append, 100)
pub = node.create_publisher(Float64, '/arm_cmd', 10)
def spin(seconds):
    end = time.time() + seconds
    while time.time() < end:
        rclpy.spin_once(node, timeout_sec=0.01)
end = time.time() + 40
while time.time() < end and (not states or pub.get_subscription_count() == 0):
    spin(0.05)
for _ in range(60):
    pub.publish(Float64(data=0.8))
    spin(0.05)
s = states[-1]
print('arm %.4f' % s.position[list(s.name).index('arm_joint')])
"#;

/// gz-sim's JointPositionController takes std_msgs/Float64 on its bridged topic, from rospy
/// (ROS 1) and from rclpy (Jazzy, Fast DDS).
#[test]
fn rospy_and_rclpy_move_a_gz_joint_position_controller() -> Result<()> {
    let _one = lock();
    if let Some(why) = missing_ros() {
        return skip(&why);
    }
    let Some(rclpy) = rover_tests::rclpy::rclpy("jazzy") else {
        return Ok(());
    };
    let dir = tempfile::tempdir()?;
    let args = gz_arm(dir.path())?;
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut graph = RosGraph::start()?;
    graph.spawn_rover(12.0, &args)?;
    let out = graph.run_python("arm.py", ROSPY_ARM, Duration::from_secs(60))?;
    graph.wait_rover(Duration::from_secs(120))?;
    let at: f64 = graph.keyed_line(&out, "arm")?[0].parse()?;
    ensure!(
        (at - 0.8).abs() < 0.05,
        "rospy: arm_joint at {at} rad; sent 0.8"
    );

    let domain = (std::process::id() % 150) as u16 + 41;
    let mut rover = ros2_rover(&dir.path().join("rover2.log"), domain, 15.0, &args)?;
    let script = dir.path().join("arm2.py");
    std::fs::write(&script, RCLPY_ARM)?;
    let out = rclpy
        .python(domain)
        .arg(&script)
        .stdin(Stdio::null())
        .output()?;
    rover_tests::wait_or_kill(&mut rover, Duration::from_secs(60))?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let at: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("arm "))
        .with_context(|| {
            format!(
                "rclpy said:\n{text}\nrover:\n{}",
                std::fs::read_to_string(dir.path().join("rover2.log")).unwrap_or_default()
            )
        })?
        .trim()
        .parse()?;
    ensure!(
        (at - 0.8).abs() < 0.05,
        "rclpy: arm_joint at {at} rad; sent 0.8"
    );
    Ok(())
}
