//! Robots rover did not design: real third-party descriptions, loaded, simulated and driven.

use std::f64::consts::PI;

use anyhow::Result;
use rover_sim::{
    description::{LoadOptions, load_mesh},
    geometry::Shape,
    model::{JointKind, RobotModel},
    physics::Twist,
};
use rover_tests::{drive, flat_sim, shared};

fn turtlebot3(file: &str) -> Result<Option<RobotModel>> {
    let Some(dir) = shared("corpus/turtlebot3_description") else {
        return Ok(None);
    };
    // Found by package.xml discovery upward from the file: no ROS_PACKAGE_PATH needed.
    let robot = RobotModel::load_with(&dir.join("urdf").join(file), &LoadOptions::default())?;
    Ok(Some(robot))
}

#[test]
fn turtlebot3_burger_xacro_expands_with_its_plugins_and_meshes() -> Result<()> {
    let Some(robot) = turtlebot3("turtlebot3_burger.urdf.xacro")? else {
        return Ok(());
    };
    assert_eq!(robot.name, "turtlebot3_burger");
    let names: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
    for link in [
        "base_footprint",
        "base_link",
        "wheel_left_link",
        "wheel_right_link",
        "caster_back_link",
        "imu_link",
        "base_scan",
    ] {
        assert!(names.contains(&link), "missing link {link}: {names:?}");
    }
    assert_eq!(robot.link(robot.root).name, "base_footprint");
    // Element text survives expansion: the diff drive plugin keeps every parameter.
    let dd = robot
        .diff_drive
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("diff drive plugin lost"))?;
    assert_eq!(dd.wheel_separation_m, 0.160);
    assert_eq!(dd.wheel_diameter_m, 0.066);
    assert_eq!(dd.left_joint, "wheel_left_joint");
    assert_eq!(dd.update_rate_hz, 30.0);
    let wheel = robot.joint(
        robot
            .joint_id("wheel_left_joint")
            .ok_or_else(|| anyhow::anyhow!("no wheel joint"))?,
    );
    assert_eq!(wheel.kind, JointKind::Continuous);
    // Millimetre STL meshes through package://, scaled to metres: the base is ~14 cm across.
    let base = robot.link(
        robot
            .link_id("base_link")
            .ok_or_else(|| anyhow::anyhow!("no base_link"))?,
    );
    let Shape::Mesh { path, scale } = &base.visuals[0].shape else {
        anyhow::bail!(
            "base_link visual is not a mesh: {:?}",
            base.visuals[0].shape
        );
    };
    let mesh = load_mesh(path, *scale)?;
    let (lo, hi) = mesh.positions.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let size = hi - lo;
    assert!(
        (0.10..0.20).contains(&size.x) && (0.10..0.20).contains(&size.y),
        "burger base is {size:?} m; expected ~0.14 m across"
    );
    // Its LDS-01 laser, as the xacro describes it (Gazebo's ray sensor).
    let lds = robot
        .lasers
        .first()
        .ok_or_else(|| anyhow::anyhow!("the LDS laser was not read"))?;
    assert_eq!(lds.name, "lds_lfcd_sensor");
    assert_eq!(lds.link, "base_scan");
    assert_eq!(lds.samples, 360);
    assert_eq!(lds.update_rate_hz, 5.0);
    assert_eq!((lds.range_min_m, lds.range_max_m), (0.12, 3.5));
    assert_eq!(lds.range_resolution_m, 0.015);
    assert_eq!(lds.noise.map(|n| n.stddev), Some(0.01));
    assert_eq!(lds.topic, "scan");
    assert!(!robot.not_simulated.iter().any(|s| s.contains("lds")));
    // Its IMU, as TurtleBot3 declares it: the model plugin libgazebo_ros_imu.so on imu_link,
    // every physics step, /imu (and its <sensor type="imu"> without a ROS plugin, listed).
    let imu = robot
        .imus
        .first()
        .ok_or_else(|| anyhow::anyhow!("the IMU plugin was not read"))?;
    assert_eq!(robot.imus.len(), 1);
    assert_eq!(imu.plugin, rover_sim::model::ImuPlugin::Model);
    assert_eq!(
        (imu.link.as_str(), imu.frame_name.as_str()),
        ("imu_link", "imu_link")
    );
    assert_eq!((imu.topic.as_str(), imu.update_rate_hz), ("imu", 0.0));
    assert_eq!(imu.gaussian_noise, 0.0);
    assert!(
        robot
            .not_simulated
            .iter()
            .any(|s| s == "sensor \"imu\" (type imu, no ROS plugin: nothing published)"),
        "{:?}",
        robot.not_simulated
    );
    assert!(
        !robot
            .not_simulated
            .iter()
            .any(|s| s.contains("gazebo_ros_imu"))
    );
    // The expanded URDF is kept for ROS's /robot_description.
    assert!(
        robot
            .description
            .contains("<wheelSeparation>0.160</wheelSeparation>")
    );
    assert!(!robot.description.contains("xacro:"));
    Ok(())
}

