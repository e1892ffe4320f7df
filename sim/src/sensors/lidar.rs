//! The 3D lidar as a sensor: a ray sensor with several beams (velodyne_simulator's
//! `libgazebo_ros_velodyne_laser.so`, or any ray plugin on a `<ray>` with more than one vertical
//! sample), simulated by ray casts against the physics scene and the people's bones (`rays.rs`)
//! at the sensor's `update_rate` on sim time, published as a point cloud of x y z intensity
//! ring.
//!
//! What the velodyne plugin does, kept: beam `ring` points `vertical_min + ring * step` up from
//! the sensor's xy plane (ring 0 the lowest), column `i` at `min_angle + i * step`
//! counter-clockwise from x; a return is a point when its range (with the `<ray><noise>`) lies
//! strictly between `max(min_range, <range><min>)` and `min(max_range, <range><max>)`, then
//! gets the plugin's `gaussianNoise`; points go column by column, the beams of a column bottom
//! to top, as the real sensor fires them. `organize_cloud` makes rows of rings instead, NaN
//! where a beam has no return. Intensity is 0: rover's surfaces carry no `laser_retro`.

use glam::Vec3;

use crate::error::{Result, SimError};
use crate::geometry::Pose;
use crate::model::robot::LinkId;
use crate::model::sensors::LidarConfig;
use crate::noise::Normals;
use crate::physics::simulation::Simulation;
use crate::sensors::cloud::{CloudLayout, CloudSource, PointCloud, write_lidar_point};
use crate::sensors::rays::RayCaster;
use crate::sensors::schedule::Schedule;

/// A 3D lidar on the robot: casts its beams when due and keeps the newest cloud.
#[derive(Debug)]
pub struct LidarSensor {
    config: LidarConfig,
    link: LinkId,
    schedule: Schedule,
    noise: Normals,
    /// Unit ray directions in the sensor frame, column by column, each column's beams bottom
    /// to top.
    directions: Vec<Vec3>,
    rays: RayCaster,
    cloud: PointCloud,
    scans: u64,
}

impl LidarSensor {
    /// The robot's lidar number `index` (`RobotModel::lidars` order).
    pub fn new(sim: &Simulation, index: usize) -> Result<Self> {
        let robot = sim.robot();
        let config = robot.lidars.get(index).cloned().ok_or_else(|| {
            SimError::Setup(format!(
                "{}: the robot has no 3D lidar number {index}; it has {}",
                robot.source.display(),
                robot.lidars.len()
            ))
        })?;
        let link = robot.link_id(&config.rays.link).ok_or_else(|| {
            SimError::Setup(format!("lidar link \"{}\" missing", config.rays.link))
        })?;
        let yaw_step = config.rays.angle_increment_rad();
        let mut directions = Vec::with_capacity(config.rays_per_scan() as usize);
        for column in 0..config.rays.samples {
            let yaw = config.rays.min_angle_rad + f64::from(column) * yaw_step;
            for ring in 0..config.vertical_samples {
                let pitch = config.ring_elevation_rad(ring);
                directions.push(Vec3::new(
                    (pitch.cos() * yaw.cos()) as f32,
                    (pitch.cos() * yaw.sin()) as f32,
                    pitch.sin() as f32,
                ));
            }
        }
        let mut cloud = PointCloud::new(
            CloudSource::Lidar(index),
            &config.rays.frame_name,
            CloudLayout::XyzIntensityRing,
        );
        cloud.data.reserve(directions.len() * 32);
        Ok(Self {
            schedule: Schedule::new(config.rays.update_rate_hz),
            // Its own stream: adding a lidar leaves the other sensors' noise alone.
            noise: Normals::new(sim.seed() ^ 0x11DA_C10D_0000_0000 ^ (index as u64)),
            rays: RayCaster::new(sim),
            config,
            link,
            directions,
            cloud,
            scans: 0,
        })
    }

    /// The sensor's settings.
    pub fn config(&self) -> &LidarConfig {
        &self.config
    }

    /// The robot link it is mounted on.
    pub fn link(&self) -> LinkId {
        self.link
    }

    /// The newest cloud (empty before the first).
    pub fn last(&self) -> &PointCloud {
        &self.cloud
    }

    /// Where the sensor is in the world now.
    pub fn world_from_sensor(&self, sim: &Simulation) -> Pose {
        sim.world_from_link(self.link) * self.config.rays.link_from_sensor
    }

    /// Scans when the sensor is due at the simulation's current time.
    pub fn scan_if_due(&mut self, sim: &Simulation) -> Option<&PointCloud> {
        if !self.schedule.take(sim.sim_time_s()) {
            return None;
        }
        Some(self.scan_now(sim))
    }

    /// Casts every beam now. No allocation after the first scan.
    pub fn scan_now(&mut self, sim: &Simulation) -> &PointCloud {
        let world_from_sensor = self.world_from_sensor(sim);
        let origin = world_from_sensor.translation;
        let c = &self.config;
        let lo = c.min_range_m.max(c.rays.range_min_m);
        let hi = c.max_range_m.min(c.rays.range_max_m);
        let (beams, columns) = (c.vertical_samples as usize, c.rays.samples as usize);
        let sdf_noise = c.rays.noise;
        let plugin_noise_m = c.gaussian_noise_m;
        let organize = c.organize;
        self.rays.pose_people(sim, None);
        let cloud = &mut self.cloud;
        cloud.data.clear();
        cloud.is_dense = true;
        if organize {
            cloud.data.resize(beams * columns * 32, 0);
        }
        for (i, dir) in self.directions.iter().enumerate() {
            let (column, ring) = (i / beams, i % beams);
            let world_dir = world_from_sensor.rotation * *dir;
            let hit = self
                .rays
                .cast(sim, origin, world_dir, c.rays.range_max_m as f32);
            let range = hit.map(f64::from).and_then(|mut r| {
                if let Some(n) = sdf_noise {
                    r += n.mean + self.noise.scaled(n.stddev);
                }
                (lo < r && r < hi).then(|| r + self.noise.scaled(plugin_noise_m))
            });
            let ring_u16 = ring as u16;
            if organize {
                let xyz = range.map_or([f32::NAN; 3], |r| (*dir * r as f32).to_array());
                cloud.is_dense &= range.is_some();
                let at = (ring * columns + column) * 32;
                write_lidar_point(&mut cloud.data[at..at + 32], xyz, 0.0, ring_u16);
            } else if let Some(r) = range {
                cloud.push_lidar_point((*dir * r as f32).to_array(), 0.0, ring_u16);
            }
        }
        if organize {
            cloud.height = beams as u32;
            cloud.width = columns as u32;
        } else {
            cloud.height = 1;
            cloud.width = cloud.len() as u32;
        }
        cloud.stamp_s = sim.sim_time_s();
        cloud.seq = self.scans;
        self.scans += 1;
        &self.cloud
    }
}
