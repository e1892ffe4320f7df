//! GPS receivers. hector_gazebo_plugins' GPS: a link's origin as latitude, longitude and
//! altitude around a reference point, on WGS-84's radii of curvature at the reference latitude
//! (hector's local model: exact to well under a millimetre within a few hundred metres), and
//! its velocity, each with hector's error model (offset, Gauss-Markov drift, white noise),
//! seeded. Gazebo's GPS sensor: the sensor's position on the world's `<spherical_coordinates>`,
//! exact on the ellipsoid (local east-north-up to Earth-centred to geodetic, as Gazebo's
//! `SphericalCoordinates` does), its velocity east, north, up, with the SDF noise.

use glam::DVec3;

use crate::model::{ErrorModel, GpsConfig, GpsSource, LinkId, SphericalCoordinates};
use crate::noise::Normals;
use crate::physics::Simulation;
use crate::sensors::schedule::Schedule;

/// WGS-84's equatorial radius (m).
pub const WGS84_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;
/// WGS-84's flattening.
pub const WGS84_FLATTENING: f64 = 1.0 / 298.257_223_563;

/// The radii of curvature (north-south, east-west; m) of WGS-84 at `latitude_deg`, as hector
/// computes them: the meridian radius, and the prime vertical radius times cos(latitude).
pub fn wgs84_radii_m(latitude_deg: f64) -> (f64, f64) {
    let e2 = 2.0 * WGS84_FLATTENING - WGS84_FLATTENING * WGS84_FLATTENING;
    let sin = latitude_deg.to_radians().sin();
    let temp = 1.0 / (1.0 - e2 * sin * sin);
    let prime_vertical = WGS84_EQUATORIAL_RADIUS_M * temp.sqrt();
    (
        prime_vertical * (1.0 - e2) * temp,
        prime_vertical * latitude_deg.to_radians().cos(),
    )
}

/// The world's local frame on WGS-84's ellipsoid (a `<spherical_coordinates>`): its origin
/// Earth-centred, Earth-fixed, and the east, north and up axes there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipsoid {
    origin_ecef_m: DVec3,
    east: DVec3,
    north: DVec3,
    up: DVec3,
    heading_sin_cos: (f64, f64),
}

impl Ellipsoid {
    /// The frame of `sc`.
    pub fn new(sc: &SphericalCoordinates) -> Self {
        let (lat, lon) = (sc.latitude_deg.to_radians(), sc.longitude_deg.to_radians());
        let (sin_lat, cos_lat) = lat.sin_cos();
        let (sin_lon, cos_lon) = lon.sin_cos();
        let e2 = 2.0 * WGS84_FLATTENING - WGS84_FLATTENING * WGS84_FLATTENING;
        let n = WGS84_EQUATORIAL_RADIUS_M / (1.0 - e2 * sin_lat * sin_lat).sqrt();
        let h = sc.elevation_m;
        Self {
            origin_ecef_m: DVec3::new(
                (n + h) * cos_lat * cos_lon,
                (n + h) * cos_lat * sin_lon,
                (n * (1.0 - e2) + h) * sin_lat,
            ),
            east: DVec3::new(-sin_lon, cos_lon, 0.0),
            north: DVec3::new(-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat),
            up: DVec3::new(cos_lat * cos_lon, cos_lat * sin_lon, sin_lat),
            heading_sin_cos: sc.heading_deg.to_radians().sin_cos(),
        }
    }

    /// A world vector as east, north, up (the heading applied).
    pub fn enu(&self, world: [f64; 3]) -> [f64; 3] {
        let (sin, cos) = self.heading_sin_cos;
        let [x, y, z] = world;
        [x * cos + y * sin, -x * sin + y * cos, z]
    }

    /// Latitude, longitude (deg) and height above the ellipsoid (m) of a world point (m).
    pub fn geodetic(&self, world_m: [f64; 3]) -> [f64; 3] {
        let [e, n, u] = self.enu(world_m);
        let p = self.origin_ecef_m + self.east * e + self.north * n + self.up * u;
        geodetic_from_ecef(p)
    }
}