#[test]
fn turtlebot3_burger_rests_drives_a_metre_and_turns_half_a_turn() -> Result<()> {
    let Some(robot) = turtlebot3("turtlebot3_burger.urdf.xacro")? else {
        return Ok(());
    };
    let mut sim = flat_sim(robot.clone())?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let base = sim.world_from_base();
    // base_footprint is on the ground when the wheels (r = 0.033 at z = 0.033) carry it.
    assert!(
        base.translation.z.abs() < 0.01,
        "base_footprint at z = {} m at rest; expected on the ground",
        base.translation.z
    );
    let (roll, pitch, _) = base.rotation.to_euler(glam::EulerRot::XYZ);
    assert!(
        roll.abs() < 0.05 && pitch.abs() < 0.1,
        "resting tilted: roll {roll} pitch {pitch} rad"
    );

    let (distance, _) = rover_tests::straight_run(&mut sim, 0.2, 5.0)?;
    assert!(
        (distance - 1.0).abs() <= 0.05,
        "0.2 m/s for 5 s moved {distance} m; expected 1.0 m within 5%"
    );

    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::ZERO, 0.5)?;
    let (error_deg, g) = rover_tests::half_turn_error_deg(&mut sim)?;
    assert!(
        error_deg < 5.0,
        "1 rad/s for pi s turned to {} deg; expected 180 within 5",
        g.yaw_rad.to_degrees()
    );
    Ok(())
}

#[test]
fn turtlebot3_autorace_camera_has_gazebos_intrinsics() -> Result<()> {
    let Some(robot) = turtlebot3("turtlebot3_burger_for_autorace.urdf.xacro")? else {
        return Ok(());
    };
    let camera = robot
        .cameras
        .first()
        .ok_or_else(|| anyhow::anyhow!("the autorace burger's camera was not found"))?;
    assert_eq!(camera.link, "camera_rgb_frame");
    assert_eq!((camera.width_px, camera.height_px), (320, 240));
    let info = rover_sim::model::CameraInfo::from_config(camera);
    // gazebo_ros_camera: f = W / (2 tan(hfov / 2)), c = (W + 1) / 2, (H + 1) / 2.
    let f = 320.0 / (2.0 * (1.085595f64 / 2.0).tan());
    assert!((info.k[0] - f).abs() < 1e-9 && (info.k[4] - f).abs() < 1e-9);
    assert_eq!((info.k[2], info.k[5]), (160.5, 120.5));
    assert_eq!((info.width, info.height), (320, 240));

    // --camera NAME picks by sensor name or cameraName; an unknown name lists the cameras.
    let mut robot = robot.clone();
    robot.select_camera("camera")?;
    let err = robot
        .select_camera("front")
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default();
    assert!(
        err.contains("no camera \"front\"; its cameras: \"Pi Camera\""),
        "{err}"
    );
    Ok(())
}

