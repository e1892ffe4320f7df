//! The sensors a session only shows its observers (the pilot reads none of them): the IMUs,
//! p3d's ground truth, the GPS receivers, the bumpers and the 3D lidars, each read after every
//! physics step
//! when due, and the depth camera's point cloud, built from each depth image.

use rover_sim::{
    geometry::Pose,
    model::{CameraInfo, GpsSource, link_from_optical},
    physics::Simulation,
    sensors::{
        BumperSensor, CameraFrame, CloudLayout, CloudSource, DepthCloudBuilder, GpsSensor,
        ImuSensor, LidarSensor, P3dSensor, PointCloud,
    },
};

use crate::error::Result;
use crate::observer::Observer;

/// A depth camera's cloud: its builder, cutoffs and reused buffer.
#[derive(Debug)]
struct DepthCloud {
    builder: DepthCloudBuilder,
    cutoff_m: (f64, f64),
    cloud: PointCloud,
}

/// The observed sensors of one robot.
#[derive(Debug)]
pub(crate) struct ObservedSensors {
    imus: Vec<ImuSensor>,
    p3ds: Vec<P3dSensor>,
    gpss: Vec<GpsSensor>,
    lidars: Vec<LidarSensor>,
    bumpers: Vec<BumperSensor>,
    depth_cloud: Option<DepthCloud>,
}

impl ObservedSensors {
    /// Every such sensor the robot declares, each announced once in the log; the depth cloud
    /// when the rendered camera (`camera`) is a depth camera.
    pub fn start(sim: &Simulation, camera: Option<&CameraInfo>) -> Result<Self> {
        let robot = sim.robot();
        let imus = (0..robot.imus.len())
            .filter_map(|i| ImuSensor::new(sim, i))
            .inspect(|imu| {
                let c = imu.config();
                let rate = rate_text(c.update_rate_hz);
                tracing::info!("imu: {} on {} at {rate}, topic {}", c.name, c.link, c.topic);
            })
            .collect();
        let p3ds = (0..robot.p3ds.len())
            .filter_map(|i| P3dSensor::new(sim, i))
            .inspect(|p| {
                let c = p.config();
                let rate = rate_text(c.update_rate_hz);
                tracing::info!(
                    "p3d: {} ground truth in {} at {rate}, topic {}",
                    c.link,
                    c.frame_name,
                    c.topic
                );
            })
            .collect();
        let gpss = (0..robot.gpss.len())
            .filter_map(|i| GpsSensor::new(sim, i))
            .inspect(|g| {
                let c = g.config();
                let rate = rate_text(c.update_rate_hz);
                let (lat, lon, model) = match c.source {
                    GpsSource::Hector => (
                        c.reference_latitude_deg,
                        c.reference_longitude_deg,
                        "hector's reference",
                    ),
                    GpsSource::Sensor => {
                        let sc = &sim.world().spherical_coordinates;
                        (
                            sc.latitude_deg,
                            sc.longitude_deg,
                            "the world's spherical coordinates",
                        )
                    }
                };
                tracing::info!(
                    "gps: {} around {lat} N {lon} E ({model}) at {rate}, topic {}{}",
                    c.link,
                    c.topic,
                    if c.velocity_topic.is_empty() {
                        String::new()
                    } else {
                        format!(" and {}", c.velocity_topic)
                    }
                );
            })
            .collect();
        let lidars = (0..robot.lidars.len())
            .map(|i| LidarSensor::new(sim, i))
            .collect::<rover_sim::Result<Vec<_>>>()?;
        for l in &lidars {
            let c = l.config();
            tracing::info!(
                "lidar: {} beams ({:.1} to {:.1} deg) x {} columns, {:.1}-{:.1} m at {}, topic {} (PointCloud2)",
                c.vertical_samples,
                c.vertical_min_angle_rad.to_degrees(),
                c.vertical_max_angle_rad.to_degrees(),
                c.rays.samples,
                c.min_range_m.max(c.rays.range_min_m),
                c.max_range_m.min(c.rays.range_max_m),
                rate_text(c.rays.update_rate_hz),
                c.rays.topic
            );
        }
        let bumpers = (0..robot.bumpers.len())
            .filter_map(|i| BumperSensor::new(sim, i))
            .inspect(|b| {
                let c = b.config();
                let rate = rate_text(c.update_rate_hz);
                tracing::info!(
                    "bumper: {} on {} ({}) at {rate}, topic {} in {}",
                    c.name,
                    c.link,
                    c.collision,
                    c.topic,
                    c.frame_name
                );
            })
            .collect();
        let depth = robot.cameras.first().and_then(|c| c.depth.as_ref());
        let depth_cloud = camera.zip(depth).map(|(info, d)| {
            tracing::info!(
                "depth camera: a point cloud of every depth image, {:.2}-{:.2} m, topic {}",
                d.cloud_cutoff_m,
                d.cloud_cutoff_max_m,
                d.cloud_topic
            );
            DepthCloud {
                builder: DepthCloudBuilder::new(info),
                cutoff_m: (d.cloud_cutoff_m, d.cloud_cutoff_max_m),
                cloud: PointCloud::new(
                    CloudSource::DepthCamera,
                    &info.frame_id,
                    CloudLayout::XyzRgb,
                ),
            }
        });
        Ok(Self {
            imus,
            p3ds,
            gpss,
            lidars,
            bumpers,
            depth_cloud,
        })
    }

