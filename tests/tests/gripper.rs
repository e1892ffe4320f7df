//! Grippers: a `<mimic>` joint follows its leader (multiplier x position + offset), as
//! Gazebo's mimic joint plugins drive a gripper's second finger, on a two-finger test gripper
//! and on Franka's panda (example-robot-data: `panda_finger_joint2` mimics joint1).

use anyhow::{Context, Result, ensure};
use rover_sim::{
    description::LoadOptions,
    model::RobotModel,
    physics::{Grasped, JointCommand},
};

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
fn run(sim: &mut rover_sim::physics::Simulation, seconds: f64) {
    let end = sim.sim_time_s() + seconds;
    while sim.sim_time_s() < end {
        sim.step();
    }
}

fn position(sim: &rover_sim::physics::Simulation, joint: &str) -> Result<f64> {
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

/// The same gripper with its `<mimic>` given instead by the mimic joint plugin Gazebo Classic
/// users add (roboticsgroup_upatras_gazebo_plugins): the right finger follows the left the same
/// way; a plugin naming a missing joint, a fixed one, or the leader itself is refused at its
/// line.
#[test]
fn the_mimic_joint_plugin_stands_for_a_mimic() -> Result<()> {
    let plugin = |joint: &str, mimic: &str| {
        let without = GRIPPER.replace(
            r#"<mimic joint="left_finger_joint" multiplier="-1" offset="0.01"/>"#,
            "",
        );
        without.replace(
            "</robot>",
            &format!(
                r#"  <gazebo>
    <plugin name="mimic" filename="libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so">
      <joint>{joint}</joint>
      <mimicJoint>{mimic}</mimicJoint>
      <multiplier>-1.0</multiplier>
      <offset>0.01</offset>
    </plugin>
  </gazebo>
</robot>"#
            ),
        )
    };
    let dir = tempfile::tempdir()?;
    let path = dir.path().join("gripper.urdf");
    std::fs::write(&path, plugin("left_finger_joint", "right_finger_joint"))?;
    let robot = RobotModel::load_with(&path, &LoadOptions::default())?;
    let mut sim = rover_tests::flat_sim(robot)?;
    run(&mut sim, 0.5);
    sim.command_joint("left_finger_joint", JointCommand::Position(0.03))?;
    run(&mut sim, 1.0);
    let (left, right) = (
        position(&sim, "left_finger_joint")?,
        position(&sim, "right_finger_joint")?,
    );
    println!("plugin: left {left:.4} m, right {right:.4} m (want 0.03, -0.02)");
    ensure!(
        (left - 0.03).abs() < 1e-3 && (right + 0.02).abs() < 1e-3,
        "closed: left {left}, right {right} (want 0.03 and -0.02)"
    );
    let plugin_line = plugin("a", "b")
        .lines()
        .position(|l| l.contains("<plugin name=\"mimic\""))
        .map_or(0, |i| i + 1);
    for (joint, mimic, expect) in [
        (
            "left_finger_joint",
            "thumb",
            "no joint \"thumb\"; joints in this robot:",
        ),
        (
            "left_finger_joint",
            "left_finger_joint",
            "a joint cannot follow itself",
        ),
    ] {
        std::fs::write(&path, plugin(joint, mimic))?;
        let err = RobotModel::load_with(&path, &LoadOptions::default())
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        ensure!(
            err.contains(expect) && err.contains(&format!(":{plugin_line}")),
            "{joint} -> {mimic}: {err:?} (want {expect:?} at line {plugin_line})"
        );
    }
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

/// tests/grasper/: a base, a wrist turning the palm, and two fingers that close toward the
/// palm's middle (the right one mimics the left), with a 5 cm ball resting on the palm between
/// them; copied into `dir`, the controllers file replaced by `controllers` if given.
fn grasper_world(dir: &std::path::Path, controllers: Option<&str>) -> Result<std::path::PathBuf> {
    let from = rover_tests::repo("tests/grasper");
    for file in ["grasper.urdf", "grasper.yaml", "grasper.toml"] {
        std::fs::copy(from.join(file), dir.join(file))?;
    }
    if let Some(yaml) = controllers {
        std::fs::write(dir.join("grasper.yaml"), yaml)?;
    }
    Ok(dir.join("grasper.toml"))
}

fn grasper_sim(world: &std::path::Path) -> Result<rover_sim::physics::Simulation> {
    let world = rover_sim::model::World::load(world)?;
    let urdf = world
        .robot
        .urdf
        .clone()
        .context("the world names its robot")?;
    let mut robot = RobotModel::load_with(&urdf, &LoadOptions::default())?;
    if let Some(c) = &world.robot.controllers {
        robot.load_controllers(c)?;
    }
    Ok(rover_sim::physics::Simulation::new(
        world,
        robot,
        &rover_sim::physics::SimOptions::default(),
    )?)
}

/// Runs until the gripper's command ends (at most `limit_s`).
fn until_done(
    sim: &mut rover_sim::physics::Simulation,
    limit_s: f64,
) -> Result<rover_sim::physics::GripperState> {
    let end = sim.sim_time_s() + limit_s;
    loop {
        sim.step();
        let state = *sim
            .gripper_state("gripper_controller")
            .context("no gripper controller")?;
        if !state.active || sim.sim_time_s() > end {
            return Ok(state);
        }
    }
}

/// control_msgs/GripperCommand as gripper_action_controller answers it: closing on nothing
/// reaches the goal; closing on the ball stalls short of it, pushing with the command's
/// max_effort, and the ball stays between the fingers; reopening reaches the goal again.
#[test]
fn a_gripper_command_reaches_its_goal_or_stalls_on_the_ball() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let mut sim = grasper_sim(&grasper_world(dir.path(), None)?)?;
    run(&mut sim, 0.5);
    sim.command_gripper("gripper_controller", 0.01, 0.0)?;
    let free = until_done(&mut sim, 5.0)?;
    println!("free: {free:?}");
    ensure!(
        free.reached_goal && !free.stalled && (free.position - 0.01).abs() <= 0.002,
        "closing 1 cm on nothing: {free:?}"
    );
    sim.command_gripper("gripper_controller", 0.05, 5.0)?;
    let closed = until_done(&mut sim, 5.0)?;
    run(&mut sim, 0.5);
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    let ball = poses.first().context("no ball")?.translation;
    let effort = sim
        .gripper_state("gripper_controller")
        .context("no gripper")?
        .effort;
    println!(
        "on the ball: {closed:?}; ball at {:.4} {:.4} {:.4}; effort after 0.5 s {effort:.3} N",
        ball.x, ball.y, ball.z
    );
    // The fingers' inner faces are 5.5 cm from the middle when open: they touch a 2.5 cm ball
    // at 3 cm. rapier's contacts are soft (a spring whose stiffness scales with the bodies'
    // masses, at 30 Hz): 5 N on each side of a 50 g ball sinks each finger ~5 mm into it.
    ensure!(
        closed.stalled
            && !closed.reached_goal
            && closed.position > 0.029
            && closed.position < 0.038,
        "closing on the ball: {closed:?}"
    );
    ensure!(
        effort > 2.5 && effort <= 5.0 + 1e-6,
        "a stalled gripper keeps squeezing with max_effort 5 N: {effort}"
    );
    ensure!(
        ball.y.abs() < 0.005 && ball.x.abs() < 0.01 && ball.z > 0.05,
        "the ball left the fingers: {ball:?}"
    );
    sim.command_gripper("gripper_controller", 0.0, 0.0)?;
    let open = until_done(&mut sim, 5.0)?;
    ensure!(open.reached_goal, "reopening: {open:?}");
    let refused = sim
        .command_gripper("gripper_controller", f64::NAN, 1.0)
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    ensure!(refused.contains("finite"), "a NaN command: {refused:?}");
    Ok(())
}

/// A gripper controller that names an arm joint, a mimic joint or a missing joint is refused
/// with the file's line and the reason.
#[test]
fn a_gripper_naming_a_joint_that_is_not_a_finger_is_refused() -> Result<()> {
    let dir = tempfile::tempdir()?;
    for (joint, expected) in [
        (
            "wrist_joint",
            "is not a finger joint: joint \"left_finger_joint\" moves beyond it",
        ),
        ("right_finger_joint", "mimics another joint"),
        ("thumb_joint", "has no joint \"thumb_joint\""),
    ] {
        let yaml = std::fs::read_to_string(rover_tests::repo("tests/grasper/grasper.yaml"))?
            .replace("left_finger_joint", joint);
        let world = grasper_world(dir.path(), Some(&yaml))?;
        let error = match grasper_sim(&world) {
            Ok(_) => String::new(),
            Err(e) => format!("{e:#}"),
        };
        println!("{joint}: {error}");
        ensure!(
            error.contains(expected) && error.contains("grasper.yaml:4"),
            "a gripper on {joint}: {error:?}"
        );
    }
    Ok(())
}

/// The ball's centre in the palm's frame (m).
fn ball_in_palm(sim: &rover_sim::physics::Simulation) -> Result<glam::Vec3> {
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    let ball = poses.first().context("no ball")?.translation;
    let palm = sim.robot().link_id("palm").context("no palm")?;
    Ok(sim.world_from_link(palm).inverse().transform_point(ball))
}

/// The lifter (tests/grasper/lifter.urdf) lowered round the ball on the ground and closed on
/// it with `squeeze_n` (the GripperCommand's max_effort); `grasp` is the world's `[robot]
/// grasp` line. The simulation and how the close ended.
fn lifter_grasp(
    grasp: &str,
    squeeze_n: f64,
) -> Result<(
    rover_sim::physics::Simulation,
    rover_sim::physics::GripperState,
)> {
    let dir = tempfile::tempdir()?;
    let from = rover_tests::repo("tests/grasper");
    for file in ["lifter.urdf", "grasper.yaml"] {
        std::fs::copy(from.join(file), dir.path().join(file))?;
    }
    let world = std::fs::read_to_string(from.join("lifter.toml"))?.replace(
        "controllers = \"grasper.yaml\"\n",
        &format!("controllers = \"grasper.yaml\"\n{grasp}\n"),
    );
    std::fs::write(dir.path().join("lifter.toml"), world)?;
    let mut sim = grasper_sim(&dir.path().join("lifter.toml"))?;
    run(&mut sim, 0.5);
    sim.command_joint("lift_joint", JointCommand::Position(-0.055))?;
    run(&mut sim, 1.5);
    sim.command_gripper("gripper_controller", 0.05, squeeze_n)?;
    let grasp_state = until_done(&mut sim, 5.0)?;
    Ok((sim, grasp_state))
}

/// How far the held ball moves in the palm's frame while the lifter lifts it 25 cm, turns it
/// 1 rad and drops and raises it 10 cm twice at full speed (m); whether it fell when the
/// fingers opened; what the grasp assist held, if anything. `grasp` is the world's `[robot]
/// grasp` line.
fn lift_and_shake(grasp: &str) -> Result<(f32, bool, Option<Grasped>)> {
    let (mut sim, grasp_state) = lifter_grasp(grasp, 10.0)?;
    ensure!(
        grasp_state.stalled,
        "the fingers did not close on the ball: {grasp_state:?}"
    );
    run(&mut sim, 1.2);
    let held = sim.grasp_assist_holds();
    let held_at = ball_in_palm(&sim)?;
    let mut worst = 0.0f32;
    let mut moves =
        |sim: &mut rover_sim::physics::Simulation, joint: &str, q: f64, s: f64| -> Result<()> {
            sim.command_joint(joint, JointCommand::Position(q))?;
            let end = sim.sim_time_s() + s;
            while sim.sim_time_s() < end {
                sim.step();
                worst = worst.max((ball_in_palm(sim)? - held_at).length());
            }
            Ok(())
        };
    let (wall, sim_start_s) = (std::time::Instant::now(), sim.sim_time_s());
    moves(&mut sim, "lift_joint", 0.2, 1.5)?;
    moves(&mut sim, "wrist_joint", 1.0, 1.5)?;
    for _ in 0..2 {
        moves(&mut sim, "lift_joint", 0.1, 0.6)?;
        moves(&mut sim, "lift_joint", 0.2, 0.6)?;
    }
    // For the record only (no test depends on the machine's speed).
    println!(
        "{grasp:?}: {:.1} s of sim time holding the ball in {:.3} s of wall time",
        sim.sim_time_s() - sim_start_s,
        wall.elapsed().as_secs_f64()
    );
    let mut poses = Vec::new();
    sim.object_poses_into(&mut poses);
    let lifted_z = poses.first().context("no ball")?.translation.z;
    ensure!(lifted_z > 0.2, "the ball was not lifted: z {lifted_z}");
    sim.command_gripper("gripper_controller", 0.0, 0.0)?;
    run(&mut sim, 2.0);
    sim.object_poses_into(&mut poses);
    let fell = poses.first().context("no ball")?.translation.z < 0.05;
    println!(
        "{grasp:?}: grasp {grasp_state:?}; the assist held {held:?}; the ball moved at most {:.2} mm in the palm's frame; lifted to z {lifted_z:.3} m; fell when opened: {fell}; the assist holds {:?} after",
        worst * 1000.0,
        sim.grasp_assist_holds()
    );
    ensure!(
        sim.grasp_assist_holds().is_none(),
        "the assist did not let go when the fingers opened"
    );
    Ok((worst, fell, held))
}

/// Holding, both ways: the lifter (tests/grasper/lifter.urdf) lowers its fingers around a 5 cm
/// ball lying on the ground, closes on it with 10 N, lifts it 25 cm, turns it 1 rad, then drops
/// and raises it 10 cm twice at the lift's full speed. By friction (the default) and with the
/// grasp assist (gazebo_grasp_fix's rule: the ball fixed to the palm once gripped), the ball
/// moves less than 1 cm in the palm's frame, and falls when the fingers open.
#[test]
fn a_held_ball_stays_in_the_fingers_while_lifted_and_turned_by_friction_or_assist() -> Result<()> {
    let (friction_slip, friction_fell, friction_held) = lift_and_shake("")?;
    ensure!(friction_held.is_none(), "no assist was asked for");
    let (assist_slip, assist_fell, assist_held) = lift_and_shake("grasp = \"assist\"")?;
    ensure!(
        assist_held == Some(Grasped::Object(0)),
        "the assist did not hold the ball: {assist_held:?}"
    );
    for (mode, slip, fell) in [
        ("friction", friction_slip, friction_fell),
        ("assist", assist_slip, assist_fell),
    ] {
        ensure!(
            slip < 0.01,
            "{mode}: the held ball slipped {slip:.4} m in the fingers"
        );
        ensure!(fell, "{mode}: opened, the ball did not fall");
    }
    Ok(())
}

/// `grasp = "assist"` on a robot without a gripper controller is refused, saying what it needs.
#[test]
fn the_grasp_assist_without_a_gripper_controller_is_refused() -> Result<()> {
    let dir = tempfile::tempdir()?;
    let world = grasper_world(
        dir.path(),
        Some(
            "wrist_controller:\n  type: position_controllers/JointPositionController\n  joint: wrist_joint\n",
        ),
    )?;
    let text = std::fs::read_to_string(&world)?.replace(
        "controllers = \"grasper.yaml\"\n",
        "controllers = \"grasper.yaml\"\ngrasp = \"assist\"\n",
    );
    std::fs::write(&world, text)?;
    let error = match grasper_sim(&world) {
        Ok(_) => String::new(),
        Err(e) => format!("{e:#}"),
    };
    ensure!(
        error.contains("grasp = \"assist\" needs a gripper controller"),
        "{error:?}"
    );
    Ok(())
}

/// Raises the lifter from where it is by `rise_m` along a smooth profile (acceleration
/// `accel_mps2` up to 5 cm/s, then the same deceleration), the lift joint tracking it, then
/// holds for half a second: the ball feels its weight and barely more.
fn lift_gently(
    sim: &mut rover_sim::physics::Simulation,
    rise_m: f64,
    accel_mps2: f64,
) -> Result<()> {
    const TOP_SPEED_MPS: f64 = 0.05;
    let from = position(sim, "lift_joint")?;
    let ramp_s = TOP_SPEED_MPS / accel_mps2;
    let ramp_m = 0.5 * accel_mps2 * ramp_s * ramp_s;
    let cruise_s = (rise_m - 2.0 * ramp_m) / TOP_SPEED_MPS;
    let total_s = 2.0 * ramp_s + cruise_s;
    let start = sim.sim_time_s();
    while sim.sim_time_s() - start < total_s {
        let t = sim.sim_time_s() - start;
        let (s, v) = if t < ramp_s {
            (0.5 * accel_mps2 * t * t, accel_mps2 * t)
        } else if t < ramp_s + cruise_s {
            (ramp_m + TOP_SPEED_MPS * (t - ramp_s), TOP_SPEED_MPS)
        } else {
            let left = total_s - t;
            (rise_m - 0.5 * accel_mps2 * left * left, accel_mps2 * left)
        };
        sim.command_joint(
            "lift_joint",
            JointCommand::Track {
                position: from + s,
                velocity: v,
            },
        )?;
        sim.step();
    }
    sim.command_joint("lift_joint", JointCommand::Position(from + rise_m))?;
    run(sim, 0.5);
    Ok(())
}

/// Friction holds no more than Coulomb's bound (the finger pads' friction anchors,
/// sim/src/physics/grip_friction.rs, included): two pads at mu 1 squeezing the 50 g ball with
/// N each hold at most 2 mu N, so no squeeze under `m g / (2 mu)` = 0.245 N can lift it. Lifted
/// gently (0.2 m/s^2: its weight and 2% more), the ball stays on the ground squeezed with 10%
/// less than that; and the squeeze that holds it is found where it was measured: 0.30 N
/// slides, 0.36 N lifts it (the grip needs about 1.3 times the bound; docs/ARM.md); far from
/// the bound too, 0.05 N slides and 10 N lifts.
#[test]
fn a_ball_squeezed_too_weakly_for_its_weight_slides_out_of_the_fingers() -> Result<()> {
    const BALL_KG: f64 = 0.05;
    const PAD_MU: f64 = 1.0;
    let holds_n = BALL_KG * 9.81 / (2.0 * PAD_MU);
    let mut wrong = Vec::new();
    for (squeeze_n, rises) in [
        (0.05, false),
        (0.9 * holds_n, false),
        (0.30, false),
        (0.36, true),
        (10.0, true),
    ] {
        let (mut sim, closed) = lifter_grasp("", squeeze_n)?;
        // The fingers are on the ball either way: what differs is the squeeze.
        ensure!(
            closed.stalled,
            "{squeeze_n} N: the fingers did not close on the ball: {closed:?}"
        );
        run(&mut sim, 1.2);
        lift_gently(&mut sim, 0.25, 0.2)?;
        let mut poses = Vec::new();
        sim.object_poses_into(&mut poses);
        let z = poses.first().context("no ball")?.translation.z;
        println!(
            "squeezed with {squeeze_n:.4} N ({:.2} of the {holds_n:.3} N that holds its weight): the ball is at z {z:.3} m",
            squeeze_n / holds_n
        );
        if (z > 0.2) != rises || (!rises && z > 0.05) {
            wrong.push(format!(
                "{squeeze_n:.4} N ({:.2} x): the ball is at z {z:.3} m; expected it to {}",
                squeeze_n / holds_n,
                if rises {
                    "rise above 0.2 m"
                } else {
                    "stay below 0.05 m"
                }
            ));
        }
    }
    ensure!(wrong.is_empty(), "{}", wrong.join("\n"));
    Ok(())
}
