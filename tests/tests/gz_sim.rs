//! Modern Gazebo's robots (issue 62): TurtleBot3's own ROS 2 Jazzy models (SDF with gz-sim
//! systems, ../shared/corpus/turtlebot3_gz) loaded, simulated and driven; the tutorial car
//! written with gz-sim systems against the same car with gazebo_ros's plugins.

use anyhow::{Context, Result};
use rover_sim::{
    description::{LoadOptions, ResourcePaths},
    model::{DrivePlugin, JointKind, RobotModel},
    physics::Twist,
};
use rover_tests::{drive, flat_sim, shared};

/// TurtleBot3's gz package, or `None` (skip recorded) without ../shared.
fn tb3_gz() -> Option<std::path::PathBuf> {
    shared("corpus/turtlebot3_gz/turtlebot3_gazebo")
}

fn tb3_model(name: &str) -> Result<Option<RobotModel>> {
    let Some(dir) = tb3_gz() else {
        return Ok(None);
    };
    let path = dir.join("models").join(name).join("model.sdf");
    // No model path given: model://turtlebot3_common is found beside the model's own folder.
    let options = LoadOptions {
        resources: ResourcePaths::default(),
        ..LoadOptions::default()
    };
    Ok(Some(
        RobotModel::load_with(&path, &options).with_context(|| path.display().to_string())?,
    ))
}

#[test]
fn turtlebot3_burger_sdf_loads_with_its_gz_systems_and_sensors() -> Result<()> {
    let Some(robot) = tb3_model("turtlebot3_burger")? else {
        return Ok(());
    };
    assert_eq!(robot.name, "turtlebot3_burger");
    assert_eq!(robot.link(robot.root).name, "base_footprint");
    let wheel = robot.joint(
        robot
            .joint_id("wheel_left_joint")
            .context("no wheel_left_joint")?,
    );
    // SDF revolute without limits is continuous; its axis (z in the joint frame, turned -1.57
    // about x) is the wheel's axle, and the link's frame now sits on the axle.
    assert_eq!(wheel.kind, JointKind::Continuous);
    let axle = wheel.parent_from_child.rotation * wheel.axis;
    assert!(
        (axle - glam::Vec3::Y).length() < 1e-2,
        "wheel axle {axle:?} in base_link; expected +y"
    );
    let at = wheel.parent_from_child.translation;
    assert!(
        (at - glam::Vec3::new(0.0, 0.08, 0.023)).length() < 1e-4,
        "wheel joint at {at:?}"
    );
    let dd = robot.diff_drive.as_ref().context("DiffDrive not read")?;
    assert_eq!(dd.plugin, DrivePlugin::GzSim);
    assert_eq!(
        (dd.left_joint.as_str(), dd.right_joint.as_str()),
        ("wheel_left_joint", "wheel_right_joint")
    );
    assert_eq!(dd.wheel_separation_m, 0.160);
    assert!((dd.wheel_diameter_m - 0.066).abs() < 1e-12);
    // The wheel joints' <limit><effort> bounds the motors, as the physics engine bounds gz-sim's
    // velocity commands.
    assert_eq!(dd.wheel_torque_nm, 20.0);
    assert_eq!(dd.command_topic, "cmd_vel");
    assert_eq!(dd.odometry_topic, "odom");
    assert_eq!(
        (dd.odometry_frame.as_str(), dd.robot_base_frame.as_str()),
        ("odom", "base_footprint")
    );
    assert_eq!(dd.tf_topic.as_deref(), Some("/tf"));
    // The file's <odom_publisher_frequency> is no gz-sim parameter (gz reads
    // <odom_publish_frequency>): gz-sim's default 50 Hz applies, as in Gazebo.
    assert_eq!(dd.odometry_rate_hz, Some(50.0));
    let lin = dd.linear_limits.context("no speed limits")?;
    assert_eq!(lin.acceleration.1, 1.0);
    let jsp = robot
        .joint_state_publisher
        .as_ref()
        .context("JointStatePublisher not read")?;
    assert_eq!(jsp.topic, "joint_states");
    assert_eq!(jsp.joints, ["wheel_left_joint", "wheel_right_joint"]);

    let lds = robot.lasers.first().context("gpu_lidar not read")?;
    assert_eq!(lds.link, "base_scan");
    assert_eq!(lds.samples, 360);
    assert_eq!(lds.update_rate_hz, 5.0);
    assert_eq!((lds.range_min_m, lds.range_max_m), (0.12, 3.5));
    assert_eq!(lds.topic, "scan");
    assert_eq!(lds.frame_name, "base_scan");
    // base_scan's pose is in the model frame; its URDF frame (fixed joint) stays there.
    let t = lds.link_from_sensor.translation;
    assert!(
        (t - glam::Vec3::new(-0.032, 0.0, 0.171)).length() < 1e-5,
        "{t:?}"
    );
    let imu = robot.imus.first().context("imu not read")?;
    assert_eq!(imu.topic, "imu");
    assert_eq!(imu.update_rate_hz, 200.0);
    // No <gz_frame_id>: gz-sim stamps the scoped name.
    assert_eq!(imu.frame_name, "turtlebot3_burger::imu_link::tb3_imu");
    // The wheels' SDF surface friction; the caster's ball joint slips freely.
    let link = |n: &str| robot.link(robot.link_id(n).unwrap_or(robot.root));
    assert_eq!(link("wheel_left_link").friction, Some(100000.0));
    assert_eq!(link("caster_back_link").friction, Some(0.0));
    Ok(())
}

