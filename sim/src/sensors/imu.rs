//! The IMU: what an inertial measurement unit fixed to a link reads, as gazebo_ros publishes it
//! on sensor_msgs/Imu. Orientation against the world (or the sensor's starting orientation),
//! angular velocity in the sensor's frame, and linear acceleration in the sensor's frame with
//! gravity in it: at rest an accelerometer reads +9.81 m/s^2 along the axis that points up.
//!
//! The acceleration is the sensor point's change of velocity since the previous reading over
//! the time between them (rapier gives velocities, not accelerations): the mean over the sample
//! interval, as an accelerometer that integrates over its sample period reports it. At a rate
//! of 0 (every physics step) that is the last step's.

use glam::{DQuat, DVec3, EulerRot};

use crate::model::{ImuConfig, LinkId, OrientationReference};
use crate::noise::Normals;
use crate::physics::Simulation;
use crate::sensors::schedule::Schedule;

/// One IMU reading, in the units and frames of sensor_msgs/Imu. `Copy`: it travels to the ROS
/// bridge and the recorder without allocating.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImuReading {
    /// Which of the robot's IMUs (its index in `RobotModel::imus`).
    pub sensor: usize,
    /// Sim time of the reading (s).
    pub stamp_s: f64,
    /// Readings so far, this one included.
    pub seq: u64,
    /// Orientation (x, y, z, w) of the sensor against its reference, noise included (not
    /// renormalised, as gazebo_ros leaves it).
    pub orientation_xyzw: [f64; 4],
    /// Angular velocity about the sensor's x, y, z axes (rad/s).
    pub angular_velocity_radps: [f64; 3],
    /// Specific force along the sensor's axes (m/s^2): acceleration minus gravity.
    pub linear_acceleration_mps2: [f64; 3],
    /// Each covariance's diagonal entry: the plugin's `gaussianNoise` squared (0: unknown).
    pub covariance_diagonal: f64,
}

/// An IMU on one of the robot's links, with seeded noise and bias.
#[derive(Debug, Clone)]
pub struct ImuSensor {
    config: ImuConfig,
    link: LinkId,
    schedule: Schedule,
    noise: Normals,
    /// Bias of each angular-velocity and linear-acceleration axis, drawn at start.
    bias_radps: [f64; 3],
    bias_mps2: [f64; 3],
    /// The sensor point's world velocity at the previous reading, and its time.
    last_velocity: Option<(f64, DVec3)>,
    acceleration_world: DVec3,
    /// Inverse of the reference orientation (identity for the world; set at the first update
    /// for the initial orientation).
    reference_inv: Option<DQuat>,
    offset: DQuat,
    gravity_mps2: DVec3,
    reading: ImuReading,
}

impl ImuSensor {
    /// The robot's IMU `index` (`RobotModel::imus`). `None` when there is no such IMU.
    pub fn new(sim: &Simulation, index: usize) -> Option<Self> {
        let config = sim.robot().imus.get(index)?.clone();
        let link = sim.robot().link_id(&config.link)?;
        let g = sim.world().physics.gravity_mps2;
        // Its own stream: adding an IMU leaves the camera's and the laser's noise alone.
        let mut noise = Normals::new(sim.seed() ^ 0x0154_1A0B_1D5E_ED00 ^ (index as u64));
        // The model plugin's axes are all zero (it reads only gaussianNoise): no bias there.
        let mut bias = |axes: &[crate::model::AxisNoise; 3]| {
            axes.map(|a| {
                if a.bias_mean == 0.0 && a.bias_stddev == 0.0 {
                    return 0.0;
                }
                // Gazebo: drawn once from N(bias_mean, bias_stddev), then a random sign.
                let b = a.bias_mean + noise.scaled(a.bias_stddev);
                if noise.unit() < 0.5 { -b } else { b }
            })
        };
        let bias_radps = bias(&config.angular_velocity_noise);
        let bias_mps2 = bias(&config.linear_acceleration_noise);
        let [roll, pitch, yaw] = config.rpy_offset_rad;
        Some(Self {
            link,
            schedule: Schedule::new(config.update_rate_hz),
            noise,
            bias_radps,
            bias_mps2,
            last_velocity: None,
            acceleration_world: DVec3::ZERO,
            reference_inv: (config.reference == OrientationReference::World)
                .then_some(DQuat::IDENTITY),
            offset: DQuat::from_euler(EulerRot::ZYX, yaw, pitch, roll),
            gravity_mps2: DVec3::from_array(g),
            reading: ImuReading {
                sensor: index,
                covariance_diagonal: config.gaussian_noise * config.gaussian_noise,
                ..ImuReading::default()
            },
            config,
        })
    }

    /// The sensor's settings.
    pub fn config(&self) -> &ImuConfig {
        &self.config
    }

    /// The newest reading (zeros before the first).
    pub fn last(&self) -> &ImuReading {
        &self.reading
    }

    /// Call after every physics step: reads when the sensor is due (its update rate on sim
    /// time; every step at rate 0, as in Gazebo).
    pub fn update(&mut self, sim: &Simulation) -> Option<&ImuReading> {
        let now = sim.sim_time_s();
        if !self.schedule.take(now) {
            return None;
        }
        let state = sim.link_point_state(self.link, self.config.link_from_sensor);
        let velocity = state.linear_mps.as_dvec3();
        if let Some((then, before)) = self.last_velocity
            && now > then
        {
            self.acceleration_world = (velocity - before) / (now - then);
        }
        self.last_velocity = Some((now, velocity));
        let world_from_sensor = state.pose.rotation.as_dquat().normalize();
        let reference_inv = *self
            .reference_inv
            .get_or_insert_with(|| world_from_sensor.inverse());
        let orientation = (self.offset * reference_inv * world_from_sensor).normalize();
        let sensor_from_world = world_from_sensor.inverse();
        let angular = sensor_from_world * state.angular_radps.as_dvec3();
        let specific_force = sensor_from_world * (self.acceleration_world - self.gravity_mps2);
        self.reading.stamp_s = now;
        self.reading.seq += 1;
        let plugin_noise = self.config.gaussian_noise;
        let mut quaternion = orientation.to_array();
        for q in &mut quaternion {
            *q += self.noise.scaled(plugin_noise);
        }
        self.reading.orientation_xyzw = quaternion;
        for i in 0..3 {
            let (w, a) = (
                self.config.angular_velocity_noise[i],
                self.config.linear_acceleration_noise[i],
            );
            self.reading.angular_velocity_radps[i] = angular[i]
                + self.bias_radps[i]
                + w.mean
                + self.noise.scaled(w.stddev)
                + self.noise.scaled(plugin_noise);
            self.reading.linear_acceleration_mps2[i] = specific_force[i]
                + self.bias_mps2[i]
                + a.mean
                + self.noise.scaled(a.stddev)
                + self.noise.scaled(plugin_noise);
        }
        Some(&self.reading)
    }
}
