//! The ROS bridges' options ([`RosArgs`]: --ros, --ros2, --record-mcap).

use std::path::PathBuf;

use clap::Args;

/// ROS 1 bridge options.
#[derive(Debug, Args)]
pub(crate) struct RosArgs {
    /// Join a ROS 1 graph (start `roscore` first; ROS_MASTER_URI, ROS_IP, ROS_HOSTNAME are
    /// honoured): /cmd_vel drives the car, and rover publishes what Gazebo and darknet_ros would
    /// (/odom, /tf, /tf_static, /joint_states, /clock, the camera's image and camera_info,
    /// /darknet_ros/bounding_boxes, found_object, detection_image, the laser's scan) and sets
    /// /robot_description. Headless runs then default to --rtf 1. See docs/ROS.md
    #[arg(long)]
    pub(crate) ros: bool,

    /// Join ROS 2 over DDS (RTPS, as rmw_cyclonedds and rmw_fastrtps speak it; ROS_DOMAIN_ID
    /// is honoured; no ROS install needed): rt/cmd_vel drives the car, and rover publishes
    /// what the ROS 1 bridge does with ROS 2's types (/clock, /odom, /tf, /tf_static,
    /// /joint_states, the camera's image and camera_info, /darknet_ros/bounding_boxes and
    /// found_object, the laser's scan). Can run beside --ros. Headless runs then default to
    /// --rtf 1. See docs/ROS2.md
    #[arg(long)]
    pub(crate) ros2: bool,

    /// Record the ROS 2 topics (those --ros2 publishes, with or without --ros2) into an MCAP
    /// file: CDR messages and their ROS 2 definitions, as `ros2 bag record -s mcap` writes
    /// them, for `ros2 bag play FILE`, Foxglove, rosbags or Rerun. Stamps are sim time;
    /// nothing is dropped (the run waits for the disk if it must). Does not change the pace
    #[arg(long, value_name = "FILE.mcap")]
    pub(crate) record_mcap: Option<PathBuf>,

    /// With --ros or --ros2: the node's name (ROS 2's tools list it, with `ros2 node list`,
    /// as `/NAME`)
    #[arg(long, value_name = "NAME", default_value = "rover")]
    pub(crate) ros_name: String,

    /// With --ros2: the ROS 2 distribution the peers run, for what differs on the wire
    /// (`ros_discovery_info`'s ids: 24 bytes on Humble, 16 from Iron on). Default:
    /// `ROS_DISTRO` when it names one of these, else lyrical (the newest LTS)
    #[arg(long, value_name = "DISTRO", value_parser = ros_distro_parser())]
    pub(crate) ros_distro: Option<crate::ros2::RosDistro>,

    /// With --ros: also set /use_sim_time so ROS nodes follow rover's /clock
    #[arg(long, requires = "ros")]
    pub(crate) ros_sim_time: bool,
}

impl RosArgs {
    /// Whether a ROS peer may be listening (--ros or --ros2): headless runs then keep real
    /// time.
    pub(crate) fn any(&self) -> bool {
        self.ros || self.ros2
    }

    /// Whether a bridge runs: a ROS peer, or the MCAP recording.
    pub(crate) fn bridges(&self) -> bool {
        self.any() || self.record_mcap.is_some()
    }

    /// The ROS 2 bridge's settings (--ros2 and/or --record-mcap), `None` when it is off.
    pub(crate) fn ros2_options(&self) -> anyhow::Result<Option<crate::ros2::Ros2Options>> {
        crate::ros2::Ros2Options::new(
            self.ros2,
            self.record_mcap.as_deref(),
            &self.ros_name,
            self.ros_distro,
        )
    }

    /// The bridge's settings, when --ros is on; `ground_truth`: the run measures it
    /// (`--ground-truth`), the bridge publishes it.
    pub(crate) fn options(&self, ground_truth: bool) -> Option<crate::ros::RosOptions> {
        self.ros.then(|| crate::ros::RosOptions {
            name: self.ros_name.clone(),
            sim_time: self.ros_sim_time,
            ground_truth,
        })
    }
}

/// `--ros-distro`: one of the distributions rover-ros2 knows, listed in `--help` and in the
/// error for any other name.
fn ros_distro_parser() -> impl clap::builder::TypedValueParser<Value = crate::ros2::RosDistro> {
    use crate::ros2::RosDistro;
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(RosDistro::ALL.map(RosDistro::as_str)).try_map(
        |name| RosDistro::from_name(&name).ok_or_else(|| format!("no ROS 2 distribution {name}")),
    )
}