#[test]
fn turtlebot3_burger_sdf_rests_and_drives_a_metre() -> Result<()> {
    let Some(robot) = tb3_model("turtlebot3_burger")? else {
        return Ok(());
    };
    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let base = sim.world_from_base();
    let (roll, pitch, _) = base.rotation.to_euler(glam::EulerRot::XYZ);
    assert!(
        roll.abs() < 0.05 && pitch.abs() < 0.1,
        "resting tilted: roll {roll} pitch {pitch} rad"
    );
    let (distance, sideways) = rover_tests::straight_run(&mut sim, 0.2, 5.0)?;
    // gz-sim's limiter (max_linear_acceleration 1) costs 0.02 m of the ramp up.
    assert!(
        (distance - 0.98).abs() <= 0.05,
        "0.2 m/s for 5 s moved {distance} m; expected 0.98 m within 5 cm"
    );
    assert!(sideways.abs() < 0.05, "drifted sideways {sideways} m");
    Ok(())
}

#[test]
fn turtlebot3_waffle_pi_sdf_has_its_camera() -> Result<()> {
    let tmp = tempfile::tempdir()?;
    let Some((path, models)) = rover_tests::turtlebot3_gz_waffle_pi(tmp.path())? else {
        return Ok(());
    };
    let options = LoadOptions {
        resources: ResourcePaths::default().with_model_path(models),
        ..LoadOptions::default()
    };
    let robot = RobotModel::load_with(&path, &options)?;
    let camera = robot.cameras.first().context("camera not read")?;
    assert_eq!(camera.link, "camera_rgb_frame");
    assert_eq!((camera.width_px, camera.height_px), (640, 480));
    assert!((camera.horizontal_fov_rad - 1.085595).abs() < 1e-9);
    assert_eq!(camera.update_rate_hz, 30.0);
    // gz-sim's names: <topic>, <camera_info_topic>, <gz_frame_id>.
    assert_eq!(camera.camera_name, "");
    assert_eq!(camera.image_topic, "camera/image_raw");
    assert_eq!(camera.info_topic, "camera/camera_info");
    assert_eq!(camera.frame_name, "camera_rgb_frame");
    assert_eq!(camera.noise.map(|n| n.stddev), Some(0.007));
    let dd = robot.diff_drive.as_ref().context("no DiffDrive")?;
    assert_eq!(dd.wheel_separation_m, 0.287);
    assert_eq!(robot.lasers.len(), 1);
    // It drives: a metre at 0.2 m/s, straight.
    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::ZERO, 1.0)?;
    let (distance, _) = rover_tests::straight_run(&mut sim, 0.2, 5.0)?;
    assert!(
        (distance - 0.98).abs() <= 0.05,
        "0.2 m/s for 5 s moved {distance} m; expected 0.98 m within 5 cm"
    );
    Ok(())
}

