//! p3d (`libgazebo_ros_p3d.so`) on real physics: the tutorial car's ground-truth pose and
//! velocity in the world and against another of its links, its offsets, rate and noise, and
//! located errors for bad plugin blocks.

use rover_sim::{
    model::{RobotModel, World},
    physics::{SimOptions, Simulation, Twist},
    sensors::P3dSensor,
};

mod common;

use common::{Result, assert_located_errors, car_with};

fn p3d(params: &str) -> String {
    format!(
        r#"<gazebo><plugin name="ground_truth" filename="libgazebo_ros_p3d.so">
      <bodyName>base_link</bodyName><topicName>ground_truth/state</topicName>{params}
    </plugin></gazebo>"#
    )
}

fn sim(robot: RobotModel) -> Result<Simulation> {
    Ok(Simulation::new(
        World::flat()?,
        robot,
        &SimOptions {
            seed: 5,
            ..SimOptions::default()
        },
    )?)
}

#[test]
fn a_driving_car_reports_its_world_pose_and_velocity_exactly() -> Result<()> {
    let robot = car_with(&p3d(
        "<updateRate>50</updateRate><xyzOffsets>1 2 3</xyzOffsets>",
    ))?;
    let c = &robot.p3ds[0];
    assert_eq!(
        (
            c.topic.as_str(),
            c.frame_name.as_str(),
            c.reference_link.as_ref()
        ),
        ("ground_truth/state", "world", None)
    );
    let mut sim = sim(robot)?;
    let mut p3d = P3dSensor::new(&sim, 0).ok_or("no p3d")?;
    sim.set_cmd_vel(Twist::new(0.3, 0.4))?;
    let base = sim.robot().root;
    let mut n = 0;
    let mut last_stamp: Option<f64> = None;
    while sim.sim_time_s() < 4.0 - 1e-9 {
        sim.step();
        let Some(r) = p3d.update(&sim) else { continue };
        n += 1;
        let truth = sim.link_point_state(base, rover_sim::geometry::Pose::IDENTITY);
        let p = truth.pose.translation.as_dvec3() + glam::DVec3::new(1.0, 2.0, 3.0);
        for i in 0..3 {
            assert!(
                (r.position_m[i] - p[i]).abs() < 1e-9,
                "{:?} vs {p}",
                r.position_m
            );
            assert!((r.linear_mps[i] - f64::from(truth.linear_mps[i])).abs() < 1e-9);
            assert!((r.angular_radps[i] - f64::from(truth.angular_radps[i])).abs() < 1e-9);
        }
        let q = truth.pose.rotation.as_dquat();
        assert!(glam::DQuat::from_array(r.orientation_xyzw).dot(q).abs() > 1.0 - 1e-6);
        // The first at the first step, then every 0.02 s.
        if let Some(before) = last_stamp.filter(|_| n > 2) {
            assert!((r.stamp_s - before - 0.02_f64).abs() < 1e-9, "50 Hz");
        }
        last_stamp = Some(r.stamp_s);
    }
    assert_eq!(n, 201, "50 Hz for 4 s, and the first step's");
    // It drove: the pose is not the spawn's.
    assert!(
        p3d.last().position_m[0] > 1.2,
        "{:?}",
        p3d.last().position_m
    );
    Ok(())
}

#[test]
fn against_another_link_and_with_noise_on_the_velocities() -> Result<()> {
    // The base seen from the camera link (fixed 0.15 m ahead, 0.1 m up): a constant pose, zero
    // velocity, whatever the car does.
    let robot = car_with(&p3d(
        "<frameName>camera_link</frameName><gaussianNoise>0.1</gaussianNoise>",
    ))?;
    assert_eq!(robot.p3ds[0].reference_link.as_deref(), Some("camera_link"));
    let mut sim = sim(robot)?;
    let mut p3d = P3dSensor::new(&sim, 0).ok_or("no p3d")?;
    sim.set_cmd_vel(Twist::new(0.2, -0.5))?;
    let mut vx = Vec::new();
    while sim.sim_time_s() < 5.0 - 1e-9 {
        sim.step();
        let Some(r) = p3d.update(&sim) else { continue };
        let [x, y, z] = r.position_m;
        assert!(
            (x + 0.15).abs() < 1e-5 && y.abs() < 1e-5 && (z + 0.1).abs() < 1e-5,
            "base from camera {:?}",
            r.position_m
        );
        assert!((r.covariance_diagonal - 0.01).abs() < 1e-15);
        vx.push(r.linear_mps[0]);
    }
    assert_eq!(vx.len(), 1000, "every 200 Hz step");
    let mean = vx.iter().sum::<f64>() / vx.len() as f64;
    let sd = (vx.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (vx.len() - 1) as f64).sqrt();
    assert!(mean.abs() < 0.02, "relative velocity mean {mean}");
    assert!(
        (sd / 0.1 - 1.0).abs() < 0.1,
        "velocity noise stddev {sd}, gaussianNoise 0.1"
    );
    Ok(())
}

#[test]
fn bad_p3d_blocks_are_located_errors() -> Result<()> {
    assert_located_errors([
        (
            r#"<gazebo><plugin name="g" filename="libgazebo_ros_p3d.so"><topicName>t</topicName></plugin></gazebo>"#,
            "missing <bodyName>",
        ),
        (
            r#"<gazebo><plugin name="g" filename="libgazebo_ros_p3d.so"><bodyName>base_link</bodyName></plugin></gazebo>"#,
            "missing <topicName>",
        ),
        (
            &p3d("<frameName>nowhere</frameName>"),
            "<frameName> \"nowhere\": no such link",
        ),
        (&p3d("<xyzOffsets>1 2</xyzOffsets>"), "<xyzOffsets>"),
        (&p3d("<updateRate>fast</updateRate>"), "<updateRate>"),
    ])
}
