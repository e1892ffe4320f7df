//! The 2D laser scanner as a sensor: Gazebo's ray sensor with `libgazebo_ros_laser.so`, simulated
//! by ray casts against the physics scene (rapier's query pipeline, not the renderer) at the
//! sensor's `update_rate` on sim time. Results are shaped like `sensor_msgs/LaserScan`.
//!
//! Conventions (REP-117, what gazebo_ros_laser publishes): ray `i` points at
//! `angle_min + i * angle_increment` counter-clockwise from the sensor's x axis in its xy plane;
//! a ray that hits nothing within `range_max` reads `+inf`, a return closer than `range_min`
//! reads `-inf`. Hits get the sensor's gaussian noise (seeded by the simulation's seed), then are
//! clamped into `[range_min, range_max]` and rounded to the range resolution.
//!
//! People with a skinned body are seen as their posed bones (`rays.rs`).

use glam::Vec3;

use crate::error::{Result, SimError};
use crate::geometry::Pose;
use crate::model::robot::LinkId;
use crate::model::sensors::LaserConfig;
use crate::noise::SplitMix64 as Rng;
use crate::physics::simulation::Simulation;
use crate::sensors::rays::RayCaster;
use crate::sensors::schedule::Schedule;

/// How far above and below the scan plane a bone may reach and still be looked at (m): the
/// scan plane tilts a little with the robot.
const PLANE_SLACK_M: f32 = 0.1;

/// One scan, shaped like `sensor_msgs/LaserScan` (f32 fields as in the message).
#[derive(Debug, Clone, PartialEq)]
pub struct LaserScan {
    /// Sim time of the scan (s).
    pub stamp_s: f64,
    /// Scan number since the start (0, 1, ...).
    pub seq: u64,
    /// Frame of the rays (the plugin's `frameName`).
    pub frame_id: String,
    /// Angle of the first ray (rad).
    pub angle_min_rad: f32,
    /// Angle of the last ray (rad).
    pub angle_max_rad: f32,
    /// Angle between rays (rad).
    pub angle_increment_rad: f32,
    /// Time between rays (s): 0, as Gazebo's rays are cast at once.
    pub time_increment_s: f32,
    /// Time between scans (s).
    pub scan_time_s: f32,
    /// Closest valid range (m).
    pub range_min_m: f32,
    /// Farthest valid range (m).
    pub range_max_m: f32,
    /// One range per ray (m; ±inf outside the valid interval).
    pub ranges_m: Vec<f32>,
}

impl LaserScan {
    /// Angle (rad, sensor frame) of ray `i`.
    pub fn angle_rad(&self, i: usize) -> f32 {
        self.angle_min_rad + i as f32 * self.angle_increment_rad
    }

    /// The valid returns as points in the sensor's frame (x, y in metres).
    pub fn points(&self) -> impl Iterator<Item = [f32; 2]> + '_ {
        self.ranges_m
            .iter()
            .enumerate()
            .filter(|(_, r)| r.is_finite())
            .map(|(i, &r)| {
                let a = self.angle_rad(i);
                [r * a.cos(), r * a.sin()]
            })
    }
}

/// A laser scanner on the robot: casts its rays when due and keeps the newest scan.
#[derive(Debug)]
pub struct LaserSensor {
    config: LaserConfig,
    link: LinkId,
    schedule: Schedule,
    rng: Rng,
    /// Unit ray directions in the sensor frame, computed once.
    directions: Vec<Vec3>,
    scans: u64,
    scan: LaserScan,
    rays: RayCaster,
}

