//! `--record-mcap`: the ROS 2 topics in an MCAP file, read back by a third-party reader —
//! `rosbags` (pure Python ROS 2 bag/MCAP reading, Humble's message types) and Rerun's own MCAP
//! importer. Skipped, with the reason, where rosbags is not installed (scripts/setup.sh puts it
//! in the tests' Python environment).

use std::path::Path;
use std::process::Command;

use anyhow::{Context, Result, ensure};
use rover_core::parse_trace;

/// Reads `run.mcap` with rosbags and prints, per line:
/// - `topic NAME TYPE COUNT` for every channel, with the messages it holds;
/// - `deffield TYPE` for a type whose definition in the file differs from Humble's;
/// - `image K EQUAL` for the K-th image against frames/frame_K.png;
/// - `odom SEC NSEC X Y YAW` for every message on /odom;
/// - `box CLASS XMIN YMIN XMAX YMAX W H` for every darknet box.
const READER: &str = r#"
import math, sys
from collections import Counter
from pathlib import Path
import numpy as np
from skimage.io import imread
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

humble = get_typestore(Stores.ROS2_HUMBLE)
ours = get_typestore(Stores.EMPTY)
counts = Counter()
with Reader(Path(sys.argv[1])) as reader:
    for c in reader.connections:
        print('topic', c.topic, c.msgtype, c.msgcount)
        types = get_types_from_msg(c.msgdef.data, c.msgtype)
        ours.register(types)
        for name, (_, fields) in types.items():
            if name in humble.fielddefs and repr(humble.fielddefs[name][1]) != repr(fields):
                print('deffield', name)
    info = None
    for c, t, raw in reader.messages():
        counts[c.topic] += 1
        store = humble if c.msgtype in humble.fielddefs else ours
        m = store.deserialize_cdr(raw, c.msgtype)
        if c.topic == '/camera/camera_info':
            info = m
        elif c.topic == '/camera/image_raw':
            k = counts[c.topic] - 1
            image = m.data.reshape(m.height, m.width, 3)
            frame = imread(Path(sys.argv[2]) / ('frame_%06d.png' % k))[:, :, :3]
            print('image', k, int(np.array_equal(image, frame)), m.encoding, m.header.frame_id)
        elif c.msgtype == 'nav_msgs/msg/Odometry' and c.topic == '/odom':
            p = m.pose.pose
            # The heading of a base that may tilt (odometrySource world), as tf reads it.
            q = p.orientation
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
            print('odom %d %d %.9f %.9f %.9f' % (m.header.stamp.sec, m.header.stamp.nanosec,
                                                 p.position.x, p.position.y, yaw))
            assert t == m.header.stamp.sec * 10**9 + m.header.stamp.nanosec
        elif c.msgtype == 'gazebo_msgs/msg/ModelStates':
            assert len(m.name) == len(m.pose) == len(m.twist) >= 2, m.name
        elif c.msgtype == 'darknet_ros_msgs/msg/BoundingBoxes':
            for b in m.bounding_boxes:
                print('box', b.class_id.replace(' ', '_'), b.xmin, b.ymin, b.xmax, b.ymax,
                      info.width, info.height)
    for topic, n in counts.items():
        print('read', topic, n)
"#;

fn rosbags_available() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import rosbags.rosbag2, skimage.io, numpy"])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        rover_tests::skip::skip_or_panic(
            "python3 cannot import rosbags, scikit-image and numpy (scripts/setup.sh installs them)",
        );
    }
    ok
}

