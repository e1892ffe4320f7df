//! hector's GPS (sensor_msgs/msg/NavSatFix, geometry_msgs/msg/Vector3Stamped) on ROS 2,
//! best effort as rclcpp's SensorDataQoS.

use anyhow::Result;
use rover_sim::sensors::FixReading;

use super::sinks::{Out, Sinks, header, sensor_qos};
use crate::bridge::RosPlan;
use crate::bridge::diagonal;
use crate::bridge::gps::{COVARIANCE_TYPE_DIAGONAL_KNOWN, GpsWire};
use rover_ros2::msgs::{self, Time};

/// A receiver's two topics and their messages.
struct Receiver {
    fix: (Out<msgs::NavSatFix>, msgs::NavSatFix),
    /// hector's velocity topic (gz-sim's NavSat has none).
    velocity: Option<(Out<msgs::Vector3Stamped>, msgs::Vector3Stamped)>,
}

/// Every receiver, in the plan's order.
pub(super) struct Gps {
    receivers: Vec<Receiver>,
}

impl Gps {
    /// Creates each receiver's topics on `sinks`.
    pub fn create(sinks: &mut Sinks<'_>, plan: &RosPlan) -> Result<Self> {
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
                    fix: (sinks.out(&t.topic, &sensor_qos())?, fix),
                    velocity: match &t.velocity_topic {
                        Some(topic) => Some((sinks.out(topic, &sensor_qos())?, velocity)),
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
        let stamp = Time::from_secs(r.stamp_s);
        let (out, msg) = &mut receiver.fix;
        msg.header.stamp = stamp;
        msg.status = msgs::NavSatStatus {
            status: r.status,
            service: r.service,
        };
        msg.latitude = r.latitude_deg;
        msg.longitude = r.longitude_deg;
        msg.altitude = r.altitude_m;
        msg.position_covariance = diagonal(r.position_covariance_diagonal);
        out.put(stamp, msg);
        if let Some((out, msg)) = &mut receiver.velocity {
            msg.header.stamp = stamp;
            msg.vector = r.velocity_mps.into();
            out.put(stamp, msg);
        }
    }
}