/// Latitude, longitude (deg) and height (m) of an Earth-centred point on WGS-84, by
/// Bowring's iteration (a few rounds reach well under a micrometre near the surface).
fn geodetic_from_ecef(p: DVec3) -> [f64; 3] {
    let a = WGS84_EQUATORIAL_RADIUS_M;
    let e2 = 2.0 * WGS84_FLATTENING - WGS84_FLATTENING * WGS84_FLATTENING;
    let r = p.x.hypot(p.y);
    let lon = p.y.atan2(p.x);
    let mut lat = p.z.atan2(r * (1.0 - e2));
    let normal = |lat: f64| a / (1.0 - e2 * lat.sin() * lat.sin()).sqrt();
    for _ in 0..6 {
        let n = normal(lat);
        let height = r * lat.cos() + p.z * lat.sin() - a * a / n;
        lat = p.z.atan2(r * (1.0 - e2 * n / (n + height)));
    }
    // The height along the normal, exact at any latitude.
    let height = r * lat.cos() + p.z * lat.sin() - a * a / normal(lat);
    [lat.to_degrees(), lon.to_degrees(), height]
}

/// One fix: sensor_msgs/NavSatFix's numbers and the velocity hector publishes beside it.
/// `Copy`, so it travels without allocating.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FixReading {
    /// Which GPS of the robot (its index in `RobotModel::gpss`).
    pub sensor: usize,
    /// Sim time (s).
    pub stamp_s: f64,
    /// Fixes so far, this one included.
    pub seq: u64,
    /// Latitude (deg, north positive).
    pub latitude_deg: f64,
    /// Longitude (deg, east positive).
    pub longitude_deg: f64,
    /// Altitude (m): hector's above the reference altitude's datum; the sensor's above the
    /// ellipsoid.
    pub altitude_m: f64,
    /// The position covariance's diagonal (m^2: drift^2 + noise^2 per axis, as hector's).
    pub position_covariance_diagonal: [f64; 3],
    /// NavSatStatus `status`.
    pub status: i8,
    /// NavSatStatus `service`.
    pub service: u16,
    /// Velocity (m/s): hector's turned by the reference heading (x north and y west by
    /// default, z up); the sensor's east, north, up.
    pub velocity_mps: [f64; 3],
}

/// A GPS receiver on one of the robot's links.
#[derive(Debug, Clone)]
pub struct GpsSensor {
    config: GpsConfig,
    link: LinkId,
    schedule: Schedule,
    last_s: Option<f64>,
    noise: Normals,
    position_drift: [f64; 3],
    velocity_drift: [f64; 3],
    radius_north_m: f64,
    radius_east_m: f64,
    /// The world on the ellipsoid, for the sensor form (`None`: hector's model).
    ellipsoid: Option<Ellipsoid>,
    reading: FixReading,
}

impl GpsSensor {
    /// The robot's GPS `index` (`RobotModel::gpss`); `None` when there is none.
    pub fn new(sim: &Simulation, index: usize) -> Option<Self> {
        let config = sim.robot().gpss.get(index)?.clone();
        let link = sim.robot().link_id(&config.link)?;
        let (radius_north_m, radius_east_m) = wgs84_radii_m(config.reference_latitude_deg);
        let square = |m: &ErrorModel| {
            std::array::from_fn(|i| {
                m.drift[i] * m.drift[i] + m.gaussian_noise[i] * m.gaussian_noise[i]
            })
        };
        Some(Self {
            link,
            schedule: Schedule::new(config.update_rate_hz),
            last_s: None,
            // Its own stream: adding a GPS leaves the other sensors' noise alone.
            noise: Normals::new(sim.seed() ^ 0x0006_9500_5EED_6F5D ^ (index as u64)),
            position_drift: [0.0; 3],
            velocity_drift: [0.0; 3],
            radius_north_m,
            radius_east_m,
            ellipsoid: (config.source == GpsSource::Sensor)
                .then(|| Ellipsoid::new(&sim.world().spherical_coordinates)),
            reading: FixReading {
                sensor: index,
                status: config.status,
                service: config.service,
                position_covariance_diagonal: square(&config.position_error),
                ..FixReading::default()
            },
            config,
        })
    }