impl LaserSensor {
    /// The robot's laser number `index` (file order).
    pub fn new(sim: &Simulation, index: usize) -> Result<Self> {
        let robot = sim.robot();
        let config = robot.lasers.get(index).cloned().ok_or_else(|| {
            SimError::Setup(format!(
                "{}: the robot has no laser number {index} (<sensor type=\"ray\">); it has {}",
                robot.source.display(),
                robot.lasers.len()
            ))
        })?;
        let link = robot
            .link_id(&config.link)
            .ok_or_else(|| SimError::Setup(format!("laser link \"{}\" missing", config.link)))?;
        let increment = config.angle_increment_rad();
        let directions = (0..config.samples)
            .map(|i| {
                let a = config.min_angle_rad + f64::from(i) * increment;
                Vec3::new(a.cos() as f32, a.sin() as f32, 0.0)
            })
            .collect();
        let schedule = Schedule::new(config.update_rate_hz);
        let scan = LaserScan {
            stamp_s: 0.0,
            seq: 0,
            frame_id: config.frame_name.clone(),
            angle_min_rad: config.min_angle_rad as f32,
            angle_max_rad: config.max_angle_rad as f32,
            angle_increment_rad: increment as f32,
            time_increment_s: 0.0,
            scan_time_s: schedule.period_s() as f32,
            range_min_m: config.range_min_m as f32,
            range_max_m: config.range_max_m as f32,
            ranges_m: Vec::with_capacity(config.samples as usize),
        };
        Ok(Self {
            rays: RayCaster::new(sim),
            // Its own stream, independent of the camera's: adding a laser leaves images alone.
            rng: Rng(sim.seed() ^ 0x1A5E_5CA7_1A5E_5CA7 ^ (index as u64)),
            config,
            link,
            schedule,
            directions,
            scans: 0,
            scan,
        })
    }

    /// The sensor's settings.
    pub fn config(&self) -> &LaserConfig {
        &self.config
    }

    /// The robot link it is mounted on.
    pub fn link(&self) -> LinkId {
        self.link
    }

    /// The newest scan (empty ranges before the first).
    pub fn last(&self) -> &LaserScan {
        &self.scan
    }

    /// Where the sensor is in the world now.
    pub fn world_from_sensor(&self, sim: &Simulation) -> Pose {
        sim.world_from_link(self.link) * self.config.link_from_sensor
    }

    /// Scans when the sensor is due at the simulation's current time (its `update_rate` on sim
    /// time; every step when the rate is 0, as in Gazebo).
    pub fn scan_if_due(&mut self, sim: &Simulation) -> Option<&LaserScan> {
        let now = sim.sim_time_s();
        if !self.schedule.take(now) {
            return None;
        }
        Some(self.scan_now(sim))
    }

    /// Casts every ray now. No allocation after the first scan.
    pub fn scan_now(&mut self, sim: &Simulation) -> &LaserScan {
        let world_from_sensor = self.world_from_sensor(sim);
        let origin = world_from_sensor.translation;
        let (min, max) = (self.config.range_min_m, self.config.range_max_m);
        let resolution = self.config.range_resolution_m;
        let noise = self.config.noise;
        self.scan.ranges_m.clear();
        let mut spare: Option<f64> = None;
        // Bones that reach the scan plane, which tilts a little with the robot.
        let band = (origin.z - PLANE_SLACK_M, origin.z + PLANE_SLACK_M);
        self.rays.pose_people(sim, Some(band));
        for dir in &self.directions {
            let world_dir = world_from_sensor.rotation * *dir;
            let hit = self.rays.cast(sim, origin, world_dir, max as f32);
            let range = match hit {
                None => f32::INFINITY,
                Some(hit) if f64::from(hit) < min => f32::NEG_INFINITY,
                Some(hit) => {
                    let mut r = f64::from(hit);
                    if let Some(n) = noise {
                        let z = match spare.take() {
                            Some(z) => z,
                            None => {
                                let (a, b) = self.rng.normal_pair();
                                spare = Some(b);
                                a
                            }
                        };
                        r += n.mean + n.stddev * z;
                    }
                    r = r.clamp(min, max);
                    if resolution > 0.0 {
                        r = ((r / resolution).round() * resolution).clamp(min, max);
                    }
                    r as f32
                }
            };
            self.scan.ranges_m.push(range);
        }
        self.scan.stamp_s = sim.sim_time_s();
        self.scan.seq = self.scans;
        self.scans += 1;
        &self.scan
    }
}
