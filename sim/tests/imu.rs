//! The IMU on real physics: the tutorial car with an IMU on its base reads its turn rate,
//! gravity (+9.81 m/s^2 up at rest) and the world-frame yaw; its noise has the SDF's spread;
//! its readings follow the update rate and repeat with the seed; bad IMU blocks are located
//! errors.

use rover_sim::{
    model::{ImuPlugin, OrientationReference, RobotModel, World},
    physics::{SimOptions, Simulation, Twist},
    sensors::{ImuReading, ImuSensor},
};

mod common;

use common::{Result, assert_located_errors, car_with};

/// An IMU on base_link, published at `rate_hz`, with `noise` inside its `<imu>` element.
fn imu_block(rate_hz: f64, noise: &str) -> String {
    format!(
        r#"<gazebo reference="base_link">
    <sensor type="imu" name="imu_sensor">
      <update_rate>{rate_hz}</update_rate>
      <imu>{noise}</imu>
      <plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so">
        <topicName>imu</topicName>
        <frameName>base_link</frameName>
        <updateRateHZ>{rate_hz}</updateRateHZ>
        <initialOrientationAsReference>false</initialOrientationAsReference>
      </plugin>
    </sensor>
  </gazebo>"#
    )
}

fn sim(robot: RobotModel, seed: u64) -> Result<Simulation> {
    Ok(Simulation::new(
        World::flat()?,
        robot,
        &SimOptions {
            seed,
            ..SimOptions::default()
        },
    )?)
}

/// Steps `sim` for `seconds`, feeding the IMU every step; returns each reading with the
/// ground truth's yaw and turn rate at that step.
fn run(sim: &mut Simulation, imu: &mut ImuSensor, seconds: f64) -> Vec<(ImuReading, f64, f64)> {
    let end = sim.sim_time_s() + seconds;
    let mut out = Vec::new();
    while sim.sim_time_s() < end - sim.dt_s() / 2.0 {
        sim.step();
        if let Some(r) = imu.update(sim) {
            let truth = sim.ground_truth();
            out.push((*r, truth.yaw_rad, truth.angular_radps));
        }
    }
    out
}

/// At rest on a world solved to convergence (`[physics] solver_iterations = 50`): every one of
/// 1,000 readings over 10 s within 9.81 +- 0.02 m/s^2 on z (the default 4 iterations leave the
/// bursts of the test above).
#[test]
fn at_rest_on_a_converged_solver_every_reading_is_gravity_within_0_02() -> Result<()> {
    let robot = car_with(&imu_block(100.0, ""))?;
    let mut world = World::flat()?;
    world.physics.solver_iterations = 50;
    let mut sim = Simulation::new(world, robot, &SimOptions::default())?;
    let mut imu = ImuSensor::new(&sim, 0).ok_or("no IMU")?;
    run(&mut sim, &mut imu, 2.0);
    let rest = run(&mut sim, &mut imu, 10.0);
    assert_eq!(rest.len(), 1000);
    let worst = rest
        .iter()
        .map(|r| (r.0.linear_acceleration_mps2[2] - 9.81).abs())
        .fold(0.0, f64::max);
    println!("at rest, 50 solver iterations: worst z {worst:.4} m/s^2 off 9.81 in 1000 readings");
    assert!(
        worst <= 0.02,
        "at rest: a reading {worst} m/s^2 off gravity"
    );
    Ok(())
}