    /// The plugin's settings.
    pub fn config(&self) -> &GpsConfig {
        &self.config
    }

    /// The newest fix.
    pub fn last(&self) -> &FixReading {
        &self.reading
    }

    /// Latitude and longitude (deg) of a world point `x`, `y` (m), with hector's model.
    pub fn to_geodetic(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        let h = self.config.reference_heading_deg.to_radians();
        let (sin, cos) = h.sin_cos();
        let latitude = self.config.reference_latitude_deg
            + (cos * x_m + sin * y_m) / self.radius_north_m * 180.0 / std::f64::consts::PI;
        let longitude = self.config.reference_longitude_deg
            - (-sin * x_m + cos * y_m) / self.radius_east_m * 180.0 / std::f64::consts::PI;
        (latitude, longitude)
    }

    /// Call after every physics step: a fix when one is due (`updateRate` on sim time).
    pub fn update(&mut self, sim: &Simulation) -> Option<&FixReading> {
        let now = sim.sim_time_s();
        if !self.schedule.take(now) {
            return None;
        }
        let dt = self.last_s.map_or(0.0, |t| now - t);
        self.last_s = Some(now);
        let state = sim.link_point_state(self.link, self.config.link_from_sensor);
        let velocity = state.linear_mps.as_dvec3().to_array();
        let position = state.pose.translation.as_dvec3().to_array();
        let (p_model, v_model) = (self.config.position_error, self.config.velocity_error);
        let mut measured_velocity = [0.0; 3];
        let mut measured_position = [0.0; 3];
        for i in 0..3 {
            self.velocity_drift[i] = self.drift(self.velocity_drift[i], &v_model, i, dt);
            measured_velocity[i] = velocity[i] + self.error(&v_model, self.velocity_drift[i], i);
            // As hector: the velocity's drift runs into the position's.
            self.position_drift[i] =
                self.drift(self.position_drift[i], &p_model, i, dt) + dt * self.velocity_drift[i];
            measured_position[i] = position[i] + self.error(&p_model, self.position_drift[i], i);
        }
        let (geodetic, velocity) = match &self.ellipsoid {
            Some(e) => (e.geodetic(measured_position), e.enu(measured_velocity)),
            None => {
                let (latitude, longitude) =
                    self.to_geodetic(measured_position[0], measured_position[1]);
                let altitude = self.config.reference_altitude_m + measured_position[2];
                let h = self.config.reference_heading_deg.to_radians();
                let (sin, cos) = h.sin_cos();
                let [vx, vy, vz] = measured_velocity;
                (
                    [latitude, longitude, altitude],
                    [cos * vx + sin * vy, -sin * vx + cos * vy, vz],
                )
            }
        };
        let r = &mut self.reading;
        r.stamp_s = now;
        r.seq += 1;
        [r.latitude_deg, r.longitude_deg, r.altitude_m] = geodetic;
        r.velocity_mps = velocity;
        Some(&self.reading)
    }

    /// One step of axis `i`'s first-order Gauss-Markov drift over `dt`: the exact discrete form
    /// of a process of stationary stddev `drift` reverting at `drift_frequency_hz`.
    fn drift(&mut self, current: f64, model: &ErrorModel, i: usize, dt: f64) -> f64 {
        let (sd, f) = (model.drift[i], model.drift_frequency_hz[i]);
        if sd == 0.0 || dt <= 0.0 {
            return current;
        }
        let decay = (-f * dt).exp();
        decay * current + self.noise.scaled(sd * (1.0 - decay * decay).sqrt())
    }

    /// Offset, drift and white noise of axis `i`.
    fn error(&mut self, model: &ErrorModel, drift: f64, i: usize) -> f64 {
        model.offset[i] + drift + self.noise.scaled(model.gaussian_noise[i])
    }
}
