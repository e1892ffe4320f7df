//! Real ROS 2 peers for the bridge's tests: rclpy on rmw_fastrtps_cpp (ROS 2's default RMW),
//! one set-up per distribution, as `scripts/ros2/peers.py` builds it into rover's cache (a venv
//! of PyPI's wheels, and control_msgs, darknet_ros_msgs, tf2_msgs and gazebo_msgs generated from
//! scripts/ros2/interfaces). Tests never build or download: without a finished set-up the test
//! records a skip (a failure under `CI=true`).

use std::path::PathBuf;
use std::process::Command;

/// One distribution's rclpy, ready to run.
#[derive(Debug, Clone)]
pub struct Rclpy {
    root: PathBuf,
    /// `jazzy`, `kilted`.
    pub distro: String,
}

impl Rclpy {
    /// The venv's Python with the built interfaces importable, on Fast DDS, in DDS domain
    /// `domain`.
    pub fn python(&self, domain: u16) -> Command {
        let interfaces = self.root.join("interfaces");
        let mut command = Command::new(self.root.join("venv/bin/python"));
        command
            .env(
                "PYTHONPATH",
                interfaces.join("lib/python3.11/site-packages"),
            )
            .env("LD_LIBRARY_PATH", interfaces.join("lib"))
            .env("RMW_IMPLEMENTATION", "rmw_fastrtps_cpp")
            .env("ROS_DISTRO", &self.distro)
            .env("ROS_DOMAIN_ID", domain.to_string())
            .env("PYTHONUNBUFFERED", "1");
        command
    }
}

/// `distro`'s rclpy as set-up left it (`<rover's cache>/ros2/DISTRO`, marked complete); `None`,
/// the skip recorded, when set-up has not built it.
pub fn rclpy(distro: &str) -> Option<Rclpy> {
    let root = rover_assets::cache_dir().join("ros2").join(distro);
    if root.join(".complete").is_file() && root.join("venv/bin/python").is_file() {
        return Some(Rclpy {
            root,
            distro: distro.to_owned(),
        });
    }
    crate::skip::skip_or_panic(format!(
        "rclpy {distro} is not set up in {} (scripts/setup.sh test runs scripts/ros2/peers.py; \
         ./test runs that)",
        root.display()
    ));
    None
}
