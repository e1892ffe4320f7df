//! The differential-drive controller, with gazebo_ros_diff_drive's semantics, and odometry.

use crate::error::{Result, SimError};
use crate::model::drive::DiffDriveConfig;

/// A velocity command, the part of `geometry_msgs/Twist` a diff drive uses.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Twist {
    /// `linear.x`: forward speed (m/s).
    pub linear_mps: f64,
    /// `angular.z`: yaw rate, counter-clockwise positive (rad/s).
    pub angular_radps: f64,
}

impl Twist {
    /// A command of `linear_mps` forward and `angular_radps` yaw rate.
    pub const fn new(linear_mps: f64, angular_radps: f64) -> Self {
        Self {
            linear_mps,
            angular_radps,
        }
    }

    /// Standing still.
    pub const ZERO: Self = Self::new(0.0, 0.0);

    /// True when both components are finite.
    pub fn is_finite(&self) -> bool {
        self.linear_mps.is_finite() && self.angular_radps.is_finite()
    }
}

/// A planar pose and velocity, as nav_msgs/Odometry carries for a ground robot.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Odometry {
    /// Position x (m).
    pub x_m: f64,
    /// Position y (m).
    pub y_m: f64,
    /// Heading (rad, in (-pi, pi]).
    pub yaw_rad: f64,
    /// Forward speed in the base frame (m/s).
    pub linear_mps: f64,
    /// Yaw rate (rad/s).
    pub angular_radps: f64,
}

/// Pose covariance diagonal gazebo_ros_diff_drive publishes (x, y, z, roll, pitch, yaw).
pub const ODOM_POSE_COVARIANCE_DIAGONAL: [f64; 6] = [1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3];

/// Left/right wheel joint speeds (rad/s), positive rolling forward.
pub type WheelSpeeds = [f64; 2];

/// Index of the left wheel in [`WheelSpeeds`].
pub const LEFT: usize = 0;
/// Index of the right wheel in [`WheelSpeeds`].
pub const RIGHT: usize = 1;

/// gazebo_ros_diff_drive's control loop: takes cmd_vel, and on its `updateRate` schedule (sim
/// time, accumulated as `next += period`) turns it into wheel joint speed targets, ramped by
/// `wheelAcceleration`.
#[derive(Debug, Clone)]
pub struct DiffDriveController {
    config: DiffDriveConfig,
    period_s: f64,
    next_update_s: f64,
    last_update_s: Option<f64>,
    cmd: Twist,
    cmd_stamp_s: f64,
    timed_out: bool,
    wheel_cmd_radps: WheelSpeeds,
    /// gz-sim's limiter state: the body command of the last two updates (newest first).
    limited: [Twist; 2],
    /// The physics step (s): the first update's time step when the loop runs every step.
    step_s: f64,
}

impl DiffDriveController {
    /// A controller at rest; the first update happens at sim time 0.
    pub fn new(config: DiffDriveConfig) -> Self {
        let period_s = if config.update_rate_hz > 0.0 {
            1.0 / config.update_rate_hz
        } else {
            0.0
        };
        Self {
            config,
            period_s,
            next_update_s: 0.0,
            last_update_s: None,
            cmd: Twist::ZERO,
            cmd_stamp_s: 0.0,
            timed_out: false,
            wheel_cmd_radps: [0.0; 2],
            limited: [Twist::ZERO; 2],
            step_s: 0.0,
        }
    }

    /// The controller for a simulation stepping every `step_s` seconds (a loop that runs every
    /// step limits its first update over one step, as gz-sim's does).
    pub fn with_step(mut self, step_s: f64) -> Self {
        self.step_s = step_s;
        self
    }

    /// The plugin configuration.
    pub fn config(&self) -> &DiffDriveConfig {
        &self.config
    }

    /// Accepts a new cmd_vel at sim time `now_s`. Non-finite commands are rejected (the last
    /// valid one stays in force) and reported as an error.
    pub fn set_command(&mut self, cmd: Twist, now_s: f64) -> Result<()> {
        if !cmd.is_finite() {
            tracing::warn!(
                "rejected cmd_vel ({}, {}): not finite; keeping ({}, {})",
                cmd.linear_mps,
                cmd.angular_radps,
                self.cmd.linear_mps,
                self.cmd.angular_radps
            );
            return Err(SimError::NonFiniteCommand {
                linear_mps: cmd.linear_mps,
                angular_radps: cmd.angular_radps,
            });
        }
        self.cmd = cmd;
        self.cmd_stamp_s = now_s;
        self.timed_out = false;
        Ok(())
    }

    /// The command in force (zero after a command timeout).
    pub fn command(&self) -> Twist {
        if self.timed_out {
            Twist::ZERO
        } else {
            self.cmd
        }
    }

