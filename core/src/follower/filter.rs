//! The follower's target estimate: a constant-velocity Kalman filter on the target's position
//! and velocity in the odometry frame, fed with positions from range + bearing (camera) or from
//! laser returns.
//!
//! The velocity decays slowly toward zero between updates (a damped constant-velocity model):
//! a person who stops is soon predicted to stand still, and a flickering detector does not let a
//! noisy velocity carry the prediction away.

use nalgebra::{Matrix2, Matrix2x4, Matrix4, Vector2, Vector4};

/// Standard deviation of the target's acceleration (m/s^2): people start, stop and turn.
const ACCEL_SIGMA_MPS2: f64 = 1.2;
/// Time constant of the velocity's decay toward zero (s).
const VELOCITY_DECAY_S: f64 = 4.0;
/// Initial velocity uncertainty (m/s).
const INITIAL_SPEED_SIGMA_MPS: f64 = 1.0;
/// Velocity uncertainty of a target taken to have stopped (m/s): people walk on again.
const HALTED_SPEED_SIGMA_MPS: f64 = 0.3;

/// Position/velocity estimate of one target in the odometry frame.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetFilter {
    /// [x, y, vx, vy] (m, m/s).
    state: Vector4<f64>,
    covariance: Matrix4<f64>,
    /// Sim time of the estimate (s).
    time_s: f64,
}

/// Covariance (m^2) of a position measured at `range_m` along `heading_rad` (odometry frame)
/// with the given range and cross-range standard deviations.
pub(crate) fn polar_covariance(
    heading_rad: f64,
    range_sigma_m: f64,
    cross_sigma_m: f64,
) -> Matrix2<f64> {
    let (s, c) = heading_rad.sin_cos();
    let rotation = Matrix2::new(c, -s, s, c);
    let local = Matrix2::new(range_sigma_m.powi(2), 0.0, 0.0, cross_sigma_m.powi(2));
    rotation * local * rotation.transpose()
}

/// The covariance of a target at rest: `position_cov`, and an unknown velocity of
/// `speed_sigma_mps` per axis, uncorrelated with the position.
fn standing_covariance(position_cov: &Matrix2<f64>, speed_sigma_mps: f64) -> Matrix4<f64> {
    let mut covariance = Matrix4::zeros();
    covariance
        .fixed_view_mut::<2, 2>(0, 0)
        .copy_from(position_cov);
    covariance[(2, 2)] = speed_sigma_mps.powi(2);
    covariance[(3, 3)] = speed_sigma_mps.powi(2);
    covariance
}

impl TargetFilter {
    /// Starts at a measured position (standing still, velocity unknown).
    pub(crate) fn new(time_s: f64, position_m: [f64; 2], position_cov: Matrix2<f64>) -> Self {
        Self {
            state: Vector4::new(position_m[0], position_m[1], 0.0, 0.0),
            covariance: standing_covariance(&position_cov, INITIAL_SPEED_SIGMA_MPS),
            time_s,
        }
    }

    /// Sim time of the estimate (s).
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Estimated velocity (m/s, odometry frame).
    pub fn velocity_mps(&self) -> [f64; 2] {
        [self.state[2], self.state[3]]
    }

    /// Estimated position at the filter's time (m, odometry frame).
    pub fn position_m(&self) -> [f64; 2] {
        [self.state[0], self.state[1]]
    }

    /// 1-sigma position uncertainty (m): the root of the larger axis of the position ellipse,
    /// bounded by the root of its trace.
    pub fn position_sigma_m(&self) -> f64 {
        ((self.covariance[(0, 0)] + self.covariance[(1, 1)]) / 2.0).sqrt()
    }

    /// Covariance of the position estimate at the filter's time (m^2).
    pub(crate) fn position_covariance(&self) -> Matrix2<f64> {
        self.covariance.fixed_view::<2, 2>(0, 0).into_owned()
    }

