//! A bumper, as `libgazebo_ros_bumper.so` publishes gazebo_msgs/ContactsState: at the contact
//! sensor's rate, every collision its link touches (from rapier's contacts after the step),
//! with the contact points, normals, depths and the force on the link, in the world or in the
//! plugin's `frameName` link. Nothing touching: a reading with no contacts, as Gazebo's.

use crate::model::{BumperConfig, LinkId};
use crate::physics::{LinkContact, Simulation};
use crate::sensors::schedule::Schedule;

/// One bumper reading.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ContactsReading {
    /// Which bumper of the robot (its index in `RobotModel::bumpers`).
    pub sensor: usize,
    /// Sim time (s).
    pub stamp_s: f64,
    /// Readings so far, this one included.
    pub seq: u64,
    /// The frame of the positions, normals and forces (the plugin's `frameName`).
    pub frame_id: String,
    /// The watched collision, scoped as Gazebo names it (`<robot>::<link>::<collision>`):
    /// each contact's `collision1_name`.
    pub collision: String,
    /// One per other collision touched, expressed in `frame_id`.
    pub contacts: Vec<LinkContact>,
}

/// A bumper on one of the robot's links.
#[derive(Debug, Clone)]
pub struct BumperSensor {
    config: BumperConfig,
    link: LinkId,
    reference: Option<LinkId>,
    schedule: Schedule,
    reading: ContactsReading,
}

impl BumperSensor {
    /// The robot's bumper `index` (`RobotModel::bumpers`); `None` when there is none, or its
    /// links are not the robot's.
    pub fn new(sim: &Simulation, index: usize) -> Option<Self> {
        let robot = sim.robot();
        let config = robot.bumpers.get(index)?.clone();
        let link = robot.link_id(&config.link)?;
        let reference = match &config.reference_link {
            Some(name) => Some(robot.link_id(name)?),
            None => None,
        };
        Some(Self {
            link,
            reference,
            schedule: Schedule::new(config.update_rate_hz),
            reading: ContactsReading {
                sensor: index,
                frame_id: config.frame_name.clone(),
                collision: format!("{}::{}::{}", robot.name, config.link, config.collision),
                ..ContactsReading::default()
            },
            config,
        })
    }

    /// The sensor's settings.
    pub fn config(&self) -> &BumperConfig {
        &self.config
    }

    /// The newest reading.
    pub fn last(&self) -> &ContactsReading {
        &self.reading
    }

    /// Reads the contacts when the sensor is due at the simulation's current time.
    pub fn update(&mut self, sim: &Simulation) -> Option<&ContactsReading> {
        if !self.schedule.take(sim.sim_time_s()) {
            return None;
        }
        let r = &mut self.reading;
        sim.link_contacts(self.link, &mut r.contacts);
        if let Some(reference) = self.reference {
            let ref_from_world = sim.world_from_link(reference).inverse();
            for c in &mut r.contacts {
                for p in &mut c.positions_m {
                    *p = ref_from_world.transform_point(*p);
                }
                for n in &mut c.normals {
                    *n = ref_from_world.rotation * *n;
                }
                c.force_n = ref_from_world.rotation * c.force_n;
                c.torque_nm = ref_from_world.rotation * c.torque_nm;
            }
        }
        r.stamp_s = sim.sim_time_s();
        r.seq += 1;
        Some(&self.reading)
    }
}