    /// True when the opt-in command timeout has stopped the robot.
    pub fn timed_out(&self) -> bool {
        self.timed_out
    }

    /// The wheel joint speed targets currently sent to the motors (rad/s).
    pub fn wheel_targets_radps(&self) -> WheelSpeeds {
        self.wheel_cmd_radps
    }

    /// Wheel joint speeds (rad/s) that realise `cmd` exactly:
    /// `v_left = v - w*sep/2`, `v_right = v + w*sep/2`, joint speed = rim speed / radius.
    pub fn wheel_speeds_for(&self, cmd: Twist) -> WheelSpeeds {
        let half_sep = self.config.wheel_separation_m / 2.0;
        let radius = self.config.wheel_diameter_m / 2.0;
        [
            (cmd.linear_mps - cmd.angular_radps * half_sep) / radius,
            (cmd.linear_mps + cmd.angular_radps * half_sep) / radius,
        ]
    }

    /// Runs the control loop at sim time `now_s` (call once per physics step, before stepping).
    /// Returns true when a control update happened, i.e. the wheel targets were recomputed.
    pub fn update(&mut self, now_s: f64) -> bool {
        if let Some(timeout) = self.config.cmd_timeout_s
            && !self.timed_out
            && now_s - self.cmd_stamp_s > timeout
        {
            tracing::warn!(
                "no cmd_vel for {timeout} s (cmd_timeout_s): stopping the robot until the next command"
            );
            self.timed_out = true;
        }
        // Tolerance against floating-point drift of the accumulated schedule.
        if now_s + 1e-9 < self.next_update_s {
            return false;
        }
        let dt = self
            .last_update_s
            .map_or(self.period_s.max(self.step_s), |last| now_s - last);
        self.last_update_s = Some(now_s);
        self.next_update_s += self.period_s;
        if self.next_update_s + 1e-9 < now_s {
            // Far behind (e.g. an update rate above the physics rate): resynchronise.
            self.next_update_s = now_s + self.period_s;
        }

        if self.config.linear_limits.is_some() || self.config.angular_limits.is_some() {
            // gz-sim's DiffDrive limits the body's speeds, then sets the wheels exactly.
            let cmd = self.command();
            let [v0, v1] = self.limited;
            let limit = |l: Option<crate::model::SpeedLimits>, v: f64, a: f64, b: f64| {
                l.map_or(v, |l| l.limit(v, a, b, dt))
            };
            let body = Twist::new(
                limit(
                    self.config.linear_limits,
                    cmd.linear_mps,
                    v0.linear_mps,
                    v1.linear_mps,
                ),
                limit(
                    self.config.angular_limits,
                    cmd.angular_radps,
                    v0.angular_radps,
                    v1.angular_radps,
                ),
            );
            self.limited = [body, v0];
            self.wheel_cmd_radps = self.wheel_speeds_for(body);
            return true;
        }
        let target = self.wheel_speeds_for(self.command());
        // gazebo_ros_diff_drive ramps the rim speed (m/s) by wheelAcceleration * dt.
        let radius_m = self.config.wheel_diameter_m / 2.0;
        let max_delta = self.config.wheel_acceleration_mps2 / radius_m * dt;
        for (cmd, goal) in self.wheel_cmd_radps.iter_mut().zip(target) {
            *cmd = if self.config.wheel_acceleration_mps2 > 0.0 {
                *cmd + (goal - *cmd).clamp(-max_delta, max_delta)
            } else {
                goal
            };
        }
        true
    }
}

/// Encoder odometry: integrates measured wheel joint speeds (so wheel slip shows up as drift),
/// heading integrated at the midpoint like gazebo_ros_diff_drive.
#[derive(Debug, Clone, Copy)]
pub struct EncoderOdometry {
    pose: Odometry,
    wheel_separation_m: f64,
    wheel_radius_m: f64,
}

impl EncoderOdometry {
    /// Starts at `start` (the spawn pose, so the odom frame coincides with the world at t = 0).
    pub fn new(start: Odometry, config: &DiffDriveConfig) -> Self {
        Self {
            pose: start,
            wheel_separation_m: config.wheel_separation_m,
            wheel_radius_m: config.wheel_diameter_m / 2.0,
        }
    }

    /// Integrates `wheel_radps` (measured left/right joint speeds) over `dt_s`.
    pub fn integrate(&mut self, wheel_radps: WheelSpeeds, dt_s: f64) {
        let sl = wheel_radps[LEFT] * self.wheel_radius_m * dt_s;
        let sr = wheel_radps[RIGHT] * self.wheel_radius_m * dt_s;
        let ds = (sl + sr) / 2.0;
        let dtheta = (sr - sl) / self.wheel_separation_m;
        let mid = self.pose.yaw_rad + dtheta / 2.0;
        self.pose.x_m += ds * mid.cos();
        self.pose.y_m += ds * mid.sin();
        self.pose.yaw_rad = wrap_angle(self.pose.yaw_rad + dtheta);
        if dt_s > 0.0 {
            self.pose.linear_mps = ds / dt_s;
            self.pose.angular_radps = dtheta / dt_s;
        }
    }