    /// The robot's IMUs (`RobotModel::imus` order).
    pub fn imus(&self) -> &[ImuSensor] {
        &self.imus
    }

    /// The robot's GPS receivers (`RobotModel::gpss` order).
    pub fn gpss(&self) -> &[GpsSensor] {
        &self.gpss
    }

    /// The robot's bumpers (`RobotModel::bumpers` order).
    pub fn bumpers(&self) -> &[BumperSensor] {
        &self.bumpers
    }

    /// The robot's 3D lidars (`RobotModel::lidars` order).
    pub fn lidars(&self) -> &[LidarSensor] {
        &self.lidars
    }

    /// Reads every sensor that is due after a physics step and shows what it read.
    pub fn update(&mut self, sim: &Simulation, observer: &mut dyn Observer) {
        for imu in &mut self.imus {
            if let Some(reading) = imu.update(sim) {
                observer.imu(reading);
            }
        }
        for p3d in &mut self.p3ds {
            if let Some(reading) = p3d.update(sim) {
                observer.p3d(reading);
            }
        }
        for gps in &mut self.gpss {
            if let Some(fix) = gps.update(sim) {
                observer.gps(fix);
            }
        }
        for bumper in &mut self.bumpers {
            if let Some(reading) = bumper.update(sim) {
                observer.contacts(reading);
            }
        }
        for lidar in &mut self.lidars {
            if lidar.scan_if_due(sim).is_some() {
                observer.point_cloud(lidar.last(), lidar.world_from_sensor(sim));
            }
        }
    }

    /// A depth camera's image as a cloud in its optical frame, shown to the observers;
    /// `world_from_camera` is the camera link's pose.
    pub fn camera_frame(
        &mut self,
        frame: &CameraFrame<'_>,
        world_from_camera: Pose,
        observer: &mut dyn Observer,
    ) {
        let (Some(d), Some(depth_m)) = (self.depth_cloud.as_mut(), frame.depth_m) else {
            return;
        };
        d.builder.fill(depth_m, frame.rgb, d.cutoff_m, &mut d.cloud);
        d.cloud.stamp_s = frame.sim_time_s;
        d.cloud.seq = frame.seq;
        let world_from_optical = world_from_camera * Pose::from_rotation(link_from_optical());
        observer.point_cloud(&d.cloud, world_from_optical);
    }
}

/// "100 Hz", or "every physics step" at rate 0.
fn rate_text(rate_hz: f64) -> String {
    if rate_hz > 0.0 {
        format!("{rate_hz} Hz")
    } else {
        "every physics step".to_owned()
    }
}