    /// Where the target is expected at `time_s`, extrapolating at most `horizon_s` past the
    /// estimate (a lost target is not followed into the distance forever).
    pub fn predicted_position_m(&self, time_s: f64, horizon_s: f64) -> [f64; 2] {
        let dt = (time_s - self.time_s).clamp(0.0, horizon_s.max(0.0));
        // Integral of the decaying velocity over dt.
        let travel_s = VELOCITY_DECAY_S * (1.0 - (-dt / VELOCITY_DECAY_S).exp());
        [
            self.state[0] + self.state[2] * travel_s,
            self.state[1] + self.state[3] * travel_s,
        ]
    }

    /// The velocity the prediction has at `time_s` (m/s, odometry frame): the estimate's,
    /// decayed with the time since, and zero once the prediction stops at `horizon_s`.
    pub fn predicted_velocity_mps(&self, time_s: f64, horizon_s: f64) -> [f64; 2] {
        let dt = (time_s - self.time_s).max(0.0);
        if dt >= horizon_s.max(0.0) && dt > 0.0 {
            return [0.0, 0.0];
        }
        let decay = (-dt / VELOCITY_DECAY_S).exp();
        [self.state[2] * decay, self.state[3] * decay]
    }

    /// The target stopped where it was last estimated: moves the estimate to `time_s` (its
    /// uncertainty grows with the time), keeps the position of the last estimate and sets the
    /// velocity to zero with an uncertainty of [`HALTED_SPEED_SIGMA_MPS`]. For a lost target
    /// whose prediction walked it out to where the camera would have seen it.
    pub(crate) fn halt(&mut self, time_s: f64) {
        let position = [self.state[0], self.state[1]];
        self.predict(time_s);
        self.state = Vector4::new(position[0], position[1], 0.0, 0.0);
        self.covariance = standing_covariance(&self.position_covariance(), HALTED_SPEED_SIGMA_MPS);
    }

    /// Moves the estimate forward to `time_s` (no-op for an earlier time).
    pub(crate) fn predict(&mut self, time_s: f64) {
        let dt = time_s - self.time_s;
        if dt <= 0.0 {
            return;
        }
        let decay = (-dt / VELOCITY_DECAY_S).exp();
        let travel_s = VELOCITY_DECAY_S * (1.0 - decay);
        let f = Matrix4::new(
            1.0, 0.0, travel_s, 0.0, //
            0.0, 1.0, 0.0, travel_s, //
            0.0, 0.0, decay, 0.0, //
            0.0, 0.0, 0.0, decay,
        );
        // White-acceleration process noise, per axis [[dt^3/3, dt^2/2], [dt^2/2, dt]] q.
        let q = ACCEL_SIGMA_MPS2.powi(2);
        let (p, pv, v) = (dt.powi(3) / 3.0 * q, dt.powi(2) / 2.0 * q, dt * q);
        let noise = Matrix4::new(
            p, 0.0, pv, 0.0, //
            0.0, p, 0.0, pv, //
            pv, 0.0, v, 0.0, //
            0.0, pv, 0.0, v,
        );
        self.state = f * self.state;
        self.covariance = f * self.covariance * f.transpose() + noise;
        self.time_s = time_s;
    }