#[test]
fn turtlebot3_world_loads_with_fuel_sun_and_ground_plane_as_rovers() -> Result<()> {
    let Some(dir) = tb3_gz() else {
        return Ok(());
    };
    let path = dir.join("worlds/turtlebot3_world.world");
    let resources = ResourcePaths::default().with_model_path(dir.join("models"));
    let world = rover_sim::model::World::load_with(&path, &resources)?;
    // The Fuel Sun is Gazebo's sun (its light direction); the Fuel Ground Plane is rover's
    // ground; the gz-sim world systems need nothing; the world's model:// obstacles load.
    assert_eq!(world.sun_direction, [-0.5, 0.1, -0.9]);
    assert_eq!(world.physics.step_hz, 1000.0);
    let names: Vec<&str> = world.models.iter().map(|m| m.name.as_str()).collect();
    assert!(
        names.iter().any(|n| n.starts_with("turtlebot3_world")),
        "{names:?}"
    );
    let collisions: usize = world
        .models
        .iter()
        .flat_map(|m| &m.links)
        .map(|l| l.collisions.len())
        .sum();
    assert!(
        collisions >= 9,
        "{collisions} collision shapes; expected the world's pillars and walls"
    );
    assert!(world.models.iter().all(|m| m.is_static));

    // A Fuel model that is no built-in and not on this machine: a located error.
    let tmp = tempfile::tempdir()?;
    let bad = tmp.path().join("fuel.world");
    std::fs::write(
        &bad,
        "<?xml version=\"1.0\"?>\n<sdf version=\"1.8\">\n  <world name=\"w\">\n    <include>\n      <uri>https://fuel.gazebosim.org/1.0/OpenRobotics/models/Cafe table</uri>\n    </include>\n  </world>\n</sdf>\n",
    )?;
    let err = match rover_sim::model::World::load_with(&bad, &resources) {
        Ok(_) => anyhow::bail!("loaded a world whose Fuel model is nowhere"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("fuel.world:5"), "{err}");
    assert!(err.contains("Cafe table"), "{err}");
    assert!(err.contains("does not download at run time"), "{err}");
    Ok(())
}

/// The tutorial car written with gz-sim systems (my_robot_gz.urdf) and with gazebo_ros's
/// plugins (my_robot_laser.urdf.xacro).
fn tutorial_cars() -> Result<(RobotModel, RobotModel)> {
    let gz = RobotModel::load(&rover_tests::repo("assets/robots/my_robot_gz.urdf"))?;
    let classic = RobotModel::load(&rover_tests::repo(
        "assets/robots/my_robot_laser.urdf.xacro",
    ))?;
    Ok((gz, classic))
}

/// The two files describe one body: the same links (inertials, shapes, where they sit,
/// friction) and joints.
#[test]
fn the_tutorial_cars_gz_file_has_the_classic_body() -> Result<()> {
    let (gz, classic) = tutorial_cars()?;
    assert_eq!(gz.links.len(), classic.links.len());
    for (a, b) in gz.links.iter().zip(&classic.links) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.inertial, b.inertial, "{}", a.name);
        assert_eq!(a.collisions, b.collisions, "{}", a.name);
        assert_eq!(a.visuals, b.visuals, "{}", a.name);
        assert_eq!(a.friction, b.friction, "{}", a.name);
    }
    assert_eq!(gz.joints, classic.joints);
    let (g, c) = (
        gz.diff_drive.as_ref().context("gz drive")?,
        classic.diff_drive.as_ref().context("classic drive")?,
    );
    assert_eq!(g.plugin, DrivePlugin::GzSim);
    assert_eq!(
        (g.wheel_separation_m, g.wheel_diameter_m, g.wheel_torque_nm),
        (c.wheel_separation_m, c.wheel_diameter_m, c.wheel_torque_nm)
    );
    Ok(())
}

/// A scripted 10 s run: forward, then a turn added, the turn dropped, a stop. Each change
/// moves the speed or the turn rate, not both, so gazebo_ros's ramp on the rim speed and
/// gz-sim's limits on the body's speeds ask the same of the wheels.
const SCRIPT: [(f64, f64, f64); 4] = [
    (0.4, 0.0, 3.0),
    (0.4, 0.8, 3.0),
    (0.4, 0.0, 2.0),
    (0.0, 0.0, 2.0),
];

fn scripted_path(robot: RobotModel) -> Result<Vec<[f64; 3]>> {
    let mut sim = flat_sim(robot)?;
    let mut path = Vec::new();
    for (v, w, seconds) in SCRIPT {
        let chunks = (seconds / 0.25).round() as usize;
        for _ in 0..chunks {
            drive(&mut sim, Twist::new(v, w), 0.25)?;
            let g = sim.ground_truth();
            path.push([g.x_m, g.y_m, g.yaw_rad]);
        }
    }
    Ok(path)
}

