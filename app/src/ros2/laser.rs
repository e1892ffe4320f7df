//! The laser's scans (sensor_msgs/msg/LaserScan) on ROS 2, best effort as rclcpp's
//! SensorDataQoS.

use anyhow::Result;
use rover_sim::sensors::LaserScan;

use super::sinks::{Out, Sinks, sensor_qos};
use crate::bridge::RosPlan;
use crate::bridge::laser::ScanWire;
use rover_ros2::msgs::{self, Header, Lent, Time};

/// The scan topic (none when the robot has no laser).
pub(super) struct Laser {
    out: Option<Out<msgs::LaserScan>>,
}

impl Laser {
    /// Creates the plan's scan topic, if any, on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            out: sinks.maybe(plan.scan_topic.as_deref(), &sensor_qos())?,
        })
    }
}

impl ScanWire for Laser {
    fn scan(&mut self, scan: &mut LaserScan) {
        let Some(out) = &mut self.out else {
            return;
        };
        // The ranges are lent to the message and come back once it is written.
        let ranges = Lent::new(std::mem::take(&mut scan.ranges_m));
        let msg = msgs::LaserScan {
            header: Header {
                stamp: Time::from_secs(scan.stamp_s),
                frame_id: std::mem::take(&mut scan.frame_id),
            },
            angle_min: scan.angle_min_rad,
            angle_max: scan.angle_max_rad,
            angle_increment: scan.angle_increment_rad,
            time_increment: scan.time_increment_s,
            scan_time: scan.scan_time_s,
            range_min: scan.range_min_m,
            range_max: scan.range_max_m,
            ranges: ranges.clone(),
            intensities: Vec::new(),
        };
        out.put(msg.header.stamp, &msg);
        // The frame's name and the ranges go back to the scan, for the next one.
        let msgs::LaserScan { header, .. } = msg;
        scan.frame_id = header.frame_id;
        scan.ranges_m = ranges.take_back().unwrap_or_default();
    }
}