    /// Folds in a position measurement taken at `time_s` with covariance `cov`. A measurement
    /// older than the estimate (a detection that arrives after a laser update) is applied at the
    /// estimate's time: the lag is a fraction of a second, inside its uncertainty.
    pub(crate) fn update(&mut self, time_s: f64, position_m: [f64; 2], cov: &Matrix2<f64>) {
        self.predict(time_s);
        let h = Matrix2x4::new(
            1.0, 0.0, 0.0, 0.0, //
            0.0, 1.0, 0.0, 0.0,
        );
        let innovation = Vector2::new(position_m[0] - self.state[0], position_m[1] - self.state[1]);
        let s = h * self.covariance * h.transpose() + cov;
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let gain = self.covariance * h.transpose() * s_inv;
        self.state += gain * innovation;
        // Joseph form keeps the covariance symmetric and positive.
        let i_kh = Matrix4::identity() - gain * h;
        self.covariance = i_kh * self.covariance * i_kh.transpose() + gain * cov * gain.transpose();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Squared Mahalanobis distance of a position measurement from the estimate at the filter's
    /// time (call [`TargetFilter::predict`] first).
    fn mahalanobis2(f: &TargetFilter, position_m: [f64; 2], cov: &Matrix2<f64>) -> f64 {
        let innovation = Vector2::new(position_m[0] - f.state[0], position_m[1] - f.state[1]);
        let s = f.covariance.fixed_view::<2, 2>(0, 0) + cov;
        match s.try_inverse() {
            Some(inv) => (innovation.transpose() * inv * innovation)[(0, 0)],
            None => f64::INFINITY,
        }
    }

    #[test]
    fn a_target_walking_at_constant_speed_is_estimated_and_predicted() {
        let cov = Matrix2::identity() * 0.05f64.powi(2);
        let mut f = TargetFilter::new(0.0, [3.0, -2.0], cov);
        for i in 1..=40 {
            let t = f64::from(i) * 0.2;
            f.update(t, [3.0, -2.0 + 0.6 * t], &cov);
        }
        let [vx, vy] = f.velocity_mps();
        assert!(vx.abs() < 0.05, "{vx}");
        assert!((vy - 0.6).abs() < 0.05, "{vy}");
        let [x, y] = f.predicted_position_m(8.0 + 0.5, 1.0);
        assert!(
            (x - 3.0).abs() < 0.05 && (y - (-2.0 + 0.6 * 8.5)).abs() < 0.08,
            "{x} {y}"
        );
        // The prediction stops at the horizon.
        let far = f.predicted_position_m(100.0, 1.0);
        let near = f.predicted_position_m(9.0, 1.0);
        assert!((far[1] - near[1]).abs() < 1e-9);
    }

    #[test]
    fn a_standing_target_stays_put_and_the_gate_grows_with_time() {
        let cov = polar_covariance(0.0, 0.2, 0.05);
        let mut f = TargetFilter::new(0.0, [2.0, 0.0], cov);
        for i in 1..=20 {
            let t = f64::from(i) * 0.2;
            let wobble = if i % 2 == 0 { 0.15 } else { -0.15 };
            f.update(t, [2.0 + wobble, 0.0], &cov);
        }
        let [vx, vy] = f.velocity_mps();
        assert!(vx.abs() < 0.2 && vy.abs() < 0.05, "{vx} {vy}");
        let jump = [2.0, 1.5];
        let soon = mahalanobis2(&f, jump, &cov);
        f.predict(10.0);
        let later = mahalanobis2(&f, jump, &cov);
        assert!(later < soon, "{later} vs {soon}");
        assert!(f.position_sigma_m() > 0.5);
    }

    #[test]
    fn the_predicted_velocity_decays_and_a_halted_target_stands() {
        let cov = Matrix2::identity() * 0.05f64.powi(2);
        let mut f = TargetFilter::new(0.0, [0.0, 0.0], cov);
        for i in 1..=20 {
            let t = f64::from(i) * 0.2;
            f.update(t, [0.5 * t, 0.0], &cov);
        }
        let [vx, _] = f.velocity_mps();
        let [soon, _] = f.predicted_velocity_mps(4.5, 2.0);
        let [later, _] = f.predicted_velocity_mps(5.5, 2.0);
        assert!(
            vx > soon && soon > later && later > 0.0,
            "{vx} {soon} {later}"
        );
        assert_eq!(f.predicted_velocity_mps(6.5, 2.0), [0.0, 0.0]);
        let before = f.position_m();
        let sigma = f.position_sigma_m();
        f.halt(5.0);
        assert_eq!(f.position_m(), before);
        assert_eq!(f.velocity_mps(), [0.0, 0.0]);
        assert_eq!(f.predicted_position_m(9.0, 2.0), before);
        assert!(
            f.position_sigma_m() > sigma,
            "the position grows less certain"
        );
    }
}