#[test]
fn the_gz_car_drives_the_classic_cars_trajectory_within_a_centimetre() -> Result<()> {
    let (gz, classic) = tutorial_cars()?;
    let a = scripted_path(gz)?;
    let b = scripted_path(classic)?;
    assert_eq!(a.len(), 40);
    let mut worst = 0.0_f64;
    for (p, q) in a.iter().zip(&b) {
        worst = worst.max((p[0] - q[0]).hypot(p[1] - q[1]));
    }
    let end = a.last().context("no path")?;
    println!(
        "gz car ends at ({:.3}, {:.3}, {:.1} deg); worst gap to the classic car {:.2} mm",
        end[0],
        end[1],
        end[2].to_degrees(),
        worst * 1000.0
    );
    // The run goes somewhere: 2 m forward and a 138 degree turn.
    assert!(end[0].hypot(end[1]) > 1.5, "{end:?}");
    assert!(worst < 0.01, "the trajectories differ by {worst} m");
    Ok(())
}

#[test]
fn the_gz_cars_gpu_lidar_scans_as_its_classic_ray_sensor() -> Result<()> {
    let (gz, classic) = tutorial_cars()?;
    let (lg, lc) = (&gz.lasers[0], &classic.lasers[0]);
    assert_eq!(
        (
            lg.samples,
            lg.min_angle_rad,
            lg.max_angle_rad,
            lg.update_rate_hz
        ),
        (
            lc.samples,
            lc.min_angle_rad,
            lc.max_angle_rad,
            lc.update_rate_hz
        )
    );
    assert_eq!(
        (
            lg.range_min_m,
            lg.range_max_m,
            lg.range_resolution_m,
            lg.noise
        ),
        (
            lc.range_min_m,
            lc.range_max_m,
            lc.range_resolution_m,
            lc.noise
        )
    );
    assert_eq!(
        (lg.link_from_sensor, lg.frame_name.as_str()),
        (lc.link_from_sensor, "base_scan")
    );
    let world_text = "[[box]]\nname = \"crate\"\nsize_m = [0.6, 0.6, 0.6]\nposition_m = [1.5, 0.4]\n\n[[cylinder]]\nname = \"post\"\nradius_m = 0.1\nlength_m = 1.0\nposition_m = [-1.0, -1.2]\n";
    let scan = |robot: RobotModel| -> Result<Vec<f32>> {
        let world = rover_sim::model::World::from_str(
            world_text,
            &rover_tests::repo("worlds/scan_compare.toml"),
        )?;
        let mut sim = rover_sim::physics::Simulation::new(
            world,
            robot,
            &rover_sim::physics::SimOptions::default(),
        )?;
        drive(&mut sim, Twist::ZERO, 0.5)?;
        let mut laser = rover_sim::sensors::LaserSensor::new(&sim, 0)?;
        Ok(laser.scan_now(&sim).ranges_m.clone())
    };
    let (a, b) = (scan(gz)?, scan(classic)?);
    let hits = a.iter().filter(|r| r.is_finite()).count();
    assert!(
        hits > 20,
        "only {hits} returns: the crate and the post should be seen"
    );
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(
            x == y || (x - y).abs() < 1e-4,
            "ray {i}: {x} m (gz) vs {y} m (classic)"
        );
    }
    Ok(())
}

