//! Helpers for tests against real ROS 1 programs (Debian's rospy, rosmaster, roslaunch).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Result, ensure};

/// The Python that has rospy (another `python3` may come first on PATH and lack it).
pub const PYTHON: &str = "/usr/bin/python3";

/// Generates darknet_ros_msgs for rospy into `out` with genpy, from the message definitions in
/// `shared_ros/darknet_ros_msgs/msg` (as ../shared/ros/README.md says); returns the folder to
/// put on PYTHONPATH.
pub fn darknet_msgs(shared_ros: &Path, out: &Path) -> Result<PathBuf> {
    let msgs = shared_ros.join("darknet_ros_msgs/msg");
    let pkg = out.join("darknet_ros_msgs");
    let gen_args = |c: &mut Command| {
        c.args(["/usr/lib/genpy/genmsg_py.py", "-p", "darknet_ros_msgs"])
            .arg(format!("-Idarknet_ros_msgs:{}", msgs.display()))
            .arg("-Istd_msgs:/usr/share/std_msgs/msg")
            .arg("-o")
            .arg(pkg.join("msg"));
    };
    let mut files = Command::new(PYTHON);
    gen_args(&mut files);
    for entry in std::fs::read_dir(&msgs)? {
        files.arg(entry?.path());
    }
    ensure!(files.status()?.success(), "genmsg_py failed");
    let mut init = Command::new(PYTHON);
    gen_args(&mut init);
    init.arg("--initpy");
    ensure!(init.status()?.success(), "genmsg_py --initpy failed");
    std::fs::write(pkg.join("__init__.py"), "")?;
    Ok(out.to_path_buf())
}

/// A TCP port nothing listens on now (for a ROS master of a test's own).
pub fn free_port() -> Result<u16> {
    Ok(std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port())
}
