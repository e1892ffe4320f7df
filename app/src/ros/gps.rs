//! hector's GPS (sensor_msgs/NavSatFix, geometry_msgs/Vector3Stamped) on ROS 1.

use anyhow::Result;
use rover_ros1::msgs;
use rover_ros1::{Node, Publisher};
use rover_sim::sensors::FixReading;

use super::convert::header;
use crate::bridge::RosPlan;
use crate::bridge::diagonal;
use crate::bridge::gps::{COVARIANCE_TYPE_DIAGONAL_KNOWN, GpsWire};

/// A receiver's two publishers and their messages.
struct Receiver {
    fix: (Publisher<msgs::NavSatFix>, msgs::NavSatFix),
    /// hector's velocity topic (gz-sim's NavSat has none).
    velocity: Option<(Publisher<msgs::Vector3Stamped>, msgs::Vector3Stamped)>,
}

/// Every receiver, in the plan's order.
pub(super) struct Gps {
    receivers: Vec<Receiver>,
}

impl Gps {
    /// Advertises each receiver's topics.
    pub fn advertise(node: &Node, plan: &RosPlan) -> Result<Self> {
        let receivers = plan
            .gpss
            .iter()
            .map(|t| {
                let fix = msgs::NavSatFix {
                    header: header(&t.frame),
                    position_covariance_type: COVARIANCE_TYPE_DIAGONAL_KNOWN,
                    ..msgs::NavSatFix::default()
                };
                let velocity = msgs::Vector3Stamped {
                    header: header(&t.frame),
                    ..msgs::Vector3Stamped::default()
                };
                Ok(Receiver {
                    fix: (node.advertise(&t.topic, 10, false)?, fix),
                    velocity: match &t.velocity_topic {
                        Some(topic) => Some((node.advertise(topic, 10, false)?, velocity)),
                        None => None,
                    },
                })
            })
            .collect::<Result<_>>()?;
        Ok(Self { receivers })
    }
}

impl GpsWire for Gps {
    fn gps(&mut self, r: &FixReading) {
        let Some(receiver) = self.receivers.get_mut(r.sensor) else {
            return;
        };
        let (publisher, msg) = &mut receiver.fix;
        msg.header.seq = r.seq as u32;
        msg.header.stamp_s = r.stamp_s;
        msg.status = msgs::NavSatStatus {
            status: r.status,
            service: r.service,
        };
        msg.latitude = r.latitude_deg;
        msg.longitude = r.longitude_deg;
        msg.altitude = r.altitude_m;
        msg.position_covariance = diagonal(r.position_covariance_diagonal);
        publisher.publish(msg);
        if let Some((publisher, msg)) = &mut receiver.velocity {
            msg.header.seq = r.seq as u32;
            msg.header.stamp_s = r.stamp_s;
            msg.vector = r.velocity_mps.into();
            publisher.publish(msg);
        }
    }
}