/// gz-sim's other sensors, with and without `<topic>` and `<gz_frame_id>`: each kind's topics
/// as gz-sim names them.
#[test]
fn gz_sim_sensor_kinds_take_gz_sims_topic_names() -> Result<()> {
    let text = r#"<sdf version="1.9">
<model name="bot">
  <link name="base"><inertial><mass>1</mass></inertial>
    <collision name="c"><geometry><box><size>0.2 0.2 0.1</size></box></geometry></collision>
    <sensor name="rgbd" type="rgbd_camera"><topic>cam</topic>
      <camera><image><width>64</width><height>48</height></image></camera></sensor>
    <sensor name="depth" type="depth_camera">
      <camera><image><width>64</width><height>48</height></image>
        <clip><near>0.1</near><far>8</far></clip></camera></sensor>
    <sensor name="vlp" type="gpu_lidar"><topic>lidar</topic><gz_frame_id>base</gz_frame_id>
      <lidar><scan><horizontal><samples>90</samples><min_angle>-3.14</min_angle><max_angle>3.14</max_angle></horizontal>
        <vertical><samples>8</samples><min_angle>-0.2</min_angle><max_angle>0.2</max_angle></vertical></scan>
        <range><min>0.2</min><max>30</max></range></lidar></sensor>
    <sensor name="gps" type="navsat"><topic>navsat</topic><update_rate>4</update_rate></sensor>
    <sensor name="bump" type="contact"><contact><collision>c</collision></contact></sensor>
  </link>
</model>
</sdf>"#;
    let robot = RobotModel::from_str(text, std::path::Path::new("bot.sdf"))?;
    let rgbd = &robot.cameras[0];
    let d = rgbd.depth.as_ref().context("rgbd depth")?;
    assert_eq!(
        (
            rgbd.image_topic.as_str(),
            rgbd.info_topic.as_str(),
            d.image_topic.as_str(),
            d.cloud_topic.as_str()
        ),
        (
            "cam/image",
            "cam/camera_info",
            "cam/depth_image",
            "cam/points"
        )
    );
    assert_eq!(rgbd.frame_name, "bot::base::rgbd");
    let depth = &robot.cameras[1];
    let d = depth.depth.as_ref().context("depth camera depth")?;
    let default = "/world/default/model/bot/link/base/sensor/depth/depth_image";
    assert_eq!(d.image_topic, default);
    assert_eq!(d.cloud_topic, format!("{default}/points"));
    assert_eq!(
        depth.info_topic,
        "/world/default/model/bot/link/base/sensor/depth/camera_info"
    );
    // The cloud keeps what the clip planes allow.
    assert_eq!((d.cloud_cutoff_m, d.cloud_cutoff_max_m), (0.1, 8.0));
    let lidar = &robot.lidars[0];
    assert_eq!(lidar.vertical_samples, 8);
    assert_eq!(
        (lidar.rays.topic.as_str(), lidar.rays.frame_name.as_str()),
        ("lidar/points", "base")
    );
    let gps = &robot.gpss[0];
    assert_eq!((gps.topic.as_str(), gps.update_rate_hz), ("navsat", 4.0));
    assert!(gps.velocity_topic.is_empty());
    assert!(
        robot
            .not_simulated
            .iter()
            .any(|s| s.starts_with("sensor \"bump\" (gz-sim contact")),
        "{:?}",
        robot.not_simulated
    );
    Ok(())
}

/// A one-joint arm on a box (and a tool on it), written with gz-sim's joint controller
/// systems: tests/tests/gz_arm.sdf.
fn gz_arm() -> Result<String> {
    Ok(std::fs::read_to_string(rover_tests::repo(
        "tests/tests/gz_arm.sdf",
    ))?)
}

#[test]
fn gz_sims_joint_controllers_move_the_joints() -> Result<()> {
    let text = gz_arm()?;
    let robot = RobotModel::from_str(&text, std::path::Path::new("bot.sdf"))?;
    let config = robot.controllers.as_ref().context("no controllers")?;
    let names: Vec<(&str, Option<&str>)> = config
        .controllers
        .iter()
        .map(|c| (c.name.as_str(), c.topic.as_deref()))
        .collect();
    assert_eq!(
        names,
        [
            (
                "arm_joint_position_controller",
                Some("/model/bot/joint/arm_joint/0/cmd_pos")
            ),
            ("tool_joint_velocity_controller", Some("tool_speed"))
        ]
    );
    let arm = robot.joint_id("arm_joint").context("arm_joint")?;
    let tool = robot.joint_id("tool_joint").context("tool_joint")?;
    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::ZERO, 0.5)?;
    sim.command_controller("arm_joint_position_controller", 0.8)?;
    sim.command_controller("tool_joint_velocity_controller", 0.5)?;
    drive(&mut sim, Twist::ZERO, 3.0)?;
    let at = sim.joint_state(arm).context("arm state")?.position;
    assert!(
        (at - 0.8).abs() < 0.03,
        "arm_joint at {at} rad; commanded 0.8"
    );
    let speed = sim.joint_state(tool).context("tool state")?.velocity;
    assert!(
        (speed - 0.5).abs() < 0.05,
        "tool_joint at {speed} rad/s; commanded 0.5"
    );
    // A system naming a joint the robot does not have: refused at the system's line.
    let bad = text.replace(
        "<joint_name>tool_joint</joint_name>",
        "<joint_name>tool</joint_name>",
    );
    let err = match RobotModel::from_str(&bad, std::path::Path::new("bot.sdf")) {
        Ok(_) => anyhow::bail!("loaded a controller of a missing joint"),
        Err(e) => e.to_string(),
    };
    let line = bad
        .lines()
        .position(|l| l.contains("gz-sim-joint-controller-system"))
        .map_or(0, |i| i + 1);
    assert!(err.contains(&format!("bot.sdf:{line}:")), "{err}");
    assert!(err.contains("<joint_name>tool</joint_name>"), "{err}");
    Ok(())
}

