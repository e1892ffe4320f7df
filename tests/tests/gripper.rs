//! Grippers: a `<mimic>` joint follows its leader (multiplier x position + offset), as
//! Gazebo's mimic joint plugins drive a gripper's second finger, on a two-finger test gripper
//! and on Franka's panda (example-robot-data: `panda_finger_joint2` mimics joint1).

use anyhow::{Context, Result, ensure};
use rover_sim::{JointCommand, LoadOptions, RobotModel};

/// A box with two prismatic fingers; the right one mirrors the left (multiplier -1) with a
/// 1 cm offset.
const GRIPPER: &str = r#"<?xml version="1.0"?>
<robot name="gripper">
  <link name="palm">
    <inertial><mass value="2.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="left_finger">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.02 0.01 0.05"/></geometry></collision>
  </link>
  <link name="right_finger">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.02 0.01 0.05"/></geometry></collision>
  </link>
  <joint name="left_finger_joint" type="prismatic">
    <parent link="palm"/><child link="left_finger"/>
    <origin xyz="0 0.03 0.1"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/>
  </joint>
  <joint name="right_finger_joint" type="prismatic">
    <parent link="palm"/><child link="right_finger"/>
    <origin xyz="0 -0.03 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-0.04" upper="0.01" effort="20" velocity="0.2"/>
    <mimic joint="left_finger_joint" multiplier="-1" offset="0.01"/>
  </joint>
</robot>
"#;

/// Steps `sim` for `seconds` of sim time.
fn run(sim: &mut rover_sim::Simulation, seconds: f64) {
    let end = sim.sim_time_s() + seconds;
    while sim.sim_time_s() < end {
        sim.step();
    }
}

fn position(sim: &rover_sim::Simulation, joint: &str) -> Result<f64> {
    let id = sim
        .robot()
        .joint_id(joint)
        .with_context(|| format!("no joint {joint}"))?;
    Ok(sim.joint_state(id).context("not built")?.position)
}

#[test]
fn a_mimic_finger_follows_its_leader_and_takes_no_commands() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("gripper.urdf");
    std::fs::write(&path, GRIPPER)?;
    let robot = RobotModel::load_with(&path, &LoadOptions::default())?;
    let mut sim = rover_tests::flat_sim(robot)?;
    run(&mut sim, 0.5);
    let (left, right) = (
        position(&sim, "left_finger_joint")?,
        position(&sim, "right_finger_joint")?,
    );
    // At rest: the right finger sits where the mimic puts it for the left's 0: 0.01.
    ensure!(
        left.abs() < 1e-3 && (right - 0.01).abs() < 1e-3,
        "at rest: left {left}, right {right} (want 0 and 0.01)"
    );
    sim.command_joint("left_finger_joint", JointCommand::Position(0.03))?;
    run(&mut sim, 1.0);
    let (left, right) = (
        position(&sim, "left_finger_joint")?,
        position(&sim, "right_finger_joint")?,
    );
    println!("left {left:.4} m, right {right:.4} m (want 0.03, -0.02)");
    ensure!(
        (left - 0.03).abs() < 1e-3 && (right + 0.02).abs() < 1e-3,
        "closed: left {left}, right {right} (want 0.03 and -1 x 0.03 + 0.01 = -0.02)"
    );
    let refused = sim
        .command_joint("right_finger_joint", JointCommand::Position(0.0))
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    ensure!(
        refused.contains("mimics \"left_finger_joint\"") && refused.contains("instead"),
        "commanding the mimic joint: {refused:?}"
    );
    Ok(())
}

#[test]
fn pandas_second_finger_follows_the_first() -> Result<()> {
    let Some(urdf) = rover_tests::example_robot_data("panda_description/urdf/panda.urdf") else {
        return Ok(());
    };
    let robot = RobotModel::load_with(&urdf, &LoadOptions::default())?;
    let mimic = robot
        .joint_id("panda_finger_joint2")
        .map(|id| robot.joint(id).mimic.is_some());
    ensure!(
        mimic == Some(true),
        "panda_finger_joint2 is not a mimic joint"
    );
    let mut sim = rover_tests::flat_sim(robot)?;
    run(&mut sim, 0.5);
    sim.command_joint("panda_finger_joint1", JointCommand::Position(0.03))?;
    run(&mut sim, 1.5);
    let (one, two) = (
        position(&sim, "panda_finger_joint1")?,
        position(&sim, "panda_finger_joint2")?,
    );
    println!("panda fingers: {one:.4} m, {two:.4} m (want 0.03 both)");
    ensure!(
        (one - 0.03).abs() < 2e-3 && (two - one).abs() < 2e-3,
        "panda fingers at {one} and {two} (want both 0.03)"
    );
    Ok(())
}
