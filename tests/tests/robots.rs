//! Robots rover did not design: real third-party descriptions, loaded, simulated and driven.

use std::f64::consts::PI;

use anyhow::Result;
use rover_sim::{JointKind, LoadOptions, RobotModel, Shape, Twist, load_mesh, wrap_angle};
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
    assert_eq!(robot.links[robot.root].name, "base_footprint");
    // Element text survives expansion: the diff drive plugin keeps every parameter.
    let dd = robot
        .diff_drive
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("diff drive plugin lost"))?;
    assert_eq!(dd.wheel_separation_m, 0.160);
    assert_eq!(dd.wheel_diameter_m, 0.066);
    assert_eq!(dd.left_joint, "wheel_left_joint");
    assert_eq!(dd.update_rate_hz, 30.0);
    let wheel = &robot.joints[robot
        .joint_index("wheel_left_joint")
        .ok_or_else(|| anyhow::anyhow!("no wheel joint"))?];
    assert_eq!(wheel.kind, JointKind::Continuous);
    // Millimetre STL meshes through package://, scaled to metres: the base is ~14 cm across.
    let base = &robot.links[robot
        .link_index("base_link")
        .ok_or_else(|| anyhow::anyhow!("no base_link"))?];
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
    let rest = sim.ground_truth();
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

    drive(&mut sim, Twist::new(0.2, 0.0), 5.0)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let moved = sim.ground_truth();
    let distance = (moved.x_m - rest.x_m).hypot(moved.y_m - rest.y_m);
    assert!(
        (distance - 1.0).abs() <= 0.05,
        "0.2 m/s for 5 s moved {distance} m; expected 1.0 m within 5%"
    );

    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::ZERO, 0.5)?;
    drive(&mut sim, Twist::new(0.0, 1.0), PI)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let g = sim.ground_truth();
    let error_deg = wrap_angle(g.yaw_rad - PI).abs().to_degrees();
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
    let info = rover_sim::CameraInfo::from_config(camera);
    // gazebo_ros_camera: f = W / (2 tan(hfov / 2)), c = (W + 1) / 2, (H + 1) / 2.
    let f = 320.0 / (2.0 * (1.085595f64 / 2.0).tan());
    assert!((info.k[0] - f).abs() < 1e-9 && (info.k[4] - f).abs() < 1e-9);
    assert_eq!((info.k[2], info.k[5]), (160.5, 120.5));
    assert_eq!((info.width, info.height), (320, 240));
    Ok(())
}