/// gz_ros2_control with its ros2_control controllers file (controller_manager's format): the
/// joint state broadcaster, a trajectory controller over both joints, run as rover's own; a
/// controller type rover does not run is refused at its line.
#[test]
fn gz_ros2_control_runs_its_ros2_control_controllers() -> Result<()> {
    let tmp = tempfile::tempdir()?;
    let text = gz_arm()?;
    // The same arm, its joints driven by gz_ros2_control instead of gz-sim's joint systems.
    let start = text
        .find("  <plugin filename=\"gz-sim-joint-position-controller-system\"")
        .context("the arm's systems")?;
    let end = text
        .find("  <plugin filename=\"gz-sim-joint-state-publisher-system\"")
        .context("the arm's systems")?;
    let model = format!(
        "{}  <plugin filename=\"gz_ros2_control-system\" name=\"gz_ros2_control::GazeboSimROS2ControlPlugin\">\n    <parameters>controllers.yaml</parameters>\n  </plugin>\n{}",
        &text[..start],
        &text[end..]
    );
    std::fs::write(tmp.path().join("bot.sdf"), &model)?;
    let yaml = "controller_manager:\n  ros__parameters:\n    update_rate: 100\n    joint_state_broadcaster:\n      type: joint_state_broadcaster/JointStateBroadcaster\n    arm_controller:\n      type: joint_trajectory_controller/JointTrajectoryController\n\narm_controller:\n  ros__parameters:\n    joints:\n      - arm_joint\n      - tool_joint\n    command_interfaces:\n      - position\n    state_interfaces:\n      - position\n      - velocity\n";
    std::fs::write(tmp.path().join("controllers.yaml"), yaml)?;
    let robot = RobotModel::load(&tmp.path().join("bot.sdf"))?;
    let config = robot.controllers.as_ref().context("no controllers")?;
    let kinds: Vec<(&str, &str)> = config
        .controllers
        .iter()
        .map(|c| (c.name.as_str(), c.type_name.as_str()))
        .collect();
    assert_eq!(
        kinds,
        [
            (
                "joint_state_broadcaster",
                "joint_state_controller/JointStateController"
            ),
            (
                "arm_controller",
                "position_controllers/JointTrajectoryController"
            )
        ]
    );
    let (arm, tool) = (
        robot.joint_id("arm_joint").context("arm_joint")?,
        robot.joint_id("tool_joint").context("tool_joint")?,
    );
    let mut sim = flat_sim(robot)?;
    drive(&mut sim, Twist::ZERO, 0.5)?;
    let trajectory = rover_sim::physics::JointTrajectory {
        start_s: 0.0,
        joint_names: vec!["arm_joint".into(), "tool_joint".into()],
        points: vec![rover_sim::physics::TrajectoryPoint {
            positions: vec![0.6, -0.4],
            time_from_start_s: 1.5,
            ..Default::default()
        }],
    };
    sim.follow_trajectory("arm_controller", &trajectory)?;
    drive(&mut sim, Twist::ZERO, 3.0)?;
    let a = sim.joint_state(arm).context("arm")?.position;
    let t = sim.joint_state(tool).context("tool")?.position;
    assert!(
        (a - 0.6).abs() < 0.02 && (t + 0.4).abs() < 0.02,
        "joints at {a} and {t} rad; the trajectory ends at 0.6 and -0.4"
    );
    // The controllers file with its trajectory controller's type replaced by `kind`: the
    // robot's load error.
    let refused = |kind: &str| -> Result<String> {
        let changed = yaml.replace(
            "joint_trajectory_controller/JointTrajectoryController",
            kind,
        );
        std::fs::write(tmp.path().join("controllers.yaml"), &changed)?;
        match RobotModel::load(&tmp.path().join("bot.sdf")) {
            Ok(_) => anyhow::bail!("loaded a {kind}"),
            Err(e) => Ok(e.to_string()),
        }
    };
    // A type rover does not run: refused at the line of its type.
    let err = refused("diff_drive_controller/DiffDriveController")?;
    assert!(err.contains("controllers.yaml:7"), "{err}");
    assert!(
        err.contains("'diff_drive_controller/DiffDriveController' is not one rover runs"),
        "{err}"
    );
    // A group controller over two joints: rover runs one joint per controller.
    let err = refused("position_controllers/JointGroupPositionController")?;
    assert!(err.contains("2 joints"), "{err}");
    Ok(())
}