/// rover headless in the playground, driving a curve, recording to `dir/run.mcap`: its stdout.
fn record(dir: &Path, name: &str) -> Result<String> {
    let script = dir.join("drive.toml");
    std::fs::write(
        &script,
        "steps = [ { at = 0.0, cmd_vel = [0.4, 0.3] }, { at = 3.0, cmd_vel = [0.0, 0.0] } ]\n",
    )?;
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(["--headless", "--duration", "4", "--script"])
        .arg(&script)
        .arg("--trace")
        .arg(dir.join(format!("{name}.csv")))
        .arg("--save-frames")
        .arg(dir.join(format!("{name}_frames")))
        .arg("--record-mcap")
        .arg(dir.join(format!("{name}.mcap")))
        .output()
        .context("starting rover")?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    ensure!(
        out.status.success(),
        "rover failed: {stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Ok(stdout)
}

/// rosbags reads rover's MCAP: every topic with its ROS 2 type and as many messages as rover
/// says it wrote; every type's definition in the file equal to Humble's; every image equal to
/// the PNG rover saved of the same frame; odometry equal to the trace at the same stamps
/// (log time = header stamp); darknet boxes with `person` inside the image. Two runs of the
/// same script write byte-identical data sections.
#[test]
fn rosbags_reads_the_recording_as_rover_wrote_it() -> Result<()> {
    if !rosbags_available() {
        return Ok(());
    }
    let dir = tempfile::tempdir()?;
    let stdout = record(dir.path(), "run")?;
    let said = stdout
        .lines()
        .find_map(|l| l.strip_prefix("MCAP: "))
        .with_context(|| format!("rover did not say what it recorded:\n{stdout}"))?;
    println!("rover: MCAP: {said}");
    let reader = dir.path().join("read.py");
    std::fs::write(&reader, READER)?;
    let out = Command::new("python3")
        .arg(&reader)
        .arg(dir.path().join("run.mcap"))
        .arg(dir.path().join("run_frames"))
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    ensure!(
        out.status.success(),
        "the rosbags reader failed:\n{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<Vec<&str>> = text.lines().map(|l| l.split(' ').collect()).collect();
    let field = |tag: &'static str| lines.iter().filter(move |l| l[0] == tag);

    // Topics, types and counts.
    let topics: Vec<(&str, &str, usize)> = field("topic")
        .map(|l| Ok((l[1], l[2], l[3].parse()?)))
        .collect::<Result<_>>()?;
    for (topic, msgtype, _) in &topics {
        println!("{topic} {msgtype}");
    }
    let expected = [
        ("/clock", "rosgraph_msgs/msg/Clock"),
        ("/odom", "nav_msgs/msg/Odometry"),
        ("/tf", "tf2_msgs/msg/TFMessage"),
        ("/tf_static", "tf2_msgs/msg/TFMessage"),
        ("/joint_states", "sensor_msgs/msg/JointState"),
        ("/camera/image_raw", "sensor_msgs/msg/Image"),
        ("/camera/camera_info", "sensor_msgs/msg/CameraInfo"),
        ("/scan", "sensor_msgs/msg/LaserScan"),
        ("/imu", "sensor_msgs/msg/Imu"),
        ("/ground_truth/state", "nav_msgs/msg/Odometry"),
        ("/fix", "sensor_msgs/msg/NavSatFix"),
        ("/fix_velocity", "geometry_msgs/msg/Vector3Stamped"),
        ("/bumper_states", "gazebo_msgs/msg/ContactsState"),
        (
            "/darknet_ros/bounding_boxes",
            "darknet_ros_msgs/msg/BoundingBoxes",
        ),
        (
            "/darknet_ros/found_object",
            "darknet_ros_msgs/msg/ObjectCount",
        ),
        ("/gazebo/model_states", "gazebo_msgs/msg/ModelStates"),
    ];
    for (topic, msgtype) in expected {
        ensure!(
            topics.iter().any(|t| t.0 == topic && t.1 == msgtype),
            "no {topic} of {msgtype} in {topics:?}"
        );
    }
    let total: usize = topics.iter().map(|t| t.2).sum();
    ensure!(
        said.contains(&format!("({total} messages on {} topics)", topics.len())),
        "rover said \"{said}\"; rosbags counts {total} on {}",
        topics.len()
    );
    for (topic, _, count) in &topics {
        let read = field("read")
            .find(|l| l[1] == *topic)
            .map_or(Ok(0), |l| l[2].parse::<usize>())?;
        ensure!(read == *count, "{topic}: {read} read, {count} indexed");
    }
    let differing: Vec<&str> = field("deffield").map(|l| l[1]).collect();
    ensure!(
        differing.is_empty(),
        "definitions unlike Humble's: {differing:?}"
    );

    // Images: every one equal to the frame rover rendered.
    let frames = std::fs::read_dir(dir.path().join("run_frames"))?.count();
    let images: Vec<&Vec<&str>> = field("image").collect();
    ensure!(
        images.len() == frames && frames >= 100,
        "{} images in the MCAP, {frames} frames saved",
        images.len()
    );
    let unequal = images.iter().filter(|l| l[2] != "1").count();
    ensure!(unequal == 0, "{unequal} images differ from their frames");
    ensure!(
        images
            .iter()
            .all(|l| l[3] == "rgb8" && l[4] == "camera_link_optical"),
        "{:?}",
        images[0]
    );

    // Odometry: every message equal to the trace at its stamp; one per control update.
    let rows = parse_trace(&std::fs::read_to_string(dir.path().join("run.csv"))?)?;
    let odom: Vec<&Vec<&str>> = field("odom").collect();
    ensure!(odom.len() >= 390, "{} odometry messages", odom.len());
    let mut compared = 0;
    for f in &odom {
        let stamp_s = f[1].parse::<f64>()? + f[2].parse::<f64>()? * 1e-9;
        let Some(row) = rows.iter().find(|r| (r.sim_time_s - stamp_s).abs() < 5e-5) else {
            continue;
        };
        let (x, y, yaw): (f64, f64, f64) = (f[3].parse()?, f[4].parse()?, f[5].parse()?);
        ensure!(
            (x - row.odom_x_m).abs() <= 1e-6
                && (y - row.odom_y_m).abs() <= 1e-6
                && rover_sim::physics::wrap_angle(yaw - row.odom_yaw_rad).abs() <= 1e-6,
            "at {stamp_s} s: odom ({x}, {y}, {yaw}) vs trace ({}, {}, {})",
            row.odom_x_m,
            row.odom_y_m,
            row.odom_yaw_rad
        );
        compared += 1;
    }
    let last = rows.last().context("an empty trace")?;
    println!(
        "{} images equal to their frames; {compared} of {} odometry messages equal to the trace; the car drove to ({:.2}, {:.2})",
        images.len(),
        odom.len(),
        last.odom_x_m,
        last.odom_y_m
    );
    ensure!(
        compared == rows.len().min(odom.len()) && last.odom_x_m > 0.5,
        "{compared} of {} compared ({} trace rows)",
        odom.len(),
        rows.len()
    );

    // darknet_ros's detection image: one per detection, the size of the camera's.
    let count = |topic: &str| topics.iter().find(|t| t.0 == topic).map_or(0, |t| t.2);
    ensure!(
        count("/darknet_ros/detection_image") == count("/darknet_ros/found_object")
            && count("/darknet_ros/found_object") > 0,
        "{} detection images for {} detections",
        count("/darknet_ros/detection_image"),
        count("/darknet_ros/found_object")
    );

    // The detector's boxes.
    let boxes: Vec<&Vec<&str>> = field("box").collect();
    let people = boxes.iter().filter(|b| b[1] == "person").count();
    println!("{} boxes, {people} of them person", boxes.len());
    ensure!(people > 0, "no person box: {boxes:?}");
    for b in &boxes {
        let v: Vec<i64> = b[2..].iter().map(|s| s.parse()).collect::<Result<_, _>>()?;
        ensure!(
            0 <= v[0] && v[0] < v[2] && v[2] <= v[4] && 0 <= v[1] && v[1] < v[3] && v[3] <= v[5],
            "a box out of the image: {b:?}"
        );
    }

    // The same run again: the same messages, byte for byte.
    record(dir.path(), "again")?;
    let first = std::fs::read(dir.path().join("run.mcap"))?;
    let second = std::fs::read(dir.path().join("again.mcap"))?;
    let same = data_section(&first)? == data_section(&second)?;
    println!(
        "{} bytes; a second run: data section identical {same}",
        first.len()
    );
    ensure!(
        same && first.len() == second.len(),
        "two runs wrote different messages"
    );
    Ok(())
}

/// An MCAP file's data section (header, schemas, channels, chunks; everything before the
/// summary), from the footer's `summary_start`. The summary after it lists channels and
/// schemas in the order of the mcap crate's hash maps, which differs between processes.
fn data_section(file: &[u8]) -> Result<&[u8]> {
    // Footer record: opcode 1 + length 8 + summary_start 8 + summary_offset_start 8 + crc 4,
    // then the 8-byte magic.
    let footer = file.len().checked_sub(8 + 29).context("not an MCAP file")?;
    ensure!(file[footer] == 0x02, "no MCAP footer record");
    let start: [u8; 8] = file[footer + 9..footer + 17].try_into()?;
    let start = usize::try_from(u64::from_le_bytes(start))?;
    ensure!(
        start > 0 && start <= footer,
        "summary_start {start} out of the file"
    );
    Ok(&file[..start])
}

/// Rerun opens rover's MCAP with its own importer (`rerun mcap convert`): every channel's
/// schema resolves (no "cannot be reflected"), the images become Image, camera_info a
/// Pinhole, /tf Transform3D. Skipped without the `rerun` CLI of rover's Rerun version.
#[test]
fn rerun_imports_the_recording() -> Result<()> {
    let rerun_ok = Command::new("rerun")
        .arg("--version")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains(" 0.36.3"));
    if !rerun_ok {
        return rover_tests::skip(
            "no `rerun` 0.36.3 CLI on PATH (scripts/setup.sh installs rerun-sdk)",
        );
    }
    let dir = tempfile::tempdir()?;
    record(dir.path(), "run")?;
    let rrd = dir.path().join("run.rrd");
    let out = Command::new("rerun")
        .args(["mcap", "convert"])
        .arg(dir.path().join("run.mcap"))
        .arg("-o")
        .arg(&rrd)
        .output()?;
    let log = String::from_utf8_lossy(&out.stderr).into_owned();
    ensure!(out.status.success(), "rerun mcap convert failed:\n{log}");
    ensure!(
        !log.contains("ERROR") && !log.contains("cannot be reflected"),
        "rerun could not decode every channel:\n{log}"
    );
    let printed = Command::new("rerun")
        .args(["rrd", "print"])
        .arg(&rrd)
        .output()?;
    let text = String::from_utf8_lossy(&printed.stdout);
    for (entity, component) in [
        ("/camera/image_raw", "Image:buffer"),
        ("/camera/camera_info", "Pinhole:"),
        ("/tf", "Transform3D:"),
        ("/odom", "nav_msgs.msg.Odometry:message"),
        (
            "/darknet_ros/bounding_boxes",
            "darknet_ros_msgs.msg.BoundingBoxes:message",
        ),
    ] {
        ensure!(
            text.lines()
                .any(|l| l.contains(&format!("- {entity} -")) && l.contains(component)),
            "no {component} on {entity} in the converted recording"
        );
    }
    println!("rerun imported every channel of the MCAP");
    Ok(())
}

/// A depth camera in the recording: TIAGo's xtion gives `/xtion/depth_registered/image_raw`
/// as 32FC1 (metres within the sensor's 0.3-8 m clip range, or NaN) with a camera_info of the
/// same size and frame, one per colour image.
#[test]
fn a_depth_camera_is_recorded_as_32fc1() -> Result<()> {
    if !rosbags_available() {
        return Ok(());
    }
    let Some(urdf) = rover_tests::example_robot_data(rover_tests::TIAGO_NO_HAND) else {
        return Ok(());
    };
    let dir = tempfile::tempdir()?;
    let mcap = dir.path().join("tiago.mcap");
    let out = Command::new(env!("CARGO_BIN_EXE_rover"))
        .args(["--headless", "--duration", "1", "--robot"])
        .arg(&urdf)
        .args([
            "--drive",
            "wheel_left_joint,wheel_right_joint",
            "--record-mcap",
        ])
        .arg(&mcap)
        .output()?;
    ensure!(
        out.status.success(),
        "rover failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let script = r#"
import sys
from pathlib import Path
import numpy as np
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore
store = get_typestore(Stores.ROS2_HUMBLE)
with Reader(Path(sys.argv[1])) as reader:
    for c, t, raw in reader.messages():
        if not c.topic.startswith('/xtion/'):
            continue
        m = store.deserialize_cdr(raw, c.msgtype)
        if c.msgtype == 'sensor_msgs/msg/Image':
            if m.encoding == '32FC1':
                d = m.data.view('<f4')
                ok = np.isnan(d) | ((d >= 0.3) & (d <= 8.0))
                print('depth', c.topic, m.width, m.height, m.step, m.header.frame_id, int(ok.all()), int(np.isfinite(d).sum()))
            else:
                print('rgb', c.topic, m.width, m.height, m.encoding, m.header.frame_id)
        else:
            print('info', c.topic, m.width, m.height, m.header.frame_id)
"#;
    let reader = dir.path().join("depth.py");
    std::fs::write(&reader, script)?;
    let out = Command::new("python3").arg(&reader).arg(&mcap).output()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    ensure!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<Vec<&str>> = text.lines().map(|l| l.split(' ').collect()).collect();
    let depth: Vec<&Vec<&str>> = lines.iter().filter(|l| l[0] == "depth").collect();
    let rgb = lines.iter().filter(|l| l[0] == "rgb").count();
    let first = depth.first().context(format!("no depth image:\n{text}"))?;
    println!("{} depth images ({rgb} colour): {first:?}", depth.len());
    ensure!(depth.len() == rgb && rgb >= 20, "{text}");
    for d in &depth {
        let (w, step): (u32, u32) = (d[2].parse()?, d[4].parse()?);
        ensure!(
            d[1] == "/xtion/depth_registered/image_raw" && step == w * 4 && d[6] == "1",
            "{d:?}"
        );
        let finite: u32 = d[7].parse()?;
        ensure!(finite > 0, "a depth image without a single distance: {d:?}");
    }
    ensure!(
        lines.iter().any(|l| l[0] == "info"
            && l[1] == "/xtion/depth_registered/camera_info"
            && l[2] == first[2]
            && l[3] == first[3]
            && l[4] == first[5]),
        "no depth camera_info like the image:\n{text}"
    );
    Ok(())
}
