//! ROS 2's wire for rover's bridge, spoken with RustDDS (pure Rust, no ROS install), as ROS 2
//! nodes speak it: topic `/odom` is DDS topic `rt/odom`, type `nav_msgs/msg/Odometry` is
//! `nav_msgs::msg::dds_::Odometry_`, CDR little-endian.
//!
//! - [`msgs`]: the ROS 2 messages rover publishes and reads, as serde structs in CDR layout, and
//!   [`definitions`]: their ROS 2 definitions (for MCAP's schemas);
//! - [`bulk`]: large best-effort samples (images) in 16 KB fragments, paced, and [`acked`]:
//!   large reliable ones, one at a time, each after the last was acknowledged;
//! - [`dds`]: ROS names as DDS topics, rclcpp's QoS profiles, typed writers;
//! - [`discovery`]: `ros_discovery_info`, so `ros2 node list` finds the node (Gids of each
//!   distribution's size);
//! - [`services`]: services in both request/reply mappings, Fast DDS's (rmw_fastrtps_cpp, ROS
//!   2's default RMW) and Cyclone DDS's, chosen per request;
//! - [`parameters`]: rclcpp's parameter services over a node's read-only parameters;
//! - [`action_msgs`]: action_msgs' goal bookkeeping and control_msgs' actions.
//!
//! The bridge's topic families, its input half and the controllers' action servers live in the
//! app (app/src/ros2), which this crate serves. Its sibling for ROS 1 is `rover-ros1`.

pub mod acked;
pub mod action_msgs;
pub mod bulk;
pub mod dds;
pub mod definitions;
pub mod discovery;
mod error;
pub mod msgs;
pub mod parameters;
pub mod services;

pub use error::{Error, Result};
