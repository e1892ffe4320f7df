//! Ground truth of a link, as `libgazebo_ros_p3d.so` publishes it on nav_msgs/Odometry: its
//! pose in the world (or against another link) and its velocity in that frame's axes, with the
//! plugin's offsets and seeded white noise on the velocities.

use glam::{DQuat, DVec3, EulerRot};

use crate::geometry::Pose;
use crate::model::{LinkId, P3dConfig};
use crate::noise::Normals;
use crate::physics::Simulation;
use crate::sensors::schedule::Schedule;

/// One p3d reading: nav_msgs/Odometry's numbers. `Copy`, so it travels without allocating.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PoseReading {
    /// Which p3d of the robot (its index in `RobotModel::p3ds`).
    pub sensor: usize,
    /// Sim time (s).
    pub stamp_s: f64,
    /// Readings so far, this one included.
    pub seq: u64,
    /// Position of the link (m) in the reference frame, offset added.
    pub position_m: [f64; 3],
    /// Orientation (x, y, z, w) in the reference frame, offset applied.
    pub orientation_xyzw: [f64; 4],
    /// Linear velocity (m/s) of the link's origin, in the reference frame's axes, noise added.
    pub linear_mps: [f64; 3],
    /// Angular velocity (rad/s), in the reference frame's axes, noise added.
    pub angular_radps: [f64; 3],
    /// Each covariance's diagonal entry: `gaussianNoise` squared.
    pub covariance_diagonal: f64,
}

/// A p3d publisher on one of the robot's links.
#[derive(Debug, Clone)]
pub struct P3dSensor {
    config: P3dConfig,
    link: LinkId,
    reference: Option<LinkId>,
    offset: DQuat,
    schedule: Schedule,
    noise: Normals,
    reading: PoseReading,
}

impl P3dSensor {
    /// The robot's p3d `index` (`RobotModel::p3ds`); `None` when there is none, or its links
    /// are not the robot's.
    pub fn new(sim: &Simulation, index: usize) -> Option<Self> {
        let config = sim.robot().p3ds.get(index)?.clone();
        let link = sim.robot().link_id(&config.link)?;
        let reference = match &config.reference_link {
            Some(name) => Some(sim.robot().link_id(name)?),
            None => None,
        };
        let [roll, pitch, yaw] = config.rpy_offset_rad;
        Some(Self {
            link,
            reference,
            offset: DQuat::from_euler(EulerRot::ZYX, yaw, pitch, roll),
            schedule: Schedule::new(config.update_rate_hz),
            // Its own stream: adding a p3d leaves the other sensors' noise alone.
            noise: Normals::new(sim.seed() ^ 0x0F3D_0F3D_5EED_0000 ^ (index as u64)),
            reading: PoseReading {
                sensor: index,
                covariance_diagonal: config.gaussian_noise * config.gaussian_noise,
                ..PoseReading::default()
            },
            config,
        })
    }

    /// The plugin's settings.
    pub fn config(&self) -> &P3dConfig {
        &self.config
    }

    /// The newest reading.
    pub fn last(&self) -> &PoseReading {
        &self.reading
    }

    /// Call after every physics step: reads when due (`updateRate` on sim time; every step at
    /// 0, as gazebo_ros).
    pub fn update(&mut self, sim: &Simulation) -> Option<&PoseReading> {
        let now = sim.sim_time_s();
        if !self.schedule.take(now) {
            return None;
        }
        let body = sim.link_point_state(self.link, Pose::IDENTITY);
        let (mut position, mut rotation) = (
            body.pose.translation.as_dvec3(),
            body.pose.rotation.as_dquat(),
        );
        let (mut linear, mut angular) = (body.linear_mps.as_dvec3(), body.angular_radps.as_dvec3());
        if let Some(reference) = self.reference {
            let frame = sim.link_point_state(reference, Pose::IDENTITY);
            let frame_inv = frame.pose.rotation.as_dquat().inverse();
            position = frame_inv * (position - frame.pose.translation.as_dvec3());
            rotation = frame_inv * rotation;
            linear = frame_inv * (linear - frame.linear_mps.as_dvec3());
            angular = frame_inv * (angular - frame.angular_radps.as_dvec3());
        }
        position += DVec3::from_array(self.config.xyz_offset_m);
        rotation = (self.offset * rotation).normalize();
        let r = &mut self.reading;
        r.stamp_s = now;
        r.seq += 1;
        r.position_m = position.to_array();
        r.orientation_xyzw = rotation.to_array();
        let stddev = self.config.gaussian_noise;
        let noise = &mut self.noise;
        r.linear_mps = linear.to_array().map(|v| v + noise.scaled(stddev));
        r.angular_radps = angular.to_array().map(|v| v + noise.scaled(stddev));
        Some(&self.reading)
    }
}
