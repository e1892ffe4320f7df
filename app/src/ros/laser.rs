//! The laser's scans (sensor_msgs/LaserScan) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::sensors::LaserScan;

use crate::bridge::RosPlan;
use crate::bridge::laser::ScanWire;

/// The scan topic's publisher (none when the robot has no laser).
pub(super) struct Laser {
    publisher: Option<Publisher<msgs::LaserScan>>,
    msg: msgs::LaserScan,
}

impl Laser {
    /// Advertises the plan's scan topic, if any.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        Ok(Self {
            publisher: plan
                .scan_topic
                .as_deref()
                .map(|t| node.advertise(t, 10, false))
                .transpose()?,
            msg: msgs::LaserScan::default(),
        })
    }
}

impl ScanWire for Laser {
    fn scan(&mut self, scan: &mut LaserScan) {
        let Some(p) = self.publisher.as_mut() else {
            return;
        };
        let msg = &mut self.msg;
        msg.header.seq = scan.seq as u32;
        msg.header.stamp_s = scan.stamp_s;
        if msg.header.frame_id != scan.frame_id {
            msg.header.frame_id = scan.frame_id.clone();
        }
        msg.angle_min = scan.angle_min_rad;
        msg.angle_max = scan.angle_max_rad;
        msg.angle_increment = scan.angle_increment_rad;
        msg.time_increment = scan.time_increment_s;
        msg.scan_time = scan.scan_time_s;
        msg.range_min = scan.range_min_m;
        msg.range_max = scan.range_max_m;
        // Published from the scan's buffer, which stays with it.
        std::mem::swap(&mut msg.ranges, &mut scan.ranges_m);
        p.publish(msg);
        std::mem::swap(&mut msg.ranges, &mut scan.ranges_m);
    }
}