/// Yaw of a quaternion (x, y, z, w), ZYX.
fn yaw_of([x, y, z, w]: [f64; 4]) -> f64 {
    (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

#[test]
fn a_car_at_rest_then_spinning_reads_gravity_its_turn_rate_and_the_world_yaw() -> Result<()> {
    let robot = car_with(&imu_block(100.0, ""))?;
    assert_eq!(robot.imus.len(), 1);
    assert_eq!(robot.imus[0].reference, OrientationReference::World);
    let mut sim = sim(robot, 1)?;
    let mut imu = ImuSensor::new(&sim, 0).ok_or("no IMU")?;
    run(&mut sim, &mut imu, 2.0); // settle on the wheels and the caster
    let rest = run(&mut sim, &mut imu, 1.0);
    assert_eq!(rest.len(), 100, "100 Hz for 1 s of sim time");
    // With the default 4 solver iterations rapier leaves the resting car a little stick-slip
    // on its contacts, about every 0.5 s: a 50 ms burst of up to ~0.06 m/s^2 the IMU reads as
    // it would a vibrating mount. Between bursts it reads gravity to 0.002 m/s^2. (A world
    // with more iterations reads every sample within 0.02: the next test.)
    let z: Vec<f64> = rest
        .iter()
        .map(|r| r.0.linear_acceleration_mps2[2])
        .collect();
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    let within = z.iter().filter(|a| (*a - 9.81).abs() <= 0.02).count();
    let worst = z.iter().map(|a| (a - 9.81).abs()).fold(0.0, f64::max);
    println!("at rest: mean z {mean:.4} m/s^2, {within}/100 within 0.02, worst {worst:.4}");
    assert!((mean - 9.81).abs() <= 0.005, "at rest: mean z {mean} m/s^2");
    assert!(
        within >= 85,
        "at rest: {within} of 100 readings within 9.81 +- 0.02"
    );
    assert!(worst <= 0.1, "at rest: z off by {worst} m/s^2");
    for (r, _, _) in &rest {
        let [ax, ay, _] = r.linear_acceleration_mps2;
        // The car rests a little nose-down on its caster: gravity, seen in the tilted sensor's
        // axes, is what x and y read, to the contacts' bursts.
        let [x, y, z, w] = r.orientation_xyzw;
        let up = glam::DQuat::from_xyzw(x, y, z, w).inverse() * glam::DVec3::new(0.0, 0.0, 9.81);
        assert!(
            (ax - up.x).abs() < 0.1 && (ay - up.y).abs() < 0.1,
            "at rest: x {ax}, y {ay}; gravity in the sensor's axes {up}"
        );
        assert!(r.angular_velocity_radps.iter().all(|w| w.abs() < 0.01));
    }

    sim.set_cmd_vel(Twist {
        linear_mps: 0.0,
        angular_radps: 1.0,
    })?;
    run(&mut sim, &mut imu, 2.0); // the wheels ramp up
    let spin = run(&mut sim, &mut imu, 3.0);
    for (r, truth_yaw, truth_rate) in &spin {
        let wz = r.angular_velocity_radps[2];
        assert!(
            (wz - truth_rate).abs() <= 0.01,
            "angular_velocity.z {wz} against the true rate {truth_rate}"
        );
        let dyaw = wrap(yaw_of(r.orientation_xyzw) - truth_yaw);
        assert!(
            dyaw.abs() <= 0.005,
            "yaw off the world odometry's by {dyaw} rad"
        );
    }
    assert_eq!(spin.len(), 300);
    // Commanded 1 rad/s, the car turns at about that, its wheels slipping on and off (the true
    // rate swings between ~0.9 and ~1.08 rad/s; the IMU follows it, above).
    let mean_rate = spin.iter().map(|r| r.2).sum::<f64>() / spin.len() as f64;
    assert!(
        (0.85..1.05).contains(&mean_rate),
        "mean turn rate {mean_rate}"
    );
    // The skidding turn shakes the car (single readings off by up to ~0.3 m/s^2); on average
    // it still reads gravity.
    let mean_z = spin
        .iter()
        .map(|r| r.0.linear_acceleration_mps2[2])
        .sum::<f64>()
        / spin.len() as f64;
    assert!((mean_z - 9.81).abs() <= 0.01, "spinning: mean z {mean_z}");
    Ok(())
}

#[test]
fn the_noise_has_the_sdf_spread_and_a_fixed_bias() -> Result<()> {
    let axis = |stddev: f64, bias: f64| {
        format!(
            "<noise type=\"gaussian\"><mean>0</mean><stddev>{stddev}</stddev>\
             <bias_mean>{bias}</bias_mean><bias_stddev>0</bias_stddev></noise>"
        )
    };
    let rate = axis(0.05, 0.01);
    let accel = axis(0.3, 0.2);
    let noise = format!(
        "<angular_velocity><x>{rate}</x><y>{rate}</y><z>{rate}</z></angular_velocity>\
         <linear_acceleration><x>{accel}</x><y>{accel}</y><z>{accel}</z></linear_acceleration>"
    );
    let robot = car_with(&imu_block(0.0, &noise))?;
    let c = &robot.imus[0];
    assert_eq!(c.angular_velocity_noise[2].stddev, 0.05);
    assert_eq!(c.linear_acceleration_noise[0].bias_mean, 0.2);
    let mut sim = sim(robot, 7)?;
    let mut imu = ImuSensor::new(&sim, 0).ok_or("no IMU")?;
    run(&mut sim, &mut imu, 1.0);
    let readings = run(&mut sim, &mut imu, 5.0);
    assert_eq!(readings.len(), 1000, "rate 0: every 200 Hz step");
    let stats = |values: Vec<f64>| {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, var.sqrt())
    };
    for i in 0..3 {
        let (mean, sd) = stats(
            readings
                .iter()
                .map(|r| r.0.angular_velocity_radps[i])
                .collect(),
        );
        assert!(
            (sd / 0.05 - 1.0).abs() < 0.1,
            "gyro axis {i}: stddev {sd}, SDF 0.05"
        );
        assert!(
            (mean.abs() - 0.01).abs() < 0.006,
            "gyro axis {i}: bias {mean}, SDF +-0.01"
        );
        let truth = [0.0, 0.0, 9.81][i];
        let (mean, sd) = stats(
            readings
                .iter()
                .map(|r| r.0.linear_acceleration_mps2[i])
                .collect(),
        );
        assert!(
            (sd / 0.3 - 1.0).abs() < 0.1,
            "accel axis {i}: stddev {sd}, SDF 0.3"
        );
        let bias = mean - truth;
        assert!(
            (bias.abs() - 0.2).abs() < 0.04,
            "accel axis {i}: bias {bias}, SDF +-0.2"
        );
    }
    Ok(())
}

#[test]
fn readings_repeat_with_the_seed_and_differ_with_another() -> Result<()> {
    let noise = "<noise><type>gaussian</type><rate><stddev>0.01</stddev></rate>\
                 <accel><stddev>0.1</stddev><bias_mean>0.1</bias_mean></accel></noise>";
    let readings = |seed| -> Result<Vec<ImuReading>> {
        let mut s = sim(car_with(&imu_block(50.0, noise))?, seed)?;
        let mut imu = ImuSensor::new(&s, 0).ok_or("no IMU")?;
        s.set_cmd_vel(Twist {
            linear_mps: 0.3,
            angular_radps: 0.5,
        })?;
        Ok(run(&mut s, &mut imu, 2.0)
            .into_iter()
            .map(|r| r.0)
            .collect())
    };
    let (a, b, c) = (readings(3)?, readings(3)?, readings(4)?);
    // The first at the first step, then every 0.02 s to 2 s.
    assert_eq!(a.len(), 101, "50 Hz for 2 s");
    for pair in a[1..].windows(2) {
        assert!((pair[1].stamp_s - pair[0].stamp_s - 0.02).abs() < 1e-9);
    }
    assert_eq!(a, b);
    assert_ne!(a, c);
    Ok(())
}

#[test]
fn turtlebot3s_model_plugin_and_bad_blocks() -> Result<()> {
    // The model plugin TurtleBot3's URDF uses: its link by <bodyName>, every step, /imu.
    let robot = car_with(
        r#"<gazebo>
    <plugin name="imu_plugin" filename="libgazebo_ros_imu.so">
      <bodyName>base_link</bodyName>
      <topicName>imu</topicName>
      <updateRate>0</updateRate>
    </plugin>
  </gazebo>"#,
    )?;
    let c = &robot.imus[0];
    assert_eq!(c.plugin, ImuPlugin::Model);
    assert_eq!(
        (c.topic.as_str(), c.frame_name.as_str()),
        ("imu", "base_link")
    );
    assert_eq!(c.reference, OrientationReference::World);
    assert!(!robot.not_simulated.iter().any(|s| s.contains("imu")));

    // A sensor without a ROS plugin publishes nothing: listed, not simulated.
    let quiet =
        car_with(r#"<gazebo reference="base_link"><sensor type="imu" name="quiet"/></gazebo>"#)?;
    assert!(quiet.imus.is_empty());
    assert!(quiet.not_simulated.iter().any(|s| s.contains("\"quiet\"")));

    assert_located_errors([
        (
            r#"<gazebo><plugin name="i" filename="libgazebo_ros_imu.so"><topicName>imu</topicName></plugin></gazebo>"#,
            "missing <bodyName>",
        ),
        (
            r#"<gazebo><plugin name="i" filename="libgazebo_ros_imu.so"><bodyName>nowhere</bodyName></plugin></gazebo>"#,
            "\"nowhere\": no such link",
        ),
        (
            r#"<gazebo reference="base_link"><sensor type="imu" name="s"><plugin name="p" filename="libgazebo_ros_imu_sensor.so"><topicName>imu</topicName></plugin></sensor></gazebo>"#,
            "missing <frameName>",
        ),
        (
            r#"<gazebo reference="base_link"><sensor type="imu" name="s"><plugin name="p" filename="libgazebo_ros_imu_sensor.so"><frameName>f</frameName><rpyOffset>0 0</rpyOffset></plugin></sensor></gazebo>"#,
            "<rpyOffset>",
        ),
        (
            r#"<gazebo reference="base_link"><sensor type="imu" name="s"><imu><noise><type>gaussian</type><rate><stddev>lots</stddev></rate></noise></imu></sensor></gazebo>"#,
            "<stddev>",
        ),
    ])
}
