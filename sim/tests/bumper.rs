//! The bumper (`<sensor type="contact">` with `libgazebo_ros_bumper.so`) on real physics: the
//! tutorial car driven into a box reports the contact with the box's name while it touches,
//! nothing before; its frame, rate and located errors.

use std::path::Path;

use rover_sim::{
    model::World,
    physics::{SimOptions, Simulation, Twist},
    sensors::BumperSensor,
};

mod common;

use common::{Result, assert_located_errors, car_with};

fn bumper(frame: &str) -> String {
    format!(
        r#"<gazebo reference="base_link"><sensor name="front_bumper" type="contact">
          <update_rate>50</update_rate>
          <contact><collision>base_link_collision</collision></contact>
          <plugin name="bumper" filename="libgazebo_ros_bumper.so">
            <bumperTopicName>bumper_states</bumperTopicName><frameName>{frame}</frameName>
          </plugin></sensor></gazebo>"#
    )
}

/// A low box (under the camera) whose near face is 1 m ahead of the car's origin.
fn sim(frame: &str) -> Result<Simulation> {
    let world = World::from_str(
        r#"
[[box]]
name = "crate"
size_m = [0.4, 1.0, 0.12]
position_m = [1.35, 0.0]
"#,
        Path::new("bumper-test.toml"),
    )?;
    Ok(Simulation::new(
        world,
        car_with(&bumper(frame))?,
        &SimOptions {
            seed: 2,
            ..SimOptions::default()
        },
    )?)
}

#[test]
fn the_car_driven_into_a_box_reports_the_box_while_touching_and_nothing_before() -> Result<()> {
    let mut sim = sim("world")?;
    let c = &sim.robot().bumpers[0];
    assert_eq!(
        (
            c.topic.as_str(),
            c.frame_name.as_str(),
            c.collision.as_str()
        ),
        ("bumper_states", "world", "base_link_collision")
    );
    let mut bumper = BumperSensor::new(&sim, 0).ok_or("no bumper")?;
    sim.set_cmd_vel(Twist::new(0.3, 0.0))?;
    let (mut before, mut touching, mut readings) = (0, 0, 0);
    while sim.sim_time_s() < 6.0 {
        sim.step();
        let Some(r) = bumper.update(&sim) else {
            continue;
        };
        readings += 1;
        assert_eq!(r.collision, "my_robot::base_link::base_link_collision");
        assert_eq!(r.frame_id, "world");
        // The car's nose (base_link is 0.3 m long) against the box's face at x = 1.15.
        let nose_x = sim.world_from_base().translation.x + 0.15;
        let gap_m = 1.15 - nose_x;
        if gap_m > 0.01 {
            assert!(
                r.contacts.is_empty(),
                "{gap_m:.3} m short of the box: {:?}",
                r.contacts
            );
            before += 1;
        }
        if let Some(c) = r
            .contacts
            .iter()
            .find(|c| c.other == "crate::link::collision")
        {
            assert!(gap_m < 0.01, "touching the box {gap_m:.3} m short of it");
            touching += 1;
            for (p, n) in c.positions_m.iter().zip(&c.normals) {
                assert!((p.x - 1.15).abs() < 0.02, "a contact point at x {:.3}", p.x);
                assert!(n.x < -0.9, "the normal pushes the car back: {n:?}");
            }
            assert!(
                c.force_n.x <= 0.0,
                "the box pushes the car back: {:?}",
                c.force_n
            );
            assert!(c.depths_m.iter().all(|d| *d >= 0.0 && *d < 0.02));
        }
    }
    // 50 Hz on sim time.
    assert!(
        (readings as i64 - 300).abs() <= 1,
        "{readings} readings in 6 s"
    );
    assert!(before > 100, "{before} readings before the box");
    assert!(touching > 50, "{touching} readings touching the box");
    Ok(())
}

#[test]
fn in_the_links_frame_the_box_is_ahead() -> Result<()> {
    let mut sim = sim("base_link")?;
    let mut bumper = BumperSensor::new(&sim, 0).ok_or("no bumper")?;
    sim.set_cmd_vel(Twist::new(0.3, 0.0))?;
    let mut seen = false;
    while sim.sim_time_s() < 6.0 {
        sim.step();
        let Some(r) = bumper.update(&sim) else {
            continue;
        };
        assert_eq!(r.frame_id, "base_link");
        for c in &r.contacts {
            for p in &c.positions_m {
                assert!(
                    (p.x - 0.15).abs() < 0.02,
                    "a contact at x {:.3} in base_link",
                    p.x
                );
            }
            seen = true;
        }
    }
    assert!(
        seen,
        "no contact; the car at {:?}",
        sim.world_from_base().translation
    );
    Ok(())
}

#[test]
fn bad_bumper_blocks_are_located_errors_and_a_contact_sensor_without_the_plugin_is_listed()
-> Result<()> {
    let robot = car_with(
        r#"<gazebo reference="base_link"><sensor name="touch" type="contact">
          <contact><collision>base_link_collision</collision></contact></sensor></gazebo>"#,
    )?;
    assert!(robot.bumpers.is_empty());
    assert!(
        robot
            .not_simulated
            .iter()
            .any(|s| s.contains("\"touch\" (type contact")),
        "{:?}",
        robot.not_simulated
    );
    let plugin = r#"<plugin name="b" filename="libgazebo_ros_bumper.so"/>"#;
    let cases = [
        (
            format!(r#"<gazebo><sensor name="b" type="contact">{plugin}</sensor></gazebo>"#),
            "<sensor type=\"contact\"> must sit in <gazebo reference=\"LINK\">",
        ),
        (
            format!(r#"<gazebo reference="base_link"><sensor name="b" type="contact">{plugin}</sensor></gazebo>"#),
            "missing <contact><collision>",
        ),
        (
            format!(r#"<gazebo reference="base_link"><sensor name="b" type="contact"><update_rate>fast</update_rate><contact><collision>c</collision></contact>{plugin}</sensor></gazebo>"#),
            "<update_rate> in <sensor name=\"b\" type=\"contact\">: expected a number",
        ),
        (
            r#"<gazebo reference="no_such_link"><sensor name="b" type="contact"><contact><collision>c</collision></contact><plugin name="b" filename="libgazebo_ros_bumper.so"/></sensor></gazebo>"#.to_owned(),
            "no_such_link",
        ),
    ];
    assert_located_errors(cases.iter().map(|(b, e)| (b.as_str(), *e)))
}
