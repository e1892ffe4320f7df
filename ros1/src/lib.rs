//! A small ROS 1 client for rover's bridge: the master and slave XML-RPC APIs, TCPROS
//! publishers (latched or not, a bounded queue per subscriber) and subscribers, and the
//! message types rover speaks, with genmsg's MD5 sums and full definitions (rosbag records
//! them). No ROS install is needed to build or run it; std threads, no async runtime.
//!
//! Why not a crate: roslibrust (the maintained ROS 1 client) brings tokio and a code
//! generator that needs vendored `.msg` trees, and has no `setParam` (rviz's RobotModel needs
//! `/robot_description`); rosrust is dormant. rover needs a dozen message types, one
//! subscription and a master watch that re-registers after a roscore restart: about a
//! thousand lines on `std::net`, no new dependencies but an MD5.

mod error;
mod msg;
pub mod msgs;
mod node;
mod tcpros;
mod xmlrpc;

pub use error::{Error, Result};
pub use msg::{Decode, Message, full_definition, md5sum};
pub use node::{Node, NodeOptions, Publisher, Subscriber, global_name};
pub use xmlrpc::{Value, ros_call};