    /// The integrated pose and velocity.
    pub fn odometry(&self) -> Odometry {
        self.pose
    }
}

/// Wraps an angle into (-pi, pi].
pub fn wrap_angle(a: f64) -> f64 {
    let wrapped = a.rem_euclid(std::f64::consts::TAU);
    if wrapped > std::f64::consts::PI {
        wrapped - std::f64::consts::TAU
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(accel: f64) -> DiffDriveConfig {
        DiffDriveConfig {
            wheel_separation_m: 0.3,
            wheel_diameter_m: 0.1,
            wheel_acceleration_mps2: accel * 0.05,
            ..DiffDriveConfig::default()
        }
    }

    #[test]
    fn wheel_speed_formula() {
        let c = DiffDriveController::new(config(0.0));
        let [l, r] = c.wheel_speeds_for(Twist::new(0.5, 1.0));
        assert!((l - (0.5 - 0.15) / 0.05).abs() < 1e-12);
        assert!((r - (0.5 + 0.15) / 0.05).abs() < 1e-12);
    }

    #[test]
    fn updates_follow_the_update_rate_on_sim_time() {
        let mut c = DiffDriveController::new(config(0.0));
        let dt = 0.002;
        let updates = (0..500).filter(|i| c.update(f64::from(*i) * dt)).count();
        assert_eq!(updates, 100, "100 Hz over 1 s of 500 Hz steps");
    }

    #[test]
    fn ramp_limits_wheel_speed_change() -> Result<()> {
        let mut c = DiffDriveController::new(config(20.0));
        c.set_command(Twist::new(0.5, 0.0), 0.0)?;
        let mut prev = c.wheel_targets_radps();
        for i in 0..100 {
            if c.update(f64::from(i) * 0.01) {
                let now = c.wheel_targets_radps();
                for w in 0..2 {
                    assert!((now[w] - prev[w]).abs() <= 20.0 * 0.01 + 1e-9);
                }
                prev = now;
            }
        }
        assert!(
            (prev[0] - 10.0).abs() < 1e-9,
            "reaches 0.5 m/s / 0.05 m = 10 rad/s"
        );
        Ok(())
    }

    #[test]
    fn non_finite_commands_keep_the_last_valid_one() -> Result<()> {
        let mut c = DiffDriveController::new(config(0.0));
        c.set_command(Twist::new(0.3, 0.1), 0.0)?;
        assert!(c.set_command(Twist::new(f64::NAN, 0.0), 0.1).is_err());
        assert!(c.set_command(Twist::new(0.0, f64::INFINITY), 0.1).is_err());
        assert_eq!(c.command(), Twist::new(0.3, 0.1));
        Ok(())
    }

    #[test]
    fn command_timeout_is_opt_in() -> Result<()> {
        let mut c = DiffDriveController::new(config(0.0));
        c.set_command(Twist::new(0.3, 0.0), 0.0)?;
        c.update(100.0);
        assert_eq!(
            c.command(),
            Twist::new(0.3, 0.0),
            "Gazebo: no timeout by default"
        );

        let mut c = DiffDriveController::new(DiffDriveConfig {
            cmd_timeout_s: Some(0.5),
            ..config(0.0)
        });
        c.set_command(Twist::new(0.3, 0.0), 0.0)?;
        c.update(0.4);
        assert_eq!(c.command(), Twist::new(0.3, 0.0));
        c.update(0.6);
        assert!(c.timed_out());
        assert_eq!(c.wheel_targets_radps(), [0.0, 0.0]);
        c.set_command(Twist::new(0.1, 0.0), 0.7)?;
        assert!(!c.timed_out());
        Ok(())
    }

    #[test]
    fn encoder_odometry_integrates_arcs() {
        let mut odo = EncoderOdometry::new(Odometry::default(), &config(0.0));
        // Turn in place at 1 rad/s for pi seconds: right wheel forward, left backward.
        let w = 0.15 / 0.05;
        for _ in 0..1000 {
            odo.integrate([-w, w], std::f64::consts::PI / 1000.0);
        }
        let o = odo.odometry();
        assert!((o.yaw_rad.abs() - std::f64::consts::PI).abs() < 1e-6);
        assert!(o.x_m.abs() < 1e-9 && o.y_m.abs() < 1e-9);
    }

    #[test]
    fn wrap_angle_range() {
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-12);
    }
}
