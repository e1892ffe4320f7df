//! Physics and diff-drive behaviour of the tutorial car on real rapier physics.

use anyhow::Result;
use rover_sim::{
    model::World,
    physics::{SimOptions, Simulation, Twist},
};
use rover_tests::{drive, flat_sim, my_robot, my_robot_with_plugin_param};

#[test]
fn straight_line_half_a_metre_per_second_for_four_seconds() -> Result<()> {
    let mut sim = flat_sim(my_robot()?)?;
    drive(&mut sim, Twist::new(0.5, 0.0), 4.0)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let g = sim.ground_truth();
    assert!(
        (g.x_m - 2.0).abs() <= 0.05 * 2.0,
        "x {} m, expected 2.0 m within 5%",
        g.x_m
    );
    assert!(g.y_m.abs() < 0.05, "y {} m, expected |y| < 0.05 m", g.y_m);
    Ok(())
}

#[test]
fn turn_in_place_half_a_turn() -> Result<()> {
    let mut sim = flat_sim(my_robot()?)?;
    let (error_deg, g) = rover_tests::half_turn_error_deg(&mut sim)?;
    assert!(
        error_deg < 5.0,
        "yaw {} deg, expected 180 within 5",
        g.yaw_rad.to_degrees()
    );
    let drift = g.x_m.hypot(g.y_m);
    assert!(drift < 0.05, "drifted {drift} m while turning in place");
    Ok(())
}

#[test]
fn wheel_acceleration_ramp_is_honoured() -> Result<()> {
    // wheelAcceleration ramps the rim speed (m/s^2), like gazebo_ros_diff_drive: 0.25 m/s^2 on
    // 0.05 m wheels is 5 rad/s^2 on the joints.
    let accel_radps2 = 5.0;
    let robot = my_robot_with_plugin_param("wheelAcceleration", "0.25")?;
    let mut sim = flat_sim(robot)?;
    let samples = drive(&mut sim, Twist::new(0.5, 0.0), 3.0)?;
    let target = 0.5 / 0.05;
    let mut reached_at = None;
    for pair in samples.windows(2) {
        let dt = pair[1].sim_time_s - pair[0].sim_time_s;
        for w in 0..2 {
            let commanded = pair[1].wheel_targets_radps[w] - pair[0].wheel_targets_radps[w];
            assert!(
                commanded.abs() <= accel_radps2 * dt + 1e-9,
                "commanded wheel speed jumped {commanded} rad/s in {dt} s at {} s",
                pair[1].sim_time_s
            );
            // The wheels themselves follow the ramp (small slack for contact transients).
            let measured = pair[1].wheel_measured_radps[w] - pair[0].wheel_measured_radps[w];
            assert!(
                measured.abs() <= accel_radps2 * dt + 0.3,
                "measured wheel speed jumped {measured} rad/s in {dt} s at {} s",
                pair[1].sim_time_s
            );
        }
        if reached_at.is_none() && (pair[1].wheel_targets_radps[0] - target).abs() < 1e-9 {
            reached_at = Some(pair[1].sim_time_s);
        }
    }
    let reached_at = reached_at.unwrap_or(f64::INFINITY);
    let expected = target / accel_radps2;
    assert!(
        (reached_at - expected).abs() < 0.03,
        "reached {target} rad/s at {reached_at} s, expected {expected} s"
    );
    let last = samples
        .last()
        .map(|s| s.wheel_measured_radps[0])
        .unwrap_or_default();
    assert!(
        (last - target).abs() < 0.3,
        "wheels settle at the target, got {last}"
    );
    Ok(())
}

#[test]
fn encoder_odometry_matches_ground_truth_on_a_straight_run() -> Result<()> {
    let robot = my_robot_with_plugin_param("odometrySource", "encoder")?;
    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::new(0.5, 0.0), 4.0)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let truth = sim.ground_truth();
    let odom = sim.odometry();
    assert_eq!(
        odom,
        sim.encoder_odometry(),
        "odometrySource encoder selects the encoder"
    );
    let travelled = truth.x_m.hypot(truth.y_m);
    let error = (odom.x_m - truth.x_m).hypot(odom.y_m - truth.y_m);
    assert!(
        error <= 0.02 * travelled,
        "encoder odometry off by {error} m over {travelled} m (> 2%)"
    );
    Ok(())
}

#[test]
fn the_robot_stops_at_a_wall_instead_of_passing_through() -> Result<()> {
    let text =
        "[[wall]]\nfrom_m = [1.5, -2.0]\nto_m = [1.5, 2.0]\nthickness_m = 0.1\nheight_m = 0.5\n";
    let world = World::from_str(text, std::path::Path::new("wall.toml"))?;
    let mut sim = Simulation::new(world, my_robot()?, &SimOptions::default())?;
    let samples = drive(&mut sim, Twist::new(0.5, 0.0), 8.0)?;
    // Front of the chassis is 0.15 m ahead of base_link; the wall's near face is at x = 1.45.
    let max_x = samples
        .iter()
        .map(|s| s.ground_truth.x_m)
        .fold(f64::MIN, f64::max);
    assert!(
        max_x < 1.45 - 0.15 + 0.02,
        "base reached x = {max_x} m: through the wall"
    );
    assert!(
        max_x > 1.45 - 0.15 - 0.05,
        "stopped short at x = {max_x} m without touching"
    );
    let pose = sim.world_from_base();
    assert!(pose.translation.z.abs() < 0.2, "robot stays on the ground");
    Ok(())
}

#[test]
fn non_finite_commands_are_rejected_and_the_last_one_kept() -> Result<()> {
    let mut sim = flat_sim(my_robot()?)?;
    sim.set_cmd_vel(Twist::new(0.3, 0.0))?;
    let err = sim.set_cmd_vel(Twist::new(f64::NAN, 0.0));
    assert!(err.is_err());
    let samples = drive(&mut sim, Twist::new(0.3, 0.0), 0.5)?;
    assert!(samples.iter().all(|s| s.cmd == Twist::new(0.3, 0.0)));
    Ok(())
}

#[test]
fn command_timeout_stops_a_runaway_robot() -> Result<()> {
    let options = SimOptions {
        cmd_timeout_s: Some(0.5),
        ..SimOptions::default()
    };
    let mut sim = Simulation::new(World::flat()?, my_robot()?, &options)?;
    let samples = drive(&mut sim, Twist::new(0.5, 0.0), 3.0)?;
    let x_at = |t: f64| {
        samples
            .iter()
            .find(|s| s.sim_time_s >= t)
            .map(|s| s.ground_truth.x_m)
            .unwrap_or_default()
    };
    assert!(
        samples.iter().any(|s| s.cmd == Twist::ZERO),
        "timeout zeroes the command"
    );
    assert!(
        (x_at(2.9) - x_at(2.0)).abs() < 0.01,
        "robot is stopped after the timeout"
    );
    assert!(
        x_at(2.9) < 0.5,
        "it stopped soon after 0.5 s, at x = {}",
        x_at(2.9)
    );
    Ok(())
}