/// pybullet's robots (PyPI `pybullet`, its `pybullet_data/`): files ROS's parser accepts load.
#[test]
fn pybullet_r2d2_husky_and_racecar_load_and_simulate() -> Result<()> {
    let Some(wheel) = rover_tests::pypi("pybullet", "3.2.7") else {
        return Ok(());
    };
    let data = wheel.join("pybullet_data");
    // r2d2: no drive plugin; it loads, is simulated, and commands are ignored.
    let r2d2 = RobotModel::load_with(&data.join("r2d2.urdf"), &LoadOptions::default())?;
    assert!(r2d2.diff_drive.is_none());
    let mut sim = flat_sim(r2d2)?;
    drive(&mut sim, Twist::new(0.5, 0.0), 1.0)?;
    let g = sim.ground_truth();
    assert!(
        g.x_m.hypot(g.y_m) < 0.1,
        "an undrivable r2d2 moved to {g:?}"
    );
    // husky: `$(optenv HUSKY_IMU_XYZ 0.19 0 0.149)` in a plain .urdf is expanded like xacro
    // would (the defaults, as the variables are unset here).
    let husky = RobotModel::load_with(&data.join("husky/husky.urdf"), &LoadOptions::default())?;
    let imu = husky
        .joint_id("imu_joint")
        .ok_or_else(|| anyhow::anyhow!("husky has no imu_joint"))?;
    let t = husky.joint(imu).parent_from_child.translation;
    assert!(
        (t - glam::Vec3::new(0.19, 0.0, 0.149)).length() < 1e-6,
        "imu at {t}"
    );
    assert!(!husky.description.contains("$("));
    // racecar: <material> inside <geometry>, which urdfdom ignores.
    let racecar =
        RobotModel::load_with(&data.join("racecar/racecar.urdf"), &LoadOptions::default())?;
    assert!(racecar.links.len() > 10, "{} links", racecar.links.len());
    flat_sim(racecar)?;
    Ok(())
}

/// PAL's TIAGo from PyPI `example-robot-data` (`package://example-robot-data/...`, STL and
/// COLLADA meshes, 78 links) loads and drives with a `[robot.drive]` naming its wheel joints.
#[test]
fn tiago_loads_and_drives_with_robot_drive() -> Result<()> {
    let Some(wheel) = rover_tests::pypi("example-robot-data", "6.0.0") else {
        return Ok(());
    };
    let urdf = wheel
        .join("cmeel.prefix/share/example-robot-data/robots/tiago_description/robots/tiago.urdf");
    let robot = RobotModel::load_with(&urdf, &LoadOptions::default())?;
    assert_eq!(robot.links.len(), 78);
    let meshes: Vec<&std::path::Path> = robot
        .links
        .iter()
        .flat_map(|l| {
            l.visuals
                .iter()
                .map(|v| &v.shape)
                .chain(l.collisions.iter().map(|c| &c.shape))
        })
        .filter_map(|shape| match shape {
            Shape::Mesh { path, .. } => Some(path.as_path()),
            _ => None,
        })
        .collect();
    assert!(
        meshes
            .iter()
            .any(|p| p.extension().is_some_and(|e| e == "dae"))
    );
    for path in &meshes {
        load_mesh(path, glam::Vec3::ONE)?;
    }

    let tmp = tempfile::tempdir()?;
    let world = tmp.path().join("world.toml");
    std::fs::write(
        &world,
        "name = \"tiago\"\n[robot.drive]\nleft_joint = \"wheel_left_joint\"\nright_joint = \"wheel_right_joint\"\n",
    )?;
    let script = tmp.path().join("drive.toml");
    std::fs::write(&script, "steps = [ { at = 0.5, cmd_vel = [0.3, 0.0] } ]\n")?;
    let summary = rover_core::run_headless(&rover_core::RunConfig {
        world: Some(world),
        robot: Some(urdf),
        script: Some(script),
        duration_s: Some(4.0),
        ..rover_core::RunConfig::default()
    })?;
    let g = summary
        .last
        .ok_or_else(|| anyhow::anyhow!("no control samples"))?
        .ground_truth;
    println!("tiago after 3.5 s at 0.3 m/s: {g:?}");
    assert!(
        g.x_m > 0.7,
        "tiago reached x = {} m; expected about 1 m",
        g.x_m
    );
    Ok(())
}

