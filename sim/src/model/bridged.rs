//! A robot's gz topics given their ROS names and types from a ros_gz_bridge topic map
//! ([`crate::description::TopicMap`]): what `parameter_bridge` with that file would make of
//! them. Applied once, after loading; ROS bridges then publish under the mapped names.

use std::path::Path;

use crate::description::{BridgeDirection, TopicBridge, TopicMap};
use crate::error::{Result, SimError};
use crate::model::robot::RobotModel;

/// One topic of the robot: its name (to rewrite), which way it flows and the ROS types rover
/// can carry on it.
struct Slot<'a> {
    topic: &'a mut String,
    /// Flows from ROS into the simulation (a command), else out of it.
    inbound: bool,
    /// The ROS types (without `/msg/`) rover carries on it.
    types: &'static [&'static str],
}

impl<'a> Slot<'a> {
    /// A topic the simulation publishes as one of `types`.
    fn out(topic: &'a mut String, types: &'static [&'static str]) -> Self {
        Self {
            topic,
            inbound: false,
            types,
        }
    }
}

/// What bridging a robot's topics did.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Bridged {
    /// `gz name -> ROS name` for each topic the map bridges.
    pub renamed: Vec<(String, String)>,
    /// The robot's topics the map does not bridge: published under their gz names.
    pub unbridged: Vec<String>,
}

fn check(entry: &TopicBridge, slot: &Slot<'_>, path: &Path) -> Result<()> {
    let wanted_way = if slot.inbound {
        BridgeDirection::RosToGz
    } else {
        BridgeDirection::GzToRos
    };
    if entry.direction != BridgeDirection::Bidirectional && entry.direction != wanted_way {
        return Err(SimError::invalid(
            path,
            Some(entry.line),
            format!(
                "gz topic '{}' flows {} here; the map bridges it the other way ({:?})",
                entry.gz_topic,
                if slot.inbound {
                    "from ROS into the simulation"
                } else {
                    "out of the simulation"
                },
                entry.direction
            ),
        ));
    }
    let short = entry.ros_type_short();
    if !slot.types.contains(&short.as_str()) {
        return Err(SimError::invalid(
            path,
            Some(entry.line),
            format!(
                "gz topic '{}' carries {} here; the map bridges it as {}",
                entry.gz_topic,
                slot.types.join(" or "),
                entry.ros_type
            ),
        ));
    }
    Ok(())
}

impl RobotModel {
    /// Renames the robot's topics as `map` bridges them (a leading `/` added), and takes the
    /// drive's command type from it (geometry_msgs/TwistStamped where the map says so). A map
    /// entry that bridges a topic the wrong way or as a type rover does not publish there is an
    /// error at its line.
    pub fn bridge_topics(&mut self, map: &TopicMap) -> Result<Bridged> {
        let mut out = Bridged::default();
        let mut stamped = None;
        {
            let slots = self.topic_slots();
            for slot in slots {
                let gz = slot.topic.clone();
                match map.for_gz_topic(&gz) {
                    Some(entry) => {
                        check(entry, &slot, &map.source)?;
                        if slot.types.contains(&"geometry_msgs/TwistStamped") {
                            stamped = Some(entry.ros_type_short() == "geometry_msgs/TwistStamped");
                        }
                        let ros = format!("/{}", entry.ros_topic.trim_start_matches('/'));
                        *slot.topic = ros.clone();
                        out.renamed.push((gz, ros));
                    }
                    None => out.unbridged.push(gz),
                }
            }
        }
        if let (Some(dd), Some(s)) = (&mut self.diff_drive, stamped) {
            dd.command_stamped = s;
        }
        if !out.unbridged.is_empty() {
            tracing::info!(
                "{}: not in the bridge map, published under their gz names: {}",
                map.source.display(),
                out.unbridged.join(", ")
            );
        }
        Ok(out)
    }

    /// Every topic of the robot a bridge map may rename, the drive's command first.
    fn topic_slots(&mut self) -> Vec<Slot<'_>> {
        let mut slots: Vec<Slot<'_>> = Vec::new();
        if let Some(dd) = &mut self.diff_drive {
            slots.push(Slot {
                topic: &mut dd.command_topic,
                inbound: true,
                types: &["geometry_msgs/Twist", "geometry_msgs/TwistStamped"],
            });
            slots.push(Slot::out(&mut dd.odometry_topic, &["nav_msgs/Odometry"]));
            if let Some(tf) = &mut dd.tf_topic {
                slots.push(Slot::out(tf, &["tf2_msgs/TFMessage"]));
            }
        }
        if let Some(jsp) = &mut self.joint_state_publisher {
            slots.push(Slot::out(&mut jsp.topic, &["sensor_msgs/JointState"]));
        }
        for c in self.cameras.iter_mut().filter(|c| c.camera_name.is_empty()) {
            slots.push(Slot::out(&mut c.image_topic, &["sensor_msgs/Image"]));
            slots.push(Slot::out(&mut c.info_topic, &["sensor_msgs/CameraInfo"]));
            if let Some(d) = &mut c.depth {
                slots.push(Slot::out(&mut d.image_topic, &["sensor_msgs/Image"]));
                slots.push(Slot::out(&mut d.cloud_topic, &["sensor_msgs/PointCloud2"]));
            }
        }
        for l in &mut self.lasers {
            slots.push(Slot::out(&mut l.topic, &["sensor_msgs/LaserScan"]));
        }
        for l in &mut self.lidars {
            slots.push(Slot::out(&mut l.rays.topic, &["sensor_msgs/PointCloud2"]));
        }
        for i in &mut self.imus {
            slots.push(Slot::out(&mut i.topic, &["sensor_msgs/Imu"]));
        }
        for g in &mut self.gpss {
            slots.push(Slot::out(&mut g.topic, &["sensor_msgs/NavSatFix"]));
        }
        for c in self
            .controllers
            .iter_mut()
            .flat_map(|c| c.controllers.iter_mut())
        {
            let types: &'static [&'static str] =
                if matches!(c.kind, crate::model::ControllerKind::Trajectory(_)) {
                    &["trajectory_msgs/JointTrajectory"]
                } else {
                    &["std_msgs/Float64"]
                };
            if let Some(topic) = &mut c.topic {
                slots.push(Slot {
                    topic,
                    inbound: true,
                    types,
                });
            }
        }
        slots
    }
}