/// A four-wheeled robot with gazebo_ros_skid_steer_drive: all four wheels driven, it goes
/// straight and turns in place.
#[test]
fn skid_steer_plugin_drives_four_wheels() -> Result<()> {
    let wheel = |name: &str, x: f64, y: f64| {
        format!(
            r#"<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="0.1" length="0.05"/></geometry></collision></link>
<joint name="{name}_joint" type="continuous"><parent link="base_link"/><child link="{name}"/><origin xyz="{x} {y} 0"/><axis xyz="0 1 0"/></joint>"#
        )
    };
    let urdf = format!(
        r#"<robot name="skid"><link name="base_link"><inertial><mass value="10"/><inertia ixx="0.2" ixy="0" ixz="0" iyy="0.3" iyz="0" izz="0.4"/></inertial>
  <collision><origin xyz="0 0 0.1"/><geometry><box size="0.6 0.4 0.15"/></geometry></collision></link>
{}{}{}{}
<gazebo><plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so">
  <leftFrontJoint>front_left_joint</leftFrontJoint><rightFrontJoint>front_right_joint</rightFrontJoint>
  <leftRearJoint>rear_left_joint</leftRearJoint><rightRearJoint>rear_right_joint</rightRearJoint>
  <wheelSeparation>0.5</wheelSeparation><wheelDiameter>0.2</wheelDiameter><torque>20</torque>
</plugin></gazebo></robot>"#,
        wheel("front_left", 0.2, 0.25),
        wheel("front_right", 0.2, -0.25),
        wheel("rear_left", -0.2, 0.25),
        wheel("rear_right", -0.2, -0.25)
    );
    let robot = RobotModel::from_str(&urdf, std::path::Path::new("skid.urdf"))?;
    let dd = robot
        .diff_drive
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("skid steer plugin not read"))?;
    assert_eq!(dd.extra_left_joints, ["rear_left_joint"]);
    assert_eq!(dd.extra_right_joints, ["rear_right_joint"]);
    let mut sim = flat_sim(robot.clone())?;
    let samples = drive(&mut sim, Twist::new(0.5, 0.0), 2.0)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let g = sim.ground_truth();
    assert!(
        (g.x_m - 1.0).abs() < 0.1,
        "0.5 m/s for 2 s reached x = {} m",
        g.x_m
    );
    assert!(
        samples
            .iter()
            .all(|s| s.wheel_targets_radps[0] <= 5.0 + 1e-9)
    );
    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::new(0.0, 1.0), 1.0)?;
    let yaw = sim.ground_truth().yaw_rad;
    assert!(yaw > 0.3, "turning in place reached yaw {yaw} rad");
    Ok(())
}

/// Renders `robot` at rest, seen from a camera 1.2 m in front of it looking back (the tutorial
/// car's 640x480 camera), and counts the pixels that differ from the same view without it.
/// With `ROVER_SAVE_VIEWS=DIR` the image is also written there (how docs/ got its pictures).
fn robot_in_view(robot: RobotModel, file: &str) -> Result<usize> {
    let camera = rover_tests::my_robot()?.cameras[0].clone();
    let world = rover_sim::model::World::flat()?;
    let mut sim = flat_sim(robot.clone())?;
    drive(&mut sim, Twist::ZERO, 0.5)?;
    let mut poses = Vec::new();
    sim.link_poses_into(&mut poses);
    let view = rover_sim::geometry::pose_from_position_yaw([1.2, 0.3, 0.5], PI + 0.25)
        * rover_sim::geometry::Pose::from_rotation(glam::Quat::from_rotation_y(0.3));
    let mut renderer = rover_sim::render::CameraRenderer::new(&world, &robot, &camera, 0)?;
    let with = renderer.render(&poses, view)?.to_vec();
    let parked =
        vec![rover_sim::geometry::Pose::from_translation(glam::Vec3::NEG_Z * 100.0); poses.len()];
    let without = renderer.render(&parked, view)?.to_vec();
    if let Some(dir) = std::env::var_os("ROVER_SAVE_VIEWS") {
        let img = image::RgbImage::from_raw(camera.width_px, camera.height_px, with.clone())
            .ok_or_else(|| anyhow::anyhow!("bad image size"))?;
        img.save(std::path::Path::new(&dir).join(file))?;
    }
    Ok(with
        .chunks_exact(3)
        .zip(without.chunks_exact(3))
        .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 30))
        .count())
}

#[test]
fn turtlebot3_and_tiago_render_with_their_meshes() -> Result<()> {
    if let Some(robot) = turtlebot3("turtlebot3_burger.urdf.xacro")? {
        let pixels = robot_in_view(robot, "turtlebot3-burger.png")?;
        assert!(pixels > 2_000, "the burger covers only {pixels} px");
    }
    if let Some(wheel) = rover_tests::pypi("example-robot-data", "6.0.0") {
        let urdf = wheel.join(
            "cmeel.prefix/share/example-robot-data/robots/tiago_description/robots/tiago.urdf",
        );
        let robot = RobotModel::load_with(&urdf, &LoadOptions::default())?;
        let pixels = robot_in_view(robot, "tiago.png")?;
        assert!(pixels > 20_000, "TIAGo covers only {pixels} px");
    }
    Ok(())
}
